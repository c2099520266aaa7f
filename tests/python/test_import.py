"""Robot files nobody here wrote (pybullet_data, from the pybullet wheel of the test extra), loaded by path and
checked against PyBullet and MuJoCo's URDF compiler, independent loaders of the same files, and against closed
forms and trimesh.

What PyBullet reports, found by experiment (pybullet 3.2.7) and relied on below:
- FK: getLinkState(..., computeForwardKinematics=True)[4], [5] is the URDF link frame in the world, in single
  precision: the pip wheel's btScalar is float, so the iiwa's link_1 origin 0.1575 m comes back as
  0.15749999880790710 and link frames carry float32 rounding (~1e-7 m here). Agreement with PyBullet is
  therefore checked at 5e-6, and the 1e-9 m agreement against an independent double-precision FK of the
  same URDF written here (numpy, from the file's own numbers: origin xyz/rpy, axis, mimic).
- Masses: getDynamicsInfo(...)[0] is the file's mass; a fixed base (useFixedBase=True) reports mass 0 and
  inertia 0 whatever the file says, so masses are compared on a free base. A link with <mass value="0"/>
  (panda_link8, panda_grasptarget) reports mass 0; its inertia is the file's diagonal with
  URDF_USE_INERTIA_FROM_FILE (0.1 kg m² for panda_link8: a massless body with inertia) and 0 without.
- Inertia with URDF_USE_INERTIA_FROM_FILE: localInertiaDiagonal is the file's tensor diagonalised (principal
  moments; the principal axes go to the inertial frame's orientation), so we compare eigenvalues.
- Inertia by default (no flag): the file's mass, and a tensor from the collision shape: Bullet's
  btCompoundShape::calculateLocalInertia, the box inertia m/12 (ly² + lz², ...) of the shape's axis-aligned
  bounding box in the inertial frame, padded by the collision margins: 4 mm a side for a mesh, 3 mm for a
  cylinder (which PyBullet turns into a convex hull), none for a box; a sphere is exact (2/5 m r²).
  We compute the solid geometry's own mass properties instead (exact for primitives and closed meshes), so we
  equal PyBullet's default for boxes and spheres only; elsewhere PyBullet approximates and the references are
  closed forms (primitives) and trimesh (meshes).
"""
import math
from pathlib import Path

import numpy as np
import pytest

import graspsim
from graspsim import _robot_files

from _support import IA, expect_error

pb = pytest.importorskip("pybullet", reason="pybullet (test extra) is not installed")
pybullet_data = pytest.importorskip("pybullet_data")

DATA = Path(pybullet_data.getDataPath())
ROBOTS = {"panda": "franka_panda/panda.urdf", "iiwa": "kuka_iiwa/model.urdf", "xarm6": "xarm/xarm6_robot.urdf"}
BASE_POSE = [0.3, -0.2, 0.1, math.cos(0.35), 0.0, 0.0, math.sin(0.35)]  # 0.7 rad about z, (w, x, y, z)
CONFIGURATIONS = 100
FK_TOLERANCE_M = 1e-9          # against the double-precision reference FK below
PYBULLET_FK_TOLERANCE = 5e-6   # m, rotation-matrix entries: PyBullet 3.2.7 computes in float32 (eps 1.2e-7, 8 joints)
REL_TOLERANCE = 1e-9           # closed forms, the file's own numbers
PYBULLET_REL_TOLERANCE = 1e-6  # PyBullet's inertias (float32; its Jacobi diagonalisation for full tensors)


@pytest.fixture
def bullet():
    """A PyBullet DIRECT connection of the test's own."""
    cid = pb.connect(pb.DIRECT)
    yield cid
    pb.disconnect(cid)


def quaternion_matrix(w, x, y, z):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def bullet_links(cid, body):
    """{link name: PyBullet link index} (-1 = the base) and {joint name: (index, type, lower, upper)}."""
    links = {pb.getBodyInfo(body, physicsClientId=cid)[0].decode(): -1}
    joints = {}
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        info = pb.getJointInfo(body, j, physicsClientId=cid)
        links[info[12].decode()] = j
        joints[info[1].decode()] = (j, info[2], info[8], info[9])
    return links, joints


def load_bullet(cid, relative, fixed=True, flags=0, base_pose=BASE_POSE):
    x, y, z, w, qx, qy, qz = base_pose
    return pb.loadURDF(str(DATA / relative), [x, y, z], [qx, qy, qz, w], useFixedBase=fixed, flags=flags,
                       physicsClientId=cid)


def xml_root(path: Path):
    """The file's root element, read as leniently as PyBullet's TinyXML (blank lines before the declaration)."""
    return _robot_files._parse(path, path.read_text())


def numbers(text, default):
    return np.array([float(v) for v in (text or default).split()])


