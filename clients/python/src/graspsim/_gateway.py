"""GatewayService methods of Client: real grippers behind graspsim-gateway processes (docs/drivers.md)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence

import grpc
import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim._devices import CommandResult, Device, EmergencyStopResult, PredictionSample
from graspsim._errors import translated_errors
from graspsim._ids import SceneLike, scene_id_of
from graspsim._stream import server_stream
from graspsim.v1 import gateway_pb2, gateway_pb2_grpc


@dataclass
class PredictionResult:
    """PredictAction's samples as arrays (one entry per sample): time s since the action began; opening m,
    current A and tactile_sum (intensity counts; measured is 0: the real grippers have no pads) predicted by the
    simulated PG70 and measured on the device; surprise (0 = as predicted, 1 = off by a whole range)."""
    time: NDArray[np.float64]
    predicted_opening: NDArray[np.float64]
    measured_opening: NDArray[np.float64]
    predicted_current: NDArray[np.float64]
    measured_current: NDArray[np.float64]
    predicted_tactile_sum: NDArray[np.float64]
    surprise: NDArray[np.float64]
    finished: bool  # the last sample says the real fingers stopped

    @classmethod
    def from_samples(cls, samples: Sequence[PredictionSample]) -> "PredictionResult":
        def column(get: Callable[[PredictionSample], float]) -> NDArray[np.float64]:
            return np.array([get(s) for s in samples], dtype=float)
        return cls(time=column(lambda s: s.time),
                   predicted_opening=column(lambda s: s.predicted.opening),
                   measured_opening=column(lambda s: s.measured.opening),
                   predicted_current=column(lambda s: s.predicted.current),
                   measured_current=column(lambda s: s.measured.current),
                   predicted_tactile_sum=column(lambda s: s.predicted.tactile_sum),
                   surprise=column(lambda s: s.surprise),
                   finished=bool(samples) and samples[-1].done)


class GatewayMethods:
    """Mixed into Client; needs self.channel and self.call_timeout."""

    channel: grpc.Channel
    call_timeout: float

    @property
    def gateway_stub(self) -> gateway_pb2_grpc.GatewayServiceStub:
        stub = self.__dict__.get("_gateway_stub")
        if stub is None:
            stub = self.__dict__["_gateway_stub"] = gateway_pb2_grpc.GatewayServiceStub(self.channel)
        return stub

    def list_devices(self) -> List[Device]:
        """The real devices the connected gateways registered, each with its limits and newest reading."""
        with translated_errors():
            reply = self.gateway_stub.ListDevices(gateway_pb2.ListDevicesRequest(), timeout=self.call_timeout)
        return [Device.from_proto(d) for d in reply.devices]

    def send_command(self, device_id: str, *, move: Optional[ArrayLike] = None,
                     move_to: Optional[float] = None, velocity: Optional[float] = None,
                     max_force: Optional[float] = None, stop: bool = False, initialize: bool = False,
                     estop: bool = False, read: bool = False, timeout: float = 0.0) -> CommandResult:
        """One command to a real device, relayed by the server to its gateway; exactly one of:
        move=(opening m, speed m/s, force N); move_to=opening m (at the velocity and max_force set last);
        velocity=m/s; max_force=N; stop; initialize (activate/reference, clears an e-stop); estop; read.
        Returns the result with the device's reading after the command. timeout: s the server waits for the
        gateway (0 = 5). Refusals raise GraspsimError: INVALID_ARGUMENT (outside the device's limits, naming
        the field and value), FAILED_PRECONDITION (device fault, latched e-stop), UNAVAILABLE (no answer)."""
        request = gateway_pb2.DeviceCommand(device_id=device_id, timeout=timeout)
        chosen = [name for name, value in (("move", move), ("move_to", move_to), ("velocity", velocity),
                                           ("max_force", max_force)) if value is not None]
        chosen += [name for name, flag in (("stop", stop), ("initialize", initialize), ("estop", estop),
                                           ("read", read)) if flag]
        if len(chosen) != 1:
            raise ValueError(f"send_command: exactly one command, got {chosen or 'none'}")
        if move is not None:
            opening, speed, force = np.asarray(move, dtype=np.float64).reshape(3).tolist()
            request.move.CopyFrom(gateway_pb2.Move(opening=opening, speed=speed, force=force))
        elif move_to is not None:
            request.move_to = move_to
        elif velocity is not None:
            request.velocity = velocity
        elif max_force is not None:
            request.max_force = max_force
        else:
            setattr(request, chosen[0], True)
        deadline = (timeout or 5.0) + self.call_timeout
        with translated_errors():
            return CommandResult.from_proto(self.gateway_stub.SendCommand(request, timeout=deadline))

    def emergency_stop(self, device_id: str = "") -> EmergencyStopResult:
        """Stops one device (or every device of every gateway) and latches the stop until `initialize`; returns the
        devices stopped and the failures."""
        with translated_errors():
            reply = self.gateway_stub.EmergencyStop(gateway_pb2.EmergencyStopRequest(device_id=device_id),
                                                    timeout=self.call_timeout)
        return EmergencyStopResult(list(reply.stopped), list(reply.failed))

    def predict_action(self, device_id: str, scene_id: SceneLike, gripper_id: str, opening: float, speed: float,
                       force: float, *, timeout: float = 0.0, rate_hz: float = 0.0,
                       on_sample: Optional[Callable[[PredictionSample], None]] = None) -> PredictionResult:
        """Moves the real device to `opening` (m) at `speed` (m/s) with `force` (N) while the scene's simulated
        PG70 `gripper_id` runs the same move from the same opening; returns predicted and measured readings side
        by side with the surprise. timeout: s until the real fingers must stop (0 = 5; then DEADLINE_EXCEEDED
        and a stop); rate_hz: samples per second (0 = 50). on_sample(sample) sees each PredictionSample as it
        arrives."""
        request = gateway_pb2.PredictActionRequest(
            device_id=device_id, scene_id=scene_id_of(scene_id), gripper_id=gripper_id,
            move=gateway_pb2.Move(opening=opening, speed=speed, force=force), timeout=timeout, rate_hz=rate_hz)
        samples: List[PredictionSample] = []
        deadline = (timeout or 5.0) + self.call_timeout
        with server_stream(self.gateway_stub.PredictAction(request, timeout=deadline)) as call:
            for message in call:
                sample = PredictionSample.from_proto(message)
                samples.append(sample)
                if on_sample is not None:
                    on_sample(sample)
        return PredictionResult.from_samples(samples)
