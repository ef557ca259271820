"""robot_survey from Python: the dataset, Table 2, a figure, a walk and the gap diagnosis.

    python -m venv .venv && . .venv/bin/activate
    pip install "./python[test]"
    python examples/python_quickstart.py --out /tmp/quickstart

Writes mass-vs-leg-length.png into --out (default: the working directory) and prints the
paper's Table 2 exponents, a Mugatu walk and the diagnosis of the published hardware trials
(dataset/trials/published.csv). CI runs it (.ci/run).
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402

import robot_survey as rs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("."), help="folder for the figure")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # 1. The dataset: one row per robot, typed columns, sources.
    robots = rs.dataset()
    info = rs.dataset_info()
    fitted = robots.filter(pl.col("fit"))
    print(f"dataset {info['version']}: {robots.height} robots, {fitted.height} fitted")

    # 2. The paper's Table 2 (release 1.0.0 is the table the paper used) and the live fits.
    paper = rs.fit(release="1.0.0").filter(pl.col("y") == "mass", pl.col("x") == "leg_length")
    live = rs.fit().filter(pl.col("y") == "mass", pl.col("x") == "leg_length")
    print("m ∝ L^b        paper (1.0.0)       live")
    for p, q in zip(paper.iter_rows(named=True), live.iter_rows(named=True)):
        print(
            f"  {p['class']:<12} b = {p['b']:.2f} (n {p['n']:>2})   "
            f"b = {q['b']:.2f} [{q['b_ci_lo']:.2f}, {q['b_ci_hi']:.2f}] (n {q['n']})"
        )

    # 3. Mass vs leg length, each class with its fitted power law.
    fig, ax = plt.subplots(figsize=(7, 5))
    for law in live.filter(pl.col("class") != "all").iter_rows(named=True):
        pts = fitted.filter(pl.col("class") == law["class"])
        (dots,) = ax.plot(pts["leg_length_m"], pts["mass_kg"], "o", alpha=0.7,
                          label=f"{law['class']} (b = {law['b']:.2f})")
        lo, hi = pts["leg_length_m"].min(), pts["leg_length_m"].max()
        xs = [lo * (hi / lo) ** (k / 50) for k in range(51)]
        ax.plot(xs, [law["a"] * x ** law["b"] for x in xs], color=dots.get_color())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("leg length L [m]")
    ax.set_ylabel("mass m [kg]")
    ax.set_title(f"Legged robots, dataset {info['version']}: m = a·L^b per class")
    ax.legend(fontsize=8)
    fig.tight_layout()
    figure = args.out / "mass-vs-leg-length.png"
    fig.savefig(figure, dpi=120)
    print(f"wrote {figure}")

    # 4. A designer query and a walk of the Mugatu design.
    p = rs.predict(1.0, cls="lower-biped", from_="design:mugatu")
    mass = p.quantities.filter(pl.col("quantity") == "mass").row(0, named=True)
    print(f"a 1 m lower biped: {mass['mean']:.1f} kg (95 % PI "
          f"{mass['prediction_interval_lo']:.1f}–{mass['prediction_interval_hi']:.1f} kg); "
          f"Mugatu's hip needs {p.torque['torques'][0]['required_nm']:.1f} N·m there")
    w = rs.walk("mugatu")
    froude = w.velocity_mps / math.sqrt(9.81 * w.leg_length_m)
    print(f"mugatu walks at {w.velocity_mps:.4f} m/s (v/√(gL) = {froude:.3f}), "
          f"{w.trajectory.height} trajectory samples")

    # 5. The published hardware trials against the simulator.
    t0 = time.perf_counter()
    d = rs.gap.diagnose(ROOT / "dataset" / "trials" / "published.csv")
    print(f"gap diagnosis of the published trials ({time.perf_counter() - t0:.0f} s):")
    print(f"  {d.summary}")
    print(f"  {d.statement}")
    for name, p in list(d.probabilities.items())[:3]:
        print(f"  P({name}) = {p:.3f}")
    print(d.where.select("metric", "n", "rms_z", "mean_relative_pct", "significant"))


if __name__ == "__main__":
    main()
