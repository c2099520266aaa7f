"""MJCF robots as the community writes them (issue 19), loaded through the real server and checked against MuJoCo.

Every MJCF of pybullet_data (the pybullet wheel) and every gripper and robot of robosuite 1.5.2 (its wheel, fetched
with pip at test time into build/test-data; nothing is vendored) is added with client.add_robot(path=...), which
uploads its meshes and includes. At random joint positions, the world pose of every MuJoCo body (mj_kinematics:
xpos, xquat) must equal graspsim's pose of the link of the same name (get_body_poses) to 1e-9 m and 1e-9 rad, and
each body's mass, centre of mass and principal moments must be MuJoCo's. Old pybullet_data files today's MuJoCo
refuses are compared with MuJoCo on a copy it accepts, or (global coordinates) with PyBullet's MJCF importer.
"""
import math
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

REPO_ROOT = Path(__file__).resolve().parents[2]
DATA_DIR = REPO_ROOT / "build" / "test-data" / "mjcf"
ROBOSUITE = "robosuite==1.5.2"
TOLERANCE = 1e-9
CONFIGURATIONS = 5


def pybullet_mjcf_files():
    try:
        import pybullet_data
    except ImportError:
        return []
    return sorted((Path(pybullet_data.getDataPath()) / "mjcf").glob("*.xml"))


def robosuite_assets() -> Path:
    """robosuite's models/assets, unpacked from its wheel (downloaded once into build/test-data)."""
    target = DATA_DIR / "robosuite-1.5.2"
    assets = target / "robosuite" / "models" / "assets"
    if assets.is_dir():
        return assets
    DATA_DIR.mkdir(parents=True, exist_ok=True)
    wheels = list(DATA_DIR.glob("robosuite-1.5.2-*.whl"))
    if not wheels:
        result = subprocess.run([sys.executable, "-m", "pip", "download", "-q", "--no-deps", ROBOSUITE, "-d",
                                 str(DATA_DIR)], capture_output=True, text=True, timeout=600)
        wheels = list(DATA_DIR.glob("robosuite-1.5.2-*.whl"))
        if result.returncode != 0 or not wheels:
            pytest.skip(f"cannot download {ROBOSUITE}: {result.stderr[-300:]}")
    with zipfile.ZipFile(wheels[0]) as wheel:
        wheel.extractall(target, [n for n in wheel.namelist() if n.startswith("robosuite/models/assets/")])
    return assets


def robosuite_mjcf_files():
    """Gripper and robot files, by name (the wheel is fetched in the test, not at collection)."""
    return ["grippers/" + name for name in (
        "bd_gripper.xml", "fourier_left_hand.xml", "fourier_right_hand.xml", "inspire_left_hand.xml",
        "inspire_right_hand.xml", "jaco_three_finger_gripper.xml", "null_gripper.xml", "panda_gripper.xml",
        "rethink_gripper.xml", "robotiq_gripper_140.xml", "robotiq_gripper_85.xml", "robotiq_gripper_s.xml",
        "wiping_gripper.xml", "xarm7_gripper.xml")] + \
        [f"robots/{robot}/robot.xml" for robot in (
            "baxter", "gr1", "iiwa", "jaco", "kinova3", "panda", "sawyer", "spot", "spot_arm", "tiago", "ur5e",
            "xarm7")]


