"""A scene and what it holds (create_scene, list_scenes, get_scene, add_robot, upload_file, builtin_models) as
frozen dataclasses: the replies of SceneService without the generated messages."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional

import numpy as np
from numpy.typing import NDArray

from graspsim._body import Body, ImportRepair, enum_name, vector
from graspsim._equality import ValueEquality
from graspsim._pose import Pose
from graspsim.v1 import common_pb2, scene_pb2


@dataclass(frozen=True)
class SceneSummary:
    """What create_scene, import_scene and list_scenes return: pass it (or its .id) wherever a scene is expected.

    Attributes:
        id: the scene id; name: free text for people.
        body_count, robot_count: what the scene holds.
        revision: increases with every accepted change.
        time: simulation time, s.
    """

    id: str
    name: str
    body_count: int
    robot_count: int
    revision: int
    time: float

    @classmethod
    def from_proto(cls, m: scene_pb2.SceneSummary) -> SceneSummary:
        return cls(m.id, m.name, m.body_count, m.robot_count, m.revision, m.time)


@dataclass(frozen=True)
class FileInfo:
    """A file held by a scene: its path as uploaded ("meshes/finger.stl"), size in bytes, lower-case hex SHA-256."""

    path: str
    size: int
    sha256: str

    @classmethod
    def from_proto(cls, m: common_pb2.FileInfo) -> FileInfo:
        return cls(m.path, m.size, m.sha256)


@dataclass(frozen=True)
class BuiltinModel:
    """A model built into the server: its name ("schunk_pg70"), kind ("robot" for add_robot, "object" for
    add_object) and description (what it is, the datasheet its dimensions come from)."""

    name: str
    kind: str
    description: str


@dataclass(frozen=True)
class Mimic:
    """A joint that follows another: position = multiplier * position of joint_id + offset (rad or m)."""

    joint_id: str
    multiplier: float
    offset: float


@dataclass(frozen=True, eq=False)
class Joint(ValueEquality):
    """A robot's joint.

    Attributes:
        id: "<robot>/<joint>"; robot_id: its robot.
        type: "revolute" (rad, limited), "continuous" (rad), "prismatic" (m, limited) or "fixed".
        parent_body, child_body: the body ids it connects.
        origin: the joint frame in the parent body frame at position 0; axis: (3,) unit, in the joint frame.
        lower, upper: limits, rad or m; velocity_limit rad/s or m/s, effort_limit N m or N (0 = none given).
        position: rad or m; velocity: rad/s or m/s.
        mimic: the joint it follows, None for an independent joint.
    """

    id: str
    robot_id: str
    type: str
    parent_body: str
    child_body: str
    origin: Pose
    axis: NDArray[np.float64]
    lower: float
    upper: float
    velocity_limit: float
    effort_limit: float
    position: float
    velocity: float
    mimic: Optional[Mimic]

    @classmethod
    def from_proto(cls, m: common_pb2.Joint) -> Joint:
        mimic = Mimic(m.mimic.joint_id, m.mimic.multiplier, m.mimic.offset) if m.HasField("mimic") else None
        return cls(id=m.id, robot_id=m.robot_id, type=enum_name(common_pb2.JointType.Name, m.type, "JOINT_TYPE_"),
                   parent_body=m.parent_body, child_body=m.child_body, origin=Pose.from_proto(m.origin),
                   axis=vector(m.axis), lower=m.lower, upper=m.upper, velocity_limit=m.velocity_limit,
                   effort_limit=m.effort_limit, position=m.position, velocity=m.velocity, mimic=mimic)


@dataclass(frozen=True, eq=False)
class TactileArray(ValueEquality):
    """A tactile array mounted on a body (a Weiss DSA 9205 on a PG70 finger).

    Attributes:
        id: "<robot>/<sensor>", the sensor id of sample() and stream_sensors(); body_id: the body it is fixed to.
        origin: the pad frame in the body frame: texels in its x-y plane, sensing along +z.
        rows, cols: texels along y and x; pitch: texel spacing, m; thickness: foam thickness, m.
        subdivision: sensing-mesh cells per texel edge; elements: "vertices" or "face_centres".
        bend_radius_x, bend_radius_y: m, the radius a curved fingertip's pad wraps around (0 = flat).
    """

    id: str
    body_id: str
    origin: Pose
    rows: int
    cols: int
    pitch: float
    thickness: float
    subdivision: int
    elements: str
    bend_radius_x: float
    bend_radius_y: float

    @classmethod
    def from_proto(cls, m: common_pb2.TactileArray) -> TactileArray:
        return cls(m.id, m.body_id, Pose.from_proto(m.origin), m.rows, m.cols, m.pitch, m.thickness, m.subdivision,
                   m.elements, m.bend_radius_x, m.bend_radius_y)


@dataclass(frozen=True)
class Robot:
    """A robot: its id, source ("builtin:<name>", "urdf", ...), root link (base_body, welded to the world at the
    base pose) and the ids of its bodies, joints and tactile arrays."""

    id: str
    source: str
    base_body: str
    body_ids: List[str]
    joint_ids: List[str]
    tactile_array_ids: List[str]

    @classmethod
    def from_proto(cls, m: common_pb2.Robot) -> Robot:
        return cls(m.id, m.source, m.base_body, list(m.body_ids), list(m.joint_ids), list(m.tactile_array_ids))


@dataclass(frozen=True)
class AddedRobot:
    """add_robot's reply: the robot with its bodies ("<name>/<link>"), joints and tactile arrays, and every repair
    made to its file (empty when it loaded as written, docs/import.md)."""

    robot: Robot
    bodies: List[Body]
    joints: List[Joint]
    tactile_arrays: List[TactileArray]
    warnings: List[ImportRepair]

    @classmethod
    def from_proto(cls, m: scene_pb2.AddRobotResponse) -> AddedRobot:
        return cls(Robot.from_proto(m.robot), [Body.from_proto(b) for b in m.bodies],
                   [Joint.from_proto(j) for j in m.joints], [TactileArray.from_proto(t) for t in m.tactile_arrays],
                   [ImportRepair.from_proto(w) for w in m.warnings])


@dataclass(frozen=True)
class Scene:
    """get_scene's reply: the whole scene. Pass it (or .id) wherever a scene is expected.

    Attributes:
        summary: id, name, counts, revision, simulation time.
        bodies, joints, robots, tactile_arrays: everything it holds (meshes only with include_geometry).
        files: the files uploaded into it.
    """

    summary: SceneSummary
    bodies: List[Body]
    joints: List[Joint]
    robots: List[Robot]
    tactile_arrays: List[TactileArray]
    files: List[FileInfo]

    @property
    def id(self) -> str:
        """The scene id (summary.id)."""
        return self.summary.id

    @classmethod
    def from_proto(cls, m: scene_pb2.Scene) -> Scene:
        return cls(SceneSummary.from_proto(m.summary), [Body.from_proto(b) for b in m.bodies],
                   [Joint.from_proto(j) for j in m.joints], [Robot.from_proto(r) for r in m.robots],
                   [TactileArray.from_proto(t) for t in m.tactile_arrays], [FileInfo.from_proto(f) for f in m.files])
