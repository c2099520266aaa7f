"""Poses and quaternions: conversion between Python values, numpy arrays and the API's Pose message.

Conventions (as on the wire): positions in metres, orientations as unit quaternions (w, x, y, z).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim.v1 import common_pb2


def _identity_quaternion() -> NDArray[np.float64]:
    return np.array([1.0, 0.0, 0.0, 0.0])


@dataclass
class Velocity:
    """A free body's velocity: linear (3,) m/s of its centre of mass and angular (3,) rad/s, both world frame."""

    linear: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    angular: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))

    if TYPE_CHECKING:  # the generated __init__ takes any 3 values: __post_init__ makes float64 arrays of them
        def __init__(self, linear: ArrayLike = ..., angular: ArrayLike = ...) -> None: ...

    def __post_init__(self) -> None:
        self.linear = np.array(self.linear, dtype=np.float64).reshape(-1)
        self.angular = np.array(self.angular, dtype=np.float64).reshape(-1)
        if self.linear.shape != (3,) or self.angular.shape != (3,):
            raise ValueError("Velocity needs 3 linear (m/s) and 3 angular (rad/s) values")

    @classmethod
    def from_proto(cls, message: common_pb2.Twist) -> Velocity:
        return cls([message.linear.x, message.linear.y, message.linear.z],
                   [message.angular.x, message.angular.y, message.angular.z])

    def to_proto(self) -> common_pb2.Twist:
        twist = common_pb2.Twist()
        twist.linear.x, twist.linear.y, twist.linear.z = (float(v) for v in self.linear)
        twist.angular.x, twist.angular.y, twist.angular.z = (float(v) for v in self.angular)
        return twist


@dataclass
class Pose:
    """A rigid transform: position (3,) in m and orientation (4,) as a quaternion (w, x, y, z).

    The client never normalises or checks values: the server rejects quaternions whose norm is farther than
    1e-3 from 1 and normalises the rest.
    """

    position: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    orientation: NDArray[np.float64] = field(default_factory=_identity_quaternion)

    if TYPE_CHECKING:  # the generated __init__ takes any 3 and 4 values: __post_init__ makes float64 arrays of them
        def __init__(self, position: ArrayLike = ..., orientation: ArrayLike = ...) -> None: ...

    def __post_init__(self) -> None:
        self.position = np.array(self.position, dtype=np.float64).reshape(-1)
        self.orientation = np.array(self.orientation, dtype=np.float64).reshape(-1)
        if self.position.shape != (3,):
            raise ValueError(f"Pose.position needs 3 values (m), got {self.position.size}")
        if self.orientation.shape != (4,):
            raise ValueError(f"Pose.orientation needs 4 values (w, x, y, z), got {self.orientation.size}")

    @classmethod
    def from_array(cls, values: ArrayLike) -> Pose:
        """From 7 values [x, y, z (m), qw, qx, qy, qz]."""
        array = np.asarray(values, dtype=np.float64).reshape(-1)
        if array.shape != (7,):
            raise ValueError(f"a pose array needs 7 values [x y z qw qx qy qz], got {array.size}")
        return cls(array[:3], array[3:])

    @classmethod
    def from_proto(cls, msg: common_pb2.Pose) -> Pose:
        """From a graspsim.v1.Pose message; an absent orientation is the identity."""
        p = msg.position
        if msg.HasField("orientation"):
            q = msg.orientation
            return cls([p.x, p.y, p.z], [q.w, q.x, q.y, q.z])
        return cls([p.x, p.y, p.z])

    def to_proto(self) -> common_pb2.Pose:
        """To a graspsim.v1.Pose message; the orientation is always sent, even (0, 0, 0, 0)."""
        x, y, z = (float(v) for v in self.position)
        w, qx, qy, qz = (float(v) for v in self.orientation)
        msg = common_pb2.Pose(position=common_pb2.Vec3(x=x, y=y, z=z))
        msg.orientation.SetInParent()
        msg.orientation.CopyFrom(common_pb2.Quaternion(w=w, x=qx, y=qy, z=qz))
        return msg

    def as_array(self) -> NDArray[np.float64]:
        """The 7 values [x, y, z (m), qw, qx, qy, qz]."""
        return np.concatenate([self.position, self.orientation])

    def rotation_matrix(self) -> NDArray[np.float64]:
        """The 3x3 rotation matrix of the (normalised) orientation."""
        return quaternion_to_matrix(self.orientation)

    def matrix(self) -> NDArray[np.float64]:
        """The 4x4 homogeneous transform (m)."""
        out = np.eye(4)
        out[:3, :3] = self.rotation_matrix()
        out[:3, 3] = self.position
        return out


# A pose: a Pose, 7 values [x y z qw qx qy qz] or a (position, quaternion) pair.
PoseLike = Union[Pose, Sequence[float], Tuple[Sequence[float], Sequence[float]], NDArray[np.float64]]


def as_pose(value: PoseLike) -> Pose:
    """Accepts a Pose, 7 values [x y z qw qx qy qz] or a (position, quaternion) pair; and, for code written
    against the raw stubs, a graspsim.v1.Pose message."""
    if isinstance(value, Pose):
        return value
    if isinstance(value, common_pb2.Pose):
        return Pose.from_proto(value)
    if not isinstance(value, np.ndarray) and len(value) == 2:
        position, orientation = value
        return Pose(position, orientation)
    return Pose.from_array(value)


def quaternion_about_axis(axis: ArrayLike, angle: float) -> NDArray[np.float64]:
    """The unit quaternion (w, x, y, z) of a rotation by angle (rad) about axis (any non-zero length)."""
    unit = np.asarray(axis, dtype=np.float64)
    unit = unit / np.linalg.norm(unit)
    return np.concatenate([[np.cos(angle / 2.0)], np.sin(angle / 2.0) * unit])


def quaternion_to_matrix(q: ArrayLike) -> NDArray[np.float64]:
    """The 3x3 rotation matrix of quaternion (w, x, y, z), normalised first."""
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