def graspsim_name(name: str) -> str:
    """The loader's sanitised name (core/validate.h CheckName: 1..64 of [A-Za-z0-9_.-])."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name[:64]) or "_"


def quaternion_angle(a, b) -> float:
    """The rotation angle between two (w, x, y, z) quaternions, accurate near 0 (atan2, not acos)."""
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    w = a[0] * b[0] + np.dot(a[1:], b[1:])  # (conj(a) * b).w
    v = a[0] * b[1:] - b[0] * a[1:] - np.cross(a[1:], b[1:])
    return 2 * math.atan2(float(np.linalg.norm(v)), abs(float(w)))


HINGE, SLIDE = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
EQ_JOINT = int(mujoco.mjtEq.mjEQ_JOINT)


def random_configuration(model, rng):
    """qpos for MuJoCo and positions for graspsim (hinge and slide joints; followers of <equality><joint> follow)."""
    qpos = model.qpos0.copy()
    ours = {}
    followers = {}
    for e in range(model.neq):
        if int(model.eq_type[e]) == EQ_JOINT and model.eq_active0[e] and model.eq_obj2id[e] >= 0:
            c = model.eq_data[e][:5]
            if not np.any(c[2:]):
                followers[int(model.eq_obj1id[e])] = (int(model.eq_obj2id[e]), c[0], c[1])
    for j in range(model.njnt):
        if int(model.jnt_type[j]) not in (HINGE, SLIDE) or j in followers:
            continue
        if model.jnt_limited[j]:
            low, high = model.jnt_range[j]
        else:
            low, high = (-math.pi, math.pi) if int(model.jnt_type[j]) == HINGE else (-0.5, 0.5)
        adr = model.jnt_qposadr[j]
        qpos[adr] = rng.uniform(low, high)
        ours[joint_name(model, j)] = qpos[adr] - model.qpos0[adr]  # graspsim's 0 is MuJoCo's ref
    for j, (leader, c0, c1) in followers.items():
        lead = model.jnt_qposadr[leader]
        qpos[model.jnt_qposadr[j]] = model.qpos0[model.jnt_qposadr[j]] + c0 + c1 * (qpos[lead] - model.qpos0[lead])
    return qpos, ours


def joint_name(model, j) -> str:
    return graspsim_name(model.joint(j).name or f"joint{j}")


def body_name(model, b) -> str:
    return graspsim_name(model.body(b).name or f"body{b}")


def check_masses(model, added, path: Path):
    """Each body's mass, centre of mass and principal moments as MuJoCo compiles them (meshes by MuJoCo's default
    "legacy" integrals), where graspsim made no repair of that body (warnings)."""
    ours = {body.id: body for body in added.bodies}
    repaired = " ".join(f"{w.element} {w.action}" for w in added.warnings)
    for b in range(1, model.nbody):
        name = body_name(model, b)
        mass = model.body_mass[b]
        if f"'{name}'" in repaired or mass < 1e-6:  # MuJoCo's massless bodies: graspsim frames or merged
            continue
        inertial = ours[f"r/{name}"].inertial
        where = f"{path.name} body {name}"
        assert abs(inertial.mass - mass) < 1e-7 * max(1.0, mass), f"{where}: mass {inertial.mass} != {mass}"
        com = inertial.center_of_mass
        assert np.linalg.norm(com - model.body_ipos[b]) < 1e-7, f"{where}: centre of mass {com} != {model.body_ipos[b]}"
        moments, expected = np.linalg.eigvalsh(inertial.inertia), np.sort(model.body_inertia[b])
        assert np.all(np.abs(moments - expected) <= 1e-6 * max(expected.max(), 1e-12)), \
            f"{where}: principal moments {moments} != {expected}"


def check_fk_against_mujoco(client, scene_id, path: Path, seed: int, must_load: bool = False):
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except Exception as err:
        if not must_load:
            pytest.skip(f"MuJoCo {mujoco.__version__} does not load {path.name}: {str(err).splitlines()[0]}")
        # PyBullet loads every pybullet_data file: MuJoCo on the file with what it refuses and what does not move
        # a body taken out, else (global coordinates) PyBullet is the reference.
        try:
            model = mujoco.MjModel.from_xml_string(for_todays_mujoco(path.read_text()))
        except Exception:
            return check_fk_against_pybullet(client, scene_id, path, seed)
    data = mujoco.MjData(model)
    added = client.add_robot(scene_id, "r", path=path)
    check_masses(model, added, path)
    rng = np.random.default_rng(seed)
    for _ in range(CONFIGURATIONS):
        qpos, ours = random_configuration(model, rng)
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        if ours:
            client.set_joint_positions(scene_id, {f"r/{name}": value for name, value in ours.items()})
        poses = client.get_body_poses(scene_id)
        for b in range(1, model.nbody):
            key = f"r/{body_name(model, b)}"
            assert key in poses, f"{path.name}: no link for body {key}"
            pose = poses[key]
            distance = np.linalg.norm(pose.position - data.xpos[b])
            angle = quaternion_angle(pose.orientation, data.xquat[b])
            assert distance < TOLERANCE and angle < TOLERANCE, \
                f"{path.name} body {key}: position off by {distance:.3g} m, orientation by {angle:.3g} rad"
    return added


def for_todays_mujoco(text: str) -> str:
    """Old pybullet_data MJCF as MuJoCo 3 accepts it, kinematics unchanged: no materials (some are not defined),
    no <option collision>, <inertial> with a pos, no PyBullet fixed joints (a body without joints is welded),
    no tendons or actuators (ground.xml names joints it does not have), planes of positive size."""
    text = re.sub(r'\smaterial="[^"]*"', "", text)
    text = re.sub(r'(<option[^>]*?)\scollision="[^"]*"', r"\1", text)
    text = re.sub(r"<inertial(?![^>]*\spos=)", '<inertial pos="0 0 0"', text)
    text = re.sub(r'<joint[^>]*type="fixed"[^>]*/>', "", text)
    text = re.sub(r"<(tendon|actuator)>.*?</\1>", "", text, flags=re.S)
    return re.sub(r'(type="plane"[^>]*size=")0 0 0"', r'\g<1>1 1 1"', text)


def check_fk_against_pybullet(client, scene_id, path: Path, seed: int):
    """For files today's MuJoCo refuses (global coordinates, PyBullet's fixed joints): PyBullet's MJCF importer
    names links after bodies too. Its parser reads numbers as float32, hence the looser tolerance."""
    import pybullet
    added = client.add_robot(scene_id, "r", path=path)
    ours = {joint.id[len("r/"):]: joint for joint in added.joints}
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        multibodies = pybullet.loadMJCF(str(path), physicsClientId=cid)
        rng = np.random.default_rng(seed)
        compared = 0
        for _ in range(CONFIGURATIONS):
            positions = {}
            for body in multibodies:
                for j in range(pybullet.getNumJoints(body, physicsClientId=cid)):
                    info = pybullet.getJointInfo(body, j, physicsClientId=cid)
                    name = info[1].decode()
                    if info[2] not in (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC) or name not in ours:
                        continue
                    low, high = ours[name].lower, ours[name].upper
                    low, high = (max(low, -1.0), min(high, 1.0)) if low < high else (-math.pi, math.pi)
                    q = rng.uniform(low, high)
                    pybullet.resetJointState(body, j, q, physicsClientId=cid)
                    positions[f"r/{name}"] = q
            client.set_joint_positions(scene_id, positions)
            poses = client.get_body_poses(scene_id)
            for body in multibodies:
                links = [(pybullet.getBodyInfo(body, physicsClientId=cid)[0].decode(), None)]
                links += [(pybullet.getJointInfo(body, j, physicsClientId=cid)[12].decode(), j)
                          for j in range(pybullet.getNumJoints(body, physicsClientId=cid))]
                for name, j in links:
                    if f"r/{name}" not in poses or name == "world":
                        continue
                    if j is None:
                        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=cid)
                    else:
                        state = pybullet.getLinkState(body, j, computeForwardKinematics=1, physicsClientId=cid)
                        position, orientation = state[4], state[5]
                    pose = poses[f"r/{name}"]
                    x, y, z, w = orientation
                    distance = np.linalg.norm(pose.position - np.array(position))
                    angle = quaternion_angle(pose.orientation, np.array([w, x, y, z]))
                    assert distance < 1e-5 and angle < 1e-5, \
                        f"{path.name} body {name}: position off by {distance:.3g} m, orientation by {angle:.3g} rad"
                    compared += 1
        assert compared > 0 or len(added.bodies) == 1, f"{path.name}: no body of PyBullet's is a link of graspsim's"
    finally:
        pybullet.disconnect(physicsClientId=cid)


@pytest.fixture(autouse=True)
def mujoco_log_elsewhere(tmp_path, monkeypatch):
    """MuJoCo appends its warnings to MUJOCO_LOG.TXT in the working directory: the test's, not the checkout."""
    monkeypatch.chdir(tmp_path)


