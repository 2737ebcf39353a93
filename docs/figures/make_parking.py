"""Figures and tables of docs/parking.md: ``python docs/figures/make_parking.py`` (writes docs/figures/parking/).

- thesis-9.1.png, thesis-9.2.png: the plans of Tables 9.1 and 9.2;
- maneuvers-vs-ratio.png: manoeuvres against the length ratio (9.37) for example 1 (the thesis's Fig. 9.30);
- thesis-9.1.gif: the executed plan of example 1, animated;
- comparison.md: the thesis planner against Reeds-Shepp (rsplan) on the same slots (printed too).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from wmrkit.parking import length_ratio, plan_parking
from wmrkit.parking.compare import compare
from wmrkit.parking.execute import execute_plan
from wmrkit.parking.plot import animate_plan, save_plan_figure
from wmrkit.parking.problem import load_problem

OUT = Path(__file__).parent / "parking"


def plans() -> None:
    for name in ("thesis-9.1", "thesis-9.2"):
        p = load_problem(name)
        plan = plan_parking(p.vehicle, p.space)
        save_plan_figure(plan, OUT / f"{name}.png", execute_plan(plan))
    p = load_problem("thesis-9.1")
    plan = plan_parking(p.vehicle, p.space)
    animate_plan(plan, OUT / "thesis-9.1.gif", max_frames=90, fps=12)


def ratio_figure() -> list[tuple[float, float, int, int]]:
    p = load_problem("thesis-9.1")
    rows = []
    fig = Figure(figsize=(7, 4))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for dx2, style, label in ((0.70, "o-", "dx2 = 0.70 m (Table 9.1: the car's side on the parked cars' line)"),
                              (0.90, "s--", "dx2 = 0.90 m (20 cm of clearance in the pass)")):
        xs, ys, bad = [], [], []
        for k in range(0, 36):
            h = 2.85 + 0.05 * k
            slot = replace(p.space, H=h, dx2=dx2)
            plan = plan_parking(p.vehicle, slot)
            r = 100 * length_ratio(p.vehicle, slot)  # in percent, as Fig. 9.30
            if plan.feasible:
                xs.append(r)
                ys.append(plan.maneuvers)
            else:
                bad.append(r)
            if dx2 == 0.90:
                rows.append((h, r, plan.maneuvers, plan.feasible))
        ax.plot(xs, ys, style, ms=4, label=label)
        if bad:
            ax.plot(bad, [0] * len(bad), "x", color=ax.lines[-1].get_color(), label=f"no plan (dx2 = {dx2} m)")
    ax.axvline(30, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("length ratio (9.37) [%]")
    ax.set_ylabel("manoeuvres")
    ax.set_title("Example 1 (Table 9.1), slot length H varied: Fig. 9.30", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "maneuvers-vs-ratio.png", dpi=120)
    return rows


def comparison(repeat: int = 7) -> str:
    """The comparison table, each planner timed over `repeat` runs (tests/parking/test_docs.py: one)."""
    p1, p2 = load_problem("thesis-9.1"), load_problem("thesis-9.2")
    cases = [("Table 9.1", p1.vehicle, p1.space), ("Table 9.2", p2.vehicle, p2.space),
             ("9.1, H = 3.0 m, dx2 = 0.9 m", p1.vehicle, replace(p1.space, H=3.0, dx2=0.9)),
             ("9.1, H = 4.0 m", p1.vehicle, replace(p1.space, H=4.0)),
             ("9.1, H = 6.0 m, dx2 = 1.2 m", p1.vehicle, replace(p1.space, H=6.0, dx2=1.2)),
             ("9.2, H = 4.0 m", p2.vehicle, replace(p2.space, H=4.0))]
    lines = ["| slot | planner | success | path [m] | direction changes | planning time [ms] | colliding poses |",
             "|---|---|---|---|---|---|---|"]
    for name, car, slot in cases:
        for o in compare(car, slot, repeat=repeat):
            length = "-" if math.isnan(o.length) else f"{o.length:.2f}"
            lines.append(f"| {name} | {o.planner} | {'yes' if o.success else 'no'} | {length} | {o.cusps} | "
                         f"{o.time_ms:.3f} | {o.colliding} |")
    return "\n".join(lines)


if __name__ == "__main__":
    OUT.mkdir(exist_ok=True)
    plans()
    for h, r, n, ok in ratio_figure():
        print(f"H = {h:.2f} m  ratio {r:5.1f} %  manoeuvres {n if ok else '-'}")
    table = comparison()
    (OUT / "comparison.md").write_text(table + "\n", encoding="utf-8")
    print(table)
