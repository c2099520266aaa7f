"""MotionBenchMaker (MBM) Panda problems, from the vamp-planner 0.6.4 source package on PyPI (nothing vendored).

MotionBenchMaker (Chamzas et al., RA-L 2022) generated 7 scenes x 100 problems for the Franka Panda; VAMP (Thomason,
Kingston, Kavraki, ICRA 2024) ships them as MoveIt YAML in its sdist, with the Panda's URDF, VAMP's sphere model of
it (panda_spherized.urdf) and MoveIt's SRDF. `fetch()` downloads the sdist into <repo>/build/bench-data/ (its URL
and SHA-256 from PyPI's simple index, PEP 691 JSON; the SHA-256 is checked), extracts resources/panda/ only into
build/bench-data/mbm/panda/, unpacks problems.tar.bz2 there as problems/<scene>_panda/{sceneNNNN,requestNNNN}.yaml
and writes problems.txt (below) for C++ tests and benchmarks that should not parse YAML. Work happens in a
".partial" directory renamed when complete, so an interrupted fetch is redone and a finished one is skipped.

    build/venv/bin/python tests/data/mbm.py fetch [--data-dir DIR]    # prints the panda directory

problems.txt: plain text, one block per problem, in scene order (SCENES) then index 1..100; tokens separated by
single spaces, numbers as Python's repr of the float (round-trips exactly); SI units (m, rad).

    problem <scene> <index>                         scene without the "_panda" suffix, index as in requestNNNN
    start q1 q2 q3 q4 q5 q6 q7                       panda_joint1..7 (the YAML's finger values are not kept)
    goal q1 q2 q3 q4 q5 q6 q7                        the goal's joint constraints, panda_joint1..7
    box <id> sx sy sz px py pz qx qy qz qw          full edge lengths; pose of the box centre, world frame
    cylinder <id> radius length px py pz qx qy qz qw  axis = the local z axis, centred on the pose
    sphere <id> radius px py pz
    end

Quaternions are (x, y, z, w) as in the YAML (ROS order; graspsim's API is (w, x, y, z)). Obstacle ids are the
MoveIt collision object ids (an object with several primitives gets "<id>_<k>", k from 0). The robot's base frame
(panda_link0) is the world frame: every scene's virtual joint and fixed frame transforms are the identity (checked).

Conversion from MoveIt: shape_msgs/SolidPrimitive dimensions are BOX [x, y, z] full sizes, CYLINDER [height,
radius] (in that order; the MBM cans are [0.14, 0.03]) and SPHERE [radius]; an object's world pose is its `pose`
(when the message has one) composed with each primitive_pose.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import shutil
import sys
import tarfile
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Sequence, Tuple

REPO = Path(__file__).resolve().parents[2]
DEFAULT_DATA_DIR = REPO / "build" / "bench-data"
PROJECT, VERSION = "vamp-planner", "0.6.4"
SDIST = f"vamp_planner-{VERSION}.tar.gz"
SIMPLE_INDEX = f"https://pypi.org/simple/{PROJECT}/"
RESOURCES = f"vamp_planner-{VERSION}/resources/panda/"
SCENES = ["bookshelf_small", "bookshelf_tall", "bookshelf_thin", "box", "cage", "table_pick", "table_under_pick"]
PROBLEMS_PER_SCENE = 100
ARM_JOINTS = [f"panda_joint{i}" for i in range(1, 8)]
HTTP_TIMEOUT_S = 60


@dataclass
class Obstacle:
    kind: str                      # "box" | "cylinder" | "sphere"
    id: str
    size: Tuple[float, ...]        # box (sx, sy, sz) full; cylinder (radius, length); sphere (radius,)
    position: Tuple[float, float, float]
    orientation: Tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)   # (x, y, z, w)


@dataclass
class Problem:
    scene: str
    index: int
    start: List[float]
    goal: List[float]
    obstacles: List[Obstacle] = field(default_factory=list)

    @property
    def name(self) -> str:
        return f"{self.scene}/{self.index:04d}"


def log(*parts) -> None:
    print(*parts, file=sys.stderr, flush=True)


# --- download and extraction ---------------------------------------------------------------------------------
def _sdist_location() -> Tuple[str, str]:
    """(url, sha256) of the sdist from PyPI's simple index (JSON form, PEP 691)."""
    request = urllib.request.Request(SIMPLE_INDEX, headers={"Accept": "application/vnd.pypi.simple.v1+json"})
    with urllib.request.urlopen(request, timeout=HTTP_TIMEOUT_S) as reply:
        index = json.load(reply)
    for entry in index.get("files", []):
        if entry.get("filename") == SDIST:
            return entry["url"], entry["hashes"]["sha256"]
    raise RuntimeError(f"{SDIST} is not listed on {SIMPLE_INDEX}")


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _download_sdist(data_dir: Path) -> Path:
    target = data_dir / SDIST
    url, sha256 = _sdist_location()
    if target.is_file() and _sha256(target) == sha256:
        return target
    partial = target.with_name(target.name + ".partial")
    log(f"mbm: downloading {url} into {data_dir}")
    with urllib.request.urlopen(url, timeout=HTTP_TIMEOUT_S) as reply, open(partial, "wb") as out:
        shutil.copyfileobj(reply, out, 1 << 20)
    got = _sha256(partial)
    if got != sha256:
        partial.unlink()
        raise RuntimeError(f"{SDIST}: SHA-256 {got} is not PyPI's {sha256}")
    partial.replace(target)
    return target


