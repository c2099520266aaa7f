"""Client: the graspsim SceneService with Python values in and numpy/dataclasses out."""
from __future__ import annotations

import secrets
from typing import Any, Callable, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import grpc
import numpy as np
from google.protobuf.message import Message
from numpy.typing import ArrayLike, NDArray

from graspsim import _build, _robot_files
from graspsim._auth import AuthMethods, PemLike, open_channel
from graspsim._body import Body
from graspsim._errors import GraspsimError, translated_errors
from graspsim._gateway import GatewayMethods
from graspsim._grasp import (CandidateLike, FrictionPairs, GraspSetResult, MeshLike, candidate_proto, grasps_to_arrays,
                             set_materials, target_proto)
from graspsim._ids import BodyLike, SceneLike, body_id_of, scene_id_of
from graspsim._motion import MotionMethods
from graspsim._perception import PerceptionMethods
from graspsim._pose import Pose, PoseLike, Velocity, as_pose
from graspsim._progress import advance, progress_bar
from graspsim._recording import RecordingMethods
from graspsim._robot_files import FilePath, PackageRoots
from graspsim._scene import AddedRobot, BuiltinModel, FileInfo, Scene, SceneSummary
from graspsim._sensors import Reading, SensorStream, reading_from_proto
from graspsim._simulation import SimulationParams, StepResult, params_message
from graspsim._stream import server_stream
from graspsim._upload import FileData, upload_chunks
from graspsim._watch import SceneWatch
from graspsim._work_cycle import STAGES as WORK_CYCLE_STAGES, WorkCycleFrame, WorkCycleResult
from graspsim.v1 import common_pb2, grasp_pb2, grasp_pb2_grpc, scene_pb2, scene_pb2_grpc, tactile_pb2, tactile_pb2_grpc

_CHANNEL_OPTIONS = [
    ("grpc.max_receive_message_length", 256 << 20),  # scenes with include_geometry can be large
    ("grpc.max_send_message_length", -1),            # the server enforces its own limit
]


def connect(target: str = "127.0.0.1:50051", timeout: float = 10.0, *, call_timeout: float = 60.0,
            token: Optional[str] = None, tls: bool = False, root_certificates: PemLike = None,
            private_key: PemLike = None, certificate_chain: PemLike = None, fleet: bool = False) -> Client:
    """Connects to a graspsim server at "host:port", waiting up to timeout (s) for the channel to be ready.

    call_timeout (s) is the deadline of every unary call. Raises GraspsimError(UNAVAILABLE) when no server
    answers in time. token: the bearer token sent with every call. tls=True (or root_certificates, PEM bytes
    or a file path: the CA of the server's certificate) connects over TLS; private_key + certificate_chain add
    a client certificate (docs/security.md). fleet=True: target is a load balancer in front of several servers
    (docs/scaling.md): create_scene then chooses each new scene's id itself, so that the balancer can route the
    creation and every later call of the scene to the same server.
    """
    channel = open_channel(target, _CHANNEL_OPTIONS, token=token, tls=tls, root_certificates=root_certificates,
                           private_key=private_key, certificate_chain=certificate_chain)
    try:
        grpc.channel_ready_future(channel).result(timeout=timeout)
    except grpc.FutureTimeoutError:
        channel.close()
        raise GraspsimError.for_code(grpc.StatusCode.UNAVAILABLE,
                            f"no graspsim server answered at {target} within {timeout:g} s") from None
    return Client(channel, call_timeout, fleet=fleet)


def _own_mixin_methods(cls: type) -> type:
    """The mixins only split Client over files: their public methods become Client's own, so the API reference
    (pdoc leaves out members inherited from private classes) lists them on Client."""
    for mixin in cls.__mro__[1:-1]:
        for name, member in vars(mixin).items():
            if not name.startswith("_") and name not in vars(cls):
                setattr(cls, name, member)
    return cls