def rpy_matrix(roll, pitch, yaw):
    """URDF's fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def axis_angle_matrix(axis, angle):
    x, y, z = axis / np.linalg.norm(axis)
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


class ReferenceFK:
    """Forward kinematics of a URDF in double precision, independent of the server: each joint's
    T(origin xyz, rpy) · (rotation about / translation along its axis by q), from the root link at base_pose."""

    def __init__(self, path: Path):
        root = xml_root(path)
        self.joints = []  # (name, type, parent, child, origin 4x4, axis, mimic (leader, multiplier, offset))
        children = set()
        for j in root.iterfind("joint"):
            origin = j.find("origin")
            T = np.eye(4)
            if origin is not None:
                T[:3, :3] = rpy_matrix(*numbers(origin.get("rpy"), "0 0 0"))
                T[:3, 3] = numbers(origin.get("xyz"), "0 0 0")
            axis = numbers(j.find("axis").get("xyz") if j.find("axis") is not None else None, "1 0 0")
            mimic = j.find("mimic")
            mimic = None if mimic is None else (mimic.get("joint"), float(mimic.get("multiplier", 1)),
                                                  float(mimic.get("offset", 0)))
            self.joints.append((j.get("name"), j.get("type"), j.find("parent").get("link"),
                                j.find("child").get("link"), T, axis, mimic))
            children.add(self.joints[-1][3])
        self.root = next(link.get("name") for link in root.iterfind("link") if link.get("name") not in children)

    def frames(self, q, base_pose):
        base = np.eye(4)
        base[:3, :3] = quaternion_matrix(*base_pose[3:])
        base[:3, 3] = base_pose[:3]
        world = {self.root: base}
        pending = list(self.joints)
        while pending:
            name, kind, parent, child, T, axis, mimic = pending.pop(0)
            if parent not in world:
                pending.append((name, kind, parent, child, T, axis, mimic))
                continue
            value = q.get(name, 0.0) if mimic is None else mimic[1] * q.get(mimic[0], 0.0) + mimic[2]
            motion = np.eye(4)
            if kind in ("revolute", "continuous"):
                motion[:3, :3] = axis_angle_matrix(axis, value)
            elif kind == "prismatic":
                motion[:3, 3] = axis / np.linalg.norm(axis) * value
            world[child] = world[parent] @ T @ motion
        return world


# --- FK ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_fk_matches_pybullet(client, scene_id, bullet, robot):
    """Every link frame of the robot loaded by path equals the double-precision reference FK to 1e-9 m (and
    1e-9 in the rotation matrix) and PyBullet's to its float32 precision (5e-6) at 100 random configurations
    within PyBullet's joint limits, base at the same pose (worst deviations printed)."""
    added = client.add_robot(scene_id, robot, path=DATA / ROBOTS[robot], base_pose=BASE_POSE)
    body = load_bullet(bullet, ROBOTS[robot])
    links, bullet_joints = bullet_links(bullet, body)
    ours = {j.id.split("/", 1)[1]: j for j in added.joints}
    movable = {name: v for name, v in bullet_joints.items() if v[1] in (pb.JOINT_REVOLUTE, pb.JOINT_PRISMATIC)}
    leaders = [name for name in movable if ours[name].mimic is None]
    body_ids = [f"{robot}/{name}" for name in links]
    missing = [b for b in body_ids if b not in {b.id for b in added.bodies}]
    assert not missing, f"links PyBullet has and we do not: {missing}"
    reference = ReferenceFK(DATA / ROBOTS[robot])
    rng = np.random.default_rng(19)
    worst_reference = worst_bullet = 0.0
    for _ in range(CONFIGURATIONS):
        q = {}
        for name in leaders:
            _, _, lower, upper = movable[name]
            if lower > upper:  # continuous: PyBullet reports (0, -1)
                lower, upper = -math.pi, math.pi
            q[name] = float(rng.uniform(lower, upper))
        client.set_joint_positions(scene_id, {f"{robot}/{name}": value for name, value in q.items()})
        for name, (index, *_rest) in movable.items():
            if name in q:
                value = q[name]
            else:  # a mimic joint: PyBullet does not enforce <mimic>, so it is set the way we follow it
                mimic = ours[name].mimic
                value = mimic.multiplier * q[mimic.joint_id.split("/", 1)[1]] + mimic.offset
            pb.resetJointState(body, index, value, physicsClientId=bullet)
        poses = client.get_body_poses(scene_id, body_ids)
        exact = reference.frames(q, BASE_POSE)
        for name, index in links.items():
            pose = poses[f"{robot}/{name}"]
            rotation = quaternion_matrix(*pose.orientation)
            dp = np.abs(pose.position - exact[name][:3, 3]).max()
            dr = np.abs(rotation - exact[name][:3, :3]).max()
            worst_reference = max(worst_reference, dp, dr)
            assert dp <= FK_TOLERANCE_M and dr <= FK_TOLERANCE_M, \
                f"{robot}/{name} at {q}: off the reference FK by {dp:.3g} m, rotation by {dr:.3g}"
            if index < 0:
                position, orientation = BASE_POSE[:3], BASE_POSE[3:]
            else:
                state = pb.getLinkState(body, index, computeForwardKinematics=True, physicsClientId=bullet)
                position = state[4]
                qx, qy, qz, qw = state[5]
                orientation = (qw, qx, qy, qz)
            dp = np.abs(pose.position - np.asarray(position)).max()
            dr = np.abs(rotation - quaternion_matrix(*orientation)).max()
            worst_bullet = max(worst_bullet, dp, dr)
            assert dp <= PYBULLET_FK_TOLERANCE and dr <= PYBULLET_FK_TOLERANCE, \
                f"{robot}/{name} at {q}: off PyBullet's by {dp:.3g} m, rotation by {dr:.3g}"
    print(f"{robot}: worst deviation from the reference FK {worst_reference:.3g}, from PyBullet {worst_bullet:.3g}")


