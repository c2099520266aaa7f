"""Textbook cases with closed-form answers, run on any engine (scene_spec.Engine) at any time step.

Each case builds an engine-neutral Scene, runs it, and compares one measured figure with its closed form:
    error = |measured − expected| / scale
where `scale` is the expected value itself unless the expected value is zero (a body at rest), in which case the
case states its scale (the distance the body would travel without the effect under test). Every case states its
figure and closed form in its docstring. The incline cases tilt gravity by θ over a static floor: the same problem
as a tilted floor, with the contact normal along z; a box pushed by a constant force F on a flat floor is the same
problem with F = m g sin θ, so the sliding grid covers it.

Conservative cases (no contact, no damping: free fall, pendulums, torque-free rotation) run with the engine's
integrator for smooth motion (Scene.smooth); contact cases with its default.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Dict, List, Sequence

import numpy as np
from scipy.special import ellipk

from scene_spec import Body, Engine, Robot, Scene

G = 9.81
TIME_STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4)  # s, coarse to fine
# Errors below this are measurement noise (the least-squares fits and crossing interpolation resolve ~1e-5): a
# case converges when its error never rises by more than this as dt falls.
ERROR_FLOOR = 1e-4


@dataclass(frozen=True)
class Case:
    name: str
    run: Callable[[Callable[[], Engine], float], float]  # (engine factory, dt) → relative error
    conservative: bool = False  # energy drift is reported for these


@dataclass
class Outcome:
    error: float
    energy_drift: float = math.nan  # |E(end) − E(0)| / E scale, conservative cases only


def _quat_about(axis: Sequence[float], angle: float) -> tuple:
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return (math.cos(angle / 2), *(math.sin(angle / 2) * axis))


def _tilted(theta: float) -> tuple:
    return (G * math.sin(theta), 0.0, -G * math.cos(theta))


def _load(factory: Callable[[], Engine], scene: Scene, dt: float) -> Engine:
    engine = factory()
    engine.load(scene, dt)
    return engine


def _sample(engine: Engine, dt: float, seconds: float, every: float, read: Callable[[Engine], object]):
    """Steps `seconds` reading `read(engine)` every `every` s (and at t = 0); returns times and readings."""
    steps = max(1, int(round(every / dt)))
    times, values = [0.0], [read(engine)]
    for i in range(int(round(seconds / (steps * dt)))):
        engine.step(steps)
        times.append((i + 1) * steps * dt)
        values.append(read(engine))
    return np.array(times), values


# --- free fall ---------------------------------------------------------------------------------------------------
def free_fall(factory, dt) -> Outcome:
    """A sphere falls 1 s from rest in vacuum: drop g t² / 2 (= 4.905 m)."""
    scene = Scene(bodies=[Body("ball", "sphere", (0.05,), mass=1.0, pose=(0, 0, 10, 1, 0, 0, 0))], smooth=True)
    engine = _load(factory, scene, dt)
    try:
        engine.step(int(round(1.0 / dt)))
        drop = 10 - engine.body("ball").position[2]
    finally:
        engine.close()
    return Outcome(abs(drop - G / 2) / (G / 2))


# --- blocks on inclines ------------------------------------------------------------------------------------------
BOX = 0.05  # m, edge


def _block_on_incline(factory, dt, theta, mu_s, mu_d, seconds=1.0):
    """Times and x positions of a 5 cm, 0.1 kg box on an incline of θ, sampled every 10 ms for `seconds`. The box
    settles on the level floor for 0.1 s, the floor is tilted at once (gravity turned), then 0.1 s passes before
    the first sample: placed on a tilted floor, a box would slide while its contact forms (faster than the
    Stribeck velocity, so at the dynamic friction), which is not the static case the closed form describes."""
    scene = Scene(gravity=(0, 0, -G), bodies=[
        Body("floor", "box", (20, 1, 0.1), pose=(0, 0, -0.05, 1, 0, 0, 0), static=True, friction=(mu_s, mu_d)),
        Body("block", "box", (BOX, BOX, BOX), mass=0.1, pose=(0, 0, BOX / 2, 1, 0, 0, 0), friction=(mu_s, mu_d))])
    engine = _load(factory, scene, dt)
    try:
        engine.step(int(round(0.1 / dt)))
        engine.set_gravity(_tilted(theta))
        engine.step(int(round(0.1 / dt)))
        times, xs = _sample(engine, dt, seconds, 0.01, lambda e: e.body("block").position[0])
    finally:
        engine.close()
    return times, np.array(xs)


def sliding(theta_deg: float, mu_s: float, mu_d: float) -> Callable:
    def case(factory, dt) -> Outcome:
        """Slides with a = g (sin θ − μ_d cos θ) (tan θ > μ_s); a from a least-squares fit of x(t) over 1 s."""
        theta = math.radians(theta_deg)
        expected = G * (math.sin(theta) - mu_d * math.cos(theta))
        times, xs = _block_on_incline(factory, dt, theta, mu_s, mu_d)
        return Outcome(abs(2 * np.polyfit(times, xs, 2)[0] - expected) / expected)
    return case


def sticking(theta_deg: float, mu_s: float, mu_d: float) -> Callable:
    def case(factory, dt) -> Outcome:
        """Stays (tan θ < μ_s): creep over 1 s, relative to the frictionless distance g sin θ t² / 2."""
        theta = math.radians(theta_deg)
        times, xs = _block_on_incline(factory, dt, theta, mu_s, mu_d)
        return Outcome(abs(xs[-1] - xs[0]) / (G * math.sin(theta) / 2 * times[-1] ** 2))
    return case


# --- rolling -----------------------------------------------------------------------------------------------------
def rolling(shape: str) -> Callable:
    def case(factory, dt) -> Outcome:
        """Rolls without slipping down 20° (μ = 1): a = g sin θ / (1 + I / (m r²)), 5/7 g sin θ for a solid sphere,
        2/3 g sin θ for a solid cylinder; a from a least-squares fit of x(t) over 1 s after 0.1 s."""
        theta, r = math.radians(20), 0.05
        if shape == "sphere":
            body, factor = Body("body", "sphere", (r,), mass=1.0, pose=(0, 0, r, 1, 0, 0, 0), friction=(1, 1)), 5 / 7
        else:  # axis along y: it rolls along x
            body = Body("body", "cylinder", (r, 0.1), mass=1.0, pose=(0, 0, r, *_quat_about((1, 0, 0), math.pi / 2)),
                        friction=(1, 1))
            factor = 2 / 3
        scene = Scene(gravity=_tilted(theta), bodies=[
            Body("floor", "box", (20, 1, 0.1), pose=(0, 0, -0.05, 1, 0, 0, 0), static=True, friction=(1, 1)), body])
        engine = _load(factory, scene, dt)
        try:
            engine.step(int(round(0.1 / dt)))
            times, xs = _sample(engine, dt, 1.0, 0.01, lambda e: e.body("body").position[0])
        finally:
            engine.close()
        expected = factor * G * math.sin(theta)
        return Outcome(abs(2 * np.polyfit(times, np.array(xs), 2)[0] - expected) / expected)
    return case


# --- pendulums ---------------------------------------------------------------------------------------------------
def _link(name: str, length: float, mass: float, radius: float) -> str:
    """A link whose mass sits in a small sphere at `length` below its joint (a compound pendulum)."""
    i = 0.4 * mass * radius ** 2
    return (f'<link name="{name}"><inertial><origin xyz="0 0 {-length}"/><mass value="{mass}"/>'
            f'<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
            f'<collision><origin xyz="0 0 {-length}"/><geometry><sphere radius="{radius}"/></geometry></collision>'
            f'</link>')


def _hinge(name: str, parent: str, child: str, offset: float) -> str:
    return (f'<joint name="{name}" type="revolute"><origin xyz="0 0 {-offset}"/><parent link="{parent}"/>'
            f'<child link="{child}"/><axis xyz="0 1 0"/>'
            f'<limit lower="-10" upper="10" effort="0" velocity="1000"/></joint>')


BASE_LINK = ('<link name="base"><inertial><mass value="1"/>'
             '<inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>')
L, M, R = 1.0, 1.0, 0.02  # m, kg, m: each pendulum link
PENDULUM = f'<robot name="pendulum">{BASE_LINK}{_link("bob", L, M, R)}{_hinge("hinge", "base", "bob", 0)}</robot>'
DOUBLE = (f'<robot name="double">{BASE_LINK}{_link("upper", L, M, R)}{_link("lower", L, M, R)}'
          f'{_hinge("shoulder", "base", "upper", 0)}{_hinge("elbow", "upper", "lower", L)}</robot>')


def _pendulum_run(factory, dt, urdf, joints, start, seconds):
    scene = Scene(gravity=(0, 0, -G), smooth=True,
                  robots=[Robot("p", urdf, base_pose=(0, 0, 3, 1, 0, 0, 0), joint_positions=dict(zip(joints, start)))])
    engine = _load(factory, scene, dt)
    try:
        return _sample(engine, dt, seconds, 0.005, lambda e: [e.joint("p", j) for j in joints])
    finally:
        engine.close()


def pendulum_period(factory, dt) -> Outcome:
    """Released at 60°, period T = 4 √(I / (m g L)) K(sin(θ0/2)) (the exact large-amplitude period, K the complete
    elliptic integral of the first kind, I = I_c + m L²), from the θ = 0 crossings over 10 s (interpolated)."""
    theta0, seconds = math.radians(60), 10.0
    times, states = _pendulum_run(factory, dt, PENDULUM, ["hinge"], [theta0], seconds)
    theta = np.array([s[0][0] for s in states])
    omega = np.array([s[0][1] for s in states])
    inertia = 0.4 * M * R * R + M * L * L
    expected = 4 * math.sqrt(inertia / (M * G * L)) * ellipk(math.sin(theta0 / 2) ** 2)
    crossings = [times[i] - theta[i] * (times[i + 1] - times[i]) / (theta[i + 1] - theta[i])
                 for i in range(len(theta) - 1) if theta[i] > 0 >= theta[i + 1] or theta[i] < 0 <= theta[i + 1]]
    period = 2 * np.mean(np.diff(crossings))
    energy = 0.5 * inertia * omega ** 2 + M * G * L * (1 - np.cos(theta))
    return Outcome(abs(period - expected) / expected, abs(energy[-1] - energy[0]) / energy[0])


def double_pendulum_energy(factory, dt) -> Outcome:
    """Released at (90°, 0) (chaotic): total energy is conserved; error = |E(10 s) − E(0)| / (E(0) − E_min),
    E_min the energy hanging at rest. Point-mass links of sphere inertia I_c about their centres."""
    times, states = _pendulum_run(factory, dt, DOUBLE, ["shoulder", "elbow"], [math.pi / 2, 0.0], 10.0)
    q1, w1 = np.array([s[0][0] for s in states]), np.array([s[0][1] for s in states])
    q2, w2 = np.array([s[1][0] for s in states]), np.array([s[1][1] for s in states])
    ic = 0.4 * M * R * R
    # Positions (x right, z up) of the two masses and their speeds; the elbow angle is relative to the upper link.
    v1 = L * w1
    v2x = L * np.cos(q1) * w1 + L * np.cos(q1 + q2) * (w1 + w2)
    v2z = L * np.sin(q1) * w1 + L * np.sin(q1 + q2) * (w1 + w2)
    kinetic = 0.5 * M * v1 ** 2 + 0.5 * M * (v2x ** 2 + v2z ** 2) + 0.5 * ic * (w1 ** 2 + (w1 + w2) ** 2)
    potential = -M * G * L * np.cos(q1) - M * G * (L * np.cos(q1) + L * np.cos(q1 + q2))
    energy = kinetic + potential
    e_min = -3 * M * G * L
    drift = abs(energy[-1] - energy[0]) / (energy[0] - e_min)
    return Outcome(drift, drift)


# --- torque-free rotation ----------------------------------------------------------------------------------------
def torque_free(factory, dt) -> Outcome:
    """A 0.1 × 0.2 × 0.3 m box in zero gravity spun near its intermediate axis (the tennis-racket flip): angular
    momentum L = R I Rᵀ ω is conserved; error = max |L(t) − L(0)| / |L(0)| over 10 s. Energy drift reported."""
    box = Body("box", "box", (0.1, 0.2, 0.3), mass=1.0, pose=(0, 0, 0, 1, 0, 0, 0), velocity=(0, 0, 0, 0.05, 5, 0.05))
    inertia = np.diag(box.inertia_diagonal())
    engine = _load(factory, Scene(gravity=(0, 0, 0), bodies=[box], smooth=True), dt)
    try:
        _, states = _sample(engine, dt, 10.0, 0.01, lambda e: e.body("box"))
    finally:
        engine.close()
    momenta, energies = [], []
    for s in states:
        w, x, y, z = s.orientation
        rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        world_inertia = rot @ inertia @ rot.T
        momenta.append(world_inertia @ s.angular)
        energies.append(0.5 * s.angular @ world_inertia @ s.angular)
    momenta = np.array(momenta)
    error = np.max(np.linalg.norm(momenta - momenta[0], axis=1)) / np.linalg.norm(momenta[0])
    return Outcome(error, abs(energies[-1] - energies[0]) / energies[0])


# --- at rest -----------------------------------------------------------------------------------------------------
def stack_at_rest(factory, dt) -> Outcome:
    """Five 5 cm boxes stacked on a floor stay put: the top box's displacement from 0.5 s to 5 s, relative to
    one edge (5 cm)."""
    bodies = [Body("floor", "box", (1, 1, 0.1), pose=(0, 0, -0.05, 1, 0, 0, 0), static=True)]
    bodies += [Body(f"box{i}", "box", (BOX, BOX, BOX), mass=0.1, pose=(0, 0, BOX / 2 + i * BOX, 1, 0, 0, 0))
               for i in range(5)]
    engine = _load(factory, Scene(bodies=bodies), dt)
    try:
        engine.step(int(round(0.5 / dt)))
        start = engine.body("box4").position.copy()
        engine.step(int(round(4.5 / dt)))
        end = engine.body("box4").position
    finally:
        engine.close()
    return Outcome(float(np.linalg.norm(end - start)) / BOX)


def arch_at_rest(factory, dt) -> Outcome:
    """Two 1 × 10 × 20 cm boards (0.2 kg) leaning 15° from vertical against each other on a floor with μ = 0.15:
    a card-house arch. Each board rests on its foot's inner edge; by symmetry the apex pushes horizontally, with
    H = W (h sin α − t cos α) / (2 h cos α) by moments about the foot, so the feet need μ ≥ H / W = 0.109: it
    stands, friction at 73 % of its limit (at μ = 0.1 it falls: checked by hand, graspsim 0.12 holds, 0.1
    falls). Error: a board's displacement from 0.5 s to 5 s, relative to its height."""
    t, h, alpha, mu = 0.01, 0.2, math.radians(15), 0.15
    # The foot's inner edge on the floor, the top inner edges meeting at x = 0.
    xc = t / 2 * math.cos(alpha) + h / 2 * math.sin(alpha)
    zc = t / 2 * math.sin(alpha) + h / 2 * math.cos(alpha)
    boards = [Body(name, "box", (t, 0.1, h), mass=0.2, friction=(mu, mu),
                   pose=(sign * xc, 0, zc, *_quat_about((0, 1, 0), -sign * alpha)))
              for name, sign in (("left", -1), ("right", 1))]
    floor = Body("floor", "box", (1, 1, 0.1), pose=(0, 0, -0.05, 1, 0, 0, 0), static=True, friction=(mu, mu))
    engine = _load(factory, Scene(bodies=[floor, *boards]), dt)
    try:
        engine.step(int(round(0.5 / dt)))
        start = engine.body("left").position.copy()
        engine.step(int(round(4.5 / dt)))
        end = engine.body("left").position
    finally:
        engine.close()
    return Outcome(float(np.linalg.norm(end - start)) / h)


