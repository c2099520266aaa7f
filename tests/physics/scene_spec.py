"""An engine-neutral description of a textbook scene, and the interface every engine adapter implements.

The textbook cases (textbook.py) describe their scenes with these records only, so graspsim (through its Python
client), MuJoCo and Bullet run exactly the same inputs. Units SI; poses are (x, y, z, qw, qx, qy, qz) in the
world frame; velocities are world-frame, linear at the centre of mass (which is the body origin here: every body
is a uniform solid primitive).
"""
from dataclasses import dataclass, field
from typing import Dict, Optional, Protocol, Sequence, Tuple

import numpy as np

IDENTITY = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Body:
    name: str
    shape: str                        # "box" | "sphere" | "cylinder"
    size: Tuple[float, ...]           # box: full edges (x, y, z); sphere: (r,); cylinder: (r, length) along body z
    mass: float = 0.0                 # kg; uniform density; ignored when static
    pose: Tuple[float, ...] = IDENTITY
    friction: Tuple[float, float] = (0.5, 0.5)  # (static μ_s, dynamic μ_d); one-coefficient engines take μ_d
    static: bool = False
    velocity: Optional[Tuple[float, ...]] = None  # (vx, vy, vz, wx, wy, wz) at t = 0, world frame

    def inertia_diagonal(self) -> np.ndarray:
        """Principal moments about the centre of mass in the body frame, kg m² (uniform solid)."""
        m = self.mass
        if self.shape == "box":
            x, y, z = self.size
            return m / 12 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])
        if self.shape == "sphere":
            return np.full(3, 0.4 * m * self.size[0] ** 2)
        r, length = self.size
        side = m * (3 * r * r + length * length) / 12
        return np.array([side, side, 0.5 * m * r * r])


@dataclass(frozen=True)
class Robot:
    """A fixed-base articulated body given as URDF text (primitives only, inertials given, no meshes)."""
    name: str
    urdf: str
    base_pose: Tuple[float, ...] = IDENTITY
    joint_positions: Dict[str, float] = field(default_factory=dict)  # by URDF joint name, rad or m, at t = 0


@dataclass(frozen=True)
class Scene:
    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.81)
    bodies: Sequence[Body] = ()
    robots: Sequence[Robot] = ()
    # No contact, no damping: the engine runs its integrator for smooth motion (graspsim and MuJoCo: Runge–Kutta 4;
    # Bullet has one); otherwise its default.
    smooth: bool = False


@dataclass
class BodyState:
    position: np.ndarray     # (3,) m
    orientation: np.ndarray  # (4,) w, x, y, z
    linear: np.ndarray       # (3,) m/s, of the centre of mass, world
    angular: np.ndarray      # (3,) rad/s, world


class Engine(Protocol):
    name: str                # "graspsim" | "mujoco" | "bullet"

    def load(self, scene: Scene, dt: float) -> None:
        """Builds the scene with time step dt (s) and sets t = 0. Called once per adapter instance."""

    def step(self, steps: int) -> None:
        """Advances `steps` steps of dt."""

    def set_gravity(self, gravity: Sequence[float]) -> None:
        """Changes gravity (m/s², world) from the next step on; bodies keep their state."""

    def push(self, robot: str, joint: str, force: float) -> None:
        """Drives a URDF joint of a robot with a constant force (N or N m) from the next step on."""

    def body(self, name: str) -> BodyState: ...

    def joint(self, robot: str, joint: str) -> Tuple[float, float]:
        """(position, velocity) of a URDF joint of a robot, rad and rad/s."""

    def close(self) -> None: ...
