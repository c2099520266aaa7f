"""A fleet on loopback (issue 23, docs/scaling.md): 3 graspsim-server replicas behind HAProxy with
deploy/haproxy/graspsim-fleet.cfg as shipped, grpc-health-probe as its health check (make go-tools).

Routing is checked from the replicas' side: each replica is asked directly which scenes it holds, so a call the
balancer sent to the wrong replica shows as NOT_FOUND (the scene is nowhere else) and is counted."""
import threading
import time
from collections import Counter

import pytest

import graspsim
from graspsim.fleet import rebalance
from graspsim.testing.fleet import Fleet, config_with_replicas
from conftest import REPO_ROOT, server_binary

CONFIG = REPO_ROOT / "deploy" / "haproxy" / "graspsim-fleet.cfg"
PROBE = REPO_ROOT / "build" / "tools" / "bin" / "grpc-health-probe"
SCENES = 100


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    if not PROBE.is_file():
        pytest.fail(f"{PROBE} missing: run make go-tools", pytrace=False)
    with Fleet(str(server_binary()), str(CONFIG), str(PROBE), str(tmp_path_factory.mktemp("fleet"))) as rig:
        yield rig


def homes(fleet):
    """scene id -> the replica that holds it, asked of each replica directly."""
    where = {}
    for replica in fleet.replicas:
        if replica.process.poll() is None:
            with graspsim.connect(replica.address) as direct:
                for summary in direct.list_scenes():
                    assert summary.id not in where, f"scene {summary.id} on two replicas"
                    where[summary.id] = replica.name
    return where


@pytest.fixture(scope="module")
def scenes(fleet):
    with graspsim.connect(fleet.address, fleet=True) as client:
        ids = [client.create_scene(f"fleet {i}").id for i in range(SCENES)]
        for i, sid in enumerate(ids):
            client.add_object(sid, "cube", builtin="cube_5cm", pose=[0, 0, 0.1 + 0.001 * i, 1, 0, 0, 0])
    return ids


def test_scenes_spread_over_every_replica_and_each_call_reaches_its_home(fleet, scenes):
    where = homes(fleet)
    assert sorted(where) == sorted(scenes), "every scene created through the balancer exists exactly once"
    counts = Counter(where.values())
    assert set(counts) == {"r0", "r1", "r2"}, counts
    assert min(counts.values()) >= 10, f"consistent hashing spread {SCENES} scenes as {counts}"
    # Scene-scoped calls of every kind go to the home replica: a misrouted one would answer NOT_FOUND.
    with graspsim.connect(fleet.address, fleet=True) as client:
        for i, sid in enumerate(scenes):
            client.step_simulation(sid, steps=2)
            pose = client.get_body_poses(sid, ["cube"])["cube"]
            assert pose.position[2] == pytest.approx(0.1 + 0.001 * i, abs=1e-3)
    # The HTTP/JSON port routes by the same header (the Matlab client sets it) and by the viewer's path.
    import json
    import urllib.request
    for sid in scenes[:10]:
        body = json.dumps({"scene_id": sid}).encode()
        request = urllib.request.Request(f"http://{fleet.http_address}/v1/SceneService/GetScene", data=body,
                                         headers={"Content-Type": "application/json", "graspsim-scene-id": sid})
        with urllib.request.urlopen(request, timeout=10) as reply:
            assert json.load(reply)["summary"]["id"] == sid
        with urllib.request.urlopen(f"http://{fleet.http_address}/view/{sid}/scene.json", timeout=10) as reply:
            assert reply.status == 200


def test_a_client_chosen_id_that_is_taken_is_refused(fleet, scenes):
    with graspsim.connect(fleet.address, fleet=True) as client:
        with pytest.raises(graspsim.AlreadyExists, match=scenes[0]):
            client.create_scene("again", scene_id=scenes[0])


