"""MuJoCo and Bullet adapters of the `Engine` protocol (scene_spec.py): the textbook cases run unchanged on them,
so graspsim can be compared like for like with two reference engines. Anything not listed is the engine's default.

MuJoCo (4.0.0), one MJCF model per scene:
  * integrator `implicitfast` (the docs' pick for accuracy; with no damping it equals semi-implicit Euler here),
    RK4 for Scene.smooth scenes; `cone="elliptic"`; kept: Newton solver, 100 iterations, tolerance 1e-8,
    impratio 1, no noslip, condim 3, margin 0, solref (0.02, 1), solimp (0.9, 0.95, 0.001, 0.5, 2) — soft
    contacts that penetrate slightly and creep slowly while sticking;
  * free bodies: `<freejoint/>` + explicit `<inertial>` (so geoms add no mass), geom friction (μ_d, 0, 0): no
    torsional/rolling resistance. MuJoCo takes the max of a pair's μ (graspsim the mean): same for equal μ;
  * robots: MuJoCo's own URDF importer (MjSpec.from_string), attached with MjSpec.attach under a world frame at
    base_pose, names prefixed "robot/". The root link becomes a jointless body welded to the world; inertials
    keep origin and full tensor (diagonalised); joint ranges in radians, limited via autolimits. Damping,
    frictionloss and armature are zeroed after compiling; self-collision excluded; URDF geoms keep μ = 1.
Bullet (pybullet, DIRECT), one physics client per adapter:
  * kept: 50 solver iterations, default ERPs, no sub-steps, primitive collision margins (~1 mm, inside shapes);
    Bullet has one integrator (semi-implicit Euler), so Scene.smooth changes nothing;
  * bodies are btMultiBody bases; lateralFriction √μ_d because Bullet multiplies a pair's coefficients (a μ_d
    pair then gets μ_d, as in graspsim and MuJoCo); no rolling/spinning friction, restitution 0, damping 0
    (Bullet's default 0.04 linear/angular damping would bleed energy from every case), sleeping disabled (a
    sleeping body would hide the resting cases' drift);
  * robots: loadURDF(useFixedBase, URDF_USE_INERTIA_FROM_FILE — else inertia comes from the collision shapes —,
    URDF_USE_IMPLICIT_CYLINDER — else cylinders become convex hulls), no self-collision (the default), velocity
    motors off, all damping 0, URDF joint limits kept; links keep Bullet's default μ 0.5.
Quaternions in the protocol are (w, x, y, z); MuJoCo uses the same order, pybullet (x, y, z, w).
"""
from __future__ import annotations

import math
import os
import tempfile
import xml.etree.ElementTree as ET
from typing import Dict, Sequence, Tuple

import mujoco
import numpy as np
import pybullet

try:
    from .scene_spec import Body, BodyState, Robot, Scene
except ImportError:  # run as a script from tests/physics
    from scene_spec import Body, BodyState, Robot, Scene


def _text(values: Sequence[float]) -> str:
    return " ".join(f"{float(v):.17g}" for v in values)


def _unit_quat(pose: Sequence[float]) -> np.ndarray:
    q = np.asarray(pose[3:7], dtype=float)
    return q / np.linalg.norm(q)


def _xyzw(q_wxyz: np.ndarray) -> list:
    return [q_wxyz[1], q_wxyz[2], q_wxyz[3], q_wxyz[0]]