@_own_mixin_methods
class Client(GatewayMethods, PerceptionMethods, MotionMethods, AuthMethods, RecordingMethods):
    """A connection to one graspsim server (see connect()); a context manager that closes the channel.

    Units are SI: m, kg, s, rad; poses are Pose, [x y z qw qx qy qz] or (position, quaternion (w, x, y, z)).
    Replies are dataclasses and numpy arrays, never the generated graspsim.v1 messages. Where a scene is expected,
    its id or the object carrying it (SceneSummary, Scene, Replay, RecordingInfo: SceneLike) is taken; where a
    body is, its id or the Body (BodyLike). Every method raises GraspsimError (gRPC code + server message) when the
    server refuses a request. The raw stubs are available as `scene_stub`, `tactile_stub` and `grasp_stub` for
    messages this class does not wrap.
    """

    def __init__(self, channel: grpc.Channel, call_timeout: float = 60.0, *, fleet: bool = False) -> None:
        self.channel = channel
        self.call_timeout = call_timeout
        self.fleet = fleet
        self.scene_stub = scene_pb2_grpc.SceneServiceStub(channel)
        self.tactile_stub = tactile_pb2_grpc.TactileServiceStub(channel)
        self.grasp_stub = grasp_pb2_grpc.GraspServiceStub(channel)

    def close(self) -> None:
        """Closes the channel; open WatchScene streams end."""
        self.channel.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _unary(self, method: str, request: Message, stub: Any = None) -> Any:
        # Any: the generated *_pb2_grpc stubs are untyped; the callers turn the response into what they return
        with translated_errors():
            return getattr(stub or self.scene_stub, method)(request, timeout=self.call_timeout)

    # --- scenes -------------------------------------------------------------------------------------------
    def create_scene(self, name: str = "scene", scene_id: Optional[str] = None) -> SceneSummary:
        """Creates an empty scene; returns its summary (.id is the scene id). scene_id: the id to give it (1-64 of
        letters, digits, '-', '_', '.'; ALREADY_EXISTS when taken); None = the server's next "scene-<n>", or a
        random "s-<16 hex digits>" on a fleet connection (connect(fleet=True))."""
        if scene_id is None and self.fleet:
            scene_id = "s-" + secrets.token_hex(8)
        request = scene_pb2.CreateSceneRequest(name=name, scene_id=scene_id or "")
        return SceneSummary.from_proto(self._unary("CreateScene", request).summary)

    def list_scenes(self) -> List[SceneSummary]:
        """Summaries of every scene on the server."""
        return [SceneSummary.from_proto(s) for s in self._unary("ListScenes", scene_pb2.ListScenesRequest()).scenes]

    def get_scene(self, scene_id: SceneLike, include_geometry: bool = False) -> Scene:
        """The whole scene: bodies, joints, robots, tactile arrays, files (meshes only with include_geometry)."""
        request = scene_pb2.GetSceneRequest(scene_id=scene_id_of(scene_id), include_geometry=include_geometry)
        return Scene.from_proto(self._unary("GetScene", request))

    def delete_scene(self, scene_id: SceneLike) -> None:
        """Deletes a scene with everything in it."""
        self._unary("DeleteScene", scene_pb2.DeleteSceneRequest(scene_id=scene_id_of(scene_id)))

    def export_scene(self, scene_id: SceneLike) -> bytes:
        """The whole scene as an archive (its edits as received, its files, its state), for import_scene on
        another server: how a fleet moves a scene (graspsim.fleet.rebalance, docs/scaling.md)."""
        request = scene_pb2.ExportSceneRequest(scene_id=scene_id_of(scene_id))
        with server_stream(self.scene_stub.ExportScene(request, timeout=self.call_timeout)) as call:
            return b"".join(chunk.data for chunk in call)

    def import_scene(self, archive: bytes, scene_id: Optional[str] = None,
                     chunk_size: int = 1 << 20) -> SceneSummary:
        """A scene rebuilt from export_scene's archive, under scene_id (None = the id it had); ALREADY_EXISTS
        when the id is taken. Returns its summary. Through a fleet's balancer give scene_id: the import is
        routed by it (None goes to any replica)."""
        if chunk_size <= 0:
            raise ValueError(f"chunk_size must be > 0 bytes, got {chunk_size}")
        view = memoryview(archive).cast("B")

        def chunks() -> Iterator[scene_pb2.SceneArchiveChunk]:
            yield scene_pb2.SceneArchiveChunk(scene_id=scene_id or "", data=bytes(view[:chunk_size]))
            for start in range(chunk_size, len(view), chunk_size):
                yield scene_pb2.SceneArchiveChunk(data=bytes(view[start:start + chunk_size]))

        with translated_errors():
            reply = self.scene_stub.ImportScene(chunks(), timeout=self.call_timeout)
        return SceneSummary.from_proto(reply.summary)

    # --- files and models ---------------------------------------------------------------------------------
    def upload_file(self, scene_id: SceneLike, path_in_scene: str, data: FileData,
                    chunk_size: int = 1 << 20) -> FileInfo:
        """Uploads a file into a scene in chunks of chunk_size bytes, so files above the message limit pass.

        data is the content (bytes) or the path of a local file (str / os.PathLike). path_in_scene is how a
        URDF or Geometry.mesh_file names it (e.g. "meshes/finger.stl"). The server checks size and SHA-256.
        """
        with translated_errors():
            reply = self.scene_stub.UploadFile(upload_chunks(scene_id_of(scene_id), path_in_scene, data, chunk_size),
                                               timeout=self.call_timeout)
        return FileInfo.from_proto(reply)

    def builtin_models(self) -> List[BuiltinModel]:
        """The server's built-in models (name, kind "robot"/"object", description)."""
        reply = self._unary("ListBuiltinModels", scene_pb2.ListBuiltinModelsRequest())
        return [BuiltinModel(m.name, m.kind, m.description) for m in reply.models]

    # --- bodies and robots --------------------------------------------------------------------------------
    def add_object(self, scene_id: SceneLike, name: str, *, builtin: Optional[str] = None,
                   box: Optional[ArrayLike] = None, sphere: Optional[float] = None,
                   cylinder: Optional[ArrayLike] = None, mesh: Optional[MeshLike] = None,
                   mesh_file: Optional[str] = None, mass: Optional[float] = None, inertia: Optional[ArrayLike] = None,
                   center_of_mass: Optional[ArrayLike] = None, friction: Optional[ArrayLike] = None,
                   pose: Optional[PoseLike] = None, is_static: bool = False, inertia_source: str = "auto",
                   density: Optional[float] = None, strict: bool = False) -> Body:
        """Adds a rigid object; give exactly one shape:

        builtin="cube_5cm" (its own mass and friction unless given), box=(x, y, z) full edge lengths m,
        sphere=radius m, cylinder=(radius, length) m along z, mesh=(vertices (N, 3) m, triangles (M, 3)
        counter-clockwise from outside), mesh_file="path" uploaded with upload_file.

        mass in kg; inertia 3x3 in kg m^2 about center_of_mass (m, body frame). With a mass but no inertia,
        the uniform-density inertia is computed here: box m(b²+c²)/12 …, sphere 2/5 m r², cylinder m r²/2
        about z and m(3r²+l²)/12 about x and y, closed mesh by the divergence theorem (its volume centroid
        becomes center_of_mass unless given); mesh_file and builtin need an explicit inertia with a mass.
        Without a mass, a static body needs none; a moving one given by geometry takes the server's solid-geometry
        mass properties at density kg/m^3 (default 1000) with inertia_source "auto" or "from_geometry" (reported
        in the reply's warnings), while "from_file" or strict=True require the mass here.
        friction=(static, dynamic) coefficients; pose is the body frame in the world; is_static fixes it.
        Returns the Body as the server holds it.
        """
        kind, value = _build.pick_shape(dict(builtin=builtin, box=box, sphere=sphere, cylinder=cylinder,
                                             mesh=mesh, mesh_file=mesh_file))
        request = scene_pb2.AddObjectRequest(scene_id=scene_id_of(scene_id), name=name, is_static=is_static)
        request.import_options.CopyFrom(_build.import_options(inertia_source, density, strict))
        if kind == "builtin":
            request.builtin = value
        else:
            request.geometry.CopyFrom(_build.geometry(kind, value))
        inertial = _build.inertial(kind, value, mass, inertia, center_of_mass)
        if inertial is not None:
            request.inertial.CopyFrom(inertial)
        material = _build.material(friction)
        if material is not None:
            request.material.CopyFrom(material)
        if pose is not None:
            request.pose.CopyFrom(as_pose(pose).to_proto())
        return Body.from_proto(self._unary("AddObject", request))

    def add_robot(self, scene_id: SceneLike, name: str, *, urdf: Optional[str] = None, builtin: Optional[str] = None,
                  mjcf: Optional[str] = None, sdf: Optional[str] = None, path: Optional[FilePath] = None,
                  package_roots: PackageRoots = None, base_pose: Optional[PoseLike] = None,
                  files: Optional[Mapping[str, bytes]] = None, inertia: str = "auto",
                  density: Optional[float] = None, strict: bool = False,
                  model_name: str = "") -> AddedRobot:
        """Adds a robot from URDF, MJCF or SDF text, a file on this machine, or a built-in model ("schunk_pg70"),
        its root link at base_pose (world).

        path="robot.urdf" | "model.xml" | "model.sdf" reads the file (format from the extension, else the root
        element), uploads every mesh its collision geometry needs that the scene does not already hold (same
        SHA-256), then adds it: one call. package:// and model:// resolve under package_roots ({package: dir},
        or directories holding package dirs; None = the file's directory and its parents); relative paths
        against the file's directory. Files missing on disk raise MissingFilesError (a FileNotFoundError) naming
        every one, before anything is sent.
        With text, meshes must be uploaded first or given in files ({path: content}, small files only).
        inertia: "auto" (the file's where physical, else from the collision geometry), "from_file" or
        "from_geometry" (solid geometry at density kg/m^3, default 1000); strict=True refuses anything that
        would need a repair. model_name picks a model of an SDF <world>. Returns the robot with its bodies
        ("<name>/<link>"), joints, tactile arrays and warnings (every repair made to the file, docs/import.md).
        """
        sources = dict(urdf=urdf, builtin=builtin, mjcf=mjcf, sdf=sdf, path=path)
        given = [k for k, v in sources.items() if v is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of urdf, mjcf, sdf, builtin, path")
        if package_roots is not None and path is None:
            raise ValueError("package_roots applies to path= only")
        scene_id = scene_id_of(scene_id)
        if path is not None:
            robot_files = _robot_files.collect(path, package_roots)
            _robot_files.upload_missing(self, scene_id, robot_files.files)
            given, sources = [robot_files.format], {robot_files.format: robot_files.text}
        request = scene_pb2.AddRobotRequest(scene_id=scene_id, name=name)
        setattr(request, given[0], sources[given[0]])
        request.import_options.CopyFrom(_build.import_options(inertia, density, strict, model_name))
        if base_pose is not None:
            request.base_pose.CopyFrom(as_pose(base_pose).to_proto())
        for file_path, data in (files or {}).items():
            request.files.add(path=file_path, data=bytes(data))
        return AddedRobot.from_proto(self._unary("AddRobot", request))

    def remove_body(self, scene_id: SceneLike, id: BodyLike) -> List[str]:
        """Removes an object, or a robot (by robot id) with its links; returns the removed body ids."""
        request = scene_pb2.RemoveBodyRequest(scene_id=scene_id_of(scene_id), id=body_id_of(id, "id"))
        return list(self._unary("RemoveBody", request).removed_body_ids)

    # --- poses and joints ---------------------------------------------------------------------------------
    def set_body_poses(self, scene_id: SceneLike, poses: Mapping[str, PoseLike]) -> int:
        """Sets world poses by body id (object, robot id or robot base body), all or none; returns the revision."""
        request = scene_pb2.SetBodyPosesRequest(scene_id=scene_id_of(scene_id))
        for body_id, pose in poses.items():
            request.poses.add(body_id=body_id, pose=as_pose(pose).to_proto())
        result: int = self._unary("SetBodyPoses", request).revision
        return result

    def set_body_pose(self, scene_id: SceneLike, body_id: BodyLike, pose: PoseLike) -> int:
        """Sets one world pose; returns the new scene revision."""
        return self.set_body_poses(scene_id, {body_id_of(body_id): pose})

    def get_body_poses(self, scene_id: SceneLike, ids: Optional[Iterable[BodyLike]] = None) -> Dict[str, Pose]:
        """World poses by body id (every body when ids is None)."""
        request = scene_pb2.GetBodyPosesRequest(scene_id=scene_id_of(scene_id),
                                                body_ids=[body_id_of(i, "ids") for i in ids or []])
        return {p.body_id: Pose.from_proto(p.pose) for p in self._unary("GetBodyPoses", request).poses}

    def set_body_velocities(self, scene_id: SceneLike,
                            velocities: Mapping[str, Union[Velocity, Sequence[float]]]) -> int:
        """Sets free objects' velocities by id, all or none: a Velocity or 6 values (vx, vy, vz m/s of the centre
        of mass, wx, wy, wz rad/s), world frame. Poses stay. Returns the new scene revision."""
        request = scene_pb2.SetBodyPosesRequest(scene_id=scene_id_of(scene_id))
        for body_id, velocity in velocities.items():
            if not isinstance(velocity, Velocity):
                values = np.asarray(velocity, dtype=np.float64).reshape(-1)
                if values.shape != (6,):
                    raise ValueError(f"velocities[{body_id!r}]: 6 values (linear m/s, angular rad/s), "
                                     f"got {values.size}")
                velocity = Velocity(values[:3], values[3:])
            request.poses.add(body_id=body_id, velocity=velocity.to_proto())
        result: int = self._unary("SetBodyPoses", request).revision
        return result

    def get_body_velocities(self, scene_id: SceneLike,
                            ids: Optional[Iterable[BodyLike]] = None) -> Dict[str, Velocity]:
        """Free objects' velocities by id (world frame, centre of mass); every free object when ids is None.
        Static bodies and robot links have none of their own and are left out."""
        request = scene_pb2.GetBodyPosesRequest(scene_id=scene_id_of(scene_id),
                                                body_ids=[body_id_of(i, "ids") for i in ids or []])
        return {p.body_id: Velocity.from_proto(p.velocity)
                for p in self._unary("GetBodyPoses", request).poses if p.HasField("velocity")}

    def set_joint_positions(self, scene_id: SceneLike, positions: Mapping[str, float],
                            velocities: Optional[Mapping[str, float]] = None) -> int:
        """Sets joint positions (rad or m) by joint id, all or none; mimic joints follow. velocities (rad/s or m/s)
        are set for the joints named there (each needs a position too); the others keep theirs. Returns the
        revision."""
        velocities = dict(velocities or {})
        unknown = sorted(set(velocities) - set(positions))
        if unknown:
            raise ValueError(f"velocities: {unknown} have no position given")
        request = scene_pb2.SetJointPositionsRequest(scene_id=scene_id_of(scene_id))
        for joint_id, value in positions.items():
            entry = request.positions.add(joint_id=joint_id, position=float(value))
            if joint_id in velocities:
                entry.velocity = float(velocities[joint_id])
        result: int = self._unary("SetJointPositions", request).revision
        return result

    def get_joint_positions(self, scene_id: SceneLike, ids: Optional[Iterable[str]] = None) -> Dict[str, float]:
        """Joint positions (rad or m) by joint id (every joint when ids is None)."""
        request = scene_pb2.GetJointPositionsRequest(scene_id=scene_id_of(scene_id), joint_ids=list(ids or []))
        return {p.joint_id: p.position for p in self._unary("GetJointPositions", request).positions}

    def get_joint_velocities(self, scene_id: SceneLike, ids: Optional[Iterable[str]] = None) -> Dict[str, float]:
        """Joint velocities (rad/s or m/s) by joint id (every joint when ids is None)."""
        request = scene_pb2.GetJointPositionsRequest(scene_id=scene_id_of(scene_id), joint_ids=list(ids or []))
        return {p.joint_id: p.velocity for p in self._unary("GetJointPositions", request).positions}

    # --- streams and simulation ---------------------------------------------------------------------------
    def watch_scene(self, scene_id: SceneLike, max_rate_hz: float = 0.0) -> SceneWatch:
        """A live iterator of Snapshots: one at once, then one per change, at most max_rate_hz (0 = server
        default). Call cancel() on it (or use it in a with-block) to end the stream."""
        request = scene_pb2.WatchSceneRequest(scene_id=scene_id_of(scene_id), max_rate_hz=max_rate_hz)
        return SceneWatch(self.scene_stub.WatchScene(request))

    def step_simulation(self, scene_id: SceneLike, duration: Optional[float] = None, *, steps: Optional[int] = None,
                        until_time: Optional[float] = None) -> StepResult:
        """Advances the dynamic simulation by `duration` (s), a number of `steps`, or `until_time` (s).

        Returns the new simulation time (s), the steps taken, and the contact points and awake free bodies of the
        last step. A diverging run raises FAILED_PRECONDITION naming the body, the step and the quantity; the
        scene then holds its last finite state."""
        given = [x is not None for x in (duration, steps, until_time)]
        if sum(given) != 1:
            raise ValueError("give exactly one of duration, steps, until_time")
        request = scene_pb2.StepSimulationRequest(scene_id=scene_id_of(scene_id))
        if duration is not None:
            request.duration = duration
        elif steps is not None:
            request.steps = steps
        elif until_time is not None:  # exactly one is given (checked above)
            request.until_time = until_time
        return StepResult.from_proto(self._unary("StepSimulation", request))

    def set_simulation_params(self, scene_id: SceneLike, **params: Any) -> SimulationParams:
        """Sets simulation parameters by SimulationParams field name (time_step s, substeps, integrator
        "linearly_implicit_euler" | "semi_implicit_euler" | "velocity_verlet" | "runge_kutta_4", engine "graspsim" |
        "mujoco" | "bullet" (docs/physics.md), gravity (3,) m/s², contact dict of ContactDefaults fields,
        sample_spacing m, sleep_speed, sleep_time); fields not given keep their values. Returns them all."""
        request = scene_pb2.SetSimulationParamsRequest(scene_id=scene_id_of(scene_id), params=params_message(params))
        return SimulationParams.from_proto(self._unary("SetSimulationParams", request))

    def get_simulation_params(self, scene_id: SceneLike) -> SimulationParams:
        """The scene's simulation parameters, defaults filled in."""
        request = scene_pb2.GetSimulationParamsRequest(scene_id=scene_id_of(scene_id))
        return SimulationParams.from_proto(self._unary("GetSimulationParams", request))

    def set_actuator(self, scene_id: SceneLike, joint_id: str, mode: str, value: float = 0.0,
                     current_limit: float = 0.0) -> None:
        """Drives a joint with its DC motor: mode "velocity" (value m/s or rad/s), "position" (m or rad),
        "voltage" (V) or "off"; current_limit (A) caps the motor current, i.e. the force (0 = the motor's own).
        The built-in PG70's finger joint uses the PG70 drive."""
        # protoc's .pyi types the enum field as its enum class, EnumTypeWrapper.Value as returning int
        mode_number = scene_pb2.ActuatorMode.Value("ACTUATOR_MODE_" + mode.upper())
        command = scene_pb2.ActuatorCommand(joint_id=joint_id, mode=mode_number,  # type: ignore[arg-type]
                                            value=value, current_limit=current_limit)
        self._unary("SetActuators", scene_pb2.SetActuatorsRequest(scene_id=scene_id_of(scene_id), commands=[command]))
    # --- sensors ------------------------------------------------------------------------------------------
    def sample(self, scene_id: SceneLike, sensor_id: str) -> Reading:
        """One reading of a sensor in the scene's current state: a TactileFrame for a tactile array
        ("pg70/pad_left"), a GripperState for a robot's gripper ("pg70/gripper"), a ForceTorqueState for a
        joint's 6-axis force/torque sensor ("pg70/finger_left_joint")."""
        request = tactile_pb2.SampleRequest(scene_id=scene_id_of(scene_id), sensor_id=sensor_id)
        return reading_from_proto(self._unary("Sample", request, self.tactile_stub))

    def stream_sensors(self, scene_id: SceneLike, sensor_ids: Iterable[str], rate_hz: float) -> SensorStream:
        """A live iterator of readings (TactileFrame / GripperState / ForceTorqueState, one per sensor id in each
        round): at once, then whenever the scene changes, at most rate_hz rounds per second (the server caps it at its
        --watch-max-rate-hz), always of the newest state. cancel() it (or use a with-block) to end it."""
        request = tactile_pb2.StreamRequest(scene_id=scene_id_of(scene_id), sensor_ids=list(sensor_ids),
                                            rate_hz=rate_hz)
        return SensorStream(self.tactile_stub.Stream(request))

    def tactile_image(self, scene_id: SceneLike, sensor_id: str, scale: int = 20) -> bytes:
        """A tactile array's current reading as a PNG heat map (inferno colour map, black = no pressure),
        scale pixels per texel: a PG70 pad (6 x 14 texels) at scale 20 is 120 x 280 px (at most 4096 px a side)."""
        request = tactile_pb2.GetTactileImageRequest(scene_id=scene_id_of(scene_id), sensor_id=sensor_id, scale=scale)
        result: bytes = self._unary("GetTactileImage", request, self.tactile_stub).png
        return result

    def run_work_cycle(self, scene_id: SceneLike, gripper_id: str, object_id: BodyLike, *, tactile_setpoint: float = 0,
                       lift_height: float = 0, coverage: float = 0, frame_rate_hz: float = 0, hold_time: float = 0,
                       on_frame: Optional[Callable[[WorkCycleFrame], None]] = None,
                       timeout: Optional[float] = None, progress: bool = True) -> WorkCycleResult:
        """Runs the grasp work cycle on a gripper carried by a z axis (built-in "schunk_pg70_on_z_axis") and
        returns its time series: approach, grasp (velocity control until the first tactile contact, then force
        control of the tactile sum), lift, hold, move_down, release, done.

        tactile_setpoint: intensity sum per pad the force controller holds (0 = 60000); lift_height m (0 = 0.05);
        coverage: fraction (0, 1] of the pads' length the object covers (0 = 1); frame_rate_hz: progress frames
        per simulated second (0 = 50); hold_time: s held at the top (0 = 1). on_frame(frame) is called with each
        WorkCycleFrame as it arrives; if it raises, the cycle is cancelled and the exception propagates.
        progress=True shows a tqdm bar of the stages on stderr. timeout (s) bounds the whole call (None: no
        deadline). The server's refusals raise GraspsimError.
        """
        request = tactile_pb2.RunWorkCycleRequest(
            scene_id=scene_id_of(scene_id), gripper_id=gripper_id, object_id=body_id_of(object_id, "object_id"),
            tactile_setpoint=tactile_setpoint, lift_height=lift_height, coverage=coverage,
            frame_rate_hz=frame_rate_hz, hold_time=hold_time,
            # A message may carry the frames that waited while this reader was busy: a fast cycle's frames then
            # cost one message per batch rather than one each.
            max_frames_per_message=64)
        frames: List[WorkCycleFrame] = []
        # The bar counts stages: the cycle's length in frames depends on the object and is not known up front.
        with progress_bar(progress, len(WORK_CYCLE_STAGES) - 1, "work cycle", "stages") as bar, \
                server_stream(self.tactile_stub.RunWorkCycle(request, timeout=timeout)) as call:
            for message in call:
                for part in (message, *message.following):
                    frame = WorkCycleFrame.from_proto(part)
                    frames.append(frame)
                    if on_frame is not None:
                        on_frame(frame)
                stage = frame.stage  # the newest; a stage this client does not know leaves the bar where it is
                done = WORK_CYCLE_STAGES.index(stage) if stage in WORK_CYCLE_STAGES else bar.n
                advance(bar, done, f"{stage}, t {frame.time:.2f} s")
        return WorkCycleResult.from_frames(frames, tactile_setpoint=tactile_setpoint, lift_height=lift_height,
                                           coverage=coverage)

    # --- grasp planning ----------------------------------------------------------------------------------
    def plan_grasps(self, hand: str, *, scene_id: Optional[SceneLike] = None, body_id: Optional[BodyLike] = None,
                    mesh: Optional[MeshLike] = None, method: str = "bounding_box", friction: Optional[float] = None,
                    preshapes: Sequence[str] = (), standoffs: ArrayLike = (), rolls: Optional[int] = None,
                    spacing: Optional[float] = None, circle_samples: Optional[int] = None,
                    grasp_points: Optional[ArrayLike] = None, seed: Optional[int] = None,
                    max_candidates: int = 0, max_grasps: int = 0,
                    recompute: bool = False, progress: bool = True,
                    on_progress: Optional[Callable[[int, int], None]] = None,
                    timeout: Optional[float] = None, object_material: Optional[str] = None,
                    link_materials: Optional[Dict[str, str]] = None,
                    friction_pairs: Optional[FrictionPairs] = None) -> GraspSetResult:
        """Plans the grasp set of an object for a built-in hand ("schunk_pg70", "barrett_bh8_282", "schunk_sdh2"),
        or returns the stored one (same hand, mesh, obstacles, parameters: .from_store is True).

        The object is a scene's body (scene_id, body_id; the scene's other bodies are obstacles) or mesh=(vertices
        (n, 3) m, triangles (m, 3)). method: "bounding_box", "grasp_points" (grasp_points=(a, b) or detected),
        "centroid_circles". friction μ (None = 0.4); preshapes (empty = all); standoffs m (empty = [0]); rolls
        per approach (None = 4); spacing m of the bounding-box samples (None = 0.02); seed (None = 1);
        max_candidates (0 = all); max_grasps kept (0 = 50). progress=True shows a tqdm bar of the candidates on
        stderr; on_progress(done, total) is called with every progress message. Returns a GraspSetResult
        whose .grasps and .contacts are numpy structured arrays (object frame). timeout (s) bounds the call.
        Materials: object_material, link_materials {hand link: material} (None/unlisted = "default") and
        friction_pairs {(material_a, material_b): μ} give each contact the μ of its pair (else friction).
        """
        request = grasp_pb2.PlanGraspsRequest(object=target_proto(scene_id, body_id, mesh), hand=hand,
                                              method=method, preshapes=list(preshapes), standoffs=np.asarray(standoffs, dtype=np.float64).ravel().tolist(),
                                              max_candidates=max_candidates, max_grasps=max_grasps,
                                              recompute=recompute)
        for name, value in (("friction", friction), ("rolls", rolls), ("spacing", spacing),
                            ("circle_samples", circle_samples), ("seed", seed)):
            if value is not None:
                setattr(request, name, value)
        set_materials(request, object_material, link_materials, friction_pairs)
        if grasp_points is not None:
            points = np.asarray(grasp_points, dtype=np.float64)
            if points.shape != (2, 3):
                raise ValueError(f"grasp_points must be two points (2, 3) m, got shape {points.shape}")
            a, b = points.tolist()
            request.grasp_point_a.CopyFrom(common_pb2.Vec3(x=a[0], y=a[1], z=a[2]))
            request.grasp_point_b.CopyFrom(common_pb2.Vec3(x=b[0], y=b[1], z=b[2]))
        result = None
        with progress_bar(progress, 0, f"grasps {hand}", "candidates") as bar, \
                server_stream(self.grasp_stub.PlanGrasps(request, timeout=timeout)) as call:
            for message in call:
                if message.candidates_total:
                    bar.total = message.candidates_total
                    advance(bar, message.candidates_done)
                if on_progress is not None:
                    on_progress(message.candidates_done, message.candidates_total)
                if message.HasField("result"):
                    result = GraspSetResult.from_proto(message.result)
        if result is None:
            raise GraspsimError.for_code(grpc.StatusCode.INTERNAL, "PlanGrasps ended without a grasp set")
        return result

    def get_grasp_set(self, set_id: str) -> GraspSetResult:
        """A stored grasp set by its id (GraspSetResult.set_id)."""
        return GraspSetResult.from_proto(
            self._unary("GetGraspSet", grasp_pb2.GetGraspSetRequest(set_id=set_id), self.grasp_stub))

    def evaluate_grasp(self, hand: str, candidate: CandidateLike, *, scene_id: Optional[SceneLike] = None,
                       body_id: Optional[BodyLike] = None, mesh: Optional[MeshLike] = None,
                       friction: Optional[float] = None, object_material: Optional[str] = None,
                       link_materials: Optional[Dict[str, str]] = None,
                       friction_pairs: Optional[FrictionPairs] = None) -> Tuple[np.void, NDArray[np.void]]:
        """Simulates one candidate, object frame: a GraspCandidate, or a row of a grasp set (GraspSetResult.grasps[i])
        to simulate again. The object as in plan_grasps. Returns (grasp row, contacts) as structured arrays of one
        grasp (grasp_dtype, CONTACT_DTYPE), whatever its outcome ("grasp", "missed", "collision"). Materials as in
        plan_grasps."""
        request = grasp_pb2.EvaluateGraspRequest(object=target_proto(scene_id, body_id, mesh), hand=hand,
                                                 candidate=candidate_proto(candidate))
        if friction is not None:
            request.friction = friction
        set_materials(request, object_material, link_materials, friction_pairs)
        reply = self._unary("EvaluateGrasp", request, self.grasp_stub)
        rows, contacts = grasps_to_arrays([reply], len(reply.joint_positions))
        return rows[0], contacts
