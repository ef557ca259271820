"""`harness.py trials`: Drake walks of trial conditions -> a trials CSV in the project's format.

Mirrors `survey gap synth` without the noise (`src/gap/synth.rs`, `src/gap/simulate.rs`):
each row's design (a bundled name or a TOML path relative to the conditions file) is built
as `Condition::design_with` builds it (effects added at 1×, amplitude/slope set, scaled to the
row's leg length with m ∝ L² (or the row's `mass_law`) and `similar` contact (or the row's
`contact`), then mass, frequency and torque set), walked for exactly
`CYCLES_PER_TRIAL` = 16 drive cycles, and measured with the port of `walk.rs` `analyze`.
A walk that falls measures nothing (empty metrics; `source` says so). The `_sd` columns stay
empty: these are exact (noise-free) Drake values.

Rows run in separate processes (`--jobs`); each is independent of the others and of the
number of processes, so the output is the same whatever `--jobs` is.
"""

from __future__ import annotations

import csv
import io
import math
import multiprocessing
import os
import time
from concurrent.futures import ProcessPoolExecutor
from decimal import Decimal
from pathlib import Path

import design as dz

CYCLES_PER_TRIAL = 16.0   # src/gap/simulate.rs

# The column order of `src/gap/trials.rs` `columns()` (what `survey gap synth` writes).
HEADER = ("label,design,leg_length_m,mass_kg,mass_law,contact,frequency_hz,amplitude_deg,"
          "torque_limit_nm,torque_nm,slope_deg,velocity_mps,velocity_mps_sd,step_frequency_hz,"
          "step_frequency_hz_sd,roll_pp_deg,roll_pp_deg_sd,pitch_pp_deg,pitch_pp_deg_sd,"
          "yaw_pp_deg,yaw_pp_deg_sd,peak_torque_nm,peak_torque_nm_sd,min_torque_nm,"
          "min_torque_nm_sd,cot,cot_sd,trajectory,source").split(",")
NUMBER_CONDITIONS = ("leg_length_m", "mass_kg", "frequency_hz", "amplitude_deg",
                     "torque_limit_nm", "torque_nm", "slope_deg")
# The metrics one walk gives (`Metric::SIMULATED`), as `analyze` names them.
METRICS = ("velocity_mps", "step_frequency_hz", "roll_pp_deg", "pitch_pp_deg", "yaw_pp_deg",
           "peak_torque_nm", "cot")
# The columns of a robot log (dataset/trials/README.md, "Logs"), as the walk's samples name them.
LOG_COLUMNS = ("t_s", "hip_angle_deg", "roll_deg", "pitch_deg", "yaw_deg", "hip_torque_nm")
# Bundled designs (`Design::builtin`).
BUNDLED = {
    "mugatu": "dataset/walkers/mugatu.toml",
    "zippy": "dataset/walkers/zippy.toml",
    "zippy-ellipsoidal": "dataset/walkers/zippy.toml",
    "zippy-spherical": "dataset/walkers/zippy-spherical.toml",
    "mugatu-ref": "dataset/walkers/reference/mugatu-ref.toml",
    "zippy-ref": "dataset/walkers/reference/zippy-ref.toml",
    "zippy-spherical-ref": "dataset/walkers/reference/zippy-spherical-ref.toml",
}


class TrialsError(dz.DesignError):
    pass


def fmt_number(x: float) -> str:
    """Rust's `format!("{}", x)` for f64: the shortest digits that read back to the same
    number, never in exponent notation ("1" for 1.0, "0.0000001" for 1e-7)."""
    x = float(x)
    if x == 0.0:
        return "-0" if math.copysign(1.0, x) < 0 else "0"
    s = format(Decimal(repr(x)), "f")
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return s


def resolve_design(name: str, base_dir: Path) -> Path:
    """A bundled design name (`Design::builtin`), or a TOML path relative to the conditions
    file's folder."""
    key = name.lower().replace("_", "-")
    if key in BUNDLED:
        return dz.REPO_ROOT / BUNDLED[key]
    p = (base_dir / name)
    if p.exists():
        return p.resolve()
    raise TrialsError(f"design {name!r} is neither a bundled design ({', '.join(BUNDLED)}) "
                      f"nor a file {p}")