class MujocoEngine:
    name = "mujoco"

    def __init__(self) -> None:
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self.time = 0.0
        self._dt = 0.0
        self._fresh = False  # whether xpos/xquat/cvel describe the current qpos/qvel

    def load(self, scene: Scene, dt: float) -> None:
        self._dt, self.time = dt, 0.0
        spec = mujoco.MjSpec.from_string(self._mjcf(scene, dt))
        for robot in scene.robots:
            urdf = mujoco.MjSpec.from_string(robot.urdf)
            links = [f"{robot.name}/{b.name}" for b in urdf.bodies if b.name != "world"]
            frame = spec.worldbody.add_frame(pos=list(robot.base_pose[:3]), quat=list(_unit_quat(robot.base_pose)))
            spec.attach(urdf, frame=frame, prefix=robot.name + "/")
            # No self-collision (graspsim skips links of one robot, Bullet's default): MuJoCo's parent filter
            # alone misses non-adjacent links and the root link, which is welded to the world.
            for i, a in enumerate(links):
                for b in links[i + 1:]:
                    spec.add_exclude(bodyname1=a, bodyname2=b)
        m = spec.compile()
        m.dof_damping[:] = 0.0  # URDF <dynamics> would otherwise add damping / dry friction
        m.dof_frictionloss[:] = 0.0
        m.dof_armature[:] = 0.0
        d = mujoco.MjData(m)
        for body in scene.bodies:
            if body.static or body.velocity is None:
                continue
            dof = m.jnt_dofadr[m.body(body.name).jntadr[0]]
            rot = np.empty(9)
            mujoco.mju_quat2Mat(rot, _unit_quat(body.pose))
            # A free joint's qvel is (linear velocity in the world, angular velocity in the BODY frame).
            d.qvel[dof:dof + 3] = body.velocity[:3]
            d.qvel[dof + 3:dof + 6] = rot.reshape(3, 3).T @ np.asarray(body.velocity[3:6], dtype=float)
        for robot in scene.robots:
            for joint, q in robot.joint_positions.items():
                d.qpos[m.joint(f"{robot.name}/{joint}").qposadr[0]] = q
        mujoco.mj_forward(m, d)
        self.model, self.data, self._fresh = m, d, True

    @staticmethod
    def _mjcf(scene: Scene, dt: float) -> str:
        root = ET.Element("mujoco", model="peer")
        ET.SubElement(root, "compiler", angle="radian")  # also applies to the attached URDF's joint ranges
        # Elliptic cones are the exact Coulomb cone |f_t| <= μ f_n; the default pyramid (4 edges for condim 3)
        # caps a diagonal sliding direction at μ/√2 and couples the two tangent directions.
        # Scene.smooth (no contact, no damping): MuJoCo's 4th-order Runge-Kutta, as scene_spec asks.
        integrator = "RK4" if getattr(scene, "smooth", False) else "implicitfast"
        ET.SubElement(root, "option", timestep=f"{dt:.17g}", gravity=_text(scene.gravity),
                      integrator=integrator, cone="elliptic")
        world = ET.SubElement(root, "worldbody")
        for b in scene.bodies:
            geom = {"name": b.name, "type": b.shape, "size": _text(MujocoEngine._size(b)),
                    "friction": _text((b.friction[1], 0.0, 0.0))}
            pose = {"pos": _text(b.pose[:3]), "quat": _text(_unit_quat(b.pose))}
            if b.static:
                ET.SubElement(world, "geom", **geom, **pose)
                continue
            body = ET.SubElement(world, "body", name=b.name, **pose)
            ET.SubElement(body, "freejoint", name=b.name)
            ET.SubElement(body, "inertial", pos="0 0 0", mass=f"{b.mass:.17g}", diaginertia=_text(b.inertia_diagonal()))
            ET.SubElement(body, "geom", **geom)
        return ET.tostring(root, encoding="unicode")

    @staticmethod
    def _size(b: Body) -> Tuple[float, ...]:
        if b.shape == "box":
            return tuple(e / 2 for e in b.size)  # MuJoCo box sizes are half edges
        if b.shape == "sphere":
            return (b.size[0],)
        return (b.size[0], b.size[1] / 2)  # cylinder: radius, half length along body z

    def set_gravity(self, gravity: Sequence[float]) -> None:
        self.model.opt.gravity[:] = gravity

    def push(self, robot: str, joint: str, force: float) -> None:
        raise NotImplementedError("joint drives: only the server's engines run the held-box case")

    def step(self, steps: int) -> None:
        for _ in range(steps):
            mujoco.mj_step(self.model, self.data)
        self.time += steps * self._dt
        self._fresh = self._fresh and steps == 0

    def _refresh(self) -> None:
        # mj_step leaves xpos/xquat/cvel at the state *before* its integration: recompute them for the new state.
        if not self._fresh:
            mujoco.mj_kinematics(self.model, self.data)
            mujoco.mj_comPos(self.model, self.data)
            mujoco.mj_comVel(self.model, self.data)
            self._fresh = True

    def body(self, name: str) -> BodyState:
        self._refresh()
        i = self.model.body(name).id
        vel = np.empty(6)  # (angular, linear); flg_local=0: world-aligned axes at the body origin (= its CoM)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, i, vel, 0)
        return BodyState(self.data.xpos[i].copy(), self.data.xquat[i].copy(), vel[3:].copy(), vel[:3].copy())

    def joint(self, robot: str, joint: str) -> Tuple[float, float]:
        j = self.model.joint(f"{robot}/{joint}")
        return float(self.data.qpos[j.qposadr[0]]), float(self.data.qvel[j.dofadr[0]])

    def close(self) -> None:
        self.model = self.data = None  # plain Python objects: dropping them frees the native buffers