def test_zero_mass_frame_link_keeps_its_frame(client, scene_id, bullet):
    """panda_link8 (<mass value="0"/>, fixed to panda_link7) is a massless frame: it loads with a warning
    naming it and its pose stays PyBullet's (FK above covers every configuration; here the home pose)."""
    added = client.add_robot(scene_id, "panda", path=DATA / ROBOTS["panda"], base_pose=BASE_POSE)
    assert any("panda_link8" in w.element for w in added.warnings), list(added.warnings)
    body = load_bullet(bullet, ROBOTS["panda"])
    links, _ = bullet_links(bullet, body)
    state = pb.getLinkState(body, links["panda_link8"], computeForwardKinematics=True, physicsClientId=bullet)
    pose = client.get_body_poses(scene_id, ["panda/panda_link8"])["panda/panda_link8"]
    np.testing.assert_allclose(pose.position, state[4], rtol=0, atol=PYBULLET_FK_TOLERANCE)
    qx, qy, qz, qw = state[5]
    np.testing.assert_allclose(quaternion_matrix(*pose.orientation), quaternion_matrix(qw, qx, qy, qz),
                               rtol=0, atol=PYBULLET_FK_TOLERANCE)
    exact = ReferenceFK(DATA / ROBOTS["panda"]).frames({}, BASE_POSE)["panda_link8"]
    np.testing.assert_allclose(pose.position, exact[:3, 3], rtol=0, atol=FK_TOLERANCE_M)
    link8 = {b.id: b for b in added.bodies}["panda/panda_link8"]
    assert link8.inertial.mass == 0.0  # PyBullet: mass 0 as well


# --- masses and inertias -----------------------------------------------------------------------------------
def handmade_urdfs(random_count: int = 20):
    handmade = sorted(p for p in DATA.rglob("*.urdf") if "random_urdfs" not in p.parts)
    return handmade + sorted(DATA.glob("random_urdfs/*/*.urdf"))[:random_count]


def file_inertials(path: Path):
    """{link: (has <inertial>, mass, centre of mass (3,), tensor 3x3 in the link frame, inertia_scaling)} as the
    file states them: the <inertia> rotated by the inertial origin's rpy."""
    out = {}
    for link in xml_root(path).iterfind("link"):
        inertial = link.find("inertial")
        scaling = link.find("./contact/inertia_scaling")
        scaling = float(scaling.get("value")) if scaling is not None else 1.0
        if inertial is None:
            out[link.get("name")] = (False, 0.0, np.zeros(3), np.zeros((3, 3)), scaling)
            continue
        origin = inertial.find("origin")
        rotation = rpy_matrix(*numbers(origin.get("rpy") if origin is not None else None, "0 0 0"))
        com = numbers(origin.get("xyz") if origin is not None else None, "0 0 0")
        element = inertial.find("inertia")
        i = {k: float(v) for k, v in element.attrib.items()} if element is not None else {}
        tensor = np.array([[i.get("ixx", 0), i.get("ixy", 0), i.get("ixz", 0)],
                           [i.get("ixy", 0), i.get("iyy", 0), i.get("iyz", 0)],
                           [i.get("ixz", 0), i.get("iyz", 0), i.get("izz", 0)]])
        mass = float(inertial.find("mass").get("value")) if inertial.find("mass") is not None else 0.0
        out[link.get("name")] = (True, mass, com, rotation @ tensor @ rotation.T, scaling)
    return out


