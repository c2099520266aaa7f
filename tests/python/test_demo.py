"""The demo runs against the real server and prints the scene."""
import subprocess
import sys
from pathlib import Path

import pytest

DEMO = Path(__file__).resolve().parents[2] / "clients" / "python" / "examples" / "demo.py"


def test_demo_runs(server, tmp_path):
    result = subprocess.run([sys.executable, str(DEMO), "--server", server.address, "--http", server.http_url,
                             "--out", str(tmp_path)], capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, f"demo failed:\n{result.stdout}\n{result.stderr}"
    for expected in ("pg70", "cube_5cm", "pg70/finger_left_joint", "14 rows x 6 cols", "5 bodies, 1 robot",
                     "cube at rest on the table", "PG70 closed", "held by friction",
                     "tactile work cycle", "approach > grasp > lift > hold > move_down > release > done",
                     "peak sums", "cube lifted", "put back", "added as 'cube_seen'", "hardware gateway", "robotiq-tcp moved to 30.0 mm",
                     "refused: INVALID_ARGUMENT", "e-stop: ", "beside its simulated twin", "surprise peak",
                     "pick and place (KR 5 + PG70", "from the goal (tolerance 10 mm, 10°): placed",
                     "arm path around a post (rrt_connect)", "arm path around a post (ompl_rrt_connect)",
                     "3 replicas behind HAProxy", "r1 killed (-9)", "UNAVAILABLE (its scenes)",
                     "restarted on its data dir", "moved by archive", "(0 failed)"):
        assert expected in result.stdout, f"{expected!r} missing from:\n{result.stdout}"
    pytest.importorskip("matplotlib")
    for name in ("demo-work-cycle.png", "demo-work-cycle-peak-100pct.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert str(tmp_path / name) in result.stdout


def test_demo_fails_without_server():
    result = subprocess.run([sys.executable, str(DEMO), "--server", "127.0.0.1:9"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode != 0 and "UNAVAILABLE" in result.stderr
