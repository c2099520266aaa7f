"""The demo runs against the real server and prints the scene."""
import subprocess
import sys
from pathlib import Path

DEMO = Path(__file__).resolve().parents[2] / "clients" / "python" / "examples" / "demo.py"


def test_demo_runs(server):
    result = subprocess.run([sys.executable, str(DEMO), "--server", server.address, "--http", server.http_url],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, f"demo failed:\n{result.stdout}\n{result.stderr}"
    for expected in ("pg70", "cube_5cm", "pg70/finger_left_joint", "14 rows x 6 cols", "5 bodies, 1 robot",
                     "cube at rest on the table", "PG70 closed", "held by friction"):
        assert expected in result.stdout, f"{expected!r} missing from:\n{result.stdout}"


def test_demo_fails_without_server():
    result = subprocess.run([sys.executable, str(DEMO), "--server", "127.0.0.1:9"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode != 0 and "UNAVAILABLE" in result.stderr
