"""SDF import through the server (issue 19): every .sdf of pybullet_data (the pybullet wheel's data, used where
pip installed it, never copied into the repository) loads as a robot, each model of a <world> by model_name, and
the KUKA iiwa's forward kinematics matches PyBullet's loadSDF link frames.

PyBullet itself is the reference: two files name collision meshes pybullet_data does not ship
(meshes/coarse/*.stl), PyBullet refuses them ("Cannot load SDF file") and graspsim refuses them listing every
missing file. (PyBullet 3.2.7 crashes on gripper/wsg50_one_motor_gripper_free_base.sdf, so it is only loaded in
its own process for the one file the FK test needs.)
"""
import math
import posixpath
import random
import xml.etree.ElementTree as ET
from pathlib import Path

import grpc
import numpy as np
import pytest

import graspsim

pybullet = pytest.importorskip("pybullet")
pybullet_data = pytest.importorskip("pybullet_data")

DATA = Path(pybullet_data.getDataPath())
SDF_FILES = sorted(str(p.relative_to(DATA)) for p in DATA.rglob("*.sdf"))
# Their collision geometry names meshes/coarse/link_*.stl, which pybullet_data does not ship.
MISSING_COARSE_MESHES = {"kuka_iiwa/kuka_world.sdf", "kuka_iiwa/model2.sdf"}


def scene_path(uri: str) -> str:
    """Where the server looks a mesh <uri> up: loader_common's StripMeshUri, lexically normalised, relative."""
    for prefix in ("package://", "model://"):
        if uri.startswith(prefix):
            rest = uri[len(prefix):]
            uri = rest[rest.find("/") + 1:] if prefix == "package://" else rest
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    return posixpath.normpath(uri).lstrip("/")


def collision_mesh_uris(model: ET.Element):
    """The mesh URIs of the model's collision geometry (visual meshes are not loaded)."""
    return sorted({uri.text.strip() for uri in model.iterfind(".//collision/geometry/mesh/uri")})


def top_models(root: ET.Element):
    """The <model> elements ImportSdf chooses from: the standalone one, or those of each <world>."""
    return [m for m in root.findall("model")] + [m for w in root.findall("world") for m in w.findall("model")]


def upload_meshes(client, scene_id: str, sdf_path: Path, model: ET.Element):
    """Uploads the collision meshes `model` names that exist next to the file; returns the paths that do not."""
    missing = []
    for uri in collision_mesh_uris(model):
        path = scene_path(uri)
        on_disk = sdf_path.parent / path
        if on_disk.is_file():
            client.upload_file(scene_id, path, on_disk.read_bytes())
        else:
            missing.append(path)
    return missing


def test_the_corpus_is_pybullet_data():
    assert len(SDF_FILES) == 15, SDF_FILES
    assert MISSING_COARSE_MESHES <= set(SDF_FILES)


@pytest.mark.parametrize("relative", SDF_FILES)
def test_pybullet_data_sdf_loads(client, scene_id, relative):
    path = DATA / relative
    text = path.read_text()
    root = ET.fromstring(text)
    models = top_models(root)
    assert models
    names = []
    for model in models:  # libsdformat keeps the first of two models with one name (model2.sdf)
        if model.get("name") not in names:
            names.append(model.get("name"))
    for k, name in enumerate(names):
        model = next(m for m in models if m.get("name") == name)
        missing = upload_meshes(client, scene_id, path, model)
        if relative in MISSING_COARSE_MESHES and missing:
            with pytest.raises(graspsim.GraspsimError) as refused:
                client.add_robot(scene_id, f"r{k}", sdf=text, model_name=name)
            assert refused.value.code == grpc.StatusCode.INVALID_ARGUMENT
            assert "not uploaded" in str(refused.value)
            for m in missing:
                assert m in str(refused.value)
            continue
        assert not missing, missing
        added = client.add_robot(scene_id, f"r{k}", sdf=text, model_name=name)
        assert added.robot.source == "sdf"
        bodies = {b.id for b in added.bodies}
        links = [link.get("name") for link in model.findall("link")]
        assert {f"r{k}/{link}" for link in links} <= bodies
        link_names = set(links)
        joints = [j.get("name") for j in model.findall("joint")
                  if not (j.findtext("parent", "").strip() == "world" and "world" not in link_names
                          and j.get("type") == "fixed")]
        assert {f"r{k}/{j}" for j in joints} <= set(added.robot.joint_ids)
        assert added.robot.base_body in bodies


def _matrix(quaternion_xyzw):
    """The rotation matrix of a quaternion (x, y, z, w), in double precision (PyBullet's getMatrixFromQuaternion
    rounds to float32)."""
    x, y, z, w = np.asarray(quaternion_xyzw, dtype=float) / np.linalg.norm(quaternion_xyzw)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _inverse_xyzw(quaternion_xyzw):
    x, y, z, w = quaternion_xyzw
    return (-x, -y, -z, w)


