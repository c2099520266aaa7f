"""GraspService end to end: planning on a scene body and on a sent mesh, numpy results, stored sets found again
(also after a restart), cancel and deadline, bad input rejected naming the field."""
import threading
import time

import grpc
import numpy as np
import pytest

import graspsim
from graspsim import meshes

IA = grpc.StatusCode.INVALID_ARGUMENT


def box(edge=(0.04, 0.06, 0.05)):
    return meshes.box_mesh(list(edge))


def test_plan_on_a_scene_body_avoids_the_table(client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, 0.775, 1, 0, 0, 0])
    result = client.plan_grasps("schunk_pg70", scene_id=scene_id, body_id="cube", spacing=0.01, progress=False)
    assert isinstance(result, graspsim.GraspSetResult) and not result.from_store
    assert result.candidates > 0 and result.collisions > 0   # from below and low sides: through the table
    assert 0 < len(result.grasps) <= 50 and result.force_closure >= len(result.grasps)
    g = result.grasps
    assert g.dtype.names[:3] == ("candidate_index", "outcome", "preshape")
    assert np.all(g["force_closure"]) and np.all(g["epsilon"] > 0)
    assert np.all(np.diff(g["epsilon"]) <= 0)                 # best first
    assert g["joint_positions"].shape == (len(g), len(result.joint_ids))
    np.testing.assert_allclose(np.linalg.norm(g["hand_pose"][:, 3:], axis=1), 1, atol=1e-9)
    # The cube's top face is at z = +0.025 of its frame: no grasp comes from below the table top (z = -0.025).
    approach = g["approach"]
    assert np.all(approach[:, 2] < 0.99)
    c = result.contacts
    assert len(c) == g["contact_count"].sum() and set(c["link"]) <= {"base_link", "finger_left", "finger_right"}
    assert np.all(np.abs(c["point"]) <= 0.025 + 1e-4)         # on the cube
    np.testing.assert_allclose(np.linalg.norm(c["normal"], axis=1), 1, atol=1e-6)


def test_second_request_is_served_from_the_store(client):
    kwargs = dict(mesh=box(), spacing=0.015, seed=7, progress=False)
    first = client.plan_grasps("schunk_pg70", **kwargs)
    start = time.monotonic()
    second = client.plan_grasps("schunk_pg70", **kwargs)
    assert second.from_store and not first.from_store
    assert second.set_id == first.set_id and len(first.set_id) == 64
    np.testing.assert_array_equal(second.grasps, first.grasps)
    np.testing.assert_array_equal(second.contacts, first.contacts)
    assert client.get_grasp_set(first.set_id).set_id == first.set_id
    other = client.plan_grasps("schunk_pg70", friction=0.6, **kwargs)   # another parameter, another set
    assert other.set_id != first.set_id and not other.from_store
    assert time.monotonic() - start < 60


def test_sets_survive_a_restart(start_server, tmp_path):
    flags = (f"--grasp-data-dir={tmp_path / 'grasps'}",)
    server = start_server(*flags)
    with graspsim.connect(server.address) as c:
        planned = c.plan_grasps("barrett_bh8_282", mesh=box((0.06, 0.06, 0.08)), spacing=0.03, progress=False)
    assert server.stop() == 0
    again = start_server(*flags)
    with graspsim.connect(again.address) as c:
        stored = c.plan_grasps("barrett_bh8_282", mesh=box((0.06, 0.06, 0.08)), spacing=0.03, progress=False)
        assert stored.from_store and stored.set_id == planned.set_id
        np.testing.assert_array_equal(stored.grasps, planned.grasps)


def test_progress_is_streamed_and_methods_work(client):
    seen = []
    for method in ("bounding_box", "grasp_points", "centroid_circles"):
        result = client.plan_grasps("schunk_sdh2", mesh=box((0.05, 0.05, 0.1)), method=method, spacing=0.02,
                                    recompute=True, progress=False, on_progress=lambda d, t: seen.append((d, t)))
        assert result.candidates > 0, method
    assert seen and seen[-1][0] == seen[-1][1]


def test_evaluate_grasp_reports_contacts(client):
    candidate = graspsim.GraspCandidate(approach=[0, 0, -1], target=[0, 0, 0.025], reference=[1, 0, 0],
                                        preshape="power")
    row, contacts = client.evaluate_grasp("schunk_pg70", candidate, mesh=box((0.04, 0.04, 0.05)))
    assert row["outcome"] == "grasp" and row["force_closure"] and row["volume"] > 0
    assert {"finger_left", "finger_right"} <= set(contacts["link"])
    # The row itself is a candidate: evaluated again, the same grasp.
    again, _ = client.evaluate_grasp("schunk_pg70", row, mesh=box((0.04, 0.04, 0.05)))
    assert again["epsilon"] == row["epsilon"] and graspsim.GraspCandidate.from_row(again) == candidate


