"""A walker exported by `survey sim export --format mjcf`, walked in MuJoCo.

The MJCF carries the design's drive in its `<custom>` data (`robot_survey:control.*`), so the
controls of a whole walk are known before it starts (the drive is open loop): a servo's target
ctrl(t) = A sin(wt) + (kd/kp) A w cos(wt) (MuJoCo's position actuator kp(ctrl - q) - kv q' is
then the design's PD law exactly), a bang-bang motor's +-tau0. `mujoco.rollout` steps the
model with them and returns every step's state and sensors (hip torque, each foot's normal
force from its touch sensor), from which the trajectory is sampled exactly as
`src/sim/walk.rs` samples its own: the t = 0 row, then every floor((1/f)/(200 dt)) steps and
the last step, with the peak |torque| since the previous row and the cumulative positive work.
"""

from __future__ import annotations

import math
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

CSV_HEADER = ("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,hip_angle_deg,hip_torque_nm,"
              "peak_abs_torque_nm,positive_work_j,feet_in_contact,left_normal_force_n,"
              "right_normal_force_n")
PREFIX = "robot_survey:"
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def survey_binary() -> str:
    """The project's binary: $SURVEY, else target/release/survey, else target/debug/survey."""
    env = os.environ.get("SURVEY")
    if env:
        return env
    for profile in ("release", "debug"):
        p = os.path.join(ROOT, "target", profile, "survey")
        if os.path.exists(p):
            return p
    raise SystemExit("no survey binary: run `cargo build --release` or set SURVEY")


def export(design: str, out: str, fmt: str = "mjcf", leg_length: float | None = None,
           mass_law: str = "l2", contact: str = "similar") -> str:
    """`survey sim export` of a design (a bundled name or a TOML path) into `out`."""
    cmd = [survey_binary(), "sim", "export", "--design", design, "--format", fmt, "--out", out,
           "--mass-law", mass_law, "--contact", contact]
    if leg_length is not None:
        cmd += ["--leg-length", repr(leg_length)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    return out


def custom(model: mujoco.MjModel) -> tuple[dict, dict]:
    """The export's `<custom>` numerics and texts, by design path."""
    nums, texts = {}, {}
    for i in range(model.nnumeric):
        name = model.numeric(i).name
        if name.startswith(PREFIX):
            nums[name[len(PREFIX):]] = float(model.numeric(i).data[0])
    raw = bytes(model.text_data)
    for i in range(model.ntext):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_TEXT, i)
        if name and name.startswith(PREFIX):
            a, n = int(model.text_adr[i]), int(model.text_size[i])
            texts[name[len(PREFIX):]] = raw[a:a + n].split(b"\0")[0].decode()
    return nums, texts


@dataclass
class Drive:
    kind: str
    frequency_hz: float
    amplitude_rad: float = 0.0
    kp: float = 0.0
    kd: float = 0.0
    torque_nm: float = 0.0

    def controls(self, nstep: int, dt: float) -> np.ndarray:
        """ctrl of every step k, applied from t = k dt (the start of the step, as the project)."""
        t = np.arange(nstep) * dt
        w = 2.0 * math.pi * self.frequency_hz
        if self.kind == "servo_sine":
            lead = self.kd / self.kp if self.kp > 0 else 0.0
            u = self.amplitude_rad * (np.sin(w * t) + lead * w * np.cos(w * t))
        else:
            phase = np.mod(t * self.frequency_hz, 1.0)
            u = np.where(phase < 0.5, self.torque_nm, -self.torque_nm)
        return u.reshape(nstep, 1)


def drive_of(model: mujoco.MjModel, frequency_hz: float | None = None) -> Drive:
    nums, texts = custom(model)
    kind = texts.get("control.kind", "servo_sine")
    f = frequency_hz if frequency_hz is not None else nums["control.frequency_hz"]
    if kind == "servo_sine":
        a = model.actuator("hip")
        return Drive(kind, f, math.radians(nums["control.amplitude_deg"]),
                     kp=float(a.gainprm[0]), kd=float(-a.biasprm[2]))
    return Drive(kind, f, torque_nm=nums["control.torque_nm"])


def rot_y(q: float) -> np.ndarray:
    s, c = math.sin(q), math.cos(q)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def quat_matrix(q: np.ndarray) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, q)
    return m.reshape(3, 3)


def hip_attitude(quat_wxyz, hip_angle: float) -> tuple[float, float, float]:
    """walk.rs `hip_frame_attitude`: (roll, pitch, yaw) [rad] of R_left·R_y(q/2)."""
    r = quat_matrix(np.asarray(quat_wxyz, dtype=float)) @ rot_y(0.5 * float(hip_angle))
    return (math.atan2(r[2, 1], r[2, 2]), math.asin(max(-1.0, min(1.0, -r[2, 0]))),
            math.atan2(r[1, 0], r[0, 0]))


class Unwrap:
    """An angle unwrapped sample by sample (walk.rs unwraps yaw the same way)."""

    def __init__(self):
        self.prev = 0.0
        self.total = 0.0

    def __call__(self, a: float) -> float:
        d = a - self.prev
        d -= round(d / (2 * math.pi)) * 2 * math.pi
        self.total += d
        self.prev = a
        return self.total


