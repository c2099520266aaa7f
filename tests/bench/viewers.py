"""viewers: 50 browser viewers on one simulating scene. Does watching slow the simulation?

The scene: the PG70 holding the 5 cm cube on the table with a 2 A closing current (contacts in every step, so
no body sleeps). A client steps it in 0.1 s requests as fast as it can; the figure is its step rate (simulated
steps per wall second). Phases of PHASE_S alternate without viewers, with VIEWERS + 1 viewers as the page
asks (contacts on), and with as many asking for poses only, ROUNDS times, so that drift in the machine's load
hits all alike; "viewer_slowdown_pct" compares the medians.

A viewer is what a browser's EventSource is: a GET /view/<scene>/poses?contacts=1 Server-Sent Events stream
as the page asks for it (30 Hz, with the step's contact points: a few hundred while the PG70 holds the cube),
read and discarded on its own socket. All reading viewers share one thread of this process with select(), so
that 50 Python threads do not compete with the server for the 2 cores more than browsers on other machines
would. One more viewer sends its request and never reads (a 4 KiB receive buffer): a
stalled browser. The server's own CPU time per wall second is reported beside the step rates: what serving
the viewers costs it; with the CPU per step it is the figure to trust when other jobs load the machine (the
step rates then move by ±15 % between phases on their own).
"""
import os
import re
import select
import socket
import statistics
import time
from urllib.parse import urlsplit

import graspsim

from _harness import Server, log

VIEWERS = 50
ROUNDS = 5
PHASE_S = 5.0
STEP_REQUEST_S = 0.1
TABLE_TOP, CUBE = 0.75, 0.05
POINTING_DOWN = graspsim.quaternion_about_axis([1, 0, 0], 3.141592653589793)


def build_scene(client) -> str:
    scene = client.create_scene("viewers bench").id
    client.add_object(scene, "table", builtin="table")
    client.add_object(scene, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene, "pg70", builtin="schunk_pg70", base_pose=[0, 0, TABLE_TOP + 0.16, *POINTING_DOWN])
    client.set_joint_positions(scene, {"pg70/finger_left_joint": 0.03})
    client.step_simulation(scene, 0.5)
    client.set_actuator(scene, "pg70/finger_left_joint", "velocity", -0.05, current_limit=2.0)
    client.step_simulation(scene, 0.8)  # closed on the cube: contacts from here on
    return scene


def http_url(server) -> str:
    """The HTTP port the server chose (--http-listen=127.0.0.1:0), from its log line."""
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        found = re.search(r'msg="http listening" .*port=(\d+)', server.log_path.read_text(errors="replace"))
        if found:
            return f"http://127.0.0.1:{found.group(1)}"
        time.sleep(0.05)
    raise RuntimeError(f"the server did not report its HTTP port:\n{server.log_tail()}")


def cpu_seconds(pid: int) -> float:
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def open_viewer(http_url: str, scene: str, receive_buffer: int = 0, contacts: bool = True) -> socket.socket:
    host, port = urlsplit(http_url).hostname, urlsplit(http_url).port
    sock = socket.socket()
    if receive_buffer:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
    sock.connect((host, port))
    sock.sendall(f"GET /view/{scene}/poses?contacts={int(contacts)} HTTP/1.1\r\nHost: {host}\r\nAccept: text/event-stream\r\n\r\n".encode())
    return sock


def step_phase(client, scene: str, pid: int, viewers=()) -> dict:
    """Steps for PHASE_S while the viewers' sockets are drained; step rate, server CPU, snapshots per viewer."""
    received = {sock: 0 for sock in viewers}
    steps, started, cpu0 = 0, time.perf_counter(), cpu_seconds(pid)
    while time.perf_counter() - started < PHASE_S:
        steps += client.step_simulation(scene, STEP_REQUEST_S).steps
        while received:  # drain whatever arrived meanwhile, without waiting
            ready, _, _ = select.select(list(received), [], [], 0)
            if not ready:
                break
            for sock in ready:
                received[sock] += sock.recv(1 << 16).count(b"event: snapshot")
    wall = time.perf_counter() - started
    cpu = cpu_seconds(pid) - cpu0
    return {"steps_per_s": steps / wall, "server_cpu_per_s": cpu / wall, "server_cpu_us_per_step": 1e6 * cpu / steps,
            "snapshots_per_viewer_per_s": statistics.mean(received.values()) / wall if received else 0.0}


def run():
    with Server("--http-listen=127.0.0.1:0") as server, graspsim.connect(server.address) as client:
        url = http_url(server)
        scene = build_scene(client)
        pid = server.process.pid
        alone, watched, poses_only = [], [], []
        for round_number in range(ROUNDS):
            alone.append(step_phase(client, scene, pid))
            log(f"round {round_number + 1}: no viewers: {alone[-1]['steps_per_s']:.0f} steps/s")
            for contacts, phases in ((True, watched), (False, poses_only)):
                stalled = open_viewer(url, scene, receive_buffer=4096, contacts=contacts)
                viewers = [open_viewer(url, scene, contacts=contacts) for _ in range(VIEWERS)]
                time.sleep(0.5)  # every stream is open and sending before the phase starts
                phases.append(step_phase(client, scene, pid, viewers))
                log(f"round {round_number + 1}: {VIEWERS} + 1 viewers{'' if contacts else ' (poses only)'}: "
                    f"{phases[-1]['steps_per_s']:.0f} steps/s, "
                    f"{phases[-1]['snapshots_per_viewer_per_s']:.1f} snapshots/s per viewer")
                for sock in viewers + [stalled]:
                    sock.close()
                time.sleep(0.5)

    def median(phases, key):
        return statistics.median(p[key] for p in phases)

    rate_alone, rate_watched = median(alone, "steps_per_s"), median(watched, "steps_per_s")
    figures = {"viewers": VIEWERS, "never_reading_viewers": 1, "rounds": ROUNDS, "phase_s": PHASE_S,
               "steps_per_s_alone": round(rate_alone), "steps_per_s_watched": round(rate_watched),
               "steps_per_s_alone_each": [round(p["steps_per_s"]) for p in alone],
               "steps_per_s_watched_each": [round(p["steps_per_s"]) for p in watched],
               "viewer_slowdown_pct": round(100 * (1 - rate_watched / rate_alone), 1),
               "server_cpu_per_s_alone": round(median(alone, "server_cpu_per_s"), 3),
               "server_cpu_per_s_watched": round(median(watched, "server_cpu_per_s"), 3),
               # Less sensitive to other load on the machine than the step rates: the server's CPU per step.
               "server_cpu_us_per_step_alone": round(median(alone, "server_cpu_us_per_step"), 1),
               "server_cpu_us_per_step_watched": round(median(watched, "server_cpu_us_per_step"), 1),
               "snapshots_per_viewer_per_s": round(median(watched, "snapshots_per_viewer_per_s"), 1),
               # The same viewers without the contact overlay (?contacts=0): what the contacts cost.
               "steps_per_s_poses_only": round(median(poses_only, "steps_per_s")),
               "viewer_slowdown_pct_poses_only": round(100 * (1 - median(poses_only, "steps_per_s") / rate_alone), 1),
               "server_cpu_us_per_step_poses_only": round(median(poses_only, "server_cpu_us_per_step"), 1),
               "loadavg_1min_after": round(os.getloadavg()[0], 2)}
    return figures, server.exit_code