def test_a_killed_replica_fails_only_its_own_scenes_with_unavailable_and_comes_back(fleet, scenes):
    where = homes(fleet)
    victim = fleet.replicas[1]
    errors = Counter()  # (home is victim, status code name)
    calls = Counter()
    stop = threading.Event()

    def load(ids):
        with graspsim.connect(fleet.address, fleet=True, call_timeout=10) as client:
            while not stop.is_set():
                for sid in ids:
                    on_victim = where[sid] == victim.name
                    calls[on_victim] += 1
                    try:
                        client.get_body_poses(sid, ["cube"])
                    except graspsim.GraspsimError as err:
                        errors[on_victim, err.code.name] += 1

    threads = [threading.Thread(target=load, args=(scenes[k::2],)) for k in range(2)]
    for t in threads:
        t.start()
    time.sleep(1.0)
    victim.kill()
    time.sleep(2.0)
    stop.set()
    for t in threads:
        t.join()
    assert calls[True] > 0 and calls[False] > 0
    others = {code: n for (on_victim, code), n in errors.items() if not on_victim}
    assert not others, f"calls for scenes on the live replicas failed: {others}"
    mine = {code: n for (on_victim, code), n in errors.items() if on_victim}
    assert set(mine) == {"UNAVAILABLE"}, f"calls for the killed replica's scenes: {mine} (want UNAVAILABLE only)"

    victim.start()
    lost = []
    with graspsim.connect(fleet.address, fleet=True) as client:
        for sid in (s for s in scenes if where[s] == victim.name):
            try:
                assert "cube" in client.get_body_poses(sid, ["cube"])
            except graspsim.GraspsimError as err:
                lost.append((sid, err.code.name))
    assert not lost, f"scenes of the restarted replica not back from its data dir: {lost}"


def test_stateless_calls_spread_and_skip_a_replica_that_is_down(fleet, scenes):
    # ListScenes names no scene: any healthy replica answers it, with the scenes that replica holds.
    where = homes(fleet)
    served_by = lambda listed: {where[s.id] for s in listed} if listed else {"?"}
    answered = set()
    with graspsim.connect(fleet.address, fleet=True) as client:
        deadline = time.monotonic() + 5  # a replica restarted by the test before is up after its next check
        while answered != {"r0", "r1", "r2"} and time.monotonic() < deadline:
            answered |= served_by(client.list_scenes())
    assert answered == {"r0", "r1", "r2"}, answered
    victim = fleet.replicas[2]
    victim.kill()
    try:
        time.sleep(2.5)  # the health check runs every second: the replica is marked down
        with graspsim.connect(fleet.address, fleet=True) as client:
            answered = set().union(*(served_by(client.list_scenes()) for _ in range(30)))
        assert answered == {"r0", "r1"}, f"answered by {answered} with r2 down (and no call failed)"
    finally:
        victim.start()


def test_a_fourth_replica_moves_about_a_quarter_of_the_scenes_and_rebalance_moves_them(fleet, scenes):
    """Consistent hashing: adding a replica changes the home of ~1/4 of the scenes, to the new replica only;
    graspsim.fleet.rebalance then moves exactly those by archive (docs/scaling.md)."""
    before = homes(fleet)
    assert sorted(before) == sorted(scenes)
    fleet.add_replica()
    fleet.start_balancer(config_with_replicas(CONFIG.read_text(), 4))
    try:
        addresses = [r.address for r in fleet.replicas]
        planned = rebalance(fleet.address, addresses, dry_run=True)
        fraction = len(planned.moved) / len(scenes)
        assert 0.1 <= fraction <= 0.4, f"{fraction:.2f} of the scenes changed home (about 0.25 expected)"
        assert all(source != fleet.replicas[3].address for _, source in planned.moved)
        done = rebalance(fleet.address, addresses)
        assert not done.failed, done.failed
        assert sorted(done.moved) == sorted(planned.moved)
        after = homes(fleet)  # every scene once, the moved ones on the new replica only
        assert sorted(after) == sorted(scenes)
        assert {sid for sid, home in after.items() if home == "r3"} == {sid for sid, _ in planned.moved}
        with graspsim.connect(fleet.address, fleet=True) as client:
            for i, sid in enumerate(scenes):
                pose = client.get_body_poses(sid, ["cube"])["cube"]
                assert pose.position[2] == pytest.approx(0.1 + 0.001 * i, abs=1e-3), sid
        assert not rebalance(fleet.address, addresses, dry_run=True).moved, "a second rebalance has nothing to do"
    finally:
        fleet.start_balancer()
