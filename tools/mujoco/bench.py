"""Speed, pair by pair: the same exported model, the same time step, one thread, in three
engines, with each engine's gait beside its figure.

    python tools/mujoco/bench.py --design mugatu-ref --duration 25 --walks 16 --out bench.json

* this simulator: `survey sim bench` (the design itself: what the export encodes);
* MuJoCo: the design's MJCF export, `mujoco.rollout` (one thread; then N rollouts on a thread
  pool of every core), its trajectory measured by `survey sim analyze`;
* Drake: the design's SDF export loaded by Drake's parser (hydroelastic; SAP, or `similar` for a
  Hunt–Crossley design as tools/drake/ does; the SDF's PD
  gains), the servo's target from Drake's C++ `Sine` source and the ground added as a rigid
  half space, so a walk is one `AdvanceTo` with no Python in the loop; N walks on every core
  are separate processes. Its state is logged by a C++ `VectorLogSink` and measured by
  `survey sim analyze` (no per-foot forces: its step frequency is not measured).

All three run in this one process, one after the other, so they share the machine's load.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import mujoco
import numpy as np
from mujoco import rollout

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import walker  # noqa: E402


def analyze(design: str, csv: str, frequency_hz: float, leg_length=None) -> dict:
    cmd = [walker.survey_binary(), "sim", "analyze", "--design", design, "--trajectory", csv,
           "--frequency", repr(frequency_hz), "--format", "json"]
    if leg_length is not None:
        cmd += ["--leg-length", repr(leg_length)]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def gait(r: dict) -> dict:
    keys = ["walks", "fall_reason", "velocity_mps", "step_frequency_hz", "roll_pp_deg",
            "pitch_pp_deg", "yaw_pp_deg"]
    return {k: r.get(k) for k in keys}


def bench_project(design: str, duration: float, walks: int, leg_length) -> dict:
    cmd = [walker.survey_binary(), "sim", "bench", "--design", design, "--duration",
           repr(duration), "--walks", str(walks), "--repeats", "5", "--format", "json"]
    if leg_length is not None:
        cmd += ["--leg-length", repr(leg_length)]
    r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return {"single_steps_per_s": r["single_best"]["steps_per_s"],
            "single_median_steps_per_s": r["single_median"]["steps_per_s"],
            "batch_steps_per_s": r["batch"]["steps_per_s"], "batch_threads": r["batch"]["threads"],
            "time_step_s": r["time_step_s"], "gait": gait(r["gait"])}


def bench_mujoco(xml: str, design: str, duration: float, walks: int, leg_length) -> dict:
    p = walker.prepare(xml, duration)
    model, data, x0, dt, nstep, drive, ctrl = p.model, p.data, p.x0, p.dt, p.nstep, p.drive, p.ctrl
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        state, sensor = rollout.rollout(model, data, x0[None, :], ctrl[None, :, :], nstep=nstep)
        best = min(best, time.perf_counter() - t0)
    rows = walker.sample(model, drive, x0, state[0], sensor[0], dt)
    with tempfile.TemporaryDirectory() as d:
        csv = os.path.join(d, "mj.csv")
        walker.write_csv(rows, csv)
        g = analyze(design, csv, drive.frequency_hz, leg_length)
    # The batch: N starts perturbed like the project's seeds (roll, pitch, yaw ±0.5°).
    rng = np.random.default_rng(1)
    starts = np.repeat(x0[None, :], walks, axis=0)
    for k in range(walks):
        q = starts[k, 4:8].copy()
        dq = np.zeros(4)
        mujoco.mju_euler2Quat(dq, np.radians(rng.uniform(-0.87, 0.87, 3)), "xyz")
        mujoco.mju_mulQuat(starts[k, 4:8], q, dq)
    controls = np.repeat(ctrl[None, :, :], walks, axis=0)
    nthread = os.cpu_count() or 1
    datas = [mujoco.MjData(model) for _ in range(nthread)]
    with rollout.Rollout(nthread=nthread) as r:
        t0 = time.perf_counter()
        r.rollout([model] * walks, datas, starts, controls, nstep=nstep)
        batch = time.perf_counter() - t0
    return {"single_steps_per_s": nstep / best, "batch_steps_per_s": walks * nstep / batch,
            "batch_threads": nthread, "time_step_s": dt, "gait": gait(g)}


def drake_walk(sdf: str, duration: float, drive: dict, log_every: int,
               contact_model: str = "hydroelastic"):
    """One Drake walk of the SDF export: (wall time of AdvanceTo, logged times, states).
    `contact_model` "point" keeps the model and ignores the feet's hydroelastic properties
    (Drake's point contact, MuJoCo's kind), to show where Drake's time goes."""
    from pydrake.geometry import AddRigidHydroelasticProperties, HalfSpace, ProximityProperties
    from pydrake.math import RigidTransform
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction,
                                         MultibodyPlantConfig)
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import (ConstantVectorSource, LogVectorOutput, Multiplexer,
                                            Sine)
    dt = drive["dt"]
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=dt, discrete_contact_approximation=drive["approximation"],
        contact_model=contact_model, stiction_tolerance=drive["stiction_mps"],
        contact_surface_representation="polygon"), builder)
    model = Parser(plant).AddModels(sdf)[0]
    props = ProximityProperties()
    AddRigidHydroelasticProperties(props)
    props.AddProperty("material", "coulomb_friction", CoulombFriction(drive["mu"], drive["mu"]))
    props.AddProperty("material", "relaxation_time", 0.0)
    plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform(), HalfSpace(), "ground",
                                    props)
    plant.Finalize()
    w = 2 * math.pi * drive["frequency_hz"]
    if drive["kind"] == "servo_sine":
        # q_d = A sin(w (t + dt)), its rate: SAP's PD acts on the end-of-step state.
        sine = builder.AddSystem(Sine(drive["amplitude_rad"], w, w * dt, 1, True))
        mux = builder.AddSystem(Multiplexer([1, 1]))
        builder.Connect(sine.get_output_port(0), mux.get_input_port(0))
        builder.Connect(sine.get_output_port(1), mux.get_input_port(1))
        builder.Connect(mux.get_output_port(0), plant.get_desired_state_input_port(model))
        zero = builder.AddSystem(ConstantVectorSource([0.0]))
        builder.Connect(zero.get_output_port(0), plant.get_actuation_input_port(model))
    logger = LogVectorOutput(plant.get_state_output_port(), builder, log_every * dt)
    diagram = builder.Build()
    sim = Simulator(diagram)
    ctx = sim.get_mutable_context()
    pc = plant.GetMyMutableContextFromRoot(ctx)
    base = plant.GetBodyByName("left_leg", model)
    q0 = drive["q0"]
    from pydrake.common.eigen_geometry import Quaternion
    from pydrake.math import RotationMatrix
    plant.SetFreeBodyPose(pc, base, RigidTransform(RotationMatrix(Quaternion(q0[3:7])), q0[0:3]))
    sim.Initialize()
    t0 = time.perf_counter()
    sim.AdvanceTo(duration)
    wall = time.perf_counter() - t0
    log = logger.FindLog(ctx)
    return wall, log.sample_times(), log.data(), plant.num_positions()