def read_conditions(path) -> list:
    """Rows of a trials CSV as {column: cell} (comment lines '#' skipped), with the checks of
    `TrialSet::parse` on the condition columns. Each row gets '_line' (1 = header)."""
    path = Path(path)
    with open(path, newline="") as f:
        raw = f.read().splitlines(keepends=True)
    lines, numbers = [], []
    for i, ln in enumerate(raw, start=1):
        if ln.lstrip("\ufeff").startswith("#"):
            continue
        lines.append(ln)
        numbers.append(i)
    rdr = csv.reader(io.StringIO("".join(lines)))
    try:
        header = [h.strip() for h in next(rdr)]
    except StopIteration:
        raise TrialsError(f"{path}: empty file") from None
    header[0] = header[0].lstrip("\ufeff")
    for req in ("design", "leg_length_m", "source"):
        if req not in header:
            raise TrialsError(f"{path}: missing required column {req!r}")
    rows = []
    for k, rec in enumerate(rdr, start=1):
        if not rec or all(not c.strip() for c in rec):
            continue
        line = numbers[k] if k < len(numbers) else k + 1
        if len(rec) != len(header):
            raise TrialsError(f"{path}:{line}: {len(rec)} cells for {len(header)} columns")
        row = {h: c.strip() for h, c in zip(header, rec)}
        row["_line"] = line

        def err(msg):
            return TrialsError(f"{path}:{line}: {msg}")

        if not row.get("design"):
            raise err("design: empty")
        if not row.get("source"):
            raise err("source: empty; every trial must say where its numbers come from")
        for c in NUMBER_CONDITIONS:
            v = row.get(c, "")
            if v:
                try:
                    x = float(v)
                except ValueError:
                    raise err(f"{c}: {v!r} is not a number") from None
                if not math.isfinite(x):
                    raise err(f"{c}: {v} is not finite")
                row[c] = x
            else:
                row[c] = None
        if row["leg_length_m"] is None:
            raise err("leg_length_m: empty; every trial needs its leg length")
        if not 1e-3 <= row["leg_length_m"] <= 100.0:
            raise err("leg_length_m must be in [0.001, 100] m")
        for c in ("mass_kg", "frequency_hz", "torque_limit_nm", "torque_nm"):
            if row[c] is not None and row[c] <= 0:
                raise err(f"{c} must be > 0")
        if row["amplitude_deg"] is not None and not 0 < row["amplitude_deg"] < 90:
            raise err("amplitude_deg must be in (0, 90) deg")
        if row["slope_deg"] is not None and abs(row["slope_deg"]) > 45:
            raise err("slope_deg must be within ±45 deg")
        ml = row.get("mass_law", "") or ""
        if ml not in ("", "l2", "l3"):
            raise err(f"mass_law: {ml!r}; expected l2 or l3")
        ct = row.get("contact", "") or ""
        if ct not in ("", "similar", "fixed-material"):
            raise err(f"contact: {ct!r}; expected similar or fixed-material")
        rows.append(row)
    if not rows:
        raise TrialsError(f"{path}: no trials: the file has a header but no rows")
    return rows


