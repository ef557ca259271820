"""`harness.py all`: regenerates every golden file of tests/golden/drake/.

Writes (paths relative to --out):
  elementary.json            every case of cases.toml (Drake + analytic) and Drake-only variants
  walks/<stem>.csv           trajectory, project format, decimated to <= 50 samples per drive cycle
  walks/<stem>.json          metrics (full-rate and from the CSV), engine settings, timing
  walks/sensitivity.json     mugatu-ref 1.4 Hz: relaxation time x0.5/x0.8/x2, time step x0.5,
                             and the servo as the explicit LeafSystem (metrics only)
  walks/resolution.json      mugatu-ref 1.4 Hz at mesh resolution hint 0.03 L and 0.015 L
  walks/timing.json          mugatu-ref 1.4 Hz run twice: wall ms per simulated second
  walks/summary.json         one line of metrics per walk
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import cases as cz
import harness as hz

MUGATU = "dataset/walkers/reference/mugatu-ref.toml"
ZIPPY = "dataset/walkers/reference/zippy-ref.toml"
ZIPPY_SPH = "dataset/walkers/reference/zippy-spherical-ref.toml"
CASES = "tests/golden/drake/cases.toml"

WALKS = (
    [(f"mugatu-ref-1x-f{f:.1f}", MUGATU, dict(frequency=f)) for f in (1.2, 1.3, 1.4, 1.5, 1.6)]
    + [("mugatu-ref-L0.05", MUGATU, dict(leg_length=0.05)),
       ("mugatu-ref-L0.5", MUGATU, dict(leg_length=0.5)),
       # Same design and drive, started rolled onto the LEFT foot: the fore-aft symmetric
       # walker has a forward and a backward gait of equal amplitude; which one the
       # +3 deg start selects depends on the transient (see README).
       ("mugatu-ref-1x-f1.4-roll-minus3", MUGATU, dict(frequency=1.4, initial_roll_deg=-3.0)),
       ("zippy-ref-1x", ZIPPY, {}),
       ("zippy-spherical-ref-1x", ZIPPY_SPH, {})]
)

SENSITIVITY = [
    ("relaxation_x0.5", dict(relaxation_scale=0.5)),
    ("relaxation_x0.8", dict(relaxation_scale=0.8)),
    ("relaxation_x2", dict(relaxation_scale=2.0)),
    ("time_step_x0.5", dict(time_step_scale=0.5)),
    ("servo_explicit", dict(servo="explicit")),
]

RESOLUTION = [0.03, 0.015]

# Drake-only variants of the elementary cases: (case, label, run_case keyword arguments,
# case-definition changes).
VARIANTS = [
    ("sinkage_sphere", "hint_0.03L", dict(hint_over_l=0.03), {}),
    ("sinkage_sphere", "hint_0.015L", dict(hint_over_l=0.015), {}),
    ("sinkage_ellipsoid", "hint_0.03L", dict(hint_over_l=0.03), {}),
    ("sinkage_ellipsoid", "hint_0.015L", dict(hint_over_l=0.015), {}),
    ("free_rocking", "hint_0.03L", dict(hint_over_l=0.03), {}),
    ("free_rocking", "hint_0.015L", dict(hint_over_l=0.015), {}),
    ("spin_down", "hint_0.03L", dict(hint_over_l=0.03), {}),
    ("rolling_incline", "hint_0.03L", dict(hint_over_l=0.03), {}),
    # The convex approximations lift a sliding contact (normal 'gap' velocity ~ mu |v_t|);
    # the non-convex 'lagged' one does not. Hunt-Crossley d = 5 s/m (walker-models.json).
    ("slide", "similar_hc5", dict(approximation="similar"),
     {"remove": ["contact.relaxation_time_s"],
      "overrides+": {"contact.hunt_crossley_dissipation_s_per_m": 5.0}}),
    ("slide", "lagged_hc5", dict(approximation="lagged"),
     {"remove": ["contact.relaxation_time_s"],
      "overrides+": {"contact.hunt_crossley_dissipation_s_per_m": 5.0}}),
    ("creep", "lagged_hc5", dict(approximation="lagged"),
     {"remove": ["contact.relaxation_time_s"],
      "overrides+": {"contact.hunt_crossley_dissipation_s_per_m": 5.0}}),
    ("creep", "similar_hc5", dict(approximation="similar"),
     {"remove": ["contact.relaxation_time_s"],
      "overrides+": {"contact.hunt_crossley_dissipation_s_per_m": 5.0}}),
    ("servo_in_air", "servo_explicit", dict(servo="explicit"), {}),
    ("free_rocking", "servo_explicit", dict(servo="explicit"), {}),
]


def _variant_case(case, change):
    c = dict(case)
    if "remove" in change:
        c["remove"] = list(case.get("remove", [])) + change["remove"]
    if "overrides+" in change:
        o = dict(case.get("overrides", {}))
        o.update(change["overrides+"])
        c["overrides"] = o
    return c


def run_elementary(out_dir: Path, command: str):
    cases = cz.load_cases(CASES)
    res = {"drake_version": hz.drake_version(), "command": command,
           "cases_file": "tests/golden/drake/cases.toml",
           "units": "SI (m, s, N, kg, rad/s) unless the key says deg",
           "cases": {}, "variants": []}
    for name in cz.CASE_ORDER:
        t0 = time.perf_counter()
        res["cases"][name] = cz.run_case(name, cases[name])
        print(f"case {name}: {time.perf_counter() - t0:.1f} s", flush=True)
    for name, label, kw, change in VARIANTS:
        case = _variant_case(cases[name], change)
        kw = dict(kw)
        hint = kw.pop("hint_over_l", 0.06)
        r = cz.run_case(name, case, hint_over_l=hint, **kw)
        res["variants"].append({"case": name, "variant": label, "changes": change,
                                "measured": r["measured"], "engine": r["engine"],
                                "wall_s": r["wall_s"]})
        print(f"variant {name}/{label} done", flush=True)
    hz.write_json(res, out_dir / "elementary.json")
    return res


def summary_line(stem, out):
    r = out["report"]
    return {
        "walk": stem, "design": r["design"], "leg_length_m": r["leg_length_m"],
        "drive_frequency_hz": r["drive_frequency_hz"], "walks": r["walks"],
        "fall_reason": r["fall_reason"], "fell_at_s": r["fell_at_s"],
        "velocity_mps": r["velocity_mps"], "froude": r["froude"],
        "step_frequency_hz": r["step_frequency_hz"],
        "roll_pp_deg": r["roll_pp_deg"], "roll_pp_deg_sd": r["roll_pp_deg_sd"],
        "pitch_pp_deg": r["pitch_pp_deg"], "pitch_pp_deg_sd": r["pitch_pp_deg_sd"],
        "yaw_pp_deg": r["yaw_pp_deg"], "yaw_pp_deg_sd": r["yaw_pp_deg_sd"],
        "turning_deg_per_m": r["turning_deg_per_m"], "cot": r["cot"],
        "peak_torque_nm": r["peak_torque_nm"], "converged_at_s": r["converged_at_s"],
        "ms_wall_per_simulated_s": out["timing"]["ms_wall_per_simulated_s"],
    }


def run_walks(out_dir: Path, duration: float):
    wdir = out_dir / "walks"
    wdir.mkdir(parents=True, exist_ok=True)
    lines = []
    for stem, design, kw in WALKS:
        args = " ".join(f"--{k.replace('_', '-')} {v}" for k, v in kw.items())
        cmd = (f"python tools/drake/harness.py walk {design} {args} --duration {duration:g} "
               f"--trajectory {(wdir / (stem + '.csv')).as_posix()} "
               f"--json {(wdir / (stem + '.json')).as_posix()}").replace("  ", " ")
        out = hz.do_walk(design, duration=duration, trajectory=wdir / f"{stem}.csv",
                         json_out=wdir / f"{stem}.json", command=_relcmd(cmd), **kw)
        lines.append(summary_line(stem, out))
    hz.write_json({"drake_version": hz.drake_version(), "duration_s": duration,
                   "walks": lines}, wdir / "summary.json")
    return lines


def _relcmd(cmd: str) -> str:
    return cmd.replace(str(hz.REPO) + "/", "")


def run_sensitivity(out_dir: Path, duration: float):
    rows = []
    base = dict(frequency=1.4)
    for label, kw in [("baseline", {})] + SENSITIVITY:
        out = hz.do_walk(MUGATU, duration=duration, **base, **kw)
        rows.append({"variant": label, "options": out["options"], "engine": out["engine"],
                     "report": out["report"], "timing": out["timing"],
                     "contact_polygons_per_loaded_foot": out["contact_polygons_per_loaded_foot"]})
    hz.write_json({"drake_version": hz.drake_version(), "design_file": MUGATU,
                   "duration_s": duration, "runs": rows}, out_dir / "walks" / "sensitivity.json")
    return rows


def run_resolution(out_dir: Path, duration: float):
    rows = []
    for hint in RESOLUTION:
        out = hz.do_walk(MUGATU, duration=duration, frequency=1.4, hint_over_l=hint)
        rows.append({"resolution_hint_over_l": hint, "engine": out["engine"],
                     "report": out["report"], "timing": out["timing"],
                     "contact_polygons_per_loaded_foot": out["contact_polygons_per_loaded_foot"]})
    hz.write_json({"drake_version": hz.drake_version(), "design_file": MUGATU,
                   "duration_s": duration, "baseline_hint_over_l": 0.06,
                   "baseline": "walks/mugatu-ref-1x-f1.4.json", "runs": rows},
                  out_dir / "walks" / "resolution.json")
    return rows


def run_timing(out_dir: Path, duration: float, repeats: int = 2):
    rows = []
    for k in range(repeats):
        out = hz.do_walk(MUGATU, duration=duration, frequency=1.4, quiet=True)
        rows.append(out["timing"])
        print(f"timing run {k + 1}: {out['timing']['ms_wall_per_simulated_s']:.0f} ms/sim-s", flush=True)
    hz.write_json({"drake_version": hz.drake_version(), "design_file": MUGATU,
                   "frequency_hz": 1.4, "duration_s": duration, "runs": rows,
                   "note": "wall time of the stepping loop only (model build excluded); "
                           "Python LeafSystem controller; 2-core machine shared with a compile"},
                  out_dir / "walks" / "timing.json")
    return rows


def run_all(out, duration=25.0, only=None, command=""):
    out_dir = Path(out)
    parts = only or ["elementary", "walks", "sensitivity", "resolution", "timing"]
    t0 = time.perf_counter()
    if "elementary" in parts:
        run_elementary(out_dir, command)
    if "walks" in parts:
        run_walks(out_dir, duration)
    if "sensitivity" in parts:
        run_sensitivity(out_dir, duration)
    if "resolution" in parts:
        run_resolution(out_dir, duration)
    if "timing" in parts:
        run_timing(out_dir, duration)
    print(f"all done in {time.perf_counter() - t0:.0f} s", flush=True)