def test_masses_and_inertias_from_file_equal_pybullets(client, bullet):
    """inertia="from_file" on every pybullet_data URDF that loads that way (the hand-made ones and 20
    random_urdfs, which all have izz = 0 and are refused; so is xArm6, whose link2 breaks the triangle
    inequality: PyBullet zeroes such a tensor, "Bad inertia tensor properties"). Where we are exact: every
    link's mass, centre of mass and tensor are the file's (relative 1e-12). Where we equal PyBullet (URDF_USE_INERTIA_FROM_FILE,
    free base): the mass (relative 1e-9) and, for links with mass, the principal moments (relative 1e-6 of the
    largest: PyBullet diagonalises in float32) of every link with an <inertial>; not where PyBullet applies
    its own conventions: a <contact><inertia_scaling> (a PyBullet extension: the tensor times it; we do not
    scale), and a link without <inertial> (next test)."""
    compared, refused, links_compared, mismatches = [], [], 0, []
    for path in handmade_urdfs():
        relative = str(path.relative_to(DATA))
        try:
            body = load_bullet(bullet, relative, fixed=False, flags=pb.URDF_USE_INERTIA_FROM_FILE,
                               base_pose=[0, 0, 0, 1, 0, 0, 0])
        except pb.error:
            continue  # PyBullet cannot load it either (a mesh missing from the wheel): nothing to compare
        scene = client.create_scene("from_file").id
        try:
            try:
                added = client.add_robot(scene, "r", path=path, inertia="from_file")
            except (graspsim.GraspsimError, FileNotFoundError) as err:
                refused.append((relative, str(err).splitlines()[0][:120]))
                continue
            bodies = {b.id.split("/", 1)[1]: b for b in added.bodies}
            links, _ = bullet_links(bullet, body)
            declared = file_inertials(path)
            for name, index in links.items():
                if name not in bodies:
                    mismatches.append(f"{relative}: link {name} missing; we have {sorted(bodies)}")
                    continue
                ours = bodies[name].inertial
                has_inertial, mass, com, tensor, scaling = declared[name]
                if not has_inertial:  # PyBullet's own default; see test_links_without_inertial_are_massless
                    continue
                our_com = ours.center_of_mass
                scale = max(np.abs(tensor).max(), 1e-300)
                off_tensor = np.abs(ours.inertia - tensor).max() > 1e-12 * scale
                off_com = np.abs(our_com - com).max() > 1e-12
                if ours.mass != pytest.approx(mass, rel=1e-12, abs=0) or (mass > 0 and (off_com or off_tensor)):
                    mismatches.append(f"{relative}: {name} is not the file's: mass {ours.mass} vs {mass}, com "
                                      f"{our_com} vs {com}, tensor {ours.inertia.tolist()} vs {tensor.tolist()}")
                info = pb.getDynamicsInfo(body, index, physicsClientId=bullet)
                if ours.mass != pytest.approx(info[0], rel=REL_TOLERANCE, abs=0):
                    mismatches.append(f"{relative}: {name} mass {ours.mass} kg, PyBullet's {info[0]} kg")
                elif info[0] > 0 and scaling == 1.0:
                    eigen = np.sort(np.linalg.eigvalsh(ours.inertia))
                    theirs = np.sort(np.asarray(info[2]))
                    if np.abs(eigen - theirs).max() > PYBULLET_REL_TOLERANCE * max(theirs.max(), 1e-300):
                        mismatches.append(f"{relative}: {name} principal moments {eigen}, PyBullet's {theirs}")
                links_compared += 1
            compared.append(relative)
        finally:
            client.delete_scene(scene)
            pb.resetSimulation(physicsClientId=bullet)
    print(f"from_file: {len(compared)} files, {links_compared} links compared; refused {len(refused)}: {refused}")
    assert not mismatches, "\n".join(mismatches)
    assert len(compared) >= 60, f"only {len(compared)} files compared; refused: {refused}"
    assert "franka_panda/panda.urdf" in compared and "kuka_iiwa/model.urdf" in compared


def test_links_without_inertial_are_massless(client):
    """A root link or a link fixed to its parent with neither <inertial> nor <collision> (a "world" link,
    husky's base_footprint and imu_link) is a massless frame, as URDF means it and as panda_link8's
    <mass value="0"/> is: mass 0.
    PyBullet gives such a link 1 kg and a unit inertia diagonal unless it is named "world" (then 0 kg)."""
    wrong = []
    for relative in ("cube_no_rotation.urdf", "pendulum5.urdf", "husky/husky.urdf", "table_square/table_square.urdf",
                     "xarm/link1.urdf"):
        path = DATA / relative
        root = xml_root(path)
        children = {j.find("child").get("link"): j.get("type") for j in root.iterfind("joint")}
        frames = [link.get("name") for link in root.iterfind("link") if link.find("inertial") is None
                  and link.find("collision") is None and children.get(link.get("name"), "fixed") == "fixed"]
        assert frames, relative
        for inertia in ("auto", "from_file"):
            scene = client.create_scene("massless").id
            try:
                bodies = {b.id.split("/", 1)[1]: b for b in
                          client.add_robot(scene, "r", path=path, inertia=inertia).bodies}
                wrong += [f"{relative} ({inertia}): {name} mass {bodies[name].inertial.mass} kg"
                          for name in frames if bodies[name].inertial.mass != 0.0]
            finally:
                client.delete_scene(scene)
    assert not wrong, "links without <inertial>, root or fixed, must be massless:\n" + "\n".join(wrong)