def _run_row(job):
    """Worker: one trial condition -> metrics (runs in its own process)."""
    import walk as wk
    import harness as hz
    idx, row, design_path, settings, approximation, log = job
    t0 = time.perf_counter()
    torque = row["torque_limit_nm"] if row["torque_limit_nm"] is not None else row["torque_nm"]
    mass_law = row.get("mass_law") or "l2"
    contact = row.get("contact") or "similar"
    d = hz.prepare_design(design_path, leg_length=row["leg_length_m"], mass_law=mass_law,
                          contact_scaling=contact, frequency=row["frequency_hz"],
                          effects=settings, amplitude_deg=row["amplitude_deg"],
                          slope_deg=row["slope_deg"], mass_kg=row["mass_kg"], torque_nm=torque)
    if torque is not None:
        kind = d["control"]["kind"]
        if (row["torque_limit_nm"] is not None) != (kind == "servo_sine"):
            raise TrialsError(f"row {row['_line']}: torque_limit_nm is for position-servo "
                              "designs, torque_nm for bang-bang ones")
    model = dz.build_model(d)
    if approximation is not None:
        kv = model.dissipation_kind == "kelvin_voigt"
        if kv != (approximation == "sap"):
            raise TrialsError(
                f"--approximation {approximation}: SAP uses the relaxation time and the others "
                f"Hunt-Crossley dissipation; {design_path} has "
                + ("relaxation_time_s" if kv else "hunt_crossley_dissipation_s_per_m"))
    freq = model.controller["frequency_hz"]
    duration = CYCLES_PER_TRIAL / freq
    run = wk.run_walk(model, duration, approximation=approximation)
    torque_limit = model.controller.get("torque_limit_nm", model.controller.get("torque_nm"))
    report = wk.analyze(
        run["samples"], name=model.name, leg_length_m=model.leg_length_m,
        mass_kg=model.total_mass_kg, freq=freq, torque_limit_nm=torque_limit,
        duration_s=duration, time_step_s=run["dt"],
        walk_speed_threshold_over_sqrt_gl=model.criteria["walk_speed_threshold_over_sqrt_gl"],
        fall=run["fall"], mass_law=mass_law, contact_scaling=contact)
    log_rows = None
    if log:
        factor = hz.auto_decimation(freq, run["dt"], run["record_every"])
        log_rows = [[s[k] for k in LOG_COLUMNS] for s in wk.decimate(run["samples"], factor)]
    return {
        "index": idx, "report": report, "fall": run["fall"], "effects": model.effects,
        "log": log_rows,
        "wall_s": time.perf_counter() - t0, "walk_wall_s": run["wall_s"],
        "simulated_s": run["simulated_s"], "steps": run["steps"], "dt": run["dt"],
    }


def _metric_cells(r: dict, fell: bool) -> dict:
    out = {}
    for m in METRICS:
        v = r["report"][m]
        out[m] = "" if fell or v is None or not math.isfinite(v) else fmt_number(v)
    return out


def _design_cell(name: str, cond_dir: Path, out_dir: Path) -> str:
    """Bundled names unchanged; a design path re-expressed relative to the output file."""
    if name.lower().replace("_", "-") in BUNDLED:
        return name
    p = (cond_dir / name).resolve()
    return Path(os.path.relpath(p, out_dir.resolve())).as_posix()


def _log_name(label: str) -> str:
    """A row's label as a file name: characters other than letters, digits, '.', '_' and '-'
    become '_'."""
    return "".join(ch if ch.isalnum() or ch in "._-" else "_" for ch in label) + ".csv"


def _log_text(rows) -> str:
    """A robot log (dataset/trials/README.md, "Logs"): the columns a small walker records,
    7 significant digits (far below the 0.3 deg / 3 % sensor noise the benchmark adds)."""
    lines = [",".join(LOG_COLUMNS)]
    for r in rows:
        lines.append(",".join(f"{v:.7g}" for v in r))
    return "\n".join(lines) + "\n"


