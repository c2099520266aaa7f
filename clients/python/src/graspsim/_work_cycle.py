"""TactileService.RunWorkCycle: its progress frames as dataclasses and the whole run as numpy time series."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, List, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, DTypeLike, NDArray

from graspsim._pose import Pose
from graspsim._sensors import GripperState, TactileFrame, reading_from_proto
from graspsim.v1 import tactile_pb2

# The server's defaults for a 0 in RunWorkCycleRequest (proto/graspsim/v1/tactile.proto).
DEFAULT_TACTILE_SETPOINT = 60000.0  # intensity sum per pad
DEFAULT_LIFT_HEIGHT = 0.05          # m
DEFAULT_COVERAGE = 1.0
DEFAULT_FRAME_RATE_HZ = 50.0        # frames per simulated second
DEFAULT_HOLD_TIME = 1.0             # s

# The stages in the order the server runs them.
STAGES = ("approach", "grasp", "lift", "hold", "move_down", "release", "done")


@dataclass(frozen=True)
class WorkCycleFrame:
    """One WorkCycleProgress message, decoded.

    Attributes:
        stage: "approach", "grasp", "lift", "hold", "move_down", "release" or "done".
        time: simulation time, s.
        left, right: the two pads' readings (the first and second tactile reading of the message).
        gripper: the gripper's own reading (finger distance m, motor current A, finger velocity m/s).
        object_pose: the picked object's world pose.
        axis_position: m, the z axis joint.
        current_limit: A, the force controller's output (the drive's own limit before it starts).
    """

    stage: str
    time: float
    left: TactileFrame
    right: TactileFrame
    gripper: GripperState
    object_pose: Pose
    axis_position: float
    current_limit: float

    @classmethod
    def from_proto(cls, msg: tactile_pb2.WorkCycleProgress) -> WorkCycleFrame:
        """Decodes the readings (both pads, then the gripper); ValueError when one of them is missing."""
        readings = [reading_from_proto(r) for r in msg.readings]
        pads = [r for r in readings if isinstance(r, TactileFrame)]
        grippers = [r for r in readings if isinstance(r, GripperState)]
        if len(pads) != 2 or len(grippers) != 1:
            raise ValueError(f"work-cycle frame at t = {msg.time:g} s ({msg.stage!r}): {len(pads)} tactile and "
                             f"{len(grippers)} gripper readings, expected 2 and 1")
        return cls(msg.stage, msg.time, pads[0], pads[1], grippers[0], Pose.from_proto(msg.object_pose),
                   msg.axis_position, msg.current_limit)


@dataclass(frozen=True)
class WorkCycleSummary:
    """The numbers of one work cycle that the paper's experiment reports (see WorkCycleResult.summary()).

    Attributes:
        peak_left, peak_right: the largest intensity sum of each pad.
        peak_mismatch: |peak_left - peak_right| / mean of the two (0.01 = 1 %).
        hold_mismatch: the largest |left - right| / mean of the two over the "hold" frames (nan without them).
        first_contact_time: s, the first frame where either pad reads anything (nan if none does).
        rise_time: s after first contact until the pads' mean sum first reaches 90 % of the set-point (nan if never).
        lift: m, how far the object rose from the start of "lift" to the end of "hold".
        slip: m, how far the gripper rose more than the object over the same frames (> 0: it slid down).
        final_offset: m, the object's height at the end minus at the start (≈ 0: put back where it was).
    """

    peak_left: float
    peak_right: float
    peak_mismatch: float
    hold_mismatch: float
    first_contact_time: float
    rise_time: float
    lift: float
    slip: float
    final_offset: float


@dataclass(frozen=True)
class WorkCycleResult:
    """A whole work cycle as time series, one entry per progress frame (N frames).

    Attributes:
        time: (N,) s.
        stage: N stage names.
        left_sum, right_sum: (N,) intensity sums of the two pads.
        left_images, right_images: (N, rows, cols) uint16 intensities, 0..4095.
        finger_distance: (N,) m; motor_current: (N,) A; finger_velocity: (N,) m/s (the gripper's reading).
        object_position: (N, 3) m, world; object_orientation: (N, 4) quaternion (w, x, y, z), world.
        axis_position: (N,) m, the z axis joint.
        current_limit: (N,) A, the force controller's output.
        tactile_setpoint, lift_height, coverage: the request's values (its zeros replaced by the server's defaults).
        left_id, right_id, gripper_sensor_id: the sensors the readings came from.
    """

    time: NDArray[np.float64]
    stage: List[str]
    left_sum: NDArray[np.float64]
    right_sum: NDArray[np.float64]
    left_images: NDArray[np.uint16]
    right_images: NDArray[np.uint16]
    finger_distance: NDArray[np.float64]
    motor_current: NDArray[np.float64]
    finger_velocity: NDArray[np.float64]
    object_position: NDArray[np.float64]
    object_orientation: NDArray[np.float64]
    axis_position: NDArray[np.float64]
    current_limit: NDArray[np.float64]
    tactile_setpoint: float = DEFAULT_TACTILE_SETPOINT
    lift_height: float = DEFAULT_LIFT_HEIGHT
    coverage: float = DEFAULT_COVERAGE
    left_id: str = ""
    right_id: str = ""
    gripper_sensor_id: str = ""

    @classmethod
    def from_frames(cls, frames: Sequence[WorkCycleFrame], *, tactile_setpoint: float = 0.0,
                    lift_height: float = 0.0, coverage: float = 0.0) -> WorkCycleResult:
        """Stacks decoded frames into arrays; the settings' zeros become the server's defaults.

        ValueError when the pads' shapes change between frames.
        """
        frames = list(frames)
        shapes = {(f.left.rows, f.left.cols) for f in frames} | {(f.right.rows, f.right.cols) for f in frames}
        if len(shapes) > 1:
            raise ValueError(f"work cycle: tactile readings of different shapes {sorted(shapes)}")
        rows, cols = shapes.pop() if shapes else (0, 0)

        def series(values: Iterable[ArrayLike], dtype: DTypeLike = np.float64) -> NDArray[Any]:
            return np.array(list(values), dtype=dtype)

        def images(pads: Iterable[TactileFrame]) -> NDArray[np.uint16]:
            return np.array([p.intensities for p in pads], dtype=np.uint16).reshape(len(frames), rows, cols)

        first = frames[0] if frames else None
        return cls(
            time=series(f.time for f in frames),
            stage=[f.stage for f in frames],
            left_sum=series(f.left.intensity_sum for f in frames),
            right_sum=series(f.right.intensity_sum for f in frames),
            left_images=images(f.left for f in frames),
            right_images=images(f.right for f in frames),
            finger_distance=series(f.gripper.finger_distance for f in frames),
            motor_current=series(f.gripper.motor_current for f in frames),
            finger_velocity=series(f.gripper.finger_velocity for f in frames),
            object_position=series((f.object_pose.position for f in frames)).reshape(len(frames), 3),
            object_orientation=series((f.object_pose.orientation for f in frames)).reshape(len(frames), 4),
            axis_position=series(f.axis_position for f in frames),
            current_limit=series(f.current_limit for f in frames),
            tactile_setpoint=float(tactile_setpoint or DEFAULT_TACTILE_SETPOINT),
            lift_height=float(lift_height or DEFAULT_LIFT_HEIGHT),
            coverage=float(coverage or DEFAULT_COVERAGE),
            left_id=first.left.sensor_id if first else "",
            right_id=first.right.sensor_id if first else "",
            gripper_sensor_id=first.gripper.sensor_id if first else "",
        )

    @classmethod
    def from_progress(cls, messages: Iterable[tactile_pb2.WorkCycleProgress], **settings: float) -> WorkCycleResult:
        """Decodes and stacks WorkCycleProgress messages (settings as in from_frames)."""
        return cls.from_frames([WorkCycleFrame.from_proto(m) for m in messages], **settings)

    def __len__(self) -> int:
        return len(self.time)

    # --- stages -------------------------------------------------------------------------------------------
    def stages(self) -> List[str]:
        """The stages in the order they first appear."""
        return list(dict.fromkeys(self.stage))

    def stage_mask(self, stage: str) -> NDArray[np.bool_]:
        """(N,) bool: the frames of one stage."""
        return np.array([s == stage for s in self.stage], dtype=bool)

    def stage_spans(self) -> List[Tuple[str, float, float]]:
        """(stage, first time, last time) of each run of equal stage names, in order."""
        spans: List[Tuple[str, float, float]] = []
        for i, name in enumerate(self.stage):
            if spans and spans[-1][0] == name:
                spans[-1] = (name, spans[-1][1], float(self.time[i]))
            else:
                spans.append((name, float(self.time[i]), float(self.time[i])))
        return spans

    def stage_starts(self) -> List[Tuple[str, float]]:
        """(stage, time of its first frame) for each stage change, in order."""
        return [(name, start) for name, start, _ in self.stage_spans()]

    # --- analysis -----------------------------------------------------------------------------------------
    def peak_index(self) -> int:
        """The frame where the pads' summed intensity is largest (-1 without frames)."""
        return int(np.argmax(self.left_sum + self.right_sum)) if len(self) else -1

    def first_contact_index(self) -> Optional[int]:
        """The first frame where either pad reads anything, or None."""
        touching = np.flatnonzero((self.left_sum > 0) | (self.right_sum > 0))
        return int(touching[0]) if touching.size else None

    def summary(self, fraction: float = 0.9) -> WorkCycleSummary:
        """Peaks, mismatch, rise time (to `fraction` of the set-point after first contact), lift and slip."""
        nan = float("nan")
        peak_left = float(self.left_sum.max()) if len(self) else 0.0
        peak_right = float(self.right_sum.max()) if len(self) else 0.0
        mean_peak = (peak_left + peak_right) / 2
        peak_mismatch = abs(peak_left - peak_right) / mean_peak if mean_peak > 0 else nan
        hold = self.stage_mask("hold")
        mean = (self.left_sum + self.right_sum) / 2
        if hold.any() and (mean[hold] > 0).all():
            hold_mismatch = float(np.max(np.abs(self.left_sum[hold] - self.right_sum[hold]) / mean[hold]))
        else:
            hold_mismatch = nan
        contact = self.first_contact_index()
        first_contact_time = rise_time = nan
        if contact is not None:
            first_contact_time = float(self.time[contact])
            reached = np.flatnonzero(mean[contact:] >= fraction * self.tactile_setpoint)
            if reached.size:
                rise_time = float(self.time[contact + reached[0]]) - first_contact_time
        lift = slip = nan
        carried = np.flatnonzero(self.stage_mask("lift") | hold)
        if carried.size:
            start, end = carried[0], carried[-1]
            lift = float(self.object_position[end, 2] - self.object_position[start, 2])
            gripper_rise = abs(float(self.axis_position[end] - self.axis_position[start]))
            slip = gripper_rise - lift
        final_offset = float(self.object_position[-1, 2] - self.object_position[0, 2]) if len(self) else nan
        return WorkCycleSummary(peak_left, peak_right, peak_mismatch, hold_mismatch, first_contact_time, rise_time,
                                lift, slip, final_offset)
