"""Real grippers behind graspsim-gateway processes (docs/drivers.md): the GatewayService replies as dataclasses."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List

from graspsim.v1 import gateway_pb2


@dataclass(frozen=True)
class DeviceLimits:
    """What a device accepts: opening m, speed m/s and force N ranges; max_current A, its rated motor current
    (the scale of PredictAction's surprise)."""

    min_opening: float
    max_opening: float
    min_speed: float
    max_speed: float
    min_force: float
    max_force: float
    max_current: float

    @classmethod
    def from_proto(cls, m: gateway_pb2.DeviceLimits) -> DeviceLimits:
        return cls(m.min_opening, m.max_opening, m.min_speed, m.max_speed, m.min_force, m.max_force, m.max_current)


@dataclass(frozen=True)
class DeviceReading:
    """A device's state as its gateway read it.

    Attributes:
        device_id: the device ("" before its first reading).
        time: s, the gateway's clock (Unix time) when the device answered.
        opening: m, between the fingers; current: A, of the motor.
        moving; object_detected: stopped by something between the fingers.
        fault: the device's fault ("" when none).
        estopped: an e-stop or the watchdog stopped it; moves are refused until `initialize`.
    """

    device_id: str
    time: float
    opening: float
    current: float
    moving: bool
    object_detected: bool
    fault: str
    estopped: bool

    @classmethod
    def from_proto(cls, m: gateway_pb2.DeviceReading) -> DeviceReading:
        return cls(m.device_id, m.time, m.opening, m.current, m.moving, m.object_detected, m.fault, m.estopped)


@dataclass(frozen=True)
class Device:
    """A real device a gateway registered: its id ("robotiq-2f85-1"), kind ("robotiq_2f85", "schunk_pg70"), the
    gateway's name, the driver's link ("modbus tcp 127.0.0.1:5020 unit 9"), its limits and newest reading."""

    id: str
    kind: str
    gateway: str
    link: str
    limits: DeviceLimits
    last_reading: DeviceReading

    @classmethod
    def from_proto(cls, m: gateway_pb2.Device) -> Device:
        return cls(m.id, m.kind, m.gateway, m.link, DeviceLimits.from_proto(m.limits),
                   DeviceReading.from_proto(m.last_reading))


@dataclass(frozen=True)
class CommandResult:
    """send_command's reply: ok, or the failure's message and gRPC status code (3 INVALID_ARGUMENT,
    9 FAILED_PRECONDITION, 14 UNAVAILABLE); the device's reading after the command; gateway_seconds: s the
    gateway spent on it (driver time); command_id: the server's number of the relayed command."""

    command_id: int
    ok: bool
    message: str
    code: int
    reading: DeviceReading
    gateway_seconds: float

    @classmethod
    def from_proto(cls, m: gateway_pb2.CommandResult) -> CommandResult:
        return cls(m.command_id, m.ok, m.message, m.code, DeviceReading.from_proto(m.reading), m.gateway_seconds)


@dataclass(frozen=True)
class EmergencyStopResult:
    """emergency_stop's reply: the devices whose gateway confirmed the stop, and "<device>: <reason>" for the
    others."""

    stopped: List[str]
    failed: List[str]


@dataclass(frozen=True)
class GripperPrediction:
    """One side of a PredictAction sample: opening m, motor current A, tactile_sum of the pads (intensity counts;
    0 where the gripper has none, as on the real devices)."""

    opening: float
    current: float
    tactile_sum: float


@dataclass(frozen=True)
class PredictionSample:
    """One PredictAction sample, as predict_action's on_sample sees it: time s since the action began, the
    simulated twin's prediction and the real device's measurement, the surprise (0 = as predicted, 1 = off by a
    whole range), done: the real fingers stopped (the last sample)."""

    time: float
    predicted: GripperPrediction
    measured: GripperPrediction
    surprise: float
    done: bool

    @classmethod
    def from_proto(cls, m: gateway_pb2.PredictionSample) -> PredictionSample:
        p, r = m.predicted, m.measured
        return cls(m.time, GripperPrediction(p.opening, p.current, p.tactile_sum),
                   GripperPrediction(r.opening, r.current, r.tactile_sum), m.surprise, m.done)
