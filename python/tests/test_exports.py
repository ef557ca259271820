"""MuJoCo loads every design `survey sim export` writes, and its total mass, centre of mass and
inertia are the design's, computed here independently from the design TOML (each leg half the
mass, its COM at (f·L, ±w·L, −(1 − h)·L) from the hip, its inertia the uniform box of edges
b·L; scaled designs by L and m ∝ L² or L³)."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from conftest import REPO

mujoco = pytest.importorskip("mujoco")

DESIGNS = {
    "mugatu": "dataset/walkers/mugatu.toml",
    "zippy": "dataset/walkers/zippy.toml",
    "zippy-spherical": "dataset/walkers/zippy-spherical.toml",
    "mugatu-ref": "dataset/walkers/reference/mugatu-ref.toml",
    "mugatu-ref-sap": "dataset/walkers/reference/mugatu-ref-sap.toml",
    "zippy-ref": "dataset/walkers/reference/zippy-ref.toml",
    "zippy-spherical-ref": "dataset/walkers/reference/zippy-spherical-ref.toml",
}
# (leg length or None, mass law exponent)
SIZES = [(None, 2), (1.0, 2), (0.05, 3)]


def expected_bodies(design: str, leg_length, exponent):
    """[(mass, COM in the leg frame, inertia about the COM)] of the two legs, from the TOML."""
    with open(REPO / DESIGNS[design], "rb") as f:
        d = tomllib.load(f)
    l0 = d["geometry"]["leg_length_m"]
    s = 1.0 if leg_length is None else leg_length / l0
    L = l0 * s
    m = d["mass"]["total_mass_kg"] * s**exponent
    w = d["geometry"]["hip_half_width_over_l"]
    h = d["mass"]["leg_com_height_over_l"]
    fwd = d["mass"].get("leg_com_forward_over_l", 0.0)
    bx, by, bz = (e * L for e in d["mass"]["leg_inertia_box_over_l"])
    inertia = np.diag([by * by + bz * bz, bx * bx + bz * bz, bx * bx + by * by]) * (m / 2) / 12
    return [(m / 2, np.array([fwd * L, side * w * L, -(1 - h) * L]), inertia)
            for side in (1.0, -1.0)], m


@pytest.mark.parametrize("design", sorted(DESIGNS))
@pytest.mark.parametrize("size", SIZES, ids=["1x", "1m-l2", "5cm-l3"])
def test_mujoco_loads_the_export_with_the_designs_mass_com_and_inertia(cli, tmp_path, design, size):
    leg_length, exponent = size
    out = tmp_path / f"{design}.xml"
    args = ["sim", "export", "--design", design, "--out", str(out),
            "--mass-law", "l2" if exponent == 2 else "l3"]
    if leg_length is not None:
        args += ["--leg-length", str(leg_length)]
    cli.run(*args)
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    bodies, m = expected_bodies(design, leg_length, exponent)
    assert model.nq == 8 and model.nv == 7 and model.nu == 1
    assert model.body_subtreemass[1] == pytest.approx(m, rel=1e-12)
    # World pose of the hip frame (the base's), then the expected COM and inertia in the world.
    r0 = data.xmat[1].reshape(3, 3)
    p0 = data.xpos[1]
    coms = [p0 + r0 @ c for _, c, _ in bodies]
    com = sum(mk * c for (mk, _, _), c in zip(bodies, coms)) / m
    assert data.subtree_com[1] == pytest.approx(com, abs=1e-12 * max(1.0, np.abs(com).max()))
    expected_i = np.zeros((3, 3))
    for (mk, _, ic), c in zip(bodies, coms):
        d = c - com
        expected_i += r0 @ ic @ r0.T + mk * (d @ d * np.eye(3) - np.outer(d, d))
    got_i = np.zeros((3, 3))
    for b in (1, 2):
        rb = data.ximat[b].reshape(3, 3)
        ib = rb @ np.diag(model.body_inertia[b]) @ rb.T
        d = data.xipos[b] - data.subtree_com[1]
        got_i += ib + model.body_mass[b] * (d @ d * np.eye(3) - np.outer(d, d))
    scale = np.abs(expected_i).max()
    assert got_i == pytest.approx(expected_i, abs=1e-9 * scale)


def test_the_exported_servo_tracks_its_drive_in_mujoco(cli, tmp_path):
    """The position actuator with ctrl = A sin(wt) + (kd/kp) A w cos(wt) is the design's PD
    servo: held in the air (gravity off), the hip follows the sine with the PD law's own lag."""
    out = tmp_path / "m.xml"
    cli.run("sim", "export", "--design", "mugatu-ref", "--out", str(out))
    model = mujoco.MjModel.from_xml_path(str(out))
    model.opt.gravity[:] = 0.0
    model.geom_contype[:] = 0
    model.geom_conaffinity[:] = 0
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    a, f = math.radians(25.0), 1.4
    w = 2 * math.pi * f
    kp = model.actuator_gainprm[0, 0]
    kd = -model.actuator_biasprm[0, 2]
    q = []
    while data.time < 3.0:
        t = data.time
        data.ctrl[0] = a * (math.sin(w * t) + kd / kp * w * math.cos(w * t))
        mujoco.mj_step(model, data)
        q.append((data.time, data.qpos[7]))
    tail = [(t, x) for t, x in q if t > 2.0]
    amp = max(abs(x) for _, x in tail)
    # In free flight the legs counter-rotate; the relative angle still follows the servo's sine.
    assert amp == pytest.approx(a, rel=0.05)