def _extract(archive: tarfile.TarFile, members, dest: Path) -> None:
    if hasattr(tarfile, "data_filter"):  # refuses absolute paths, "..", links out of dest (Python >= 3.11.4)
        archive.extractall(dest, members=members, filter="data")
        return
    for m in members:
        if m.name.startswith("/") or ".." in Path(m.name).parts or not (m.isfile() or m.isdir()):
            raise RuntimeError(f"unsafe archive member {m.name!r}")
    archive.extractall(dest, members=members)


def fetch(data_dir: Path = DEFAULT_DATA_DIR) -> Path:
    """The panda directory (panda.urdf, panda_spherized.urdf, panda.srdf, meshes/, problems/, problems.txt),
    downloaded and written on first use."""
    panda = Path(data_dir) / "mbm" / "panda"
    if (panda / "problems.txt").is_file():
        return panda
    data_dir = Path(data_dir)
    data_dir.mkdir(parents=True, exist_ok=True)
    sdist = _download_sdist(data_dir)
    partial = panda.with_name("panda.partial")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    with tarfile.open(sdist, "r:gz") as archive:
        members = []
        for m in archive:
            if m.name.startswith(RESOURCES) and m.name != RESOURCES:
                m.name = m.name[len(RESOURCES):]
                members.append(m)
        if not members:
            raise RuntimeError(f"{sdist} has no {RESOURCES}")
        _extract(archive, members, partial)
    with tarfile.open(partial / "problems.tar.bz2", "r:bz2") as archive:
        _extract(archive, archive.getmembers(), partial)
    problems = load_yaml_problems(partial)
    write_problems_txt(problems, partial / "problems.txt")
    shutil.rmtree(panda, ignore_errors=True)
    partial.rename(panda)
    log(f"mbm: {len(problems)} problems in {panda}")
    return panda


# --- MoveIt YAML ---------------------------------------------------------------------------------------------
def _yaml():
    try:
        import yaml
    except ImportError:
        raise SystemExit("tests/data/mbm.py needs PyYAML to read the MotionBenchMaker problems: "
                         f"{REPO}/build/venv/bin/pip install -e '{REPO}/clients/python[bench]' (or [test])") from None
    return yaml


