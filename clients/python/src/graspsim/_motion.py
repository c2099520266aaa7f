"""Arm motion methods of Client (docs/motion.md): collision-free arm paths as numpy arrays."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Sequence

import numpy as np

from graspsim._errors import translated_errors
from graspsim._pose import PoseLike, as_pose
from graspsim.v1 import grasp_pb2, grasp_pb2_grpc


@dataclass
class ArmPath:
    """PlanArmPath's answer: waypoints (n, dof) rad or m in joint_ids order, start first; times (n,) s, the arm
    at rest at each (trapezoidal velocity between them, within the joints' velocity and acceleration limits)."""
    joint_ids: List[str]
    waypoints: np.ndarray
    times: np.ndarray
    tip_body: str
    direct: bool
    checks: int
    seconds: float
    duration: float


class MotionMethods:
    """Mixed into Client; needs self.channel and self.call_timeout."""

    def plan_arm_path(self, scene_id: str, arm_id: str, *, goal: Optional[PoseLike] = None,
                      goal_positions: Optional[Sequence[float]] = None,
                      start_positions: Optional[Sequence[float]] = None, tip_body: str = "",
                      timeout: float = 0.0, seed: Optional[int] = None,
                      call_timeout: Optional[float] = None) -> ArmPath:
        """A collision-free path of robot `arm_id` from its configuration in the scene (or start_positions) to a
        tip pose `goal` (world; tip = tip_body, default "<arm_id>/flange") or to goal_positions. timeout: s of
        search (0 = 2 s). A blocked or unreachable goal raises FailedPrecondition naming what blocks it."""
        request = grasp_pb2.PlanArmPathRequest(scene_id=scene_id, arm_id=arm_id, tip_body=tip_body,
                                               timeout=timeout)
        if goal is not None:
            request.goal.CopyFrom(as_pose(goal).to_proto())
        if goal_positions is not None:
            request.goal_positions.extend(float(v) for v in goal_positions)
        if start_positions is not None:
            request.start_positions.extend(float(v) for v in start_positions)
        if seed is not None:
            request.seed = seed
        stub = grasp_pb2_grpc.GraspServiceStub(self.channel)
        with translated_errors():
            response = stub.PlanArmPath(request, timeout=call_timeout or self.call_timeout)
        dof = len(response.joint_ids)
        return ArmPath(joint_ids=list(response.joint_ids),
                       waypoints=np.frombuffer(response.waypoints, dtype="<f8").reshape(-1, dof).copy(),
                       times=np.frombuffer(response.times, dtype="<f8").copy(), tip_body=response.tip_body,
                       direct=response.direct, checks=response.checks, seconds=response.seconds,
                       duration=response.duration)