class BulletEngine:
    name = "bullet"

    def __init__(self) -> None:
        self.client = -1
        self.time = 0.0
        self._dt = 0.0
        self._bodies: Dict[str, int] = {}
        self._joints: Dict[Tuple[str, str], Tuple[int, int]] = {}  # (robot, joint) -> (body id, joint index)

    def load(self, scene: Scene, dt: float) -> None:
        self.client = pybullet.connect(pybullet.DIRECT)
        self._dt, self.time = dt, 0.0
        c = {"physicsClientId": self.client}
        pybullet.setTimeStep(dt, **c)
        pybullet.setGravity(*scene.gravity, **c)
        for b in scene.bodies:
            if b.shape == "box":
                shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[e / 2 for e in b.size], **c)
            elif b.shape == "sphere":
                shape = pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=b.size[0], **c)
            else:  # along the shape's z, like the protocol's cylinder
                shape = pybullet.createCollisionShape(pybullet.GEOM_CYLINDER, radius=b.size[0], height=b.size[1], **c)
            uid = pybullet.createMultiBody(baseMass=0.0 if b.static else b.mass, baseCollisionShapeIndex=shape,
                                           basePosition=list(b.pose[:3]), baseOrientation=_xyzw(_unit_quat(b.pose)),
                                           baseInertialFramePosition=[0, 0, 0], **c)
            extra = {} if b.static else {"localInertiaDiagonal": list(b.inertia_diagonal())}
            pybullet.changeDynamics(uid, -1, lateralFriction=math.sqrt(b.friction[1]), rollingFriction=0.0,
                                    spinningFriction=0.0, restitution=0.0, linearDamping=0.0, angularDamping=0.0,
                                    activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING, **extra, **c)
            if b.velocity is not None and not b.static:
                pybullet.resetBaseVelocity(uid, list(b.velocity[:3]), list(b.velocity[3:6]), **c)
            self._bodies[b.name] = uid
        for robot in scene.robots:
            self._load_robot(robot)

    def _load_robot(self, robot: Robot) -> None:
        c = {"physicsClientId": self.client}
        fd, path = tempfile.mkstemp(suffix=".urdf", prefix=f"peer-{robot.name}-")
        try:
            with os.fdopen(fd, "w") as f:
                f.write(robot.urdf)
            uid = pybullet.loadURDF(path, basePosition=list(robot.base_pose[:3]),
                                    baseOrientation=_xyzw(_unit_quat(robot.base_pose)), useFixedBase=True,
                                    flags=pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER,
                                    **c)
        finally:
            os.remove(path)
        for link in range(-1, pybullet.getNumJoints(uid, **c)):
            pybullet.changeDynamics(uid, link, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0,
                                    activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING, **c)
            if link < 0:
                continue
            name = pybullet.getJointInfo(uid, link, **c)[1].decode()
            self._joints[(robot.name, name)] = (uid, link)
            # loadURDF drives every joint with a velocity motor towards 0: free the joints.
            pybullet.setJointMotorControl2(uid, link, pybullet.VELOCITY_CONTROL, force=0.0, **c)
            if name in robot.joint_positions:
                pybullet.resetJointState(uid, link, robot.joint_positions[name], 0.0, **c)

    def set_gravity(self, gravity: Sequence[float]) -> None:
        pybullet.setGravity(*gravity, physicsClientId=self.client)

    def push(self, robot: str, joint: str, force: float) -> None:
        raise NotImplementedError("joint drives: only the server's engines run the held-box case")

    def step(self, steps: int) -> None:
        for _ in range(steps):
            pybullet.stepSimulation(physicsClientId=self.client)
        self.time += steps * self._dt

    def body(self, name: str) -> BodyState:
        uid = self._bodies[name]
        pos, q = pybullet.getBasePositionAndOrientation(uid, physicsClientId=self.client)
        lin, ang = pybullet.getBaseVelocity(uid, physicsClientId=self.client)  # world frame, at the CoM
        return BodyState(np.array(pos), np.array([q[3], q[0], q[1], q[2]]), np.array(lin), np.array(ang))

    def joint(self, robot: str, joint: str) -> Tuple[float, float]:
        uid, j = self._joints[(robot, joint)]
        q, qd = pybullet.getJointState(uid, j, physicsClientId=self.client)[:2]
        return float(q), float(qd)

    def close(self) -> None:
        if self.client >= 0:
            pybullet.disconnect(physicsClientId=self.client)
            self.client = -1


