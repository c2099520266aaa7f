"""Tables and plot of the stability sweep: reads graspsim_stress's JSON lines, writes an SVG map of the stable
region over k × dt per integrator, and prints (or writes into a Markdown file between the markers
<!-- stress-tables:begin --> and <!-- stress-tables:end -->) the tables of docs/physics-stability.md.

usage: report.py SWEEP.jsonl SVG [MARKDOWN]

Plain Python (no matplotlib in build/venv): the SVG is written by hand.
"""
import json
import re
import sys
from collections import defaultdict

INTEGRATORS = ["linearly_implicit_euler", "semi_implicit_euler", "velocity_verlet"]
SHORT = {"linearly_implicit_euler": "lin. implicit Euler", "semi_implicit_euler": "semi-implicit Euler",
         "velocity_verlet": "velocity Verlet"}
SCENARIOS = ["tip_on_table", "tip_on_object", "slide"]


def fmt(x):
    """1e-05, 3e-03 … as the grid's round numbers."""
    return f"{x:.0e}".replace("e-0", "e-").replace("e+0", "e")


def largest_stable(runs):
    """The largest dt below which every grid dt is stable, '<' the smallest if none; '*' marks a stable dt above
    an unstable one (not monotone)."""
    by_dt = sorted(runs, key=lambda r: r["dt"])
    best = None
    for r in by_dt:
        if not r["stable"]:
            break
        best = r["dt"]
    text = fmt(best) if best else "<" + fmt(by_dt[0]["dt"])
    first_bad = next((i for i, r in enumerate(by_dt) if not r["stable"]), len(by_dt))
    if any(r["stable"] for r in by_dt[first_bad:]):
        text += "*"
    return best, text


def table(rows, grid, row_key, row_label, columns):
    """Markdown: one row per integrator × row_key value, one column per (scenario, mass)."""
    groups = defaultdict(list)
    for r in rows:
        if r["grid"] == grid:
            groups[(r["integrator"], r[row_key], r["scenario"], r["mass"])].append(r)
    values = sorted({r[row_key] for r in rows if r["grid"] == grid})
    head = "| integrator | " + row_label + " | " + " | ".join(f"{s} {m:g} kg" for s, m in columns) + " |"
    out = [head, "|" + "---|" * (2 + len(columns))]
    for integrator in INTEGRATORS:
        for v in values:
            cells = [largest_stable(groups[(integrator, v, s, m)])[1] if groups[(integrator, v, s, m)] else "–"
                     for s, m in columns]
            out.append(f"| {SHORT[integrator]} | {v:g} | " + " | ".join(cells) + " |")
    return "\n".join(out)


def summary(rows, meta):
    reasons = defaultdict(int)
    for r in rows:
        reasons[r["reason"] or "stable"] += 1
    breaches = [r for r in rows if r["contract"]]
    lines = [f"{len(rows)} runs ({meta.get('seconds', 0):.0f} s on {meta.get('jobs', '?')} threads): "
             + ", ".join(f"{k} {v}" for k, v in sorted(reasons.items())) + f"; contract breaches: {len(breaches)}."]
    for r in breaches[:10]:
        lines.append(f"- breach: {r['scenario']} {r['integrator']} dt={r['dt']} k={r['k']}: {r['contract']}")
    return "\n".join(lines)


def tables(rows, meta):
    masses = sorted({r["mass"] for r in rows if r["grid"] == "main"})
    main_cols = [(s, m) for s in SCENARIOS for m in masses]
    parts = ["**Summary.** " + summary(rows, meta),
             "**Largest stable time step (s) by contact stiffness k** (grid `main`: c = 10 N s/m, σ0 = 1e4 N/m, "
             "σ1 = 30 N s/m):", table(rows, "main", "k", "k (N/m)", main_cols)]
    for grid, key, label, scen in [("damping", "c", "c (N s/m)", ["tip_on_table", "tip_on_object"]),
                                   ("sigma0", "sigma0", "σ0 (N/m)", ["slide"]),
                                   ("sigma1", "sigma1", "σ1 (N s/m)", ["slide"])]:
        grid_rows = [r for r in rows if r["grid"] == grid]
        if not grid_rows:
            continue
        cols = [(s, m) for s in scen for m in sorted({r["mass"] for r in grid_rows})]
        parts += [f"**Largest stable time step (s) by {label}** (grid `{grid}`, k = 1e4 N/m, the other "
                  "parameters at their defaults):", table(rows, grid, key, label, cols)]
    return "\n\n".join(parts)


