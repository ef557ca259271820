#!/usr/bin/env python3
"""Does an effect change Drake's logged cycles the way it changes ours?

For each Drake trials file with an effect and robot logs (tests/golden/drake/gap-lagged-logs),
each logged trial's cycle of every signal (roll, pitch, yaw, hip torque) is reduced to its
Fourier coefficients over the steady drive cycles (cycles 6-15, the mean and 12 harmonics,
yaw with a trend: as src/gap/waveform.rs does). Against Drake's own no-effect logs, the
change the effect makes in Drake is compared with the change the same effect makes in this
project's simulator (`survey gap synth --expected --logs` at the same conditions):

* r: the correlation of the two changes' harmonic coefficients (1: the same shape);
* size: |change in ours| / |change in Drake|;
* and, for the no-effect logs, how far the engines' cycles are apart (shape: |R - N| / |R|;
  amplitude: |rms_R - rms_N| / rms_R, the discrepancy `gap separate --reference` charges).

A reference of the same robot without the effect can carry a change onto the model only
where r is near 1 and the size near 1. Usage (repository root; numpy needed, e.g. the
Drake harness's pinned environment, tools/drake/requirements.txt):

    python tools/gap-drake-cycles.py [path/to/survey] [drake trials folder]
"""
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

SURVEY = sys.argv[1] if len(sys.argv) > 1 else "target/release/survey"
D = Path(sys.argv[2] if len(sys.argv) > 2 else "tests/golden/drake/gap-lagged-logs")
CONDITIONS = next(iter(sorted(D.glob("conditions-*.csv"))))
SIGNALS = ["roll_deg", "pitch_deg", "yaw_deg", "hip_torque_nm"]
HARMONICS = 12
SETTLE = 6


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(l for l in f if not l.startswith("#")))


def coefficients(log_path, f_hz):
    """{signal: [a1, b1, ..., aH, bH]} of the log's steady cycles (means and yaw's trend
    fitted and left out)."""
    r = rows(log_path)
    t = np.array([float(x["t_s"]) for x in r])
    phase = t * f_hz
    keep = (phase >= SETTLE) & (phase < np.floor(phase.max()))
    ph = phase[keep]
    cols = [np.ones(ph.size)]
    for k in range(1, HARMONICS + 1):
        cols += [np.cos(2 * np.pi * k * ph), np.sin(2 * np.pi * k * ph)]
    cols.append(ph - ph.mean())
    a = np.array(cols).T
    out = {}
    for s in SIGNALS:
        y = np.array([float(x[s]) for x in r])[keep]
        c, *_ = np.linalg.lstsq(a, y, rcond=None)
        out[s] = c[1:-1]
    return out


def synth_logs(tmp, effect):
    """Our logs at the conditions (design paths made absolute), noise-free summaries."""
    cond = tmp / "conditions.csv"
    with open(CONDITIONS) as f:
        text = f.read()
    design_dir = CONDITIONS.resolve().parent
    lines = text.splitlines()
    head = lines[0].split(",")
    di = head.index("design")
    fixed = [lines[0]]
    for line in lines[1:]:
        cells = line.split(",")
        if cells[di].endswith(".toml"):
            cells[di] = str((design_dir / cells[di]).resolve())
        fixed.append(",".join(cells))
    cond.write_text("\n".join(fixed) + "\n")
    name = "none" if effect is None else effect.replace("=", "-")
    cmd = [SURVEY, "gap", "synth", "--conditions", str(cond), "--expected", "--noise", "0.03",
           "--logs", str(tmp / f"logs-{name}"), "--sensor-noise-deg", "1e-9",
           "--sensor-noise-torque", "1e-9", "--out", str(tmp / f"{name}.csv")]
    if effect is not None:
        cmd += ["--effect", effect]
    subprocess.run(cmd, check=True, capture_output=True)
    return tmp / f"logs-{name}"


def main():
    frequency = {r["label"]: float(r["frequency_hz"]) for r in rows(CONDITIONS)}
    none = {r["label"]: r["trajectory"] for r in rows(D / "trials-none.csv") if r["trajectory"]}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        ours_none = synth_logs(tmp, None)
        print("engines apart, no effect (shape | amplitude), per signal:")
        for label, rel in none.items():
            a = coefficients(D / rel, frequency[label])
            b = coefficients(ours_none / f"{label}.csv", frequency[label])
            cells = []
            for s in SIGNALS:
                ra, rb = np.linalg.norm(a[s]), np.linalg.norm(b[s])
                cells.append(f"{s} {np.linalg.norm(a[s] - b[s]) / ra:.2f} | {abs(ra - rb) / ra:.3f}")
            print(f"  {label}: " + "; ".join(cells))
        print("effect: per logged trial and signal, r (change in ours vs Drake's) and size:")
        for p in sorted(D.glob("trials-*.csv")):
            if p.stem == "trials-none":
                continue
            effect = "=".join(p.stem[len("trials-"):].rsplit("-", 1))
            ours = synth_logs(tmp, effect)
            for r in rows(p):
                if not r["trajectory"]:
                    continue
                label, f_hz = r["label"], frequency[r["label"]]
                dk = coefficients(D / r["trajectory"], f_hz)
                dn = coefficients(D / none[label], f_hz)
                ok = coefficients(ours / f"{label}.csv", f_hz)
                on = coefficients(ours_none / f"{label}.csv", f_hz)
                cells = []
                for s in SIGNALS:
                    x, y = dk[s] - dn[s], ok[s] - on[s]
                    nx, ny = np.linalg.norm(x), np.linalg.norm(y)
                    rr = float(x @ y / (nx * ny)) if nx > 0 and ny > 0 else float("nan")
                    cells.append(f"{s} r {rr:+.3f} size {ny / nx if nx > 0 else float('nan'):.2f}")
                print(f"  {effect} {label}: " + "; ".join(cells))


if __name__ == "__main__":
    main()