VISE = (f'<robot name="vise">{BASE_LINK}'
        + "".join(f'<link name="{side}"><inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" '
                  f'ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.02 0.06 0.4"/>'
                  f'</geometry></collision></link>'
                  f'<joint name="{side}_slide" type="prismatic"><origin xyz="{sign * 0.035} 0 0"/>'
                  f'<parent link="base"/><child link="{side}"/><axis xyz="{-sign} 0 0"/>'
                  f'<limit lower="-0.02" upper="0.02" effort="100" velocity="1"/></joint>'
                  for side, sign in (("left", -1), ("right", 1)))
        + "</robot>")


def held_box(force_ratio: float) -> Callable:
    def case(factory, dt) -> Outcome:
        """A 5 cm, 0.1 kg box squeezed between two 40 cm tall pads, each pressed with F = ratio · m g / (2 μ_s).
        Pads and box have the links' default friction, μ_s 0.6 and μ_d 0.4. Above ratio 1 it is held (error: its
        drop over 0.25 s relative to free fall's g t² / 2); below, it slides down with a = g − 2 μ_d F / m (error:
        relative, from a least-squares fit of z(t) over 0.25 s after 0.05 s, within the pads' height)."""
        mass, mu_s, mu_d = 0.1, 0.6, 0.4
        force = force_ratio * mass * G / (2 * mu_s)
        vise = Robot("v", VISE, base_pose=(0, 0, 0.5, 1, 0, 0, 0))
        box = Body("box", "box", (BOX, BOX, BOX), mass=mass, pose=(0, 0, 0.67, 1, 0, 0, 0), friction=(mu_s, mu_d))
        # Gravity off while the pads close on the box.
        engine = _load(factory, Scene(gravity=(0, 0, 0), bodies=[box], robots=[vise]), dt)
        try:
            for side in ("left", "right"):
                engine.push("v", f"{side}_slide", force)
            engine.step(int(round(0.2 / dt)))
            engine.set_gravity((0, 0, -G))
            engine.step(int(round(0.05 / dt)))
            times, zs = _sample(engine, dt, 0.25, 0.005, lambda e: e.body("box").position[2])
        finally:
            engine.close()
        zs = np.array(zs)
        if force_ratio >= 1:
            return Outcome(abs(zs[-1] - zs[0]) / (G / 2 * times[-1] ** 2))
        expected = G - 2 * mu_d * force / mass
        return Outcome(abs(-2 * np.polyfit(times, zs, 2)[0] - expected) / expected)
    return case


