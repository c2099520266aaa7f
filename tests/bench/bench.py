"""Dispatcher of tests/bench/run: runs the named benchmark (or all) and prints one JSON line per benchmark."""
import datetime
import importlib
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import commit, load_avg_1m, log, machine  # noqa: E402

BENCHMARKS = ["scene_ops", "upload", "watch", "physics", "tactile", "grasp", "shape", "viewers", "gateway", "motion", "crash", "rpc", "import", "mbm", "record", "batch", "fleet"]
# A benchmark whose module has another name ("record": tests/bench/recording.py).
MODULES = {"record": "recording"}


def run_one(name: str) -> bool:
    """Runs one benchmark module's run() -> (figures, server exit code); prints its JSON; True if all went well."""
    log(f"== {name}")
    started, load_start = time.perf_counter(), load_avg_1m()
    try:
        figures, server_exit = importlib.import_module(MODULES.get(name, name)).run()
    except Exception as err:  # one broken benchmark must not hide the others' figures
        log(f"{name}: failed: {type(err).__name__}: {err}")
        return False
    # The protocol (docs/benchmarks.md): every benchmark reports the machine's load, wall-clock figures move with
    # it. A benchmark that samples it itself (around its timed parts) keeps its own key.
    figures.setdefault("load_avg_1m", [load_start, load_avg_1m()])
    result = {"benchmark": name, **figures, "server_exit_code": server_exit,
              "run_s": round(time.perf_counter() - started, 1),
              "date": datetime.datetime.now(datetime.timezone.utc).date().isoformat(),
              "machine": machine(), **commit()}
    print(json.dumps(result), flush=True)
    return server_exit == 0


def main(argv) -> int:
    if len(argv) != 1 or argv[0] not in BENCHMARKS + ["all"]:
        log(f"usage: tests/bench/run NAME   (NAME: {', '.join(BENCHMARKS)} or all)")
        return 2
    names = BENCHMARKS if argv[0] == "all" else argv
    ok = [run_one(name) for name in names]
    return 0 if all(ok) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