PRIMITIVES_URDF = """<robot name="prims">
  <link name="box"><inertial><mass value="1.5"/><inertia ixx="1" iyy="1" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link>
  <link name="sphere"><inertial><mass value="2"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="cylinder"><inertial><mass value="3"/><inertia ixx="1" iyy="1" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="box"/><child link="sphere"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="sphere"/><child link="cylinder"/><origin xyz="0 0 0.4"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def closed_form_inertia_per_kg(shape):
    """Solid inertia about the centre of mass per kg (kg m² / kg) and volume (m³) of the primitives above."""
    if shape == "box":
        a, b, c = 0.1, 0.2, 0.3
        return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) / 12, a * b * c
    if shape == "sphere":
        r = 0.1
        return np.eye(3) * 0.4 * r * r, 4 / 3 * math.pi * r ** 3
    r, length = 0.05, 0.4
    return np.diag([(3 * r * r + length * length) / 12] * 2 + [r * r / 2]), math.pi * r * r * length


def test_inertia_from_geometry_primitives(client, scene_id, bullet, tmp_path):
    """Invalid file inertias (izz = 0, all zero) are taken from the solid collision geometry. inertia="auto"
    keeps the file's mass (as PyBullet does) and the solid shape's inertia per kg: the closed forms; for the
    box and the sphere that is exactly PyBullet's default (no-flag) inertia too, for the cylinder PyBullet's
    padded convex-hull box differs (noted, not compared). "from_geometry" at a density takes the mass from it."""
    path = tmp_path / "prims.urdf"
    path.write_text(PRIMITIVES_URDF)
    added = client.add_robot(scene_id, "auto", path=path)
    assert {w.element.split("'")[1] for w in added.warnings if "'" in w.element} >= {"box", "sphere", "cylinder"}, \
        list(added.warnings)
    bodies = {b.id.split("/", 1)[1]: b for b in added.bodies}
    body = pb.loadURDF(str(path), useFixedBase=False, physicsClientId=bullet)
    links, _ = bullet_links(bullet, body)
    file_mass = {"box": 1.5, "sphere": 2.0, "cylinder": 3.0}
    for shape in ("box", "sphere", "cylinder"):
        per_kg, _ = closed_form_inertia_per_kg(shape)
        ours = bodies[shape].inertial
        assert ours.mass == file_mass[shape]
        np.testing.assert_allclose(ours.inertia, per_kg * ours.mass, rtol=REL_TOLERANCE, atol=1e-15,
                                   err_msg=shape)
        theirs = np.asarray(pb.getDynamicsInfo(body, links[shape], physicsClientId=bullet)[2])
        if shape != "cylinder":
            np.testing.assert_allclose(np.diag(ours.inertia), theirs, rtol=REL_TOLERANCE,
                                       err_msg=f"{shape}: PyBullet's default inertia")

    density = 750.0
    added = client.add_robot(scene_id, "geom", path=path, inertia="from_geometry", density=density)
    bodies = {b.id.split("/", 1)[1]: b for b in added.bodies}
    for shape in ("box", "sphere", "cylinder"):
        per_kg, volume = closed_form_inertia_per_kg(shape)
        ours = bodies[shape].inertial
        assert ours.mass == pytest.approx(density * volume, rel=REL_TOLERANCE), shape
        np.testing.assert_allclose(ours.inertia, per_kg * density * volume, rtol=REL_TOLERANCE,
                                   atol=1e-15, err_msg=shape)


def test_pybullet_default_inertia_is_the_padded_bounding_box(bullet):
    """The finding the module docstring states, kept true by a test: PyBullet's default inertia of a mesh link
    is the box inertia of the collision AABB (inertial frame) padded by 4 mm a side, at the file's mass."""
    trimesh = pytest.importorskip("trimesh")
    body = load_bullet(bullet, ROBOTS["panda"], base_pose=[0, 0, 0, 1, 0, 0, 0])
    for index in range(7):  # panda_link1 .. panda_link7: one collision mesh each
        mass, _, diagonal = pb.getDynamicsInfo(body, index, physicsClientId=bullet)[:3]
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for shape in pb.getCollisionShapeData(body, index, physicsClientId=bullet):
            vertices = trimesh.load(shape[4].decode(), force="mesh", process=False).vertices * np.asarray(shape[3])
            rotation = np.asarray(pb.getMatrixFromQuaternion(shape[6])).reshape(3, 3)
            world = vertices @ rotation.T + np.asarray(shape[5])
            lo, hi = np.minimum(lo, world.min(0)), np.maximum(hi, world.max(0))
        edges = hi - lo + 2 * 0.004
        box = mass / 12 * np.array([edges[1] ** 2 + edges[2] ** 2, edges[0] ** 2 + edges[2] ** 2,
                                    edges[0] ** 2 + edges[1] ** 2])
        np.testing.assert_allclose(diagonal, box, rtol=1e-5, err_msg=f"link {index}")


