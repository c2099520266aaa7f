"""graspsim: Python client of the graspsim grasp-simulation server.

    import graspsim
    with graspsim.connect("127.0.0.1:50051") as client:
        scene = client.create_scene("demo")
        client.add_object(scene.id, "cube", box=(0.05, 0.05, 0.05), mass=0.1, pose=[0, 0, 0.5, 1, 0, 0, 0])

Units are SI (m, kg, s, rad); quaternions are (w, x, y, z). The generated messages live in graspsim.v1.
Matplotlib helpers (optional extra "plot") live in graspsim.plot, imported only when asked for; the reader of
recordings (optional extra "record", the mcap package) in graspsim.mcap, likewise.
"""
from graspsim import inertia, meshes, viewer
from graspsim._client import Client, connect
from graspsim._errors import (AlreadyExists, Aborted, Cancelled, DataLoss, DeadlineExceeded, FailedPrecondition,
                              GraspsimError, Internal, InvalidArgument, NotFound, OutOfRange, PermissionDenied,
                              ResourceExhausted, Unauthenticated, Unavailable, Unimplemented)
from graspsim._gateway import PredictionResult
from graspsim._grasp import GraspSetResult
from graspsim._motion import ArmMotion, ArmPath, PickAndPlaceResult
from graspsim._perception import CompletedShape, SceneSegments
from graspsim._robot_files import MissingFilesError
from graspsim._recording import RecordingInfo, Replay
from graspsim._pose import Pose, Velocity, as_pose, quaternion_about_axis, quaternion_to_matrix
from graspsim._sensors import ForceTorqueState, GripperState, SensorStream, TactileFrame
from graspsim._watch import SceneWatch, Snapshot
from graspsim.viewer import viewer_url
from graspsim._work_cycle import WorkCycleFrame, WorkCycleResult, WorkCycleSummary
from graspsim.v1 import common_pb2, scene_pb2, tactile_pb2

__all__ = ["ArmMotion", "ArmPath", "PickAndPlaceResult", "Client", "CompletedShape", "SceneSegments", "ForceTorqueState", "GraspSetResult", "GraspsimError", "Cancelled", "InvalidArgument", "DeadlineExceeded", "NotFound", "AlreadyExists", "PermissionDenied", "ResourceExhausted", "FailedPrecondition", "Aborted", "OutOfRange", "Unimplemented", "Internal", "Unavailable", "DataLoss", "Unauthenticated", "GripperState", "MissingFilesError", "Pose", "Velocity", "PredictionResult", "RecordingInfo", "Replay", "SceneWatch", "SensorStream",
           "Snapshot", "TactileFrame", "WorkCycleFrame", "WorkCycleResult", "WorkCycleSummary", "as_pose",
           "common_pb2", "connect", "inertia", "meshes", "quaternion_about_axis", "quaternion_to_matrix",
           "scene_pb2", "tactile_pb2", "viewer", "viewer_url"]
__version__ = "0.1.0"