def svg(rows, path):
    """Three heat maps (one per integrator) over k × dt of the main grid: each cell coloured by the share of its
    scenario × mass runs that are stable (red none … green all), with the count written in it."""
    ks = sorted({r["k"] for r in rows if r["grid"] == "main"})
    dts = sorted({r["dt"] for r in rows if r["grid"] == "main"})
    cells = defaultdict(list)
    for r in rows:
        if r["grid"] == "main":
            cells[(r["integrator"], r["k"], r["dt"])].append(r["stable"])
    cw, ch, left, top, gap = 52, 30, 70, 40, 40
    pw = cw * len(ks)
    w, h = left + 3 * pw + 2 * gap + 20, top + ch * len(dts) + 60
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" '
           'font-size="11"><rect width="100%" height="100%" fill="white"/>']
    for p, integrator in enumerate(INTEGRATORS):
        x0 = left + p * (pw + gap)
        out.append(f'<text x="{x0 + pw / 2}" y="{top - 12}" text-anchor="middle" font-size="13">{SHORT[integrator]}</text>')
        for i, k in enumerate(ks):
            out.append(f'<text x="{x0 + (i + 0.5) * cw}" y="{top + ch * len(dts) + 14}" text-anchor="middle">{fmt(k)}</text>')
            for j, dt in enumerate(reversed(dts)):
                stable = cells.get((integrator, k, dt), [])
                share = sum(stable) / len(stable) if stable else 0
                red, green = int(215 - 170 * share), int(60 + 140 * share)
                out.append(f'<rect x="{x0 + i * cw}" y="{top + j * ch}" width="{cw}" height="{ch}" '
                           f'fill="rgb({red},{green},70)" stroke="white"/>')
                out.append(f'<text x="{x0 + (i + 0.5) * cw}" y="{top + (j + 0.5) * ch + 4}" text-anchor="middle" '
                           f'fill="white">{sum(stable)}/{len(stable)}</text>')
                if p == 0 and i == 0:
                    out.append(f'<text x="{x0 - 6}" y="{top + (j + 0.5) * ch + 4}" text-anchor="end">{fmt(dt)}</text>')
        out.append(f'<text x="{x0 + pw / 2}" y="{top + ch * len(dts) + 30}" text-anchor="middle">k (N/m)</text>')
    out.append(f'<text x="14" y="{top + ch * len(dts) / 2}" transform="rotate(-90 14 {top + ch * len(dts) / 2})" '
               'text-anchor="middle">time step (s)</text>')
    out.append(f'<text x="{left}" y="{h - 8}">cells: stable runs of the 9 (scenario × mass) cases: fingertip on table, '
               'fingertip on 3 kg object, slide; 0.05, 0.3, 3 kg</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    rows, meta = [], {}
    with open(argv[0]) as f:
        for line in f:
            record = json.loads(line)
            if record.get("summary"):
                meta = record
            else:
                rows.append(record)
    svg(rows, argv[1])
    text = tables(rows, meta)
    if len(argv) == 3:
        doc = open(argv[2]).read()
        begin, end = "<!-- stress-tables:begin -->", "<!-- stress-tables:end -->"
        if begin not in doc or end not in doc:
            print(f"{argv[2]}: markers {begin} … {end} not found", file=sys.stderr)
            return 1
        doc = re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: f"{begin}\n{text}\n{end}", doc, flags=re.S)
        open(argv[2], "w").write(doc)
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
