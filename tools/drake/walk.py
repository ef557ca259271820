"""Running a walk in Drake and measuring it exactly as `src/sim/walk.rs` does.

* sampling: every floor((1/f)/(200·dt)) steps and at the last step, plus the t = 0 sample
  (torque, work, contact all zero, like the project's `StepInfo::default()`);
* per-step bookkeeping: positive work += max(τ·q̇⁺, 0)·dt with τ the actuator torque
  applied during the step and q̇⁺ the hip rate after it; peak |τ| since the last sample;
* fall checks at every sample (hip z < fall_hip_height_over_l·L, |roll|, |pitch|);
* `analyze` is a line-by-line port of walk.rs `analyze` (Poincaré convergence, window,
  per-cycle attitude peak-to-peak, speed along the circular-mean heading, steps at 75 %
  load share, work, CoT, peak torque).
"""

from __future__ import annotations

import bisect
import math
import time

import numpy as np

from design import GRAVITY_MPS2, Model, rot_y, rpy_matrix, touch_height, design_sinkage_m
from drake_model import DrakeWalker

STANCE_LOAD_SHARE = 0.75

CSV_HEADER = ("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,hip_angle_deg,hip_torque_nm,"
              "peak_abs_torque_nm,positive_work_j,feet_in_contact,left_normal_force_n,"
              "right_normal_force_n")
FIELDS = CSV_HEADER.split(",")


def hip_frame_attitude(R_left: np.ndarray, q: float):
    """walk.rs `hip_frame_attitude`: R = R_left·R_y(q/2); (roll, pitch, yaw) [rad]."""
    r = R_left @ rot_y(0.5 * q)
    pitch = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    roll = math.atan2(r[2, 1], r[2, 2])
    yaw = math.atan2(r[1, 0], r[0, 0])
    return roll, pitch, yaw


def initial_pose(model: Model, roll_deg: float, pitch_deg: float = 0.0, yaw_deg: float = 0.0,
                 placement: str = "design", sink_m: float | None = None):
    """`Design::initial_state` (without seed): hip placed so the lowest foot just touches,
    then lowered by sqrt(m g/(π E)) ('design'); 'touch' = not lowered; 'sink' = lowered
    by `sink_m`."""
    R = rpy_matrix(math.radians(roll_deg), math.radians(pitch_deg), math.radians(yaw_deg))
    z = touch_height(model, R)
    if placement == "design":
        z -= design_sinkage_m(model)
    elif placement == "sink":
        z -= float(sink_m)
    elif placement != "touch":
        raise ValueError(f"unknown placement {placement!r}")
    return np.array([0.0, 0.0, z]), R


class Recorder:
    """Samples in the project's trajectory format (dicts keyed by the CSV header)."""

    def __init__(self):
        self.samples = []
        self._yaw_prev = 0.0
        self._yaw_unwrapped = 0.0

    def push(self, t, p, R, q, torque, peak, work, feet, fz):
        roll, pitch, yaw = hip_frame_attitude(R, q)
        dy = yaw - self._yaw_prev
        dy -= round(dy / math.tau) * math.tau
        self._yaw_unwrapped += dy
        self._yaw_prev = yaw
        self.samples.append({
            "t_s": t, "x_m": float(p[0]), "y_m": float(p[1]), "z_m": float(p[2]),
            "roll_deg": math.degrees(roll), "pitch_deg": math.degrees(pitch),
            "yaw_deg": math.degrees(self._yaw_unwrapped), "hip_angle_deg": math.degrees(q),
            "hip_torque_nm": torque, "peak_abs_torque_nm": peak, "positive_work_j": work,
            "feet_in_contact": int(feet), "left_normal_force_n": float(fz[0]),
            "right_normal_force_n": float(fz[1]),
        })
        return self.samples[-1]


