#!/usr/bin/env python3
"""Drake cross-check harness for the project's walker simulator (src/sim/).

Subcommands (run from the repository root; paths are relative to it):
  walk DESIGN.toml [options]   one walk -> trajectory CSV (project format) + metrics JSON
  trials CONDITIONS.csv --out TRIALS.csv [--effect ...] [--jobs N] [--logs DIR]
                               one 16-cycle walk per trial condition -> trials CSV
                               (project format, dataset/trials/README.md)
  case NAME [--out FILE]       one elementary case of tests/golden/drake/cases.toml
  effect-cases [--out FILE]    the effect checks of tests/golden/drake/gap/effect_cases.toml
  cases [--out FILE]           all elementary cases -> elementary.json
  all --out tests/golden/drake/  regenerate every golden file

See tools/drake/README.md and tests/golden/drake/README.md.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import design as dz  # noqa: E402
import drake_model as dm  # noqa: E402
import walk as wk  # noqa: E402

REPO = dz.REPO_ROOT
EFFECT_HELP = ("add a physical effect (repeatable): NAME=VALUE sets its magnitude (first "
               "parameter), NAME.PARAM=VALUE one parameter; SI at the design's 1x size, other "
               "parameters at the default of dataset/effects/NAME.toml. Supported: "
               + ", ".join(dz.SUPPORTED_EFFECTS))
DEFAULT_HINT_OVER_L = 0.06
MAX_SAMPLES_PER_CYCLE = 50


def drake_version() -> str:
    try:
        from importlib.metadata import version
        return version("drake")
    except Exception:  # pragma: no cover
        return "unknown"


def rel(path) -> str:
    """Path relative to the repository root (never an absolute machine path)."""
    p = Path(path).resolve()
    try:
        return str(p.relative_to(REPO))
    except ValueError:
        return os.path.relpath(p, REPO)


def clean(x):
    """JSON-safe copy: NaN/inf -> None, numpy -> python."""
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.ndarray):
        return clean(x.tolist())
    return x


def write_json(obj, path):
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        json.dump(clean(obj), f, indent=1, allow_nan=False)
        f.write("\n")


def engine_settings(model: dz.Model, hint_over_l: float, time_step_s: float,
                    servo: str = "auto", approximation: str | None = None) -> dict:
    kv = model.dissipation_kind == "kelvin_voigt"
    return {
        "drake_version": drake_version(),
        "plant": "MultibodyPlant, discrete",
        "time_step_s": time_step_s,
        "discrete_contact_approximation": approximation or ("sap" if kv else "similar"),
        "contact_model": "hydroelastic",
        "contact_surface_representation": "polygon",
        "foot_geometry": "compliant hydroelastic Ellipsoid (tetrahedral mesh, linear pressure p = E(1 - r))",
        "ground_geometry": (
            "rigid hydroelastic HalfSpace z <= 0 (slope: gravity tilted, as in the project)"
            if model.ground_modulus_pa is None else
            "soft_ground: compliant hydroelastic Box slab, top face z = 0, thickness %.6g m "
            "(2 R_z: field gradient E_g/R_z at the top face), lateral half-size %.6g m, "
            "E_g = %.6g Pa (slope: gravity tilted)" % (*dm.ground_slab(model), model.ground_modulus_pa)),
        "hydroelastic_modulus_pa": model.modulus_pa,
        "ground_hydroelastic_modulus_pa": model.ground_modulus_pa,
        "contact_modulus_series_pa": model.contact_modulus_pa,
        "mesh_resolution_hint_over_l": hint_over_l,
        "mesh_resolution_hint_m": hint_over_l * model.leg_length_m,
        "relaxation_time_s": model.relaxation_time_s if kv else None,
        "hunt_crossley_dissipation_s_per_m": None if kv else model.hunt_crossley_s_per_m,
        "friction_mu_static_dynamic": model.friction_mu,
        "friction_regularisation": (
            "SAP: regularised friction R_t = sigma*w_t (sigma = 1e-3, w_t = Delassus diagonal "
            "estimate); slip in stiction ~ sigma*dt*g; design stiction_speed_mps NOT used"
            if kv else
            "Similar: s/sqrt(1+s^2) with s = |v_t|/eps, eps = max(stiction_tolerance, "
            "mu*sigma*w_t*n0); stiction_tolerance = design stiction_speed_mps = "
            f"{model.stiction_speed_mps} m/s"),
        "sap_near_rigid_threshold": 1.0,
        "gravity_mps2": list(model.gravity_mps2),
        "hip_actuation": (
            "LeafSystem -> applied generalized force, held over each step "
            "(explicit; evaluated at the state at the start of the step)" if servo == "explicit"
            else "Drake PD-controlled JointActuator (implicit in SAP), effort limit = torque limit; "
                 "desired state [A sin wt, A w cos wt] at the start of the step"),
        "hardstop": "same LeafSystem, one-sided spring-damper (model.rs law); Drake joint limits not used",
        "effects": model.effects,
        "effects_in_drake": effects_in_drake(model),
        "normal_force_per_foot": "|z component| of the hydroelastic contact force on the foot "
                                 "(ContactResults, sampled output port = the last step's solve)",
    }


def effects_in_drake(model: dz.Model) -> dict:
    """How each effect of `model` is realised in the Drake plant (for the JSON)."""
    out = {}
    names = {e["effect"] for e in model.effects}
    if "hip_viscous_damping" in names:
        out["hip_viscous_damping"] = (
            f"RevoluteJoint damping c = {model.hip_damping_nms_per_rad:.9g} N m s/rad "
            "(Drake's joint damping, implicit in the discrete solver)")
    if "hip_coulomb_friction" in names:
        out["hip_coulomb_friction"] = (
            "-tau_f qdot/sqrt(qdot^2 + w_s^2) added by the controller LeafSystem to the applied "
            "generalized force (explicit: from the state at the start of the step), "
            "[tau_f, w_s] = " + str([list(x) for x in model.hip_coulomb]))
    if "soft_ground" in names:
        out["soft_ground"] = (
            f"compliant ground slab E_g = {model.ground_modulus_pa:.9g} Pa, thickness 2 R_z; "
            "Drake combines the foot's and the ground's pressure fields in series by their "
            f"gradients: first-order contact modulus {model.contact_modulus_pa:.9g} Pa "
            "= E_foot E_g/(E_foot + E_g)")
    if "friction_coefficient" in names:
        out["friction_coefficient"] = (
            f"mu_static = mu_dynamic = {model.friction_mu:.9g} on the foot and on the ground "
            "(Drake's combination 2 mu1 mu2/(mu1 + mu2) = mu)")
    return out


# --------------------------------------------------------------------------------- walk
def prepare_design(design_path, leg_length=None, mass_law="l2", contact_scaling="similar",
                   frequency=None, relaxation_scale=1.0, overrides=None, effects=None,
                   amplitude_deg=None, slope_deg=None, mass_kg=None, torque_nm=None):
    """The design as `src/gap/simulate.rs` `Condition::design_with` builds it: read (and
    dotted-key overrides), `effects` added (settings [(name, nondimensional)] of
    `dz.parse_effect_args`, evaluated for the 1× design), amplitude and slope set, scaled
    to `leg_length` (effects by their rule), then mass, frequency and torque (servo limit or
    bang-bang magnitude) set at the scaled size."""
    d = dz.load_toml(design_path)
    if overrides:
        d = dz.apply_overrides(d, overrides)
    dz.check_supported(d)
    if effects:
        d["effects"] = list(d.get("effects", [])) + [
            dz.effect_spec(d, name, nd, origin=f"effect {name}") for name, nd in effects]
    if amplitude_deg is not None:
        if d["control"]["kind"] != "servo_sine":
            raise dz.DesignError("amplitude_deg given, but the design is not a position servo")
        d["control"]["amplitude_deg"] = amplitude_deg
    if slope_deg is not None:
        d.setdefault("ground", {})["slope_deg"] = slope_deg
    L = leg_length if leg_length is not None else d["geometry"]["leg_length_m"]
    d = dz.scaled(d, L, mass_law, contact_scaling)
    if mass_kg is not None:
        d["mass"]["total_mass_kg"] = mass_kg
    if frequency is not None:
        d["control"]["frequency_hz"] = frequency
    if torque_nm is not None:
        key = "torque_limit_nm" if d["control"]["kind"] == "servo_sine" else "torque_nm"
        d["control"][key] = torque_nm
    if relaxation_scale != 1.0:
        if "relaxation_time_s" not in d["contact"]:
            raise dz.DesignError("--relaxation-scale needs a relaxation_time_s design")
        d["contact"]["relaxation_time_s"] *= relaxation_scale
    return d


def auto_decimation(freq, dt, record_every):
    per_cycle = (1.0 / freq) / (record_every * dt)
    return max(1, math.ceil(per_cycle / MAX_SAMPLES_PER_CYCLE))


def do_walk(design_path, *, leg_length=None, mass_law="l2", contact_scaling="similar",
            frequency=None, duration=25.0, hint_over_l=DEFAULT_HINT_OVER_L,
            relaxation_scale=1.0, time_step_scale=1.0, trajectory=None, json_out=None,
            decimation="auto", command=None, quiet=False, servo="auto",
            initial_roll_deg=None, approximation=None, effects=None):
    """effects: `--effect` arguments (strings), in SI at the design's 1× size."""
    settings = None
    if effects:
        base = dz.load_toml(design_path)
        settings = dz.parse_effect_args(base, effects)
    d = prepare_design(design_path, leg_length, mass_law, contact_scaling, frequency,
                       relaxation_scale, effects=settings)
    model = dz.build_model(d)
    dt = model.time_step_s * time_step_scale
    freq = model.controller["frequency_hz"]
    if approximation is not None:
        kv = model.dissipation_kind == "kelvin_voigt"
        if kv != (approximation == "sap"):
            raise dz.DesignError(
                f"--approximation {approximation}: SAP uses the relaxation time and the others "
                "Hunt-Crossley dissipation; the design's contact has "
                + ("relaxation_time_s" if kv else "hunt_crossley_dissipation_s_per_m"))
    run = wk.run_walk(model, duration, resolution_hint_over_l=hint_over_l, time_step_s=dt,
                      servo=servo, initial_roll_deg=initial_roll_deg,
                      approximation=approximation)
    samples = run["samples"]
    torque_limit = model.controller.get("torque_limit_nm", model.controller.get("torque_nm"))
    common = dict(name=model.name, leg_length_m=model.leg_length_m,
                  mass_kg=model.total_mass_kg, freq=freq, torque_limit_nm=torque_limit,
                  duration_s=duration, time_step_s=dt,
                  walk_speed_threshold_over_sqrt_gl=model.criteria["walk_speed_threshold_over_sqrt_gl"],
                  fall=run["fall"], mass_law=mass_law, contact_scaling=contact_scaling)
    report = wk.analyze(samples, **common)
    factor = auto_decimation(freq, dt, run["record_every"]) if decimation == "auto" else int(decimation)
    out = {
        "command": command,
        "design_file": rel(dz.REPO_ROOT / design_path) if not Path(design_path).is_absolute() else rel(design_path),
        "options": {"leg_length_m": model.leg_length_m, "mass_law": mass_law,
                    "contact_scaling": contact_scaling, "frequency_hz": freq,
                    "duration_s": duration, "relaxation_scale": relaxation_scale,
                    "time_step_scale": time_step_scale, "servo": run["walker"].servo,
                    "initial_roll_deg": model.initial_roll_deg if initial_roll_deg is None else initial_roll_deg,
                    "effect_args": list(effects or [])},
        "scaled_design": d,
        "engine": engine_settings(model, hint_over_l, dt, run["walker"].servo,
                                  run["walker"].approximation),
        "report": report,
        "timing": {
            "wall_s": run["wall_s"], "simulated_s": run["simulated_s"], "steps": run["steps"],
            "ms_wall_per_simulated_s": 1000.0 * run["wall_s"] / max(run["simulated_s"], 1e-12),
            "host": f"{platform.machine()}, {os.cpu_count()} logical cores (shared with other work)",
        },
        "contact_polygons_per_loaded_foot": run["polygons_per_loaded_foot"],
        "sampling": {"record_every_steps": run["record_every"],
                     "samples_per_drive_cycle": (1.0 / freq) / (run["record_every"] * dt),
                     "csv_decimation_factor": factor},
    }
    if trajectory:
        dec = wk.decimate(samples, factor)
        Path(trajectory).parent.mkdir(parents=True, exist_ok=True)
        wk.write_csv(dec, trajectory)
        out["trajectory_csv"] = rel(trajectory)
        out["csv_rows"] = len(dec)
        # The metrics the Rust side will get from the committed (decimated) CSV.
        out["report_from_csv"] = wk.analyze(wk.read_csv(trajectory), **common)
    if json_out:
        write_json(out, json_out)
    if not quiet:
        r = report
        print(f"{model.name} L={model.leg_length_m:.4g} f={freq:.4g} Hz: walks={r['walks']} "
              f"fall={r['fall_reason']} v={r['velocity_mps']:.4g} m/s step_f={r['step_frequency_hz']:.4g} Hz "
              f"roll {r['roll_pp_deg']:.3g}±{r['roll_pp_deg_sd']:.2g} pitch {r['pitch_pp_deg']:.3g}±{r['pitch_pp_deg_sd']:.2g} "
              f"yaw {r['yaw_pp_deg']:.3g}±{r['yaw_pp_deg_sd']:.2g} deg; "
              f"{out['timing']['ms_wall_per_simulated_s']:.0f} ms/sim-s", flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("walk", help="run one walk")
    w.add_argument("design")
    w.add_argument("--leg-length", type=float, help="scale the design to this L [m]")
    w.add_argument("--mass-law", choices=["l2", "l3"], default="l2")
    w.add_argument("--contact-scaling", choices=["similar", "fixed-material"], default="similar")
    w.add_argument("--frequency", type=float, help="drive frequency [Hz] (default: scaled design's)")
    w.add_argument("--duration", type=float, default=25.0)
    w.add_argument("--resolution-hint-over-l", type=float, default=DEFAULT_HINT_OVER_L)
    w.add_argument("--relaxation-scale", type=float, default=1.0)
    w.add_argument("--time-step-scale", type=float, default=1.0)
    w.add_argument("--servo", choices=["auto", "explicit", "sap_pd"], default="auto",
                   help="hip servo: 'sap_pd' = Drake's PD-controlled joint actuator (implicit, "
                        "like the project's servo), 'explicit' = the servo law in the controller "
                        "LeafSystem (torque held over each step); 'auto' (default) = sap_pd for "
                        "servo_sine designs")
    w.add_argument("--initial-roll-deg", type=float,
                   help="initial roll (default: the design's initial.roll_deg)")
    w.add_argument("--approximation", choices=["sap", "similar", "lagged"],
                   help="Drake's discrete contact approximation (default: sap for a relaxation-time "
                        "design, similar for a Hunt-Crossley one). sap and similar are convex "
                        "(a sliding contact separates); lagged is not")
    w.add_argument("--effect", action="append", default=[], metavar="NAME[.PARAM]=VALUE",
                   help=EFFECT_HELP)
    w.add_argument("--trajectory", help="output CSV")
    w.add_argument("--decimate", default="auto",
                   help="keep every N-th sample in the CSV ('auto': <= 50 per drive cycle)")
    w.add_argument("--json", help="output JSON (metrics, settings, timing)")
    t = sub.add_parser("trials", help="one walk per trial condition -> trials CSV")
    t.add_argument("conditions", help="trials CSV (dataset/trials/README.md); only the "
                                      "condition columns are used")
    t.add_argument("--effect", action="append", default=[], metavar="NAME[.PARAM]=VALUE",
                   help=EFFECT_HELP + " Values refer to the first row's design at 1x "
                        "(like survey gap synth --design) and apply to every row in scale units.")
    t.add_argument("--out", required=True, help="output trials CSV")
    t.add_argument("--jobs", type=int, default=2, help="parallel processes (default 2); "
                                                       "does not change the output")
    t.add_argument("--approximation", choices=["sap", "similar", "lagged"],
                   help="Drake's discrete contact approximation (default as for walk); lagged "
                        "needs a Hunt-Crossley design")
    t.add_argument("--logs", metavar="DIR",
                   help="also write each logged trial's robot log (t_s, hip_angle_deg, "
                        "roll_deg, pitch_deg, yaw_deg, hip_torque_nm; <= 50 samples per drive "
                        "cycle) into DIR as <label>.csv, named in the trials' trajectory column "
                        "(the input of survey gap separate's waveform evidence)")
    t.add_argument("--log-labels", metavar="L1,L2,...",
                   help="with --logs: log only these rows (by label; default every row)")
    c = sub.add_parser("case", help="run one elementary case")
    c.add_argument("name")
    c.add_argument("--cases", default="tests/golden/drake/cases.toml")
    c.add_argument("--resolution-hint-over-l", type=float, default=DEFAULT_HINT_OVER_L)
    c.add_argument("--out", help="output JSON")
    ec = sub.add_parser("effect-cases", help="run the effect checks (Drake vs analytic)")
    ec.add_argument("--cases", default="tests/golden/drake/gap/effect_cases.toml")
    ec.add_argument("--only", nargs="*", help="case names (default: all, plus the mesh variant)")
    ec.add_argument("--out", default="tests/golden/drake/gap/effect_cases.json")
    cs = sub.add_parser("cases", help="run all elementary cases")
    cs.add_argument("--cases", default="tests/golden/drake/cases.toml")
    cs.add_argument("--out", default="tests/golden/drake/elementary.json")
    a = sub.add_parser("all", help="regenerate all golden files")
    a.add_argument("--out", default="tests/golden/drake/")
    a.add_argument("--duration", type=float, default=25.0)
    a.add_argument("--only", nargs="*", help="subset: elementary walks sensitivity resolution timing")
    args = ap.parse_args(argv)
    command = "python tools/drake/harness.py " + " ".join(argv if argv is not None else sys.argv[1:])

    if args.cmd == "trials":
        import trials as tz
        labels = None
        if args.log_labels:
            if not args.logs:
                ap.error("--log-labels needs --logs")
            labels = [x.strip() for x in args.log_labels.split(",") if x.strip()]
        return tz.run_trials(args.conditions, args.out, args.effect, jobs=args.jobs,
                             approximation=args.approximation, logs=args.logs,
                             log_labels=labels)
    if args.cmd == "walk":
        do_walk(args.design, leg_length=args.leg_length, mass_law=args.mass_law,
                contact_scaling=args.contact_scaling, frequency=args.frequency,
                duration=args.duration, hint_over_l=args.resolution_hint_over_l,
                relaxation_scale=args.relaxation_scale, time_step_scale=args.time_step_scale,
                trajectory=args.trajectory, json_out=args.json, decimation=args.decimate,
                command=command, servo=args.servo, initial_roll_deg=args.initial_roll_deg,
                approximation=args.approximation, effects=args.effect)
    elif args.cmd == "case":
        import cases as cz
        res = cz.run_case_by_name(args.name, args.cases, hint_over_l=args.resolution_hint_over_l)
        res["command"] = command
        if args.out:
            write_json(res, args.out)
        print(json.dumps(clean(res["measured"]), indent=1))
        print(json.dumps(clean(res["analytic"]), indent=1))
    elif args.cmd == "effect-cases":
        import effect_cases as ez
        t0 = time.perf_counter()
        if args.only:
            allc = dz.load_toml(args.cases)["cases"]
            res = {"cases": {n: ez.run_case(n, allc[n]) for n in args.only}}
        else:
            res = ez.run_all(args.cases)
        res = {"drake_version": drake_version(), "command": command,
               "cases_file": rel(args.cases), "units": "SI (m, s, N, kg, rad/s) unless the key says deg",
               "relative_difference": "(measured - analytic)/|analytic|",
               "wall_s": time.perf_counter() - t0, **res}
        write_json(res, args.out)
        for n, r in res["cases"].items():
            for k, c in r["comparison"].items():
                print(f"{n}: {k} Drake {c['measured']:.6g}")
                for a, x in c["analytic"].items():
                    rd = x["relative_difference"]
                    print(f"    {a:56s} {x['value']:.6g}  "
                          + (f"{100 * rd:+.3f} %" if rd is not None else ""))
    elif args.cmd == "cases":
        import cases as cz
        res = cz.run_all_cases(args.cases)
        res["command"] = command
        write_json(res, args.out)
    elif args.cmd == "all":
        import regenerate
        regenerate.run_all(args.out, duration=args.duration, only=args.only, command=command)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except dz.DesignError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
