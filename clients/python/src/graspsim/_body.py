"""A rigid body as the server holds it (add_object's reply, get_scene's bodies), as dataclasses with numpy arrays.

Enumerations become their lower-case names ("free", "revolute"), vectors (3,) float64 arrays, poses Pose, so that a
user never needs the generated graspsim.v1 messages to read a reply.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, List

import numpy as np
from numpy.typing import NDArray

from graspsim._equality import ValueEquality
from graspsim._pose import Pose, Velocity
from graspsim.meshes import unpack_mesh
from graspsim.v1 import common_pb2


def enum_name(name_of: Callable[[int], str], value: int, prefix: str, unspecified: str = "unspecified") -> str:
    """"BODY_MOTION_FREE" -> "free"; 0 (the proto's UNSPECIFIED) -> `unspecified`, the name of what the server does
    then; a number this client does not know yet -> its digits, rather than an error on a newer server's reply."""
    if value == 0:
        return unspecified
    try:
        return name_of(value).removeprefix(prefix).lower()
    except ValueError:
        return str(value)


def vector(message: common_pb2.Vec3) -> NDArray[np.float64]:
    return np.array([message.x, message.y, message.z], dtype=np.float64)


@dataclass(frozen=True, eq=False)
class Geometry(ValueEquality):
    """One collision shape of a body, named as add_object's shape keywords name it.

    Attributes:
        shape: "box", "sphere", "cylinder", "mesh" or "mesh_file" ("" for a shape this client does not know).
        origin: the shape's frame in the body frame.
        size: (3,) float64, m: a box's full edge lengths (zeros for the other shapes).
        radius: m, of a sphere or a cylinder; length: m, of a cylinder along its z (0 for the other shapes).
        vertices: (n, 3) float32, m, and triangles: (m, 3) uint32 of an inline mesh, in the shape's frame before
            `scale`; empty for the other shapes, and for every mesh unless get_scene(include_geometry=True).
        mesh_file: the uploaded file of a "mesh_file" shape ("" otherwise).
        scale: (3,) float64, the per-axis scale of a mesh, dimensionless.
    """

    shape: str
    origin: Pose
    size: NDArray[np.float64]
    radius: float
    length: float
    vertices: NDArray[np.float32]
    triangles: NDArray[np.uint32]
    mesh_file: str
    scale: NDArray[np.float64]

    @classmethod
    def from_proto(cls, message: common_pb2.Geometry) -> Geometry:
        shape = message.WhichOneof("shape") or ""
        vertices, triangles = unpack_mesh(message.mesh)
        radius = message.sphere.radius if shape == "sphere" else message.cylinder.radius
        return cls(shape=shape, origin=Pose.from_proto(message.origin), size=vector(message.box.size),
                   radius=radius, length=message.cylinder.length, vertices=vertices.astype(np.float32),
                   triangles=triangles.astype(np.uint32), mesh_file=message.mesh_file,
                   scale=vector(message.scale) if message.HasField("scale") else np.ones(3))


@dataclass(frozen=True, eq=False)
class Inertial(ValueEquality):
    """Mass properties: mass kg, center_of_mass (3,) m in the body frame, inertia (3, 3) kg m^2 about the centre
    of mass in the body frame (symmetric). All zero for a body without them (a static one)."""

    mass: float
    center_of_mass: NDArray[np.float64]
    inertia: NDArray[np.float64]

    @classmethod
    def from_proto(cls, message: common_pb2.Inertial) -> Inertial:
        m = message
        tensor = np.array([[m.ixx, m.ixy, m.ixz], [m.ixy, m.iyy, m.iyz], [m.ixz, m.iyz, m.izz]], dtype=np.float64)
        return cls(m.mass, vector(m.center_of_mass), tensor)


@dataclass(frozen=True)
class Material:
    """Surface properties (docs/physics.md): friction coefficients μ_s, μ_d (dimensionless); contact stiffness N/m
    and damping N s/m per contact point, LuGre bristle stiffness N/m and damping N s/m, viscous friction N s/m,
    Stribeck velocity m/s; a contact parameter of 0 takes the scene's default (SimulationParams.contact)."""

    static_friction: float
    dynamic_friction: float
    contact_stiffness: float
    contact_damping: float
    bristle_stiffness: float
    bristle_damping: float
    viscous_friction: float
    stribeck_velocity: float

    @classmethod
    def from_proto(cls, m: common_pb2.Material) -> Material:
        return cls(m.static_friction, m.dynamic_friction, m.contact_stiffness, m.contact_damping,
                   m.bristle_stiffness, m.bristle_damping, m.viscous_friction, m.stribeck_velocity)


@dataclass(frozen=True)
class ImportRepair:
    """One repair made so that a file (or an object's request) loads, docs/import.md: the element as the file names
    it ("urdf: link 'panda_link8' inertial mass (kg)"), the value found ("0") and the action taken."""

    element: str
    value: str
    action: str

    @classmethod
    def from_proto(cls, m: common_pb2.ImportWarning) -> ImportRepair:
        return cls(m.element, m.value, m.action)


@dataclass(frozen=True, eq=False)
class Body(ValueEquality):
    """A rigid body as the server holds it.

    Attributes:
        id: unique in the scene: an object's name, or "<robot>/<link>". Pass the Body itself where a body id is
            expected.
        robot_id: the owning robot ("" for an object).
        motion: "static" (never moves), "free" (6 DoF) or "articulated" (a robot's link).
        collision: its collision shapes (meshes inline only with get_scene(include_geometry=True)).
        inertial, material: its mass and surface properties.
        pose: the body frame in the world.
        triangle_count: triangles of its mesh shapes (primitives count 0).
        velocity: a free body's, world frame (zero for static bodies and robot links).
        sleeping: a free body at rest that the simulation skips until something touches it.
        warnings: add_object's reply only: what was assumed for the request (an inertia from the geometry).
    """

    id: str
    robot_id: str
    motion: str
    collision: List[Geometry]
    inertial: Inertial
    material: Material
    pose: Pose
    triangle_count: int
    velocity: Velocity
    sleeping: bool
    warnings: List[ImportRepair]

    @classmethod
    def from_proto(cls, m: common_pb2.Body) -> Body:
        motion = enum_name(common_pb2.BodyMotion.Name, m.motion, "BODY_MOTION_")
        return cls(id=m.id, robot_id=m.robot_id, motion=motion,
                   collision=[Geometry.from_proto(g) for g in m.collision], inertial=Inertial.from_proto(m.inertial),
                   material=Material.from_proto(m.material), pose=Pose.from_proto(m.pose),
                   triangle_count=m.triangle_count, velocity=Velocity.from_proto(m.velocity), sleeping=m.sleeping,
                   warnings=[ImportRepair.from_proto(w) for w in m.warnings])