def test_cancel_and_deadline_stop_planning(client):
    request = dict(mesh=box(), spacing=0.002, recompute=True, progress=False)  # ~100k candidates
    with pytest.raises(graspsim.GraspsimError) as info:
        client.plan_grasps("schunk_pg70", timeout=0.5, **request)
    assert info.value.code == grpc.StatusCode.DEADLINE_EXCEEDED
    cancelled = threading.Event()

    def stop_after_first(done, total):
        if done > 0:
            cancelled.set()
            raise KeyboardInterrupt  # leaves the stream: plan_grasps cancels the call
    with pytest.raises(KeyboardInterrupt):
        client.plan_grasps("schunk_pg70", on_progress=stop_after_first, **request)
    assert cancelled.is_set()
    # The server is still serving and plans the next request.
    assert client.plan_grasps("schunk_pg70", mesh=box(), spacing=0.03, progress=False).candidates > 0


@pytest.mark.parametrize("kwargs, fragments", [
    (dict(hand="ur5", mesh=box()), ["hand", "ur5"]),
    (dict(hand="schunk_pg70", mesh=(np.zeros((0, 3)), np.zeros((0, 3)))), ["object"]),
    (dict(hand="schunk_pg70", mesh=box(), friction=0.0), ["friction", "0"]),
    (dict(hand="schunk_pg70", mesh=box(), friction=-0.2), ["friction", "-0.2"]),
    (dict(hand="schunk_pg70", mesh=box(), circle_samples=0, method="centroid_circles"), ["circle_samples", "0"]),
    (dict(hand="schunk_pg70", mesh=box(), rolls=0), ["rolls", "0"]),
    (dict(hand="schunk_pg70", mesh=box(), spacing=0.0), ["spacing", "0"]),
    (dict(hand="schunk_pg70", mesh=box(), method="random"), ["method", "random"]),
    (dict(hand="schunk_pg70", mesh=box(), preshapes=["fist"]), ["preshapes[0]", "fist"]),
    (dict(hand="schunk_pg70", mesh=box(), standoffs=[0.5]), ["standoffs[0]", "0.5"]),
    (dict(hand="schunk_pg70", scene_id="nope", body_id="cube"), ["nope"]),
    (dict(hand="schunk_pg70", mesh=box(), friction_pairs={("a", "b"): 0.0}), ["friction_pairs[0].friction", "0"]),
    (dict(hand="schunk_pg70", mesh=box(), link_materials={"thumb": "rubber"}), ["link_materials", "thumb"]),
])
def test_bad_input_is_rejected_naming_the_field(client, kwargs, fragments):
    with pytest.raises(graspsim.GraspsimError) as info:
        client.plan_grasps(progress=False, **kwargs)
    expected = grpc.StatusCode.NOT_FOUND if "scene_id" in kwargs else IA
    assert info.value.code == expected, str(info.value)
    for fragment in fragments:
        assert fragment in info.value.message, f"{fragment!r} not in {info.value.message!r}"


def test_get_grasp_set_errors(client):
    with pytest.raises(graspsim.GraspsimError) as info:
        client.get_grasp_set("xyz")
    assert info.value.code == IA and "set_id" in info.value.message
    with pytest.raises(graspsim.GraspsimError) as info:
        client.get_grasp_set("0" * 64)
    assert info.value.code == grpc.StatusCode.NOT_FOUND


def test_material_pairs_set_each_contacts_friction(client):
    """Every PG70 link rubber on a wooden box at μ 0.8 plans exactly the set of friction=0.8, under its own
    store key; the pair in either order and as (a, b, μ) triples is the same request."""
    common = dict(mesh=box(), spacing=0.02, progress=False, recompute=True)
    links = {"base_link": "rubber", "finger_left": "rubber", "finger_right": "rubber"}
    by_pair = client.plan_grasps("schunk_pg70", object_material="wood", link_materials=links,
                                 friction_pairs={("wood", "rubber"): 0.8}, **common)
    plain = client.plan_grasps("schunk_pg70", friction=0.8, **common)
    assert len(by_pair.grasps) > 0 and by_pair.set_id != plain.set_id
    np.testing.assert_array_equal(by_pair.grasps["epsilon"], plain.grasps["epsilon"])
    np.testing.assert_array_equal(by_pair.grasps["candidate_index"], plain.grasps["candidate_index"])
    again = client.plan_grasps("schunk_pg70", object_material="wood", link_materials=links,
                               friction_pairs=[("rubber", "wood", 0.8)], mesh=box(), spacing=0.02, progress=False)
    assert again.from_store and again.set_id == by_pair.set_id
    # A slippery left jaw (steel on the default material, μ 0.1) never raises a grasp's ε.
    slippery = client.plan_grasps("schunk_pg70", link_materials={"finger_left": "steel"},
                                  friction_pairs={("steel", "default"): 0.1}, **common)
    default = client.plan_grasps("schunk_pg70", **common)
    assert slippery.grasps["epsilon"].max() < default.grasps["epsilon"].max()
    assert by_pair.cpu_seconds > 0