def _quat_mul(a, b):
    """Hamilton product of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def _rotate(q, v):
    x, y, z, _ = _quat_mul(_quat_mul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


def _compose(outer, inner):
    """outer ∘ inner, poses as (position, quaternion xyzw)."""
    (p0, q0), (p1, q1) = outer, inner
    r = _rotate(q0, p1)
    return (tuple(p0[i] + r[i] for i in range(3)), _quat_mul(q0, q1))


def _pose(message) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
    position = tuple(float(v) for v in message.get("position", (0, 0, 0)))
    orientation = tuple(float(v) for v in message.get("orientation", (0, 0, 0, 1)))
    if len(position) != 3 or len(orientation) != 4:
        raise ValueError(f"bad pose {message}")
    return position, orientation


def _is_identity(transform) -> bool:
    return [float(v) for v in transform.get("translation", [0, 0, 0])] == [0, 0, 0] and \
        [float(v) for v in transform.get("rotation", [0, 0, 0, 1])] == [0, 0, 0, 1]


def _obstacles(scene_yaml, where: str) -> List[Obstacle]:
    for t in scene_yaml.get("robot_state", {}).get("multi_dof_joint_state", {}).get("transforms", []):
        if not _is_identity(t):
            raise ValueError(f"{where}: the robot's virtual joint is not at the origin ({t})")
    for t in scene_yaml.get("fixed_frame_transforms", []) or []:
        if not _is_identity(t.get("transform", {})):
            raise ValueError(f"{where}: fixed frame transform {t} is not the identity")
    out = []
    for obj in scene_yaml["world"].get("collision_objects", []):
        if obj.get("meshes") or obj.get("planes"):
            raise ValueError(f"{where}: object {obj['id']} has meshes or planes (not handled)")
        base = _pose(obj["pose"]) if "pose" in obj else ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        primitives, poses = obj.get("primitives", []), obj.get("primitive_poses", [])
        if len(primitives) != len(poses):
            raise ValueError(f"{where}: object {obj['id']}: {len(primitives)} primitives, {len(poses)} poses")
        for k, (prim, pose) in enumerate(zip(primitives, poses)):
            oid = obj["id"] if len(primitives) == 1 else f"{obj['id']}_{k}"
            position, orientation = _compose(base, _pose(pose))
            dims = [float(v) for v in prim["dimensions"]]
            kind = prim["type"].lower()
            if kind == "box" and len(dims) == 3:
                size = tuple(dims)
            elif kind == "cylinder" and len(dims) == 2:   # SolidPrimitive: [CYLINDER_HEIGHT, CYLINDER_RADIUS]
                size = (dims[1], dims[0])
            elif kind == "sphere" and len(dims) == 1:
                size = (dims[0],)
            else:
                raise ValueError(f"{where}: object {oid}: primitive {prim['type']} {dims} not handled")
            out.append(Obstacle(kind, oid, size, position, orientation))
    return out


def _joints(names: Sequence[str], values: Sequence[float], where: str) -> List[float]:
    by_name = dict(zip(names, (float(v) for v in values)))
    missing = [j for j in ARM_JOINTS if j not in by_name]
    if missing:
        raise ValueError(f"{where}: no value for {missing}")
    return [by_name[j] for j in ARM_JOINTS]


def load_yaml_problems(panda_dir: Path) -> List[Problem]:
    """Every problem of problems/<scene>_panda/, parsed from MoveIt's YAML."""
    yaml = _yaml()
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    problems = []
    for scene in SCENES:
        folder = Path(panda_dir) / "problems" / f"{scene}_panda"
        requests = sorted(folder.glob("request*.yaml"))
        if not requests:
            raise RuntimeError(f"no problems in {folder}")
        for request_path in requests:
            index = int(request_path.stem[len("request"):])
            scene_path = folder / f"scene{index:04d}.yaml"
            where = f"{scene}_panda/{request_path.name}"
            with open(request_path) as f:
                request = yaml.load(f, Loader=loader)
            with open(scene_path) as f:
                scene_yaml = yaml.load(f, Loader=loader)
            state = request["start_state"]["joint_state"]
            start = _joints(state["name"], state["position"], where)
            for t in request["start_state"].get("multi_dof_joint_state", {}).get("transforms", []):
                if not _is_identity(t):
                    raise ValueError(f"{where}: the start state's virtual joint is not at the origin ({t})")
            goals = request["goal_constraints"]
            if len(goals) != 1:
                raise ValueError(f"{where}: {len(goals)} goal constraints (one expected)")
            constraints = goals[0]["joint_constraints"]
            goal = _joints([c["joint_name"] for c in constraints], [c["position"] for c in constraints], where)
            problems.append(Problem(scene, index, start, goal, _obstacles(scene_yaml, where)))
    return problems


