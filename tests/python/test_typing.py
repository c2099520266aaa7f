"""The Python client's static typing (issue 24): `python -m mypy` run from clients/python checks the package with the
configuration of its pyproject.toml ([tool.mypy]: strict, the generated graspsim/v1 excluded, grpc/protobuf/tqdm typed
by their stub packages of the "test" extra) and must find nothing."""
import subprocess
import sys
from pathlib import Path

import pytest

CLIENT = Path(__file__).resolve().parents[2] / "clients" / "python"


@pytest.mark.skipif(sys.version_info < (3, 10), reason="the pinned mypy (the client's test extra) needs Python >= 3.10")
def test_mypy_strict_on_the_package_is_clean():
    run = subprocess.run([sys.executable, "-m", "mypy"], cwd=CLIENT, capture_output=True, text=True, timeout=600)
    output = run.stdout + run.stderr
    assert run.returncode == 0, f"mypy --strict (clients/python/pyproject.toml [tool.mypy]):\n{output}"
    assert "Success: no issues found" in output, output
