"""The dynamic simulation's settings and steps (set/get_simulation_params, step_simulation) as dataclasses, and the
SimulationParams message built from set_simulation_params' keywords."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from numpy.typing import NDArray

from graspsim._body import enum_name, vector
from graspsim._equality import ValueEquality
from graspsim.v1 import scene_pb2


@dataclass(frozen=True)
class StepResult:
    """step_simulation's reply: the simulation time after the steps (s), the steps taken by the call, the contact
    points and awake free bodies of the last step, and the scene's new revision."""

    time: float
    steps: int
    contacts: int
    awake_bodies: int
    revision: int

    @classmethod
    def from_proto(cls, m: scene_pb2.StepSimulationResponse) -> StepResult:
        return cls(m.time, m.steps, m.contacts, m.awake_bodies, m.revision)


@dataclass(frozen=True)
class ContactDefaults:
    """The contact parameters of bodies whose Material leaves them at 0 (docs/physics.md): stiffness N/m per
    contact point, damping N s/m, LuGre bristle stiffness N/m and damping N s/m, viscous friction N s/m, Stribeck
    velocity m/s."""

    stiffness: float
    damping: float
    bristle_stiffness: float
    bristle_damping: float
    viscous_friction: float
    stribeck_velocity: float

    @classmethod
    def from_proto(cls, m: scene_pb2.ContactDefaults) -> ContactDefaults:
        return cls(m.stiffness, m.damping, m.bristle_stiffness, m.bristle_damping, m.viscous_friction,
                   m.stribeck_velocity)


@dataclass(frozen=True, eq=False)
class SimulationParams(ValueEquality):
    """A scene's simulation parameters, the server's defaults filled in (the keywords of set_simulation_params).

    Attributes:
        time_step: s; substeps: integration steps per step.
        integrator: "linearly_implicit_euler" (the default), "semi_implicit_euler", "velocity_verlet" or
            "runge_kutta_4".
        gravity: (3,) float64, m/s^2.
        contact: the default contact parameters.
        sample_spacing: m between the surface samples of primitives.
        sleep_speed: m/s and rad/s below which a free body is at rest; sleep_time: s at rest before it sleeps.
        engine: "graspsim" (the default), "mujoco" or "bullet" (docs/physics.md).
    """

    time_step: float
    substeps: int
    integrator: str
    gravity: NDArray[np.float64]
    contact: ContactDefaults
    sample_spacing: float
    sleep_speed: float
    sleep_time: float
    engine: str

    @classmethod
    def from_proto(cls, m: scene_pb2.SimulationParams) -> SimulationParams:
        return cls(time_step=m.time_step, substeps=m.substeps,
                   integrator=enum_name(scene_pb2.Integrator.Name, m.integrator, "INTEGRATOR_",
                                        "linearly_implicit_euler"),
                   gravity=vector(m.gravity) if m.HasField("gravity") else np.array([0.0, 0.0, -9.81]),
                   contact=ContactDefaults.from_proto(m.contact), sample_spacing=m.sample_spacing,
                   sleep_speed=m.sleep_speed, sleep_time=m.sleep_time,
                   engine=enum_name(scene_pb2.PhysicsEngine.Name, m.engine, "PHYSICS_ENGINE_", "graspsim"))


def params_message(params: Mapping[str, Any]) -> scene_pb2.SimulationParams:
    """The SimulationParams message of set_simulation_params' keywords; fields not given stay unset (the scene
    keeps them). Enumerations by name, gravity as 3 values, contact as a dict of ContactDefaults fields."""
    message = scene_pb2.SimulationParams()
    for key, value in params.items():
        if key == "integrator":
            # protoc's .pyi types an enum field as its enum class, EnumTypeWrapper.Value as returning int
            integrator = scene_pb2.Integrator.Value("INTEGRATOR_" + str(value).upper())
            message.integrator = integrator  # type: ignore[assignment]
        elif key == "engine":
            engine = scene_pb2.PhysicsEngine.Value("PHYSICS_ENGINE_" + str(value).upper())
            message.engine = engine  # type: ignore[assignment]  # (an enum field set from an int, as above)
        elif key == "gravity":
            message.gravity.x, message.gravity.y, message.gravity.z = (float(v) for v in value)
        elif key == "contact":
            for field, v in value.items():
                setattr(message.contact, field, float(v))
        else:
            setattr(message, key, value)
    return message
