"""The MotionBenchMaker problem fetcher and parser (tests/data/mbm.py) against facts of the data itself.

The problems come from vamp-planner 0.6.4's sdist on PyPI (downloaded once into build/bench-data; the test is
skipped when that fails). Facts checked without trusting the parser: 7 scenes x 100 problems; the Panda's joint
limits read here from panda.urdf; positive box and cylinder sizes and unit quaternions; values read by eye from
box_panda/request0001.yaml and scene0001.yaml; MoveIt's [height, radius] cylinder order; the world pose of a
primitive whose object has its own pose; problems.txt reading back exactly what the YAML holds. No server.
"""
import importlib.util
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytest.importorskip("yaml", reason="pyyaml (test extra) is not installed: pip install 'graspsim[test]'")

REPO_ROOT = Path(__file__).resolve().parents[2]
SCENES = {"bookshelf_small", "bookshelf_tall", "bookshelf_thin", "box", "cage", "table_pick", "table_under_pick"}
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]   # panda.srdf's group state "ready"


def _load_mbm():
    spec = importlib.util.spec_from_file_location("mbm_data", REPO_ROOT / "tests" / "data" / "mbm.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mbm_data"] = module
    spec.loader.exec_module(module)
    return module


mbm = _load_mbm()


@pytest.fixture(scope="module")
def panda_dir():
    try:
        return mbm.fetch()
    except (OSError, RuntimeError) as err:
        pytest.skip(f"cannot fetch vamp-planner {mbm.VERSION} from PyPI: {err}")


@pytest.fixture(scope="module")
def problems(panda_dir):
    return mbm.read_problems_txt(panda_dir / "problems.txt")


def urdf_limits(path: Path):
    joints = {j.get("name"): j.find("limit") for j in ET.parse(path).getroot().iter("joint")}
    return [(float(joints[f"panda_joint{i}"].get("lower")), float(joints[f"panda_joint{i}"].get("upper")))
            for i in range(1, 8)]


def test_seven_scenes_of_one_hundred(panda_dir, problems):
    assert len(problems) == 700
    for scene in SCENES:
        indices = sorted(p.index for p in problems if p.scene == scene)
        assert indices == list(range(1, 101)), scene
        assert len(list((panda_dir / "problems" / f"{scene}_panda").glob("scene*.yaml"))) == 100
    for name in ("panda.urdf", "panda_spherized.urdf", "panda.srdf"):
        assert (panda_dir / name).is_file()


def test_configurations_within_the_urdf_limits(panda_dir, problems):
    limits = urdf_limits(panda_dir / "panda.urdf")
    assert limits == urdf_limits(panda_dir / "panda_spherized.urdf")
    for p in problems:
        for kind, q in (("start", p.start), ("goal", p.goal)):
            assert len(q) == 7
            for i, (value, (lo, hi)) in enumerate(zip(q, limits)):
                assert lo <= value <= hi, f"{p.name} {kind} joint {i + 1}: {value} outside [{lo}, {hi}]"
    # every problem starts at "ready" except table_under_pick's, which start under the table
    assert all((p.start == READY) == (p.scene != "table_under_pick") for p in problems)


def test_obstacle_sizes_and_quaternions(problems):
    kinds = {"box": 0, "cylinder": 0, "sphere": 0}
    for p in problems:
        assert p.obstacles, p.name
        assert len({o.id for o in p.obstacles}) == len(p.obstacles), f"{p.name}: repeated obstacle ids"
        for o in p.obstacles:
            kinds[o.kind] += 1
            assert len(o.size) == {"box": 3, "cylinder": 2, "sphere": 1}[o.kind]
            assert all(s > 0 and math.isfinite(s) for s in o.size), f"{p.name} {o.id}: {o.size}"
            assert abs(math.sqrt(sum(c * c for c in o.orientation)) - 1) < 1e-9, f"{p.name} {o.id}"
            assert all(math.isfinite(c) and abs(c) < 3 for c in o.position), f"{p.name} {o.id}: {o.position}"
    assert kinds == {"box": 5500, "cylinder": 2700, "sphere": 0}


def test_values_read_by_eye(problems):
    """box_panda/request0001.yaml and scene0001.yaml as printed by `cat`."""
    p = next(p for p in problems if p.scene == "box" and p.index == 1)
    assert p.goal == [0.4534448383669427, 1.7628, 0.1941262264518609, -0.8667848896139277, -0.3798524112731043,
                      2.606927984171601, -0.1898611792470702]
    can = next(o for o in p.obstacles if o.id == "Can1")   # dimensions: [0.14, 0.03] = [height, radius]
    assert (can.kind, can.size) == ("cylinder", (0.03, 0.14))
    assert can.position == (0.5408380884576693, 0.3580155146897772, -0.3762264457751537)
    assert can.orientation == (0.0, 0.0, 0.07406844364750122, 0.9972531602635496)
    cap = next(o for o in p.obstacles if o.id == "side_cap")
    assert (cap.kind, cap.size) == ("box", (0.7, 0.7, 0.04))
    assert cap.orientation == (-0.0283616206065852, 0.3818591884381666, 0.06842333535374601, 0.9212477548743235)


def test_object_pose_composes_with_the_primitive_pose():
    """MoveIt: world pose of a primitive = object pose * primitive pose. Object at (1, 0, 0) turned 90° about z,
    a sphere 0.5 m along the object's x and a box turned another 90°: the sphere at (1, 0.5, 0), the box at
    (1, 0, 0) turned 180° (quaternion (0, 0, 1, 0) up to sign)."""
    h = math.sqrt(0.5)
    scene = {"world": {"collision_objects": [{
        "id": "thing", "pose": {"position": [1, 0, 0], "orientation": [0, 0, h, h]},
        "primitives": [{"type": "sphere", "dimensions": [0.1]}, {"type": "box", "dimensions": [1, 2, 3]}],
        "primitive_poses": [{"position": [0.5, 0, 0], "orientation": [0, 0, 0, 1]},
                            {"position": [0, 0, 0], "orientation": [0, 0, h, h]}]}]}}
    sphere, box = mbm._obstacles(scene, "synthetic")
    assert (sphere.id, sphere.kind, sphere.size) == ("thing_0", "sphere", (0.1,))
    assert sphere.position == pytest.approx((1.0, 0.5, 0.0), abs=1e-15)
    assert (box.id, box.size) == ("thing_1", (1.0, 2.0, 3.0))
    assert box.position == pytest.approx((1.0, 0.0, 0.0), abs=1e-15)
    assert [abs(c) for c in box.orientation] == pytest.approx([0, 0, 1, 0], abs=1e-15)


def test_problems_txt_reads_back_the_yaml(panda_dir, problems):
    from_yaml = mbm.load_yaml_problems(panda_dir)
    assert [p.name for p in from_yaml] == [p.name for p in problems]
    assert from_yaml == problems   # repr floats round-trip exactly


def test_fetch_is_idempotent(panda_dir):
    before = (panda_dir / "problems.txt").stat().st_mtime_ns
    assert mbm.fetch() == panda_dir
    assert (panda_dir / "problems.txt").stat().st_mtime_ns == before