def _drake_batch_one(args):
    return drake_walk(*args)[0]


def bench_drake(sdf: str, xml: str, design: str, duration: float, walks: int, leg_length) -> dict:
    model = mujoco.MjModel.from_xml_path(xml)
    nums, texts = walker.custom(model)
    d = walker.drive_of(model)
    kind = texts.get("control.kind", "servo_sine")
    if kind != "servo_sine":
        return {"error": "the paired Drake run drives a servo (bang-bang needs a Python source)"}
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    q0 = np.array(data.qpos[:7])
    drive = {"kind": kind, "frequency_hz": d.frequency_hz, "amplitude_rad": d.amplitude_rad,
             "dt": model.opt.timestep, "mu": float(model.geom_friction[0, 0]), "q0": q0,
             # As tools/drake/: SAP for a Kelvin–Voigt design, `similar` for a Hunt–Crossley
             # one (SAP ignores the Hunt–Crossley dissipation).
             "approximation": "sap" if nums.get("contact.relaxation_time_s", 0.0) > 0 else "similar",
             "stiction_mps": nums.get("contact.stiction_speed_mps", 1e-4)}
    every = max(1, int(math.floor((1.0 / d.frequency_hz) / (200.0 * drive["dt"]))))
    walls = []
    for _ in range(3):
        wall, t, x, nq = drake_walk(sdf, duration, drive, every)
        walls.append(wall)
    nstep = int(round(duration / drive["dt"]))
    rows = []
    unwrap = walker.Unwrap()
    for k in range(len(t)):
        # Drake's free body: qw qx qy qz x y z, then the hip angle.
        q = x[:, k]
        roll, pitch, yaw = walker.hip_attitude(q[0:4], q[7])
        rows.append(dict(t_s=float(t[k]), x_m=q[4], y_m=q[5], z_m=q[6], roll_deg=math.degrees(roll),
                         pitch_deg=math.degrees(pitch), yaw_deg=math.degrees(unwrap(yaw)),
                         hip_angle_deg=math.degrees(q[7]), hip_torque_nm=0.0,
                         peak_abs_torque_nm=0.0, positive_work_j=0.0, feet_in_contact=0,
                         left_normal_force_n=0.0, right_normal_force_n=0.0))
    with tempfile.TemporaryDirectory() as tmp:
        csv = os.path.join(tmp, "drake.csv")
        walker.write_csv(rows, csv)
        g = analyze(design, csv, d.frequency_hz, leg_length)
    point = min(drake_walk(sdf, duration, drive, every, "point")[0] for _ in range(3))
    nproc = os.cpu_count() or 1
    t0 = time.perf_counter()
    with ProcessPoolExecutor(nproc) as ex:
        list(ex.map(_drake_batch_one, [(sdf, duration, drive, every)] * walks))
    batch = time.perf_counter() - t0
    return {"single_steps_per_s": nstep / min(walls), "batch_steps_per_s": walks * nstep / batch,
            "point_contact_single_steps_per_s": nstep / point,
            "approximation": drive["approximation"],
            "batch_threads": nproc, "time_step_s": drive["dt"], "gait": gait(g),
            "note": "step frequency not measured (no per-foot forces logged)"}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--design", default="mugatu-ref")
    p.add_argument("--leg-length", type=float)
    p.add_argument("--duration", type=float, default=25.0)
    p.add_argument("--walks", type=int, default=16)
    p.add_argument("--drake-walks", type=int, default=4,
                   help="walks of Drake's batch (each ~25 s of wall per simulated 25 s)")
    p.add_argument("--no-drake", action="store_true")
    p.add_argument("--out")
    a = p.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="bench-")
    xml = walker.export(a.design, os.path.join(tmp, "walker.xml"), leg_length=a.leg_length)
    sdf = walker.export(a.design, os.path.join(tmp, "walker.sdf"), fmt="sdf", leg_length=a.leg_length)
    out = {"design": a.design, "leg_length_m": a.leg_length, "duration_s": a.duration,
           "walks": a.walks, "mujoco": mujoco.__version__, "cpus": os.cpu_count(),
           "survey": walker.survey_binary()}
    out["project"] = bench_project(a.design, a.duration, a.walks, a.leg_length)
    print("project", json.dumps(out["project"]), flush=True)
    out["mujoco_rollout"] = bench_mujoco(xml, a.design, a.duration, a.walks, a.leg_length)
    print("mujoco", json.dumps(out["mujoco_rollout"]), flush=True)
    if not a.no_drake:
        import pydrake
        out["drake_version"] = getattr(pydrake, "__version__", "1.51.1")
        out["drake"] = bench_drake(sdf, xml, a.design, a.duration, a.drake_walks, a.leg_length)
        print("drake", json.dumps(out["drake"]), flush=True)
    if a.out:
        with open(a.out, "w") as f:
            json.dump(out, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