def test_inertia_from_geometry_meshes_equal_trimesh(client, scene_id):
    """xArm6's collision meshes are closed (watertight) solids: with inertia="from_geometry" each link's
    mass, centre of mass and inertia are the solid's at the density, as trimesh computes them (the meshes
    travel as float32: relative 1e-5)."""
    trimesh = pytest.importorskip("trimesh")
    density = 1000.0
    path = DATA / ROBOTS["xarm6"]
    added = client.add_robot(scene_id, "xarm", path=path, inertia="from_geometry", density=density)
    bodies = {b.id.split("/", 1)[1]: b for b in added.bodies}
    resolved = _robot_files.collect(path)
    import xml.etree.ElementTree as ET
    checked = 0
    for link in ET.parse(path).getroot().iterfind("link"):
        meshes = link.findall("./collision/geometry/mesh")
        if len(meshes) != 1 or link.find("./collision/origin") is not None and \
                link.find("./collision/origin").get("xyz", "0 0 0").split() != ["0", "0", "0"]:
            continue
        local = resolved.files[_robot_files.scene_path(meshes[0].get("filename"))]
        mesh = trimesh.load(local, force="mesh")
        if not mesh.is_watertight:
            continue
        mesh.density = density
        ours = bodies[link.get("name")].inertial
        assert ours.mass == pytest.approx(mesh.mass, rel=1e-5), link.get("name")
        com = ours.center_of_mass
        np.testing.assert_allclose(com, mesh.center_mass, rtol=0, atol=1e-5 * np.ptp(mesh.bounds, axis=0).max())
        np.testing.assert_allclose(ours.inertia, mesh.moment_inertia, rtol=0,
                                   atol=1e-5 * np.abs(mesh.moment_inertia).max(), err_msg=link.get("name"))
        checked += 1
    assert checked >= 6, f"only {checked} closed collision meshes checked"


# --- one call from disk; missing files; static objects ---------------------------------------------------
def test_add_robot_by_path_uploads_its_meshes_once(client, scene_id, monkeypatch):
    """add_robot(path=...) uploads the Panda's collision meshes under the paths the server looks up
    (package://meshes/collision/x.obj -> collision/x.obj), one call; a second robot from the same file uploads
    nothing (same SHA-256 in the scene)."""
    uploads = []
    original = client.upload_file
    monkeypatch.setattr(client, "upload_file",
                        lambda sid, p, data, **kw: uploads.append(p) or original(sid, p, data, **kw))
    added = client.add_robot(scene_id, "panda", path=str(DATA / ROBOTS["panda"]))
    assert added.robot.base_body == "panda/panda_link0"
    expected = {f"collision/{n}.obj" for n in ["link0", "link1", "link2", "link3", "link4", "link5", "link6",
                                                "link7", "hand", "finger"]}
    assert set(uploads) == expected and len(uploads) == len(expected)
    assert expected <= {f.path for f in client.get_scene(scene_id).files}
    assert sum(b.triangle_count for b in added.bodies) > 0
    uploads.clear()
    client.add_robot(scene_id, "panda2", path=DATA / ROBOTS["panda"], base_pose=[1, 0, 0, 1, 0, 0, 0])
    assert uploads == []


def test_missing_files_are_listed_at_once(client, scene_id, tmp_path):
    """Three meshes missing on disk: one MissingFilesError names all three before anything is sent; the same
    URDF sent as text without its meshes: one INVALID_ARGUMENT naming all three."""
    (tmp_path / "pkg" / "meshes").mkdir(parents=True)
    text = """<robot name="r">
      <link name="a"><collision><geometry><mesh filename="package://pkg/meshes/one.stl"/></geometry></collision></link>
      <link name="b"><collision><geometry><mesh filename="meshes/two.stl"/></geometry></collision></link>
      <link name="c"><collision><geometry><mesh filename="../three.stl"/></geometry></collision></link>
      <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint>
    </robot>"""
    path = tmp_path / "pkg" / "robot.urdf"
    path.write_text(text)
    with pytest.raises(graspsim.MissingFilesError) as info:
        client.add_robot(scene_id, "r", path=path)
    for name in ("package://pkg/meshes/one.stl", "meshes/two.stl", "../three.stl"):
        assert name in str(info.value)
    assert [m[0] for m in info.value.missing] == ["package://pkg/meshes/one.stl", "meshes/two.stl", "../three.stl"]
    scene = client.get_scene(scene_id)
    assert not scene.files and not scene.robots
    with expect_error(IA, "meshes/one.stl", "meshes/two.stl", "three.stl"):
        client.add_robot(scene_id, "r", urdf=text)