def run_trials(conditions, out, effect_args, jobs: int = 2, approximation=None, logs=None,
               log_labels=None) -> int:
    """approximation: Drake's discrete contact approximation (None: sap for a relaxation-time
    design, similar for a Hunt-Crossley one; 'lagged' is the non-convex one). logs: a folder
    for the rows' robot logs (log_labels: only these rows; None: every row)."""
    import harness as hz
    t_start = time.perf_counter()
    cond_path = Path(conditions)
    out_path = Path(out)
    rows = read_conditions(cond_path)
    base_dir = cond_path.resolve().parent
    designs = [resolve_design(r["design"], base_dir) for r in rows]
    # Effect values are SI at the first row's design at 1× (`survey gap synth --design`);
    # as nondimensional settings they apply to every row (scale units of its own design).
    settings = dz.parse_effect_args(dz.load_toml(designs[0]), effect_args) if effect_args else []
    if settings and len({str(p) for p in designs}) > 1:
        print(f"note: --effect values are SI for {hz.rel(designs[0])} at 1x; other designs get "
              "the same values in scale units (m g L, sqrt(g/L), ...)", flush=True)
    command = "python tools/drake/harness.py trials " + hz.rel(cond_path)
    for e in effect_args:
        command += f" --effect {e}"
    if approximation is not None:
        command += f" --approximation {approximation}"
    command += " --out " + hz.rel(out_path)
    if logs is not None:
        command += " --logs " + hz.rel(Path(logs))
        if log_labels:
            command += " --log-labels " + ",".join(log_labels)
    source = f"{command} (Drake {hz.drake_version()})"
    n = len(rows)
    labels = [r.get("label") or "" for r in rows]
    if log_labels:
        unknown = [x for x in log_labels if x not in labels]
        if unknown:
            raise TrialsError(f"--log-labels: no row of {cond_path} is labelled "
                              + ", ".join(unknown))
    if logs is not None:
        missing = [r["_line"] for r in rows if not r.get("label")]
        if missing:
            raise TrialsError(f"--logs: rows without a label (lines {missing}) cannot name a log")
        names = [_log_name(x) for x in labels]
        if len(set(names)) != len(names):
            raise TrialsError(f"--logs: two rows of {cond_path} give the same log file name")
    logged = [logs is not None and (not log_labels or x in log_labels) for x in labels]
    jobs_list = [(i, r, str(p), settings, approximation, logged[i])
                 for i, (r, p) in enumerate(zip(rows, designs))]
    print(f"{n} trials, {max(1, jobs)} processes; effects: "
          + (", ".join(effect_args) if effect_args else "none"), flush=True)
    results = [None] * n
    done = 0

    def report_line(res):
        r = res["report"]
        row = rows[res["index"]]
        label = row.get("label") or f"row {row['_line']}"
        if res["fall"]:
            what = f"fell ({res['fall'][0]} at {res['fall'][1]:.3g} s)"
        else:
            what = (f"v = {r['velocity_mps']:+.4f} m/s, step {r['step_frequency_hz']:.3g} Hz, "
                    f"roll/pitch/yaw {r['roll_pp_deg']:.3g}/{r['pitch_pp_deg']:.3g}/"
                    f"{r['yaw_pp_deg']:.3g} deg, walks={r['walks']}")
        return (f"[{done}/{n}] {label} (L = {r['leg_length_m']:.4g} m, "
                f"f = {r['drive_frequency_hz']:.4g} Hz): {what}; {res['wall_s']:.1f} s wall")

    if jobs <= 1:
        for j in jobs_list:
            res = _run_row(j)
            results[res["index"]] = res
            done += 1
            print(report_line(res), flush=True)
    else:
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as ex:
            futures = [ex.submit(_run_row, j) for j in jobs_list]
            from concurrent.futures import as_completed
            for fut in as_completed(futures):
                res = fut.result()
                results[res["index"]] = res
                done += 1
                print(report_line(res), flush=True)

    out_dir = out_path.resolve().parent
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(HEADER)
    fell = 0
    for row, res in zip(rows, results):
        is_fall = res["fall"] is not None
        fell += is_fall
        cells = {h: "" for h in HEADER}
        cells["label"] = row.get("label", "")
        cells["design"] = _design_cell(row["design"], base_dir, out_dir)
        for c in NUMBER_CONDITIONS:
            if row[c] is not None:
                cells[c] = fmt_number(row[c])
        cells["mass_law"] = row.get("mass_law", "") or ""
        cells["contact"] = row.get("contact", "") or ""
        cells.update(_metric_cells(res, is_fall))
        if res["log"] is not None and not is_fall:
            log_path = Path(logs).resolve() / _log_name(cells["label"])
            cells["trajectory"] = Path(os.path.relpath(log_path, out_dir)).as_posix()
        cells["source"] = (source + f"; the walk fell ({res['fall'][0]} at "
                           f"{fmt_number(round(res['fall'][1], 6))} s): nothing measured"
                           if is_fall else source)
        w.writerow([cells[h] for h in HEADER])
    if logs is not None:
        # Logs first, each atomically: the trials file that names them comes last.
        Path(logs).mkdir(parents=True, exist_ok=True)
        for row, res in zip(rows, results):
            if res["log"] is None or res["fall"] is not None:
                continue
            lp = Path(logs) / _log_name(row["label"])
            ltmp = lp.with_name("." + lp.name + ".tmp")
            ltmp.write_text(_log_text(res["log"]))
            os.replace(ltmp, lp)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    tmp = out_path.with_name("." + out_path.name + ".tmp")
    tmp.write_text(buf.getvalue())
    os.replace(tmp, out_path)
    wall = time.perf_counter() - t_start
    walk_wall = sum(r["wall_s"] for r in results)
    print(f"wrote {hz.rel(out_path)} ({n} trials, {fell} fell); {wall:.0f} s wall "
          f"({walk_wall:.0f} s summed over the trials)", flush=True)
    return 0