@pytest.mark.parametrize("path", pybullet_mjcf_files(), ids=lambda p: p.name)
def test_pybullet_data_mjcf_matches_mujoco(client, scene_id, path):
    check_fk_against_mujoco(client, scene_id, path, seed=1, must_load=True)


@pytest.mark.parametrize("relative", robosuite_mjcf_files())
def test_robosuite_mjcf_matches_mujoco(client, scene_id, relative):
    check_fk_against_mujoco(client, scene_id, robosuite_assets() / relative, seed=2)


def test_no_pybullet_data_is_a_clean_skip():
    if not pybullet_mjcf_files():
        pytest.skip("pybullet (pybullet_data) is not installed: pip install 'graspsim[test]'")


def test_warnings_name_what_was_not_imported(client, scene_id):
    added = client.add_robot(scene_id, "w", mjcf="""
        <mujoco model="w"><worldbody><geom type="plane" size="1 1 0.1"/>
          <body name="b"><joint name="j"/><geom size="0.1"/><site name="s"/></body></worldbody>
          <actuator><motor joint="j" ctrlrange="-1 1" gear="3"/></actuator></mujoco>""")
    text = " ".join(f"{w.element} {w.value} {w.action}" for w in added.warnings)
    assert "<actuator>" in text and "<site>" in text and "plane" in text, text


def test_bad_mjcf_names_the_element_and_value(client, scene_id):
    import grpc
    import graspsim
    with pytest.raises(graspsim.GraspsimError) as caught:
        client.add_robot(scene_id, "bad", mjcf='<mujoco><worldbody><body name="x"><geom type="box" size="1 -2 1"/>'
                                              '</body></worldbody></mujoco>')
    assert caught.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "body 'x' geom 0 size" in caught.value.message and "-2" in caught.value.message