def run_walk(model: Model, duration_s: float, resolution_hint_over_l: float = 0.06,
             time_step_s: float | None = None, initial_roll_deg: float | None = None,
             progress: bool = False, servo: str = "auto", approximation: str | None = None):
    """Runs the walk; returns dict(samples, fall, wall_s, steps, dt, record_every, contact
    statistics)."""
    walker = DrakeWalker(model, resolution_hint_over_l=resolution_hint_over_l,
                         time_step_s=time_step_s, servo=servo, approximation=approximation)
    dt = walker.time_step_s
    freq = model.controller.get("frequency_hz", 1.0)
    steps = int(round(duration_s / dt))
    record_every = max(1, int(math.floor((1.0 / freq) / (200.0 * dt))))
    roll0 = model.initial_roll_deg if initial_roll_deg is None else initial_roll_deg
    p0, R0 = initial_pose(model, roll0)
    walker.set_state(p0, R0)
    rec = Recorder()
    rec.push(0.0, p0, R0, 0.0, 0.0, 0.0, 0.0, 0, [0.0, 0.0])
    crit = model.criteria
    L = model.leg_length_m
    work = 0.0
    peak = 0.0
    fall = None
    faces_hist = []
    t_start = time.perf_counter()
    for i in range(1, steps + 1):
        tau, _hs, _tc = walker.step()
        qd = walker.hip_rate()
        work += max(tau * qd, 0.0) * dt
        peak = max(peak, abs(tau))
        if i % record_every == 0 or i == steps:
            p, R, q, qd_, _w, _v = walker.pose()
            t = round(i * dt, 12)
            if not (np.all(np.isfinite(p)) and np.all(np.isfinite(R)) and math.isfinite(q)
                    and math.isfinite(qd_)):
                fall = ("diverged", t)
                break
            feet, fz, faces, _area, _f = walker.contact()
            faces_hist.append(faces)
            last = rec.push(t, p, R, q, tau, peak, work, feet, fz)
            peak = 0.0
            reason = None
            if last["z_m"] < crit["fall_hip_height_over_l"] * L:
                reason = "hip_low"
            elif abs(last["roll_deg"]) > crit["fall_roll_deg"]:
                reason = "roll"
            elif abs(last["pitch_deg"]) > crit["fall_pitch_deg"]:
                reason = "pitch"
            if reason is not None:
                fall = (reason, t)
                break
            if progress and (i // record_every) % 500 == 0:
                print(f"  t = {t:.2f} s", flush=True)
    wall = time.perf_counter() - t_start
    fh = np.array(faces_hist) if faces_hist else np.zeros((0, 2))
    loaded = fh[fh > 0] if fh.size else np.zeros(0)
    return {
        "samples": rec.samples, "fall": fall, "wall_s": wall, "steps": steps, "dt": dt,
        "record_every": record_every, "simulated_s": rec.samples[-1]["t_s"],
        "polygons_per_loaded_foot": {
            "mean": float(loaded.mean()) if loaded.size else None,
            "min": int(loaded.min()) if loaded.size else None,
            "max": int(loaded.max()) if loaded.size else None,
        },
        "walker": walker,
    }


# ----------------------------------------------------------------------------- analysis
def _times(samples):
    return [s["t_s"] for s in samples]


def interp(samples, times, t, key):
    i = bisect.bisect_left(times, t)
    if i == 0:
        return samples[0][key]
    if i >= len(samples):
        return samples[-1][key]
    a, b = samples[i - 1], samples[i]
    w = (t - a["t_s"]) / (b["t_s"] - a["t_s"])
    return a[key] * (1.0 - w) + b[key] * w


def cycle_range(samples, times, t0, t1, f):
    i0 = bisect.bisect_left(times, t0)
    i1 = bisect.bisect_right(times, t1)
    lo, hi = math.inf, -math.inf
    for s in samples[i0:max(i1, i0)]:
        v = f(s)
        lo = min(lo, v)
        hi = max(hi, v)
    return lo, hi


def mean_sd(v):
    if not v:
        return math.nan, math.nan
    n = len(v)
    m = sum(v) / n
    var = sum((x - m) ** 2 for x in v) / (n - 1) if n > 1 else 0.0
    return m, math.sqrt(var)


def detect_convergence(samples, times, freq, t_end):
    period = 1.0 / freq
    n = int(math.floor(t_end / period))
    if n < 5:
        return None
    w = math.tau * freq
    h = 0.01 * period
    pts, amp = [], []
    for k in range(n):
        t = k * period
        p = interp(samples, times, t, "pitch_deg")
        rate = (interp(samples, times, t + h, "pitch_deg")
                - interp(samples, times, max(t - h, 0.0), "pitch_deg")) / (2.0 * h)
        pts.append((p, rate / w))
        lo, hi = cycle_range(samples, times, t, t + period, lambda s: s["pitch_deg"])
        amp.append(max(hi - lo, 1.0))

    def close(a, b):
        (pa, ra), (pb, rb) = pts[a], pts[b]
        return math.hypot(pa - pb, ra - rb) <= 0.1 * amp[b]

    for k in range(2, max(n - 3, 0)):
        if all(close(j, j - 1) for j in range(k, k + 3)) or \
                all(close(j, j - 2) for j in range(k, k + 3)):
            return (k - 1) * period
    return None


def analyze(samples, *, name, leg_length_m, mass_kg, freq, torque_limit_nm, duration_s,
            time_step_s, walk_speed_threshold_over_sqrt_gl, fall=None,
            mass_law="l2", contact_scaling="similar"):
    """walk.rs `analyze` on a list of samples (NaN where undefined)."""
    L, m = leg_length_m, mass_kg
    period = 1.0 / freq
    times = _times(samples)
    t_end = samples[-1]["t_s"] if samples else 0.0
    converged = detect_convergence(samples, times, freq, t_end) if fall is None else None
    start = converged if converged is not None else 0.5 * t_end
    cycles = max(int(math.floor((t_end - start) / period)), 0)
    stop = start + cycles * period
    nan = math.nan
    r = {
        "design": name, "leg_length_m": L, "mass_kg": m, "mass_law": mass_law,
        "contact_scaling": contact_scaling, "drive_frequency_hz": freq,
        "torque_limit_nm": torque_limit_nm, "duration_s": duration_s,
        "time_step_s": time_step_s, "seed": None, "walks": False,
        "fall_reason": fall[0] if fall else None, "fell_at_s": fall[1] if fall else None,
        "converged_at_s": converged, "window_start_s": start, "cycles": cycles,
        "velocity_mps": nan, "froude": nan, "step_frequency_hz": nan,
        "roll_pp_deg": nan, "roll_pp_deg_sd": nan, "pitch_pp_deg": nan,
        "pitch_pp_deg_sd": nan, "yaw_pp_deg": nan, "yaw_pp_deg_sd": nan,
        "turning_deg_per_m": nan, "mechanical_work_j": nan, "cot": nan,
        "peak_torque_nm": nan,
    }
    if fall is not None or cycles < 2:
        return r
    i0 = bisect.bisect_left(times, start)
    i1 = bisect.bisect_right(times, stop + 1e-9)
    win = samples[i0:i1]
    if len(win) < 3:
        return r
    pp = [[], [], []]
    for c in range(cycles):
        t0 = start + c * period
        t1 = t0 + period
        lo, hi = cycle_range(samples, times, t0, t1, lambda s: s["roll_deg"])
        pp[0].append(hi - lo)
        lo, hi = cycle_range(samples, times, t0, t1, lambda s: s["pitch_deg"])
        pp[1].append(hi - lo)
        y0 = interp(samples, times, t0, "yaw_deg")
        y1 = interp(samples, times, t1, "yaw_deg")
        lo, hi = cycle_range(samples, times, t0, t1,
                             lambda s: s["yaw_deg"] - y0 - (y1 - y0) * (s["t_s"] - t0) / period)
        pp[2].append(hi - lo)
    r["roll_pp_deg"], r["roll_pp_deg_sd"] = mean_sd(pp[0])
    r["pitch_pp_deg"], r["pitch_pp_deg_sd"] = mean_sd(pp[1])
    r["yaw_pp_deg"], r["yaw_pp_deg_sd"] = mean_sd(pp[2])
    sx = sum(math.cos(math.radians(s["yaw_deg"])) for s in win)
    sy = sum(math.sin(math.radians(s["yaw_deg"])) for s in win)
    heading = math.atan2(sy, sx)
    a, b = win[0], win[-1]
    dt = b["t_s"] - a["t_s"]
    dx, dy = b["x_m"] - a["x_m"], b["y_m"] - a["y_m"]
    forward = dx * math.cos(heading) + dy * math.sin(heading)
    r["velocity_mps"] = forward / dt
    r["froude"] = r["velocity_mps"] / math.sqrt(GRAVITY_MPS2 * L)
    distance = math.hypot(dx, dy)
    r["turning_deg_per_m"] = (b["yaw_deg"] - a["yaw_deg"]) / distance if distance > 0 else nan
    stance = None
    crossings = 0
    for s in win:
        f = (s["left_normal_force_n"], s["right_normal_force_n"])
        total = f[0] + f[1]
        if total < 0.2 * m * GRAVITY_MPS2:
            continue
        now = next((k for k in range(2) if f[k] > STANCE_LOAD_SHARE * total), None)
        if now is not None:
            if stance is not None and stance != now:
                crossings += 1
            stance = now
    r["step_frequency_hz"] = crossings / dt
    r["mechanical_work_j"] = b["positive_work_j"] - a["positive_work_j"]
    r["cot"] = r["mechanical_work_j"] / (m * GRAVITY_MPS2 * distance) if distance > 0 else nan
    r["peak_torque_nm"] = max([s["peak_abs_torque_nm"] for s in win[1:]] + [0.0])
    r["walks"] = bool(r["velocity_mps"] > walk_speed_threshold_over_sqrt_gl
                      * math.sqrt(GRAVITY_MPS2 * L))
    return r


# ----------------------------------------------------------------------------- output
def decimate(samples, factor: int):
    """Keeps sample 0, every `factor`-th sample after it and the last one; the kept
    sample's peak_abs_torque_nm becomes the max over the samples it now stands for (so it
    still means 'largest |hip torque| since the previous (kept) sample')."""
    if factor <= 1:
        return [dict(s) for s in samples]
    out = [dict(samples[0])]
    peak = 0.0
    n = len(samples)
    for j in range(1, n):
        peak = max(peak, samples[j]["peak_abs_torque_nm"])
        if j % factor == 0 or j == n - 1:
            s = dict(samples[j])
            s["peak_abs_torque_nm"] = peak
            out.append(s)
            peak = 0.0
    return out


def _fmt(v):
    """Integers as such, floats with 10 significant digits (sub-nm, sub-µN at these sizes)."""
    if isinstance(v, int):
        return str(v)
    return f"{float(v):.10g}"


def write_csv(samples, path):
    with open(path, "w", newline="\n") as f:
        f.write(CSV_HEADER + "\n")
        for s in samples:
            f.write(",".join(_fmt(s[k]) for k in FIELDS) + "\n")


def read_csv(path):
    out = []
    with open(path) as f:
        header = f.readline().strip().split(",")
        assert header == FIELDS, header
        for line in f:
            vals = line.strip().split(",")
            d = {k: float(v) for k, v in zip(header, vals)}
            d["feet_in_contact"] = int(d["feet_in_contact"])
            out.append(d)
    return out
