"""scripts/check_includes.py (make check-includes, first in make test) fails on what the folder map and the
namespace rule of docs/architecture.md forbid, and passes a tree that follows them: run on a small tree made here."""
import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "check_includes.py"

MAP = """# Architecture
## Folder map
| Folder | Its one job | May include | gRPC / protobuf |
|---|---|---|---|
| `rpc` | the edge | `grasp` `core` | grpcpp, .pb.h |
| `grasp` | grasps | `core` | — |
| `core` | basics | — | — |
"""


def tree(tmp_path: Path, files: dict) -> Path:
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "architecture.md").write_text(MAP)
    (tmp_path / "drivers").mkdir()
    for folder in ("rpc", "grasp", "core"):
        (tmp_path / "server" / "src" / folder).mkdir(parents=True)
    for name, text in files.items():
        (tmp_path / "server" / "src" / name).write_text(text)
    return tmp_path


def check(root: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT)], env={**os.environ, "GRASPSIM_CHECK_ROOT": str(root)},
                          capture_output=True, text=True)


GOOD = {"core/math.h": "namespace graspsim {\nstruct Pose {\n};\n}\n",
        "grasp/planner.h": '#include "core/math.h"\nnamespace graspsim::grasp {\nstruct ClosingParams {\n};\n}\n',
        "rpc/service.cpp": '#include <grpcpp/grpcpp.h>\n#include "grasp/planner.h"\nnamespace graspsim::rpc {}\n'}


def test_a_tree_that_follows_the_map_passes(tmp_path):
    result = check(tree(tmp_path, GOOD))
    assert result.returncode == 0, result.stdout
    assert "0 failed" in result.stdout


def test_an_upward_include_fails_naming_the_line(tmp_path):
    result = check(tree(tmp_path, {**GOOD, "core/bad.cpp": '#include "grasp/planner.h"\n'}))
    assert result.returncode == 1
    assert "server/src/core/bad.cpp:1" in result.stdout and "core may not include grasp" in result.stdout


def test_grpc_below_rpc_fails(tmp_path):
    result = check(tree(tmp_path, {**GOOD, "grasp/net.cpp": "#include <grpcpp/grpcpp.h>\n"}))
    assert result.returncode == 1 and "grasp may not include gRPC headers" in result.stdout


def test_another_folders_namespace_fails(tmp_path):
    result = check(tree(tmp_path, {**GOOD, "grasp/x.h": "namespace graspsim::rpc {\nint x;\n}\n"}))
    assert result.returncode == 1 and "namespace graspsim::rpc belongs to rpc/, not grasp/" in result.stdout


def test_one_type_name_in_two_namespaces_fails(tmp_path):
    twice = {**GOOD, "core/sim.h": "namespace graspsim {\nstruct ClosingParams {\n};\n}\n"}
    result = check(tree(tmp_path, twice))
    assert result.returncode == 1 and "type ClosingParams is declared in 2 namespaces" in result.stdout
    # A forward declaration is not a second type.
    forward = {**GOOD, "core/sim.h": "namespace graspsim {\nstruct ClosingParams;\n}\n"}
    (tmp_path / "f").mkdir()
    assert check(tree(tmp_path / "f", forward)).returncode == 0
