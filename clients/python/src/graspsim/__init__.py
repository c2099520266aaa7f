"""graspsim: Python client of the graspsim grasp-simulation server.

    import graspsim
    with graspsim.connect("127.0.0.1:50051") as client:
        scene = client.create_scene("demo")
        client.add_object(scene, "cube", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 0.5, 1, 0, 0, 0])

Units are SI (m, kg, s, rad); quaternions are (w, x, y, z). Every reply is a dataclass or numpy arrays; the
generated messages live in graspsim.v1, for the raw stubs (Client.scene_stub, ...) only.
Matplotlib helpers (optional extra "plot") live in graspsim.plot, imported only when asked for; the reader of
recordings (optional extra "record", the mcap package) in graspsim.mcap, likewise.
"""
from graspsim import inertia, meshes, viewer
from graspsim._auth import Identity
from graspsim._body import Body, Geometry, ImportRepair, Inertial, Material
from graspsim._client import Client, connect
from graspsim._devices import (CommandResult, Device, DeviceLimits, DeviceReading, EmergencyStopResult,
                               GripperPrediction, PredictionSample)
from graspsim._errors import (AlreadyExists, Aborted, Cancelled, DataLoss, DeadlineExceeded, FailedPrecondition,
                              GraspsimError, Internal, InvalidArgument, NotFound, OutOfRange, PermissionDenied,
                              ResourceExhausted, Unauthenticated, Unavailable, Unimplemented)
from graspsim._gateway import PredictionResult
from graspsim._grasp import CandidateLike, GraspCandidate, GraspSetResult
from graspsim._ids import BodyLike, SceneLike
from graspsim._motion import ArmMotion, ArmPath, PickAndPlaceProgress, PickAndPlaceResult
from graspsim._perception import CompletedShape, SceneSegments
from graspsim._robot_files import MissingFilesError
from graspsim._recording import RecordingInfo, Replay
from graspsim._pose import Pose, PoseLike, Velocity, as_pose, quaternion_about_axis, quaternion_to_matrix
from graspsim._scene import (AddedRobot, BuiltinModel, FileInfo, Joint, Mimic, Robot, Scene, SceneSummary,
                             TactileArray)
from graspsim._sensors import ForceTorqueState, GripperState, SensorStream, TactileFrame
from graspsim._simulation import ContactDefaults, SimulationParams, StepResult
from graspsim._watch import SceneWatch, Snapshot
from graspsim.viewer import viewer_url
from graspsim._work_cycle import WorkCycleFrame, WorkCycleResult, WorkCycleSummary
from graspsim.v1 import common_pb2, scene_pb2, tactile_pb2

__all__ = [
    # the connection
    "Client", "connect",
    # what names a scene, a body, a pose, a grasp candidate in a call
    "BodyLike", "CandidateLike", "PoseLike", "SceneLike", "as_pose",
    # replies: scenes and bodies
    "AddedRobot", "Body", "BuiltinModel", "FileInfo", "Geometry", "ImportRepair", "Inertial", "Joint", "Material",
    "Mimic", "Pose", "Robot", "Scene", "SceneSummary", "TactileArray", "Velocity",
    # simulation, streams, sensors
    "ContactDefaults", "ForceTorqueState", "GripperState", "SceneWatch", "SensorStream", "SimulationParams",
    "Snapshot", "StepResult", "TactileFrame", "WorkCycleFrame", "WorkCycleResult", "WorkCycleSummary",
    # grasps, motion, perception, recordings, devices, the caller
    "ArmMotion", "ArmPath", "CommandResult", "CompletedShape", "Device", "DeviceLimits", "DeviceReading",
    "EmergencyStopResult", "GraspCandidate", "GraspSetResult", "GripperPrediction", "Identity",
    "PickAndPlaceProgress", "PickAndPlaceResult", "PredictionResult", "PredictionSample", "RecordingInfo",
    "Replay", "SceneSegments",
    # errors
    "GraspsimError", "Cancelled", "InvalidArgument", "DeadlineExceeded", "NotFound", "AlreadyExists",
    "PermissionDenied", "ResourceExhausted", "FailedPrecondition", "Aborted", "OutOfRange", "Unimplemented",
    "Internal", "Unavailable", "DataLoss", "Unauthenticated", "MissingFilesError",
    # helpers and modules
    "common_pb2", "inertia", "meshes", "quaternion_about_axis", "quaternion_to_matrix", "scene_pb2", "tactile_pb2",
    "viewer", "viewer_url",
]
__version__ = "0.1.0"