# --- problems.txt --------------------------------------------------------------------------------------------
def _num(v: float) -> str:
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"non-finite value {v}")
    return repr(v)


def format_problems(problems: Sequence[Problem]) -> str:
    lines = []
    for p in problems:
        lines.append(f"problem {p.scene} {p.index}")
        lines.append("start " + " ".join(map(_num, p.start)))
        lines.append("goal " + " ".join(map(_num, p.goal)))
        for o in p.obstacles:
            if any(c.isspace() for c in o.id) or not o.id:
                raise ValueError(f"{p.name}: obstacle id {o.id!r} is empty or has white space")
            if o.kind == "sphere":
                numbers = [*o.size, *o.position]
            else:
                numbers = [*o.size, *o.position, *o.orientation]
            lines.append(f"{o.kind} {o.id} " + " ".join(map(_num, numbers)))
        lines.append("end")
    return "\n".join(lines) + "\n"


def write_problems_txt(problems: Sequence[Problem], path: Path) -> None:
    tmp = Path(str(path) + ".tmp")
    tmp.write_text(format_problems(problems))
    tmp.replace(path)


_SIZES = {"box": 3, "cylinder": 2, "sphere": 1}


def read_problems_txt(path: Path) -> List[Problem]:
    """problems.txt back into Problems (no YAML needed)."""
    problems, current = [], None
    with open(path) as f:
        for number, line in enumerate(f, 1):
            words = line.split()
            if not words:
                continue
            head = words[0]
            try:
                if head == "problem":
                    current = Problem(words[1], int(words[2]), [], [])
                elif head in ("start", "goal"):
                    values = [float(v) for v in words[1:]]
                    if len(values) != len(ARM_JOINTS):
                        raise ValueError(f"{len(values)} joint values")
                    setattr(current, head, values)
                elif head in _SIZES:
                    n = _SIZES[head]
                    values = [float(v) for v in words[2:]]
                    if len(values) != n + (3 if head == "sphere" else 7):
                        raise ValueError(f"{len(values)} numbers")
                    orientation = (0.0, 0.0, 0.0, 1.0) if head == "sphere" else tuple(values[n + 3:])
                    current.obstacles.append(Obstacle(head, words[1], tuple(values[:n]), tuple(values[n:n + 3]),
                                                      orientation))
                elif head == "end":
                    problems.append(current)
                    current = None
                else:
                    raise ValueError(f"unknown line kind {head!r}")
            except (ValueError, IndexError, AttributeError) as err:
                raise ValueError(f"{path}:{number}: {err}: {line.strip()}") from None
    return problems


def problems_by_scene(problems: Sequence[Problem]) -> Dict[str, List[Problem]]:
    out: Dict[str, List[Problem]] = {}
    for p in problems:
        out.setdefault(p.scene, []).append(p)
    return out


def main(argv) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    fetch_cmd = sub.add_parser("fetch", help="download and unpack the problems (once); print the panda directory")
    fetch_cmd.add_argument("--data-dir", type=Path, default=DEFAULT_DATA_DIR,
                           help=f"where the sdist and mbm/panda go (default {DEFAULT_DATA_DIR})")
    args = parser.parse_args(argv)
    if args.command == "fetch":
        try:
            print(fetch(args.data_dir))
        except (OSError, RuntimeError, ValueError) as err:
            log(f"mbm: fetch failed: {err}")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