def test_static_object_needs_no_mass(client, scene_id):
    """A wall or a table: is_static with geometry and no mass loads; a moving box without a mass takes the
    solid box's (density 1000 unless given) with a warning, unless from_file or strict."""
    wall = client.add_object(scene_id, "wall", box=(0.1, 2.0, 1.0), is_static=True, pose=[1, 0, 0.5, 1, 0, 0, 0])
    assert wall.id == "wall"
    box = client.add_object(scene_id, "box", box=(0.1, 0.2, 0.3), density=500.0, pose=[0, 0, 1, 1, 0, 0, 0])
    assert box.inertial.mass == pytest.approx(500.0 * 0.1 * 0.2 * 0.3, rel=REL_TOLERANCE)
    np.testing.assert_allclose(np.diag(box.inertial.inertia),
                               box.inertial.mass / 12 * np.array([0.13, 0.10, 0.05]), rtol=REL_TOLERANCE)
    assert box.warnings, "inertia taken from the geometry must be reported"
    for options in (dict(inertia_source="from_file"), dict(strict=True)):
        with expect_error(IA, "inertial"):
            client.add_object(scene_id, "moving", box=(0.1, 0.1, 0.1), **options)


# --- the client's file resolution (no server) ---------------------------------------------------------------
def write(path: Path, data: str = "solid x\nendsolid x\n") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(data)
    return path


def test_resolution_package_model_relative_absolute(tmp_path):
    """package:// under package_roots (mapping, list, default: the file's directory and parents, or the package
    the file lies in), relative and absolute paths, and the scene paths the server looks them up by."""
    ws = tmp_path / "ws" / "src"
    write(ws / "arm_description" / "meshes" / "a.stl")
    write(ws / "arm_description" / "meshes" / "b.stl")
    write(ws / "arm_description" / "urdf" / "c.stl")
    write(ws / "arm_description" / "d.stl")
    text = """<robot name="r">
      <link name="a"><collision><geometry><mesh filename="package://arm_description/meshes/a.stl"/></geometry></collision>
        <visual><geometry><mesh filename="package://arm_description/meshes/visual_only_missing.dae"/></geometry></visual></link>
      <link name="b"><collision><geometry><mesh filename="../meshes/b.stl"/></geometry></collision></link>
      <link name="c"><collision><geometry><mesh filename="./c.stl"/></geometry></collision></link>
      <link name="d"><collision><geometry><mesh filename="file://%s"/></geometry></collision></link>
    </robot>""" % (ws / "arm_description" / "d.stl")
    urdf = write(ws / "arm_description" / "urdf" / "robot.urdf", text)
    package = ws / "arm_description"
    expected = {"meshes/a.stl": package / "meshes/a.stl", "meshes/b.stl": package / "meshes/b.stl",
                "c.stl": package / "urdf/c.stl", "d.stl": package / "d.stl"}
    for roots in (None, {"arm_description": ws / "arm_description"}, [ws], str(ws)):
        found = _robot_files.collect(urdf, roots)
        assert found.format == "urdf"
        assert {k: v.resolve() for k, v in found.files.items()} == {k: v.resolve() for k, v in expected.items()}, roots
    with pytest.raises(graspsim.MissingFilesError, match="package_roots"):
        _robot_files.collect(urdf, [tmp_path / "elsewhere"])
    # PyBullet's reading of "/meshes/x.stl": next to the file when it is not at the root of the disk
    write(tmp_path / "k" / "meshes" / "x.stl")
    sdf = write(tmp_path / "k" / "m.sdf", "<sdf version='1.6'><model name='m'><link name='l'><collision name='c'>"
                "<geometry><mesh><uri>/meshes/x.stl</uri></mesh></geometry></collision></link></model></sdf>")
    assert _robot_files.collect(sdf).files == {"x.stl": tmp_path / "k" / "meshes" / "x.stl"}


def test_resolution_mjcf_meshdir_include_and_sdf_models(tmp_path):
    """MJCF: <compiler meshdir> joined with each <asset><mesh file>, <include>d files followed (and uploaded);
    SDF: <include><uri>model://name</uri> found under the package roots, its meshes under "name/..."."""
    write(tmp_path / "mj" / "assets" / "hand.stl")
    write(tmp_path / "mj" / "assets" / "finger.stl")
    write(tmp_path / "mj" / "parts.xml", '<mujoco><asset><mesh name="f" file="finger.stl"/></asset></mujoco>')
    main = write(tmp_path / "mj" / "gripper.xml", '<mujoco model="g"><compiler angle="radian" meshdir="assets/"/>'
                 '<include file="parts.xml"/><asset><mesh file="hand.stl"/></asset><worldbody/></mujoco>')
    found = _robot_files.collect(main)
    assert found.format == "mjcf"
    assert set(found.files) == {"parts.xml", "assets/hand.stl", "assets/finger.stl"}
    # the root element decides when the extension does not
    other = write(tmp_path / "mj" / "gripper.model", main.read_text())
    assert _robot_files.collect(other).format == "mjcf"

    models = tmp_path / "models"
    write(models / "gripper" / "meshes" / "palm.stl")
    write(models / "gripper" / "model.config",
          "<model><name>gripper</name><sdf version='1.6'>gripper.sdf</sdf></model>")
    write(models / "gripper" / "gripper.sdf", "<sdf version='1.6'><model name='gripper'><link name='palm'>"
          "<collision name='c'><geometry><mesh><uri>meshes/palm.stl</uri></mesh></geometry></collision></link>"
          "</model></sdf>")
    world = write(tmp_path / "worlds" / "cell.sdf", "<sdf version='1.6'><world name='w'><include>"
                  "<uri>model://gripper</uri></include></world></sdf>")
    found = _robot_files.collect(world, [models])
    assert found.format == "sdf"
    assert set(found.files) == {"gripper/gripper.sdf", "gripper/model.config", "gripper/meshes/palm.stl"}
    with pytest.raises(graspsim.MissingFilesError, match="gripper"):
        _robot_files.collect(world)  # the default roots (the file's directory and its parents) miss models/