@dataclass
class Walk:
    model_path: str
    drive: Drive
    dt: float
    nstep: int
    wall_s: float
    rows: list


@dataclass
class Prepared:
    """An export loaded at its initial keyframe with the controls of a whole walk."""
    model: mujoco.MjModel
    data: mujoco.MjData
    x0: np.ndarray
    dt: float
    nstep: int
    drive: Drive
    ctrl: np.ndarray


def prepare(model_path: str, duration_s: float, frequency_hz: float | None = None) -> Prepared:
    model = mujoco.MjModel.from_xml_path(model_path)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, x0, spec)
    dt = model.opt.timestep
    nstep = int(round(duration_s / dt))
    drive = drive_of(model, frequency_hz)
    return Prepared(model, data, x0, dt, nstep, drive, drive.controls(nstep, dt))


def walk(model_path: str, duration_s: float, frequency_hz: float | None = None) -> Walk:
    """One walk from the export's initial keyframe; `wall_s` is the rollout's time alone."""
    p = prepare(model_path, duration_s, frequency_hz)
    model, data, x0, dt, nstep, drive, ctrl = p.model, p.data, p.x0, p.dt, p.nstep, p.drive, p.ctrl
    t0 = time.perf_counter()
    state, sensor = rollout.rollout(model, data, x0[None, :], ctrl[None, :, :], nstep=nstep)
    wall = time.perf_counter() - t0
    rows = sample(model, drive, x0, state[0], sensor[0], dt)
    return Walk(model_path, drive, dt, nstep, wall, rows)


def sample(model, drive: Drive, x0: np.ndarray, state: np.ndarray, sensor: np.ndarray,
           dt: float) -> list:
    """The trajectory rows, sampled and accumulated as walk.rs does (the t = 0 row: the start
    with torque, work and contact zero, like the project's `StepInfo::default()`)."""
    # FULLPHYSICS state: time, qpos (7 + 1), qvel (6 + 1), ...
    nq, nv = model.nq, model.nv
    qpos = np.vstack([x0[None, 1:1 + nq], state[:, 1:1 + nq]])
    qvel = state[:, 1 + nq:1 + nq + nv]
    torque = sensor[:, 0]
    touch = sensor[:, 1:3]
    f = drive.frequency_hz
    every = max(1, int(math.floor((1.0 / f) / (200.0 * dt))))
    rows = []
    work = 0.0
    peak = 0.0
    unwrap = Unwrap()
    n = len(state)

    def row(k: int, tau: float, fl: float, fr: float) -> dict:
        q = qpos[k]
        roll, pitch, yaw = hip_attitude(q[3:7], q[7])
        return dict(t_s=k * dt, x_m=float(q[0]), y_m=float(q[1]), z_m=float(q[2]),
                    roll_deg=math.degrees(roll), pitch_deg=math.degrees(pitch),
                    yaw_deg=math.degrees(unwrap(yaw)), hip_angle_deg=math.degrees(float(q[7])),
                    hip_torque_nm=tau, peak_abs_torque_nm=peak, positive_work_j=work,
                    feet_in_contact=int(fl > 0.0) + int(fr > 0.0),
                    left_normal_force_n=fl, right_normal_force_n=fr)

    rows.append(row(0, 0.0, 0.0, 0.0))
    for k in range(n):
        tau = float(torque[k])
        work += max(tau * float(qvel[k, 6]), 0.0) * dt
        peak = max(peak, abs(tau))
        if (k + 1) % every and k != n - 1:
            continue
        rows.append(row(k + 1, tau, float(touch[k, 0]), float(touch[k, 1])))
        peak = 0.0
    return rows


def decimate(rows: list, keep_every: int = 5) -> list:
    """The t = 0 row, every `keep_every`-th row after it and the last, as the Drake goldens
    (tests/golden/drake/README.md): a kept row's peak |torque| is the largest over the rows it
    replaces; the other columns are instantaneous."""
    out = [rows[0]]
    peak = 0.0
    for i, r in enumerate(rows[1:], start=1):
        peak = max(peak, r["peak_abs_torque_nm"])
        if i % keep_every == 0 or i == len(rows) - 1:
            out.append(dict(r, peak_abs_torque_nm=peak))
            peak = 0.0
    return out


def write_csv(rows: list, path: str) -> None:
    """The project's trajectory CSV (10 significant digits)."""
    fields = CSV_HEADER.split(",")
    with open(path + ".tmp", "w") as f:
        f.write(CSV_HEADER + "\n")
        for r in rows:
            f.write(",".join(
                str(r[k]) if k == "feet_in_contact" else f"{r[k]:.10g}" for k in fields) + "\n")
    os.replace(path + ".tmp", path)


def temp_export(design: str, **kw) -> str:
    d = tempfile.mkdtemp(prefix="mujoco-walk-")
    return export(design, os.path.join(d, "walker.xml"), **kw)
