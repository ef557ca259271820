#!/usr/bin/env python3
"""Does an effect change Drake's walks the way it changes ours?

For each Drake trials file with an effect (tests/golden/drake/gap), the change it makes
against Drake's own no-effect trials, and the change the same effect makes in this
project's simulator (`survey gap synth --expected` at the same conditions), each in units
of 3 % of the metric, over the 9 conditions x 7 metrics. If the changes agreed, a
diagnosis could subtract the engine difference (a baseline of the same robot without the
effect) and name the effect on top of it. Usage (repository root, release build):

    python3 tools/gap-drake-deltas.py [path/to/survey] [drake trials folder]

The folder (default tests/golden/drake/gap, SAP) holds one conditions-*.csv and the
trials-*.csv made from it; tests/golden/drake/gap-lagged holds Drake-Lagged's.
"""
import csv
import math
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

SURVEY = sys.argv[1] if len(sys.argv) > 1 else "target/release/survey"
D = Path(sys.argv[2] if len(sys.argv) > 2 else "tests/golden/drake/gap")
CONDITIONS = next(iter(sorted(D.glob("conditions-*.csv"))))
METRICS = ["velocity_mps", "step_frequency_hz", "roll_pp_deg", "pitch_pp_deg",
           "yaw_pp_deg", "peak_torque_nm", "cot"]
# Every Drake trials file with an effect, named trials-<effect>-<value>.csv as the
# benchmark reads them: the effect and its value come from the name.
CASES = [(p.stem[len("trials-"):], "=".join(p.stem[len("trials-"):].rsplit("-", 1)))
         for p in sorted(D.glob("trials-*.csv")) if p.stem != "trials-none"]


def load(path):
    with open(path) as f:
        return {r["label"]: r for r in csv.DictReader(l for l in f if not l.startswith("#"))}


def synth(out, effect=None):
    # the design of the conditions' first row (a bundled name or a path relative to them)
    with open(CONDITIONS) as f:
        first = next(csv.DictReader(l for l in f if not l.startswith("#")))["design"]
    design = str(CONDITIONS.parent / first) if first.endswith(".toml") else first
    cmd = [SURVEY, "gap", "synth", "--design", design, "--conditions",
           str(CONDITIONS), "--noise", "0.03", "--expected", "--out", out]
    if effect:
        cmd += ["--effect", effect]
    subprocess.run(cmd, check=True, capture_output=True)
    return load(out)


def dz(with_effect, without, label, metric):
    a, b = float(with_effect[label][metric]), float(without[label][metric])
    return (a - b) / (0.03 * abs(b)) if b != 0 else float("nan")


with tempfile.TemporaryDirectory() as tmp:
    drake_none = load(D / "trials-none.csv")
    sim_none = synth(f"{tmp}/none.csv")
    print("| Drake case | r (Drake change vs ours) | Drake changes > 2·3 % | same sign where both > 2·3 % |")
    print("|---|---:|---:|---:|")
    for drake_key, effect in CASES:
        drake = load(D / f"trials-{drake_key}.csv")
        sim = synth(f"{tmp}/e.csv", effect)
        xs, ys, agree, both = [], [], 0, 0
        for label in drake_none:
            for m in METRICS:
                a, b = dz(drake, drake_none, label, m), dz(sim, sim_none, label, m)
                if math.isfinite(a) and math.isfinite(b):
                    xs.append(a)
                    ys.append(b)
                    if abs(a) > 2 and abs(b) > 2:
                        both += 1
                        agree += (a > 0) == (b > 0)
        r = statistics.correlation(xs, ys)
        big = sum(1 for a in xs if abs(a) > 2)
        print(f"| {drake_key} | {r:.2f} | {big} / {len(xs)} | {agree} / {both} |")
