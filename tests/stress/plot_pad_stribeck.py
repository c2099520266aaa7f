"""Plots the tactile pad's Stribeck curve from the CSV of TactileContactTest.DISABLED_WriteStribeckCurve.

    build/venv/bin/python tests/stress/plot_pad_stribeck.py build/pad-stribeck.csv docs/tactile-stribeck.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path: str, png_path: str) -> None:
    with open(csv_path) as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    speed = [r["speed_m_s"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogx(speed, [r["lugre_n"] for r in rows], "-", label="LuGre steady state g(v) + c_t v")
    ax.semilogx(speed, [r["force_n"] for r in rows], "o", label="simulated: box dragged over the pad")
    ax.set_xlabel("sliding speed (m/s)")
    ax.set_ylabel("friction force on the pad (N)")
    ax.set_title("DSA 9205 pad, 9.81 N load: the Stribeck curve")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    worst = max(abs(r["force_n"] / r["lugre_n"] - 1) for r in rows)
    print(f"{png_path}: {len(rows)} speeds, worst relative error {worst:.2e}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
