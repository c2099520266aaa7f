"""physics "textbook" figures: every case of tests/physics/textbook.py on every engine at every time step.

Engines: the server's three (SimulationParams.engine = graspsim, mujoco, bullet: one API, one scene description,
the same reads through gRPC), and, as a cross-check of the server's MuJoCo and Bullet backends, MuJoCo's own
Python wheel and PyBullet on the same scenes (tests/physics/peers.py). Each case's error is deterministic (one
run per case, engine and dt); the run time of a case (wall seconds, gRPC reads included) is the median of
REPEATS runs at dt = 1 ms. A case "converges" when its error never rises by more than textbook.ERROR_FLOOR as
dt falls (2 → 0.1 ms). Energy drift: |E(end) − E(0)| / E over the conservative cases' 10 s, at 1 ms.
"""
import math
import statistics
import sys
import time
from pathlib import Path

from _harness import REPO, log

sys.path.insert(0, str(REPO / "tests" / "physics"))
import textbook  # noqa: E402
from graspsim_engine import GraspsimEngine  # noqa: E402
from peers import BulletEngine, MujocoEngine  # noqa: E402

SERVER_ENGINES = ("graspsim", "mujoco", "bullet")
REPEATS = 5
PLOT = REPO / "docs" / "physics-textbook.png"


def _grid(factory):
    errors, drift = {}, {}
    for case in textbook.CASES:
        outcomes = textbook.run_case(case, factory)
        errors[case.name] = {dt: outcomes[dt].error for dt in textbook.TIME_STEPS}
        if case.conservative:
            drift[case.name] = outcomes[1e-3].energy_drift
    return errors, drift


class _Counting:
    """An engine that counts the steps it is asked for (steps/s of a case)."""

    def __init__(self, engine):
        self.engine, self.steps = engine, 0

    def __getattr__(self, name):
        return getattr(self.engine, name)

    def step(self, steps):
        self.steps += steps
        self.engine.step(steps)


def _run_time(case, factory):
    """Median, min and max wall seconds of REPEATS runs at 1 ms, and the steps one run takes."""
    times, counted = [], []
    for _ in range(REPEATS):
        def counting():
            counted.append(_Counting(factory()))
            return counted[-1]
        t0 = time.perf_counter()
        case.run(counting, 1e-3)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times), max(times), sum(c.steps for c in counted) // REPEATS


def _peer_error(case, factory):
    """A cross-check's error at 1 ms, or None where the wheel adapters have no joint drives (the held box)."""
    try:
        return case.run(factory, 1e-3).error
    except NotImplementedError:
        return None


def _within(errors):
    return sum(1 for e in errors.values() if e[1e-3] <= 0.01)


def _plot(errors_by_engine, times_by_engine):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for engine, errors in errors_by_engine.items():
        # One point per dt: the median error over the cases against the summed run time of all cases at that dt
        # (run times scale with 1/dt from the 1 ms medians).
        total_1ms = sum(times_by_engine[engine].values())
        xs = [total_1ms * 1e-3 / dt for dt in textbook.TIME_STEPS]
        ys = [max(statistics.median(e[dt] for e in errors.values()), 1e-9) for dt in textbook.TIME_STEPS]
        ax.loglog(xs, ys, marker="o", label=engine)
        for x, y, dt in zip(xs, ys, textbook.TIME_STEPS):
            ax.annotate(f"{dt * 1e3:g} ms", (x, y), fontsize=7, textcoords="offset points", xytext=(3, 3))
    ax.set_xlabel("run time of the textbook cases, s (through gRPC; 1 ms medians scaled by 1/dt)")
    ax.set_ylabel("median relative error over the cases")
    ax.set_title("textbook cases: error against run time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(PLOT, dpi=110)
    plt.close(fig)


def textbook_figures(client) -> dict:
    errors_by_engine, drift_by_engine, times_by_engine, spreads, steps = {}, {}, {}, {}, {}
    factories = {name: (lambda name=name: GraspsimEngine(client, name)) for name in SERVER_ENGINES}
    for name, factory in factories.items():
        log(f"textbook: {len(textbook.CASES)} cases x {len(textbook.TIME_STEPS)} steps on the server's {name}")
        errors_by_engine[name], drift_by_engine[name] = _grid(factory)
        times_by_engine[name], spreads[name], steps[name] = {}, {}, {}
        for case in textbook.CASES:
            median, low, high, count = _run_time(case, factory)
            times_by_engine[name][case.name], spreads[name][case.name], steps[name][case.name] = median, (low, high), count
    peers = {}
    for name, factory in (("mujoco_wheel", MujocoEngine), ("pybullet", BulletEngine)):
        log(f"textbook: cross-check on {name}")
        peers[name] = {c.name: _peer_error(c, factory) for c in textbook.CASES}
    _plot(errors_by_engine, times_by_engine)

    ours = errors_by_engine["graspsim"]
    table = {}
    for case in textbook.CASES:
        row = {}
        for engine in SERVER_ENGINES:
            row[engine] = {"error_by_dt_ms": {f"{dt * 1e3:g}": float(f"{errors_by_engine[engine][case.name][dt]:.3g}")
                                              for dt in textbook.TIME_STEPS},
                           "converging": textbook.converging([errors_by_engine[engine][case.name][dt]
                                                              for dt in textbook.TIME_STEPS]),
                           "run_s_median_1ms": round(times_by_engine[engine][case.name], 3),
                           "run_s_min_max_1ms": [round(t, 3) for t in spreads[engine][case.name]],
                           "steps_per_s_through_grpc_1ms": round(steps[engine][case.name] /
                                                                 times_by_engine[engine][case.name])}
        for peer, errs in peers.items():
            error = errs[case.name]
            row[peer] = {"error_1ms": None if error is None else float(f"{error:.3g}")}
        table[case.name] = row
    drifts = [d for d in drift_by_engine["graspsim"].values() if not math.isnan(d)]
    le_peers = [c.name for c in textbook.CASES
                if all(ours[c.name][1e-3] <= errors_by_engine[e][c.name][1e-3] + textbook.ERROR_FLOOR
                       for e in ("mujoco", "bullet"))]
    return {
        "textbook_cases": len(textbook.CASES),
        "textbook_within_1pct": _within(ours),
        "textbook_converging": sum(table[c]["graspsim"]["converging"] for c in table),
        "mujoco_within_1pct": _within(errors_by_engine["mujoco"]),
        "bullet_within_1pct": _within(errors_by_engine["bullet"]),
        "mujoco_wheel_within_1pct": sum(1 for e in peers["mujoco_wheel"].values() if e is not None and e <= 0.01),
        "pybullet_within_1pct": sum(1 for e in peers["pybullet"].values() if e is not None and e <= 0.01),
        "wheel_cross_check_cases": sum(1 for e in peers["pybullet"].values() if e is not None),
        "textbook_ours_le_peers_1ms": len(le_peers),
        "textbook_ours_above_a_peer_1ms": sorted(set(table) - set(le_peers)),
        "energy_drift_pct_max": round(100 * max(drifts), 5),
        "textbook_run_s_1ms": {e: round(sum(times_by_engine[e].values()), 2) for e in SERVER_ENGINES},
        "textbook_plot": str(PLOT.relative_to(REPO)),
        "textbook": table,
    }
