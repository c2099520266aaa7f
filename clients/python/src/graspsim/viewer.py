"""The browser viewer's address, and a matplotlib view of a scene for people without a browser at hand.

    url = graspsim.viewer_url(scene.id, "http://127.0.0.1:8080")   # open it in any browser: live, read-only
    fig = graspsim.viewer.scene_figure(client, scene.id)          # a 3D snapshot (needs the "plot" extra)
    graspsim.plot.save(fig, "scene.png")

The server serves the viewer on its HTTP port (--http-listen, default 127.0.0.1:8080): /view lists the scenes,
/view/<scene> shows one (docs/viewer.md). matplotlib is imported only by scene_figure / draw_scene.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, List, Optional, Tuple
from urllib.parse import quote, urlencode

import numpy as np
from numpy.typing import NDArray

from graspsim._body import Geometry
from graspsim._ids import SceneLike, scene_id_of
from graspsim._scene import Scene
from graspsim.meshes import box_mesh, uv_sphere

if TYPE_CHECKING:  # pragma: no cover - typing only
    from mpl_toolkits.mplot3d import Axes3D
    from matplotlib.figure import Figure

    from graspsim._client import Client

DEFAULT_HTTP_URL = "http://127.0.0.1:8080"


def viewer_url(scene: SceneLike, http_url: str = DEFAULT_HTTP_URL, *, grasp_set: Optional[str] = None,
               grasp_object: Optional[str] = None) -> str:
    """The viewer page of a scene (its id, SceneSummary or Scene) on the server's HTTP address.

    grasp_set: a set_id from plan_grasps, drawn as hand ghosts on grasp_object (default: the first object).
    """
    scene_id = scene_id_of(scene, "scene")
    if not scene_id:
        raise ValueError("viewer_url: empty scene id")
    query = {key: value for key, value in (("grasp_set", grasp_set), ("grasp_object", grasp_object)) if value}
    return f"{http_url.rstrip('/')}/view/{quote(scene_id, safe='')}" + (f"?{urlencode(query)}" if query else "")


def _cylinder_mesh(radius: float, length: float, segments: int = 24) -> Tuple[NDArray[np.float64], NDArray[np.uint32]]:
    """Closed cylinder along z, centred on the origin."""
    phi = 2.0 * np.pi * np.arange(segments) / segments
    ring = np.stack([radius * np.cos(phi), radius * np.sin(phi)], axis=1)
    vertices = np.vstack([np.column_stack([ring, np.full(segments, -length / 2)]),
                          np.column_stack([ring, np.full(segments, length / 2)]),
                          [[0, 0, -length / 2], [0, 0, length / 2]]])
    j, k = np.arange(segments), (np.arange(segments) + 1) % segments
    bottom, top = 2 * segments, 2 * segments + 1
    faces = np.vstack([np.stack([j, k, segments + k], 1), np.stack([j, segments + k, segments + j], 1),
                       np.stack([np.full(segments, bottom), k, j], 1),
                       np.stack([np.full(segments, top), segments + j, segments + k], 1)])
    return vertices, faces.astype(np.uint32)


def geometry_mesh(geometry: Geometry) -> Optional[Tuple[NDArray[np.float64], NDArray[np.uint32]]]:
    """A collision shape as (vertices (n, 3) m in the body frame, triangles (m, 3)); None for a mesh_file the
    server did not inline."""
    if geometry.shape == "box":
        vertices, triangles = box_mesh(geometry.size)
    elif geometry.shape == "sphere":
        vertices, triangles = uv_sphere(geometry.radius, 8, 16)
    elif geometry.shape == "cylinder":
        vertices, triangles = _cylinder_mesh(geometry.radius, geometry.length)
    elif geometry.shape == "mesh":
        vertices, triangles = geometry.vertices * geometry.scale, geometry.triangles
    else:
        return None
    origin = geometry.origin
    return np.asarray(vertices, dtype=np.float64) @ origin.rotation_matrix().T + origin.position, triangles


def world_meshes(scene: Scene) -> List[Tuple[str, NDArray[np.float64], NDArray[np.uint32]]]:
    """Every drawable shape of a scene (get_scene with include_geometry) in the world frame:
    (body id, vertices (n, 3) m, triangles (m, 3))."""
    out = []
    for body in scene.bodies:
        pose = body.pose
        for geometry in body.collision:
            mesh = geometry_mesh(geometry)
            if mesh is not None:
                out.append((body.id, mesh[0] @ pose.rotation_matrix().T + pose.position, mesh[1]))
    return out


def draw_scene(ax: Axes3D, scene: Scene) -> List[str]:
    """Draws the scene's bodies into 3D axes (projection="3d") at their poses; returns the body id of each
    drawn shape, in drawing order."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    colours = {"static": "#8a8f96", "articulated": "#5d7fa8"}
    motion = {body.id: body.motion for body in scene.bodies}
    drawn, points = [], []
    for body_id, vertices, triangles in world_meshes(scene):
        ax.add_collection3d(Poly3DCollection(vertices[triangles], facecolor=colours.get(motion[body_id], "#e0913a"),
                                             edgecolor="#333333", linewidths=0.2, alpha=0.9))
        drawn.append(body_id)
        points.append(vertices)
    if points:  # equal scale on every axis, so that a cube looks like one
        every = np.vstack(points)
        centre, half = (every.max(0) + every.min(0)) / 2, max(1e-3, float(np.ptp(every, axis=0).max()) / 2)
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(f"{scene.summary.id} at t = {scene.summary.time:.3f} s", fontsize="medium")
    return drawn


def scene_figure(client: Client, scene_id: SceneLike, *, fig: Optional[Figure] = None) -> Figure:
    """A figure of the scene as it is now (one GetScene with geometry): a snapshot, not a live view."""
    from graspsim.plot import new_figure

    fig = fig if fig is not None else new_figure(figsize=(6.0, 6.0))
    ax = fig.add_subplot(projection="3d")
    draw_scene(ax, client.get_scene(scene_id, include_geometry=True))
    return fig