def test_scene_paths():
    """The server's lookup path of a reference (StripMeshUri + normalisation)."""
    cases = {"package://pkg/a/b.stl": "a/b.stl", "file:///x/b.stl": "b.stl", "model://m/b.stl": "m/b.stl",
             "./meshes/../b.stl": "b.stl", "../../meshes/b.stl": "meshes/b.stl", "meshes//x/./y.obj": "meshes/x/y.obj",
             "/abs/c.dae": "c.dae"}
    assert {ref: _robot_files.scene_path(ref) for ref in cases} == cases


# --- FK against MuJoCo's URDF compiler (double precision) -------------------------------------------------------
def mujoco_model_of_urdf(path: Path):
    """MuJoCo's own URDF compiler on the file's kinematics: geometry left out (FK does not depend on it), static
    links kept as bodies (fusestatic off), massless links given MuJoCo's bounds so that it compiles."""
    mujoco = pytest.importorskip("mujoco", reason="mujoco (test extra) is not installed")
    import xml.etree.ElementTree as ET
    root = xml_root(path)
    for link in root.iterfind("link"):
        for element in list(link):
            if element.tag in ("collision", "visual"):
                link.remove(element)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", fusestatic="false", discardvisual="true", boundmass="1e-6",
                  boundinertia="1e-9", balanceinertia="true")
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    return mujoco, model


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_fk_matches_mujocos_urdf_compiler(client, scene_id, robot):
    """Every link frame of the robot loaded by path equals MuJoCo's (its URDF compiler and mj_kinematics, double
    precision, an independent implementation) to 1e-9 m and 1e-9 in the rotation matrix at 100 random
    configurations within the joint limits, base at the same pose."""
    mujoco, model = mujoco_model_of_urdf(DATA / ROBOTS[robot])
    data = mujoco.MjData(model)
    added = client.add_robot(scene_id, robot, path=DATA / ROBOTS[robot], base_pose=BASE_POSE)
    ours = {j.id.split("/", 1)[1]: j for j in added.joints}
    leaders = {name: j for name, j in ours.items()
               if j.type != "fixed" and j.mimic is None}
    bodies = [model.body(i).name for i in range(1, model.nbody)]
    assert {f"{robot}/{name}" for name in bodies} <= {b.id for b in added.bodies}
    base = np.eye(4)
    base[:3, :3] = quaternion_matrix(*BASE_POSE[3:])
    base[:3, 3] = BASE_POSE[:3]
    rng = np.random.default_rng(1919)
    worst = 0.0
    for _ in range(CONFIGURATIONS):
        q = {}
        for name, joint in leaders.items():
            limited = joint.type in ("revolute", "prismatic")
            lower, upper = (joint.lower, joint.upper) if limited else (-math.pi, math.pi)
            q[name] = float(rng.uniform(lower, upper))
        client.set_joint_positions(scene_id, {f"{robot}/{name}": value for name, value in q.items()})
        data.qpos[:] = 0
        for name, joint in ours.items():
            if joint.type == "fixed":
                continue
            value = q[name] if name in q else \
                joint.mimic.multiplier * q[joint.mimic.joint_id.split("/", 1)[1]] + joint.mimic.offset
            data.qpos[model.joint(name).qposadr[0]] = value
        mujoco.mj_kinematics(model, data)
        poses = client.get_body_poses(scene_id, [f"{robot}/{name}" for name in bodies])
        for name in bodies:
            expected = base @ np.block([[data.body(name).xmat.reshape(3, 3), data.body(name).xpos[:, None]],
                                        [np.zeros((1, 3)), np.ones((1, 1))]])
            pose = poses[f"{robot}/{name}"]
            dp = np.abs(pose.position - expected[:3, 3]).max()
            dr = np.abs(quaternion_matrix(*pose.orientation) - expected[:3, :3]).max()
            worst = max(worst, dp, dr)
            assert dp <= FK_TOLERANCE_M and dr <= FK_TOLERANCE_M, \
                f"{robot}/{name} at {q}: off MuJoCo's FK by {dp:.3g} m, rotation by {dr:.3g}"
    print(f"{robot}: worst deviation from MuJoCo's FK {worst:.3g}")
