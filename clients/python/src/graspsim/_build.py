"""Builders of AddObject's geometry, inertial and material from plain Python/numpy values."""
from __future__ import annotations

from typing import Any, Dict, Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspsim import inertia as mass_properties
from graspsim.meshes import pack_mesh
from graspsim.v1 import common_pb2

SHAPES = ("builtin", "box", "sphere", "cylinder", "mesh", "mesh_file")


def vec3(values: ArrayLike, what: str) -> common_pb2.Vec3:
    """A Vec3 message from 3 numbers (no value checks: the server validates)."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.shape != (3,):
        raise ValueError(f"{what} needs 3 values, got {v.size}")
    return common_pb2.Vec3(x=v[0], y=v[1], z=v[2])


def pick_shape(shapes: Dict[str, Any]) -> Tuple[str, Any]:
    """The one (kind, value) given among the shape keywords; ValueError unless exactly one is given."""
    given = [(kind, value) for kind, value in shapes.items() if value is not None]
    if len(given) != 1:
        raise ValueError(f"give exactly one of {', '.join(SHAPES)}; got {[kind for kind, _ in given] or 'none'}")
    return given[0]


def geometry(kind: str, value: Any) -> common_pb2.Geometry:
    """The Geometry message of a shape keyword: box=(x, y, z) m, sphere=r m, cylinder=(r, l) m,
    mesh=(vertices (N, 3) m, triangles (M, 3)), mesh_file="uploaded/path.stl"."""
    if kind == "box":
        return common_pb2.Geometry(box=common_pb2.Box(size=vec3(value, "box size")))
    if kind == "sphere":
        return common_pb2.Geometry(sphere=common_pb2.Sphere(radius=float(value)))
    if kind == "cylinder":
        radius, length = value
        return common_pb2.Geometry(cylinder=common_pb2.Cylinder(radius=float(radius), length=float(length)))
    if kind == "mesh":
        vertices, triangles = value
        return common_pb2.Geometry(mesh=pack_mesh(vertices, triangles))
    if kind == "mesh_file":
        return common_pb2.Geometry(mesh_file=str(value))
    raise ValueError(f"unknown shape {kind!r}")


def _inertia_of_shape(kind: str, value: Any, mass: float, center_of_mass: Optional[ArrayLike]
                      ) -> Tuple[Optional[ArrayLike], NDArray[np.float64]]:
    """(center_of_mass, inertia 3x3) computed for a uniform-density shape, or ValueError where impossible."""
    if kind == "box":
        return center_of_mass, mass_properties.box_inertia(mass, value)
    if kind == "sphere":
        return center_of_mass, mass_properties.sphere_inertia(mass, value)
    if kind == "cylinder":
        return center_of_mass, mass_properties.cylinder_inertia(mass, *value)
    if kind == "mesh":
        centroid, tensor = mass_properties.mesh_inertia(mass, *value)
        return (centroid if center_of_mass is None else center_of_mass), tensor
    raise ValueError(f"give inertia (3x3, kg m^2) with mass for a {kind} object: it cannot be computed here")


def inertial(kind: str, value: Any, mass: Optional[float], inertia: Optional[ArrayLike],
             center_of_mass: Optional[ArrayLike]) -> Optional[common_pb2.Inertial]:
    """The Inertial message: None when no mass is given (a builtin keeps its own, a static body needs none, a
    moving body given by geometry gets the server's from the geometry unless import options say from_file or
    strict: then the server says a mass is needed). With a mass but no inertia, a primitive's or closed mesh's
    uniform-density inertia is used."""
    if mass is None:
        if inertia is not None or center_of_mass is not None:
            raise ValueError("inertia and center_of_mass need a mass (kg)")
        return None
    if inertia is None:
        center_of_mass, inertia = _inertia_of_shape(kind, value, float(mass), center_of_mass)
    tensor = np.asarray(inertia, dtype=np.float64)
    if tensor.shape != (3, 3):
        raise ValueError(f"inertia must be a 3x3 tensor (kg m^2), got shape {tensor.shape}")
    if np.any(np.abs(tensor - tensor.T) > 1e-12 * np.nanmax(np.abs(tensor), initial=1.0)):
        raise ValueError(f"inertia must be symmetric, got {tensor.tolist()}")
    msg = common_pb2.Inertial(mass=float(mass), ixx=tensor[0, 0], iyy=tensor[1, 1], izz=tensor[2, 2],
                              ixy=tensor[0, 1], ixz=tensor[0, 2], iyz=tensor[1, 2])
    if center_of_mass is not None:
        msg.center_of_mass.CopyFrom(vec3(center_of_mass, "center_of_mass"))
    return msg


def material(friction: Optional[ArrayLike]) -> Optional[common_pb2.Material]:
    """Material from friction = (static, dynamic), dimensionless; None keeps the server's default."""
    if friction is None:
        return None
    pair = np.asarray(friction, dtype=np.float64)
    if pair.shape != (2,):
        raise ValueError(f"friction must be (static, dynamic), got shape {pair.shape}")
    static, dynamic = pair
    return common_pb2.Material(static_friction=float(static), dynamic_friction=float(dynamic))


_INERTIA_SOURCES = {"auto": common_pb2.INERTIA_SOURCE_AUTO, "from_file": common_pb2.INERTIA_SOURCE_FROM_FILE,
                    "from_geometry": common_pb2.INERTIA_SOURCE_FROM_GEOMETRY}


def import_options(inertia: str = "auto", density: Optional[float] = None, strict: bool = False,
                   model_name: str = "") -> common_pb2.ImportOptions:
    """ImportOptions from the keyword arguments of add_robot / add_object (docs/import.md)."""
    if inertia not in _INERTIA_SOURCES:
        raise ValueError(f"inertia: {inertia!r} is not one of {', '.join(_INERTIA_SOURCES)}")
    return common_pb2.ImportOptions(inertia=_INERTIA_SOURCES[inertia], density=density or 0.0, strict=strict,
                                    model_name=model_name)