PENDULUM_URDF = """<robot name="pendulum">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="bob">
    <inertial><origin xyz="0 0 -1"/><mass value="1"/><inertia ixx="1.6e-4" iyy="1.6e-4" izz="1.6e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 -1"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/><limit lower="-3.2" upper="3.2" effort="0" velocity="100"/></joint>
</robot>"""


def _self_check(make) -> bool:
    dt, g, ok = 1e-3, 9.81, True

    def run(scene: Scene):
        e = make()
        e.load(scene, dt)
        return e

    def report(label: str, passed: bool, text: str) -> None:
        nonlocal ok
        ok &= passed
        print(f"  {'ok  ' if passed else 'FAIL'} {label}: {text}")

    print(make.name)
    e = run(Scene(bodies=[Body("ball", "sphere", (0.05,), 1.0, (0, 0, 10, 1, 0, 0, 0))]))
    e.step(1000)
    drop, exact = 10 - e.body("ball").position[2], g / 2
    report("free fall 1 s", abs(drop / exact - 1) < 5e-3,
           f"drop {drop:.5f} m vs {exact:.5f} m ({drop / exact - 1:+.3%})")
    e.close()

    floor = Body("floor", "box", (1, 1, 0.1), pose=(0, 0, -0.05, 1, 0, 0, 0), static=True)
    e = run(Scene(bodies=[floor, Body("cube", "box", (0.05,) * 3, 0.1, (0, 0, 0.025, 1, 0, 0, 0))]))
    worst = 0.0
    for _ in range(100):
        e.step(10)
        worst = max(worst, abs(e.body("cube").position[2] - 0.025))
    report("resting cube 1 s", worst < 1e-3, f"max |z - z0| {worst * 1e3:.4f} mm")
    e.close()

    e = run(Scene(robots=[Robot("p", PENDULUM_URDF, joint_positions={"hinge": 0.3})]))
    crossings, last = [], e.joint("p", "hinge")[0]
    for _ in range(7000):
        e.step(1)
        q = e.joint("p", "hinge")[0]
        if last > 0 >= q:  # downward zero crossings, interpolated within the step
            crossings.append(e.time - dt * q / (q - last))
        last = q
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    exact = 2 * math.pi * math.sqrt((1.6e-4 + 1.0) / g)
    report("pendulum period", abs(period / exact - 1) < 0.03,
           f"{period:.4f} s vs small-angle {exact:.4f} s ({period / exact - 1:+.2%}; 0.3 rad adds ~+0.56 %)")
    e.close()

    # Symmetric about body x, which the pose turns onto world z: a world/body mix-up of ω would show.
    q0 = np.array([math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0])  # +90° about y: body x -> world -z
    box = Body("top", "box", (0.3, 0.1, 0.1), 1.0, (0, 0, 0, *q0), velocity=(0, 0, 0, 0, 0, 5))
    e = run(Scene(gravity=(0, 0, 0), bodies=[box]))
    e.step(1000)
    s = e.body("top")
    spin = np.array([math.cos(2.5), 0, 0, math.sin(2.5)])  # 5 rad about world z, w x y z
    expected = np.empty(4)
    mujoco.mju_mulQuat(expected, spin, q0)
    q_err = min(np.linalg.norm(s.orientation - expected), np.linalg.norm(s.orientation + expected))
    w_err = np.linalg.norm(s.angular - (0, 0, 5))
    report("torque-free spin 1 s", w_err < 5e-3 and q_err < 1e-3,
           f"ω {np.round(s.angular, 6)} rad/s, |Δω| {w_err:.2e}, |Δq| {q_err:.2e}")
    e.close()
    return ok


if __name__ == "__main__":
    import sys

    results = [_self_check(engine) for engine in (MujocoEngine, BulletEngine)]
    sys.exit(0 if all(results) else 1)
