"""MuJoCo peer of the walker simulator: walks a design's MJCF export and writes the trajectory
CSV that `survey sim analyze` (and `survey sim crosscheck`) read.

    python tools/mujoco/harness.py walk dataset/walkers/reference/mugatu-ref.toml \\
        --frequency 1.4 --duration 25 --trajectory out.csv --json out.json
    python tools/mujoco/harness.py goldens --out tests/golden/mujoco/walks/

The design is exported by the project's binary (`survey sim export --format mjcf`; $SURVEY or
target/{release,debug}/survey), so MuJoCo runs exactly the file a user would get.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys

import mujoco
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import walker  # noqa: E402

# The goldens: (stem, design file, options). Stems shared with tests/golden/drake/walks/
# put MuJoCo beside Drake in the cross-check; the bundled designs' feet are section meshes
# (Drake's harness refuses them), so for them MuJoCo is the only peer.
GOLDENS = [
    ("mugatu-ref-1x-f1.4", "dataset/walkers/reference/mugatu-ref.toml", {"frequency_hz": 1.4}),
    ("mugatu-ref-L0.05", "dataset/walkers/reference/mugatu-ref.toml", {"leg_length_m": 0.05}),
    ("mugatu-ref-L0.5", "dataset/walkers/reference/mugatu-ref.toml", {"leg_length_m": 0.5}),
    ("mugatu-ref-hc40-similar", "tests/golden/drake/designs/mugatu-ref-hc40.toml", {"frequency_hz": 1.4}),
    ("zippy-ref-1x", "dataset/walkers/reference/zippy-ref.toml", {}),
    ("zippy-spherical-ref-1x", "dataset/walkers/reference/zippy-spherical-ref.toml", {}),
    ("mugatu-1x", "dataset/walkers/mugatu.toml", {}),
    ("zippy-1x", "dataset/walkers/zippy.toml", {}),
    ("zippy-spherical-1x", "dataset/walkers/zippy-spherical.toml", {}),
    ("mugatu-lab-1x", "dataset/walkers/mugatu-lab.toml", {}),
]


def run_walk(design: str, out_csv: str | None, out_json: str | None, leg_length_m=None,
             frequency_hz=None, duration_s=25.0, command: str = "") -> dict:
    xml = walker.temp_export(design, leg_length=leg_length_m)
    w = walker.walk(xml, duration_s, frequency_hz)
    if out_csv:
        walker.write_csv(walker.decimate(w.rows), out_csv)
    meta = {
        "design_file": os.path.relpath(os.path.abspath(design), walker.ROOT)
        if os.path.exists(design) else design,
        "options": {"leg_length_m": leg_length_m, "mass_law": "l2",
                    "frequency_hz": w.drive.frequency_hz if frequency_hz is not None else None,
                    "duration_s": duration_s},
        "engine": {"name": "mujoco", "version": mujoco.__version__, "model": "survey sim export --format mjcf",
                   "timestep_s": w.dt, "integrator": "implicitfast", "cone": "elliptic"},
        "timing": {"steps": w.nstep, "rollout_wall_s": w.wall_s,
                   "steps_per_s": w.nstep / w.wall_s},
        "command": command,
    }
    if out_json:
        with open(out_json + ".tmp", "w") as f:
            json.dump(meta, f, indent=1)
            f.write("\n")
        os.replace(out_json + ".tmp", out_json)
    return meta


def hip_roll(model, data) -> float:
    return math.degrees(walker.hip_attitude(data.qpos[3:7], data.qpos[7])[0])


def elementary() -> dict:
    """Two cases of tests/golden/drake/cases.toml in MuJoCo, measured as cases.toml says:
    sinkage_sphere (mugatu-ref upright on both feet, servo holding q = 0) and free_rocking
    (rolled 5°, released)."""
    xml = walker.temp_export("dataset/walkers/reference/mugatu-ref.toml")
    model = mujoco.MjModel.from_xml_path(xml)
    data = mujoco.MjData(model)
    out = {}
    # sinkage_sphere: both feet just touching (the lowest sphere point at z = 0), settle 2 s.
    mujoco.mj_resetDataKeyframe(model, data, 0)
    data.qpos[3:7] = [1, 0, 0, 0]
    foot = model.geom("left_foot")
    data.qpos[2] = foot.size[0] - foot.pos[2]
    z0 = data.qpos[2]
    zs, fs = [], []
    while data.time < 2.0:
        data.ctrl[0] = 0.0
        mujoco.mj_step(model, data)
        if data.time > 1.8:
            zs.append(data.qpos[2])
            fs.append(data.sensordata[1:3].copy())
    out["sinkage_sphere"] = {"sinkage_m": z0 - float(np.mean(zs)),
                             "left_normal_force_n": float(np.mean([f[0] for f in fs])),
                             "right_normal_force_n": float(np.mean([f[1] for f in fs]))}
    # free_rocking: rolled 5° about x at the design's start height, released.
    mujoco.mj_resetDataKeyframe(model, data, 0)
    half = math.radians(2.5)
    data.qpos[3:7] = [math.cos(half), math.sin(half), 0, 0]
    ts, rolls = [0.0], [5.0]
    while data.time < 6.0:
        data.ctrl[0] = 0.0
        mujoco.mj_step(model, data)
        ts.append(data.time)
        rolls.append(hip_roll(model, data))
    t, r = np.array(ts), np.array(rolls)
    i = np.nonzero((r[:-1] > 0) != (r[1:] > 0))[0]
    zc = t[i] - r[i] * (t[i + 1] - t[i]) / (r[i + 1] - r[i])
    period = float(np.mean(zc[2:10] - zc[0:8])) if len(zc) >= 10 else float("nan")
    peaks = [5.0] + [float(r[k]) for k in range(1, len(r) - 1) if r[k] > 0 and r[k] >= r[k - 1] and r[k] > r[k + 1]]
    out["free_rocking"] = {"roll_period_s": period,
                           "roll_decay_ratio_per_cycle": (peaks[4] / peaks[0]) ** 0.25 if len(peaks) > 4 else float("nan"),
                           "roll_peaks_deg": peaks[:6]}
    out["mujoco_version"] = mujoco.__version__
    out["command"] = "python tools/mujoco/harness.py elementary --out tests/golden/mujoco/elementary.json"
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("walk", help="one walk of a design's MJCF export")
    w.add_argument("design", help="a bundled design name or a design TOML")
    w.add_argument("--leg-length", type=float)
    w.add_argument("--frequency", type=float)
    w.add_argument("--duration", type=float, default=25.0)
    w.add_argument("--trajectory")
    w.add_argument("--json")
    e = sub.add_parser("elementary", help="sinkage and free rocking of mugatu-ref in MuJoCo")
    e.add_argument("--out", default="tests/golden/mujoco/elementary.json")
    g = sub.add_parser("goldens", help="every golden walk of tests/golden/mujoco/walks/")
    g.add_argument("--out", default="tests/golden/mujoco/walks")
    a = p.parse_args(argv)
    if a.cmd == "walk":
        meta = run_walk(a.design, a.trajectory, a.json, a.leg_length, a.frequency, a.duration,
                        "python tools/mujoco/harness.py " + " ".join(argv or sys.argv[1:]))
        print(json.dumps(meta["timing"]))
        return
    if a.cmd == "elementary":
        with open(a.out, "w") as f:
            json.dump(elementary(), f, indent=1)
            f.write("\n")
        return
    os.makedirs(a.out, exist_ok=True)
    for stem, design, opts in GOLDENS:
        csv = os.path.join(a.out, stem + ".csv")
        js = os.path.join(a.out, stem + ".json")
        cmd = f"python tools/mujoco/harness.py walk {design}"
        if "leg_length_m" in opts:
            cmd += f" --leg-length {opts['leg_length_m']}"
        if "frequency_hz" in opts:
            cmd += f" --frequency {opts['frequency_hz']}"
        cmd += f" --duration 25 --trajectory {csv} --json {js}"
        meta = run_walk(os.path.join(walker.ROOT, design), csv, js, opts.get("leg_length_m"),
                        opts.get("frequency_hz"), 25.0, cmd)
        print(stem, f"{meta['timing']['steps_per_s']:.0f} steps/s", flush=True)


if __name__ == "__main__":
    main()
