"""TactileService readings as dataclasses with numpy arrays, and Stream as an iterator of them."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import grpc
import numpy as np
from numpy.typing import NDArray

from graspsim._stream import CancellableStream, StreamCall
from graspsim.v1 import tactile_pb2


@dataclass(frozen=True)
class TactileFrame:
    """One tactile-array reading, as the Weiss DSACON32 controller delivers it.

    Attributes:
        sensor_id: the tactile array ("<robot>/<pad>").
        time: simulation time of the state read, s.
        rows, cols: texels; rows run along the pad's y, cols along its x.
        intensities: (rows, cols) uint16, 0..4095 (12 bit): proportional to the texel's normal force, saturated.
        forces: (rows, cols, 3) float32, N: the force the object exerts on each texel, pad frame
            (+z is the pad normal toward the object, so pressing reads negative z).
        intensity_sum: sum of intensities.
        force_sum: (3,) float64, N, pad frame.
    """

    sensor_id: str
    time: float
    rows: int
    cols: int
    intensities: NDArray[np.uint16]
    forces: NDArray[np.float32]
    intensity_sum: int
    force_sum: NDArray[np.float64]

    @classmethod
    def from_proto(cls, sensor_id: str, time: float, msg: tactile_pb2.TactileReading) -> TactileFrame:
        """Unpacks the little-endian uint16 intensities and float32 forces of a TactileReading."""
        texels = msg.rows * msg.cols
        intensities = np.frombuffer(msg.intensities, dtype="<u2").astype(np.uint16)
        forces = np.frombuffer(msg.forces, dtype="<f4").astype(np.float32)
        if intensities.size != texels or forces.size != 3 * texels:
            raise ValueError(f"tactile reading of {sensor_id!r}: {intensities.size} intensities and {forces.size} "
                             f"force values for {msg.rows} x {msg.cols} texels")
        return cls(sensor_id, time, msg.rows, msg.cols, intensities.reshape(msg.rows, msg.cols),
                   forces.reshape(msg.rows, msg.cols, 3), msg.intensity_sum,
                   np.array([msg.force_sum.x, msg.force_sum.y, msg.force_sum.z], dtype=np.float64))


@dataclass(frozen=True)
class GripperState:
    """The Schunk PG70's own sensor: jaw opening, motor current, finger speed.

    Attributes:
        sensor_id: "<robot>/gripper".
        time: simulation time of the state read, s.
        finger_distance: m, the sum of the finger joints' positions (0 = closed).
        motor_current: A, of the driven finger's motor (0 when undriven).
        finger_velocity: m/s, of the driven finger (negative = closing).
    """

    sensor_id: str
    time: float
    finger_distance: float
    motor_current: float
    finger_velocity: float


@dataclass(frozen=True)
class ForceTorqueState:
    """A 6-axis force/torque sensor on a joint (e.g. a wrist flange): the wrench the joint transmits from its parent
    side to its child side, i.e. what the child body and everything it carries receive through the joint.

    Attributes:
        sensor_id: the joint ("<robot>/<joint>").
        time: simulation time of the state read, s.
        force: (3,) float64, N, in the joint's child frame (the child body's frame). A gripper hanging still
            from its wrist reads -(m g) of the gripper and what it holds.
        torque: (3,) float64, N m, child frame, about the frame's origin.
    """

    sensor_id: str
    time: float
    force: NDArray[np.float64]
    torque: NDArray[np.float64]


Reading = Union[TactileFrame, GripperState, ForceTorqueState]


def reading_from_proto(msg: tactile_pb2.SensorReading) -> Reading:
    """The dataclass of a SensorReading; ValueError for a kind this client does not know."""
    kind = msg.WhichOneof("reading")
    if kind == "tactile":
        return TactileFrame.from_proto(msg.sensor_id, msg.time, msg.tactile)
    if kind == "gripper":
        g = msg.gripper
        return GripperState(msg.sensor_id, msg.time, g.finger_distance, g.motor_current, g.finger_velocity)
    if kind == "force_torque":
        f, t = msg.force_torque.force, msg.force_torque.torque
        return ForceTorqueState(msg.sensor_id, msg.time, np.array([f.x, f.y, f.z], dtype=np.float64),
                                np.array([t.x, t.y, t.z], dtype=np.float64))
    raise ValueError(f"reading of {msg.sensor_id!r}: kind {kind!r} is not supported by this client")


class SensorStream(CancellableStream[Reading]):
    """Iterator over a TactileService.Stream: one reading per sensor each time the scene changes, at most at the
    requested rate, always of the newest state. cancel() (or close(), or leaving a with-block) ends it.

    Iteration blocks until the next reading; after cancel() it stops cleanly (StopIteration). Server errors
    (bad ids, the scene deleted) are raised as GraspsimError.
    """

    def __init__(self, call: StreamCall) -> None:
        super().__init__(call, reading_from_proto)

