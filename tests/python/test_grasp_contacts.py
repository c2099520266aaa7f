"""Contact generation and ε against an analytic case (issue 22): the PG70 closing on a 4 x 4 x 8 cm box from above.

The geometry is known exactly (server/models/schunk_pg70.urdf): the hand comes down its +z (the approach) until
its palm, the housing's 64 x 90 mm face, rests on the box's top face, which it covers; its jaws, 24 mm wide and
60 mm long, start 1 mm beyond the palm and close along the hand's y (finger_left on +y) onto the two side faces.
So each contact patch is a rectangle: the top face, and on each side face x ∈ [-12, 12] mm, z from 1 mm to 61 mm
below the top (the box is 80 mm tall: the jaws end inside the faces, so every patch edge is a jaw or face edge).

Quality convention (docs/grasp.md, server/src/grasp/quality.h): point contacts, μ = 0.4, cones of 8 edges
f = n + μ (cos θ t1 + sin θ t2) with t1 = n × (the axis least aligned with n), wrenches (f, (p - c) × f / λ), c the
surface centroid (the box's centre), λ the largest centroid-vertex distance (half the diagonal); ε = the distance
from the origin to the hull's nearest facet. No closed form is at hand for these 8-edge cones in 6-D, so ε is
checked against scipy's qhull on wrenches built here from the analytic contacts.
"""
import numpy as np
import pytest
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

import graspsim
from graspsim import meshes

HALF = np.array([0.02, 0.02, 0.04])      # m, the box's half extents
JAW_HALF_WIDTH, JAW_GAP, JAW_LENGTH = 0.012, 0.001, 0.060   # m, the URDF's finger boxes
FRICTION, CONE_EDGES = 0.4, 8
ON_FACE_M = 1e-5      # ray hits on a float32 mesh: rounding only, far below a hand sample step (3 mm)
NORMAL_DEG = 1.0
EPSILON_REL = 1e-6
# The box in the object frame: axis-aligned at the origin, or turned and moved (no normal near a tie between two
# of its components, where the server's tangent basis would switch axes).
POSES = {"axis_aligned": ([0, 0, 0], [0, 0, 0]), "turned": ([0.3, -0.5, 0.4], [0.1, -0.05, 0.2])}


def grasp_box(client, pose):
    """The PG70 down onto the box's top face, jaws closing along the box's y; the contacts in the box frame."""
    rotation, offset = Rotation.from_rotvec(pose[0]).as_matrix(), np.array(pose[1], float)
    vertices, triangles = meshes.box_mesh(2 * HALF)
    candidate = graspsim.GraspCandidate(approach=rotation @ [0, 0, -1], target=rotation @ [0, 0, HALF[2]] + offset,
                                        reference=rotation @ [1, 0, 0])   # hand x; its y = z × x = -box y
    row, contacts = client.evaluate_grasp("schunk_pg70", candidate, mesh=(vertices @ rotation.T + offset, triangles),
                                          friction=FRICTION)
    assert row["outcome"] == "grasp" and row["force_closure"]
    return row["epsilon"], (contacts["point"] - offset) @ rotation, contacts["normal"] @ rotation, \
        list(contacts["link"]), rotation


def tangent_basis(n):
    """The server's: t1 = n × the axis least aligned with n (first of equals)."""
    x, y, z = np.abs(n)
    t1 = np.cross(n, np.eye(3)[0 if x <= y and x <= z else (1 if y <= z else 2)])
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def epsilon(points, normals, rotation):
    """ε of contacts given in the box frame, the wrenches built in the object frame (where the server builds its
    cones: the tangent basis depends on the frame); the box's centre is the centroid."""
    length = np.linalg.norm(HALF)
    wrenches = []
    for p, n in zip(points @ rotation.T, normals @ rotation.T):
        t1, t2 = tangent_basis(n)
        for k in range(CONE_EDGES):
            theta = 2 * np.pi * k / CONE_EDGES
            f = n + FRICTION * (np.cos(theta) * t1 + np.sin(theta) * t2)
            wrenches.append(np.concatenate([f, np.cross(p / length, f)]))
    return float(np.min(-ConvexHull(np.array(wrenches)).equations[:, -1]))


# Each link's face: its outward normal in the box frame (the palm on top, finger_left on the hand's +y = box -y).
FACE = {"base_link": np.array([0, 0, 1.0]), "finger_left": np.array([0, -1.0, 0]), "finger_right": np.array([0, 1.0, 0])}


@pytest.mark.parametrize("pose", POSES.values(), ids=POSES.keys())
def test_pg70_contacts_lie_on_the_box_faces_and_epsilon_follows(client, pose):
    eps, points, normals, links, rotation = grasp_box(client, pose)
    assert set(links) == set(FACE), links
    for p, n, link in zip(points, normals, links):
        out = FACE[link]
        # On the face's plane and inside the face; the normal that face's, pointing into the box.
        assert abs(p @ out - HALF @ np.abs(out)) <= ON_FACE_M, (link, p)
        assert np.all(np.abs(p) <= HALF + ON_FACE_M), (link, p)
        assert np.degrees(np.arccos(np.clip(n @ -out, -1, 1))) <= NORMAL_DEG, (link, n)
    # The analytic contacts: the reported points put exactly on their faces, with the faces' exact normals.
    exact = np.array([p - (p @ FACE[link] - HALF @ np.abs(FACE[link])) * FACE[link] for p, link in zip(points, links)])
    exact_normals = np.array([-FACE[link] for link in links])
    assert eps == pytest.approx(epsilon(exact, exact_normals, rotation), rel=EPSILON_REL)


def patch_corners():
    """The contact patches' corners (box frame) and their inward normals: the top face's four, and the four of
    each jaw's inner face where it covers a side face."""
    top = [[sx * HALF[0], sy * HALF[1], HALF[2]] for sx in (-1, 1) for sy in (-1, 1)]
    jaw = [(sx * JAW_HALF_WIDTH, HALF[2] - z) for sx in (-1, 1) for z in (JAW_GAP, JAW_GAP + JAW_LENGTH)]
    left = [[x, -HALF[1], z] for x, z in jaw]
    right = [[x, HALF[1], z] for x, z in jaw]
    normals = [-FACE["base_link"]] * 4 + [-FACE["finger_left"]] * 4 + [-FACE["finger_right"]] * 4
    return np.array(top + left + right), np.array(normals)


@pytest.mark.parametrize("pose", [
    pytest.param(POSES["axis_aligned"], id="axis_aligned"),
    pytest.param(POSES["turned"], id="turned")])
def test_pg70_epsilon_is_that_of_the_whole_contact_patches(client, pose):
    """A flat patch's wrench hull is that of its corners: ε of the grasp is ε of the twelve patch corners,
    whatever the box's orientation in the object frame."""
    eps, _, _, _, rotation = grasp_box(client, pose)
    points, normals = patch_corners()
    assert eps == pytest.approx(epsilon(points, normals, rotation), rel=EPSILON_REL)