def _frame(position, quaternion_xyzw):
    """A 4x4 transform from PyBullet's (position, quaternion x y z w)."""
    rotation = _matrix(quaternion_xyzw)
    frame = np.eye(4)
    frame[:3, :3] = rotation
    frame[:3, 3] = position
    return frame


def _quaternion_wxyz(rotation):
    """A unit quaternion (w, x, y, z) from a rotation matrix (Shepperd's method)."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        return [s / 4, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i, i] - m[j, j] - m[k, k])
    q = [0.0] * 4
    q[0] = (m[k, j] - m[j, k]) / s
    q[1 + i] = s / 4
    q[1 + j] = (m[j, i] + m[i, j]) / s
    q[1 + k] = (m[k, i] + m[i, k]) / s
    return q


def _rotation(axis, angle):
    """A 4x4 rotation by `angle` about the unit `axis` (Rodrigues)."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    frame = np.eye(4)
    frame[:3, :3] = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)
    return frame


def test_kuka_iiwa_forward_kinematics_matches_pybullet(client, scene_id):
    """Link frames at 50 random configurations, against PyBullet twice: getLinkState's worldLinkFramePosition and
    orientation, which PyBullet 3.2.7 returns rounded to float32 (-2.3 comes back as -2.3000001907348633), so to
    2e-6; and, to 1e-9, the same frames composed in double precision from what PyBullet's SDF importer made of the
    file (getJointInfo's parent frames and axes, getDynamicsInfo's inertial frames: PyBullet places each joint in
    its parent's centre-of-mass frame). getJointInfo's parentFrameOrn is the inverse of the joint frame's rotation
    in that frame: composed that way, the frames agree with getLinkState's to its float32 rounding (2.2e-7 here),
    composed the other way they are off by up to 2."""
    path = DATA / "kuka_iiwa" / "model.sdf"
    text = path.read_text()
    model = top_models(ET.fromstring(text))[0]
    assert upload_meshes(client, scene_id, path, model) == []

    physics = pybullet.connect(pybullet.DIRECT)
    try:
        (body,) = pybullet.loadSDF(str(path), physicsClientId=physics)
        # PyBullet reports the base's centre of mass; its link frame is that times the inverse inertial frame.
        base_com = _frame(*pybullet.getBasePositionAndOrientation(body, physicsClientId=physics))
        info = pybullet.getDynamicsInfo(body, -1, physicsClientId=physics)
        base = base_com @ np.linalg.inv(_frame(info[3], info[4]))
        added = client.add_robot(scene_id, "iiwa", sdf=text,
                                 base_pose=list(base[:3, 3]) + _quaternion_wxyz(base[:3, :3]))
        assert added.robot.base_body == "iiwa/lbr_iiwa_link_0"
        joints = []
        for j in range(pybullet.getNumJoints(body, physicsClientId=physics)):
            ji = pybullet.getJointInfo(body, j, physicsClientId=physics)
            inertial = pybullet.getDynamicsInfo(body, j, physicsClientId=physics)
            joints.append(dict(index=j, name=ji[1].decode(), link=ji[12].decode(), lower=ji[8], upper=ji[9],
                               axis=ji[13], parent_frame=_frame(ji[14], _inverse_xyzw(ji[15])), parent=ji[16],
                               inertial=_frame(inertial[3], inertial[4])))
        assert [j["name"] for j in joints] == [f"lbr_iiwa_joint_{k}" for k in range(1, 8)]
        rng = random.Random(19)
        for _ in range(50):
            q = {j["name"]: rng.uniform(j["lower"], j["upper"]) for j in joints}
            for j in joints:
                pybullet.resetJointState(body, j["index"], q[j["name"]], physicsClientId=physics)
            client.set_joint_positions(scene_id, {f"iiwa/{name}": value for name, value in q.items()})
            poses = client.get_body_poses(scene_id, [f"iiwa/{j['link']}" for j in joints])
            com = {-1: base_com}
            for j in joints:
                exact = com[j["parent"]] @ j["parent_frame"] @ _rotation(j["axis"], q[j["name"]])
                com[j["index"]] = exact @ j["inertial"]
                ours = poses[f"iiwa/{j['link']}"]
                w, x, y, z = ours.orientation
                mine = _matrix([x, y, z, w])
                np.testing.assert_allclose(ours.position, exact[:3, 3], rtol=0, atol=1e-9, err_msg=j["link"])
                np.testing.assert_allclose(mine, exact[:3, :3], rtol=0, atol=1e-9, err_msg=j["link"])
                state = pybullet.getLinkState(body, j["index"], computeForwardKinematics=True,
                                              physicsClientId=physics)
                np.testing.assert_allclose(ours.position, state[4], rtol=0, atol=2e-6, err_msg=j["link"])
                np.testing.assert_allclose(mine, _frame(state[4], state[5])[:3, :3], rtol=0, atol=2e-6,
                                           err_msg=j["link"])
    finally:
        pybullet.disconnect(physics)
