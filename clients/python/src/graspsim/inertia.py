"""Mass properties of uniform-density solids, for AddObject's Inertial when only a mass is given.

Every tensor is about the centre of mass, in the body (geometry) frame, in kg m^2; masses in kg, lengths in m.
"""
from __future__ import annotations

from typing import Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray


def box_inertia(mass: float, size: ArrayLike) -> NDArray[np.float64]:
    """Solid box of full edge lengths size = (a, b, c): diag(b²+c², a²+c², a²+b²) * m / 12."""
    a, b, c = np.asarray(size, dtype=np.float64).reshape(3).tolist()
    return np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * float(mass) / 12.0


def sphere_inertia(mass: float, radius: float) -> NDArray[np.float64]:
    """Solid sphere: 2/5 m r² about every axis."""
    return np.eye(3) * 0.4 * float(mass) * float(radius) ** 2


def cylinder_inertia(mass: float, radius: float, length: float) -> NDArray[np.float64]:
    """Solid cylinder along z: m r²/2 about z, m (3r² + l²)/12 about x and y."""
    m, r, l = float(mass), float(radius), float(length)
    side = m * (3.0 * r * r + l * l) / 12.0
    return np.diag([side, side, 0.5 * m * r * r])


def mesh_volume_properties(vertices: ArrayLike, triangles: ArrayLike
                           ) -> Tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Volume (m³), centroid (3,) (m) and the second moment ∫ (x-c)(x-c)ᵀ dV (3x3, m⁵) of a closed mesh.

    Divergence theorem: the solid is the signed sum of the tetrahedra (origin, a, b, c) over the triangles,
    which must be counter-clockwise seen from outside. A tetrahedron of volume V = det[a b c]/6 has its
    centroid at (a+b+c)/4 and ∫ x xᵀ dV = V/20 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a+b+c.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    tet_volume = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    volume = float(tet_volume.sum())
    if not volume > 0.0:
        raise ValueError(f"mesh encloses volume {volume} m^3: it must be closed with outward-facing triangles")
    s = a + b + c
    centroid = (tet_volume[:, None] * s).sum(axis=0) / (4.0 * volume)
    outer = sum(np.einsum("ni,nj->nij", p, p) for p in (a, b, c, s))
    second = np.einsum("n,nij->ij", tet_volume / 20.0, outer)
    return volume, centroid, second - volume * np.outer(centroid, centroid)


def mesh_inertia(mass: float, vertices: ArrayLike, triangles: ArrayLike
                 ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centre of mass (3,) (m) and inertia tensor about it (3x3, kg m²) of a closed mesh of uniform density."""
    volume, centroid, second = mesh_volume_properties(vertices, triangles)
    density = float(mass) / volume
    return centroid, density * (np.trace(second) * np.eye(3) - second)