CASES: List[Case] = [
    Case("free_fall", free_fall, conservative=True),
    *[Case(f"slide_{t}deg_mu{m}", sliding(t, m, m)) for t, m in ((20, 0.1), (20, 0.3), (30, 0.1), (30, 0.3),
                                                                   (45, 0.3), (45, 0.6))],
    Case("slide_35deg_mus0.6_mud0.3", sliding(35, 0.6, 0.3)),
    Case("stick_25deg_mus0.6_mud0.3", sticking(25, 0.6, 0.3)),
    Case("stick_20deg_mu0.5", sticking(20, 0.5, 0.5)),
    Case("roll_sphere_20deg", rolling("sphere")),
    Case("roll_cylinder_20deg", rolling("cylinder")),
    Case("pendulum_period_60deg", pendulum_period, conservative=True),
    Case("double_pendulum_energy", double_pendulum_energy, conservative=True),
    Case("torque_free_intermediate_axis", torque_free, conservative=True),
    Case("stack_of_5_at_rest", stack_at_rest),
    Case("arch_of_2_boards_at_rest", arch_at_rest),
    Case("held_box_at_1.2x_min_force", held_box(1.2)),
    Case("held_box_slips_at_0.8x_min_force", held_box(0.8)),
]


def converging(errors: Sequence[float]) -> bool:
    """Errors given coarse to fine: never rising by more than ERROR_FLOOR as dt falls."""
    return all(b <= a + ERROR_FLOOR for a, b in zip(errors, errors[1:]))


def run_case(case: Case, factory: Callable[[], Engine], time_steps: Sequence[float] = TIME_STEPS) -> Dict[float, Outcome]:
    return {dt: case.run(factory, dt) for dt in time_steps}
