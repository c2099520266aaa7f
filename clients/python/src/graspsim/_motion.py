"""Arm motion methods of Client (docs/motion.md): collision-free arm paths as numpy arrays."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import grpc
import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim._errors import GraspsimError, error_for_code, translated_errors
from graspsim._grasp import grasps_to_arrays
from graspsim._ids import BodyLike, SceneLike, body_id_of, scene_id_of
from graspsim._pose import Pose, PoseLike, as_pose
from graspsim._progress import advance, progress_bar
from graspsim._stream import CancellableStream
from graspsim.v1 import grasp_pb2, grasp_pb2_grpc


@dataclass
class ArmPath:
    """PlanArmPath's answer: waypoints (n, dof) rad or m in joint_ids order, start first; times (n,) s, the arm
    at rest at each (trapezoidal velocity between them, within the joints' velocity and acceleration limits)."""
    joint_ids: List[str]
    waypoints: NDArray[np.float64]
    times: NDArray[np.float64]
    tip_body: str
    direct: bool
    checks: int
    seconds: float             # s, server-side planning time (checks of start and goal, search, shortcuts, timing)
    duration: float
    setup_seconds: float = 0.0  # s, building the call's collision model before planning
    planner: str = ""           # the search that ran: "rrt_connect" or "ompl_rrt_connect"
    search_seconds: float = 0.0  # s, of `seconds`: start/goal checks, straight segment, search (not shortcutting)


def _arm_path(response: grasp_pb2.PlanArmPathResponse) -> ArmPath:
    dof = len(response.joint_ids)
    return ArmPath(joint_ids=list(response.joint_ids),
                   waypoints=np.frombuffer(response.waypoints, dtype="<f8").reshape(-1, max(dof, 1)).copy(),
                   times=np.frombuffer(response.times, dtype="<f8").copy(), tip_body=response.tip_body,
                   direct=response.direct, checks=response.checks, seconds=response.seconds,
                   duration=response.duration, setup_seconds=response.setup_seconds, planner=response.planner,
                   search_seconds=response.search_seconds)


def _arm_path_request(scene_id: SceneLike, arm_id: str, goal: Optional[PoseLike],
                      goal_positions: Optional[ArrayLike], start_positions: Optional[ArrayLike],
                      tip_body: str, timeout: float, seed: Optional[int], planner: str) -> grasp_pb2.PlanArmPathRequest:
    request = grasp_pb2.PlanArmPathRequest(scene_id=scene_id_of(scene_id), arm_id=arm_id, tip_body=tip_body,
                                           timeout=timeout, planner=planner)
    if goal is not None:
        request.goal.CopyFrom(as_pose(goal).to_proto())
    if goal_positions is not None:
        request.goal_positions.extend(np.asarray(goal_positions, dtype=np.float64).ravel().tolist())
    if start_positions is not None:
        request.start_positions.extend(np.asarray(start_positions, dtype=np.float64).ravel().tolist())
    if seed is not None:
        request.seed = seed
    return request


@dataclass
class ArmMotion:
    """One arm motion of an executed pick-and-place: waypoints (n, dof) in joint_ids order, times (n,) s from
    the motion's start; `closed`: the hand held the object during it."""
    stage: str
    waypoints: NDArray[np.float64]
    times: NDArray[np.float64]
    closed: bool


@dataclass
class PickAndPlaceResult:
    """PickAndPlace's last message: the object ended at the goal (1 cm, 10°) and the scene holds the end state."""
    success: bool
    grasp_set_id: str
    grasp_index: int           # the successful grasp's index in the set
    grasp: np.void             # that grasp: a row of grasp_dtype (hand_pose in the object frame, epsilon, …)
    grasp_contacts: NDArray[np.void]  # its contacts (CONTACT_DTYPE, object frame)
    reachable: int             # grasps that passed the reachability filter
    failures: List[str]        # why earlier attempts failed
    object_pose: Pose          # where the object ended, world
    position_error: float      # m
    orientation_error: float   # rad
    grip_force: float          # N, the hand's contact force on the object after closing
    simulated_seconds: float
    joint_ids: List[str]
    motions: List[ArmMotion]


@dataclass(frozen=True)
class PickAndPlaceProgress:
    """One message of pick_and_place_stream: the stage ("planning_grasps", "filtering", "planning_path",
    "approach", "close", "lift", …, "done"), the fraction 0..1 of the whole job done, and in the "done" message
    the result."""
    stage: str
    fraction: float
    result: Optional[PickAndPlaceResult] = None


def _pick_result(message: grasp_pb2.PickAndPlaceProgress) -> PickAndPlaceResult:
    dof = len(message.joint_ids)
    motions = [ArmMotion(m.stage, np.frombuffer(m.waypoints, dtype="<f8").reshape(-1, max(dof, 1)).copy(),
                         np.frombuffer(m.times, dtype="<f8").copy(), m.closed) for m in message.motions]
    grasps, contacts = grasps_to_arrays([message.grasp], len(message.grasp.joint_positions))
    return PickAndPlaceResult(message.success, message.grasp_set_id, message.grasp_index, grasps[0], contacts,
                              message.reachable, list(message.failures), Pose.from_proto(message.object_pose),
                              message.position_error, message.orientation_error, message.grip_force,
                              message.simulated_seconds, list(message.joint_ids), motions)


def _pick_progress(message: grasp_pb2.PickAndPlaceProgress) -> PickAndPlaceProgress:
    return PickAndPlaceProgress(message.stage, message.fraction,
                                _pick_result(message) if message.stage == "done" else None)


class MotionMethods:
    """Mixed into Client; needs self.channel and self.call_timeout."""

    channel: grpc.Channel
    call_timeout: float

    def plan_arm_path(self, scene_id: SceneLike, arm_id: str, *, goal: Optional[PoseLike] = None,
                      goal_positions: Optional[ArrayLike] = None,
                      start_positions: Optional[ArrayLike] = None, tip_body: str = "",
                      timeout: float = 0.0, seed: Optional[int] = None, planner: str = "",
                      call_timeout: Optional[float] = None) -> ArmPath:
        """A collision-free path of robot `arm_id` from its configuration in the scene (or start_positions) to a
        tip pose `goal` (world; tip = tip_body, default "<arm_id>/flange") or to goal_positions. timeout: s of
        search (0 = 2 s). planner: "" / "rrt_connect" (graspsim's) or "ompl_rrt_connect" (OMPL's, same checker).
        A blocked or unreachable goal raises FailedPrecondition naming what blocks it."""
        request = _arm_path_request(scene_id, arm_id, goal, goal_positions, start_positions, tip_body, timeout,
                                    seed, planner)
        stub = grasp_pb2_grpc.GraspServiceStub(self.channel)
        with translated_errors():
            response = stub.PlanArmPath(request, timeout=call_timeout or self.call_timeout)
        return _arm_path(response)

    def plan_arm_paths(self, problems: Sequence[Dict[str, Any]], *,
                       call_timeout: Optional[float] = None) -> List[Union[ArmPath, GraspsimError]]:
        """Many plan_arm_path problems in one call: each a dict of plan_arm_path's keyword arguments plus
        scene_id and arm_id. Returns, in order, an ArmPath per solved problem and the error (not raised) of each
        other one."""
        requests = []
        for i, p in enumerate(problems):
            unknown = set(p) - {"scene_id", "arm_id", "goal", "goal_positions", "start_positions", "tip_body",
                                "timeout", "seed", "planner"}
            if unknown:
                raise TypeError(f"problems[{i}]: unknown keys {sorted(unknown)}")
            scene_id = scene_id_of(p["scene_id"], f"problems[{i}]['scene_id']")
            requests.append(_arm_path_request(scene_id, p["arm_id"], p.get("goal"), p.get("goal_positions"),
                                              p.get("start_positions"), p.get("tip_body", ""),
                                              p.get("timeout", 0.0), p.get("seed"), p.get("planner", "")))
        stub = grasp_pb2_grpc.GraspServiceStub(self.channel)
        with translated_errors():
            response = stub.PlanArmPaths(grasp_pb2.PlanArmPathsRequest(problems=requests),
                                         timeout=call_timeout or self.call_timeout)
        return [_arm_path(r.path) if r.status_code == 0 else error_for_code(r.status_code, r.error)
                for r in response.results]

    def pick_and_place_stream(self, scene_id: SceneLike, arm_id: str, body_id: BodyLike, goal: PoseLike, *,
                              hand_id: str = "", grasp_set_id: str = "", max_attempts: int = 0,
                              seed: Optional[int] = None, call_timeout: Optional[float] = None
                              ) -> CancellableStream[PickAndPlaceProgress]:
        """The progress stream of pick_and_place: PickAndPlaceProgress (stage, fraction, and the result in the
        "done" one); cancel(), leaving a with-block or dropping the stream stops the server's job."""
        request = grasp_pb2.PickAndPlaceRequest(scene_id=scene_id_of(scene_id), arm_id=arm_id, hand_id=hand_id,
                                                body_id=body_id_of(body_id), grasp_set_id=grasp_set_id,
                                                max_attempts=max_attempts)
        request.goal.CopyFrom(as_pose(goal).to_proto())
        if seed is not None:
            request.seed = seed
        stub = grasp_pb2_grpc.GraspServiceStub(self.channel)
        return CancellableStream(stub.PickAndPlace(request, timeout=call_timeout), _pick_progress)

    def pick_and_place(self, scene_id: SceneLike, arm_id: str, body_id: BodyLike, goal: PoseLike, *, hand_id: str = "",
                       grasp_set_id: str = "", max_attempts: int = 0, seed: Optional[int] = None,
                       on_progress: Optional[Callable[[str, float], None]] = None,
                       call_timeout: Optional[float] = None, progress: bool = True) -> PickAndPlaceResult:
        """Picks body_id up with the hand on arm_id's flange and puts it at `goal` (world pose of the object),
        planned and executed in the dynamic simulation (docs/motion.md, "Pick and place"). The grasps come from
        grasp_set_id (a PlanGrasps set for this hand and object) or a set planned now. on_progress(stage,
        fraction) is called for every progress message; progress=True shows a tqdm bar on stderr. On success the
        scene holds the simulated end state; an unreachable goal or grasps that all fail raise FailedPrecondition
        with the reasons (scene unchanged). Leaving the call early (on_progress raising, KeyboardInterrupt)
        cancels the server's job."""
        last = None
        with progress_bar(progress, 100, "pick and place", "%") as bar, \
                self.pick_and_place_stream(scene_id, arm_id, body_id, goal, hand_id=hand_id,
                                           grasp_set_id=grasp_set_id, max_attempts=max_attempts, seed=seed,
                                           call_timeout=call_timeout) as stream:
            for message in stream:
                advance(bar, round(100 * message.fraction), message.stage)
                if on_progress is not None:
                    on_progress(message.stage, message.fraction)
                last = message
        if last is None or last.result is None:
            raise GraspsimError.for_code(grpc.StatusCode.INTERNAL, "PickAndPlace ended without a result")
        return last.result
