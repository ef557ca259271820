"""Project walker designs (TOML) for the Drake harness.

Mirrors `src/sim/design.rs` (schema, `Design::scaled`, `Design::model`,
`Design::controller`, `Design::initial_state`) so the Drake model is built from the same
file as the project's own simulator. Everything is SI; angles in the TOML are degrees.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

GRAVITY_MPS2 = 9.81

REPO_ROOT = Path(__file__).resolve().parents[2]


class DesignError(ValueError):
    """A design the harness cannot (or will not) model."""


def load_toml(path: str | Path) -> dict:
    p = Path(path)
    if not p.is_absolute() and not p.exists():
        p = REPO_ROOT / p
    with open(p, "rb") as f:
        return tomllib.load(f)


def apply_overrides(design: dict, overrides: dict, remove=()) -> dict:
    """Returns a copy of `design` with dotted keys in `remove` deleted, then dotted-key
    overrides applied ("a.b" = v sets design["a"]["b"] = v; a missing table is created)."""
    d = copy.deepcopy(design)
    for key in remove:
        parts = key.split(".")
        node = d
        for p in parts[:-1]:
            node = node.get(p, {})
        node.pop(parts[-1], None)
    for key, value in overrides.items():
        parts = key.split(".")
        node = d
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = copy.deepcopy(value)
    return d


def contact_dissipation_kind(design: dict) -> str:
    """'kelvin_voigt' (contact.relaxation_time_s) or 'hunt_crossley'
    (contact.hunt_crossley_dissipation_s_per_m)."""
    c = design["contact"]
    has_kv = "relaxation_time_s" in c
    has_hc = "hunt_crossley_dissipation_s_per_m" in c
    if has_kv and has_hc:
        raise DesignError(
            "contact has both relaxation_time_s and hunt_crossley_dissipation_s_per_m; "
            "the dissipation model is ambiguous"
        )
    if not (has_kv or has_hc):
        raise DesignError("contact needs relaxation_time_s or hunt_crossley_dissipation_s_per_m")
    return "kelvin_voigt" if has_kv else "hunt_crossley"


def check_supported(design: dict) -> None:
    g = design["geometry"]
    if g.get("foot_section_cut_over_l") is not None:
        raise DesignError(
            "geometry.foot_section_cut_over_l is set: the Drake harness models whole "
            "ellipsoid feet only (Drake has no clipped-ellipsoid hydroelastic primitive)"
        )
    if design.get("effects"):
        raise DesignError("design has [[effects]]; the Drake harness does not model them")
    kind = design["control"]["kind"]
    if kind not in ("servo_sine", "bang_bang"):
        raise DesignError(f"unknown control kind {kind!r}")
    contact_dissipation_kind(design)


def scaled(design: dict, leg_length_m: float, mass_law: str = "l2",
           contact_scaling: str = "similar") -> dict:
    """`Design::scaled`: lengths ∝ s, mass ∝ s² (l2) or s³ (l3), frequency ∝ s^-1/2,
    torque ∝ m·L, time step ∝ s^1/2; contact 'similar': E ∝ m/L², HC d ∝ s^-1/2,
    relaxation time ∝ s^1/2; 'fixed-material': E, d, relaxation time unchanged.
    The stiction speed (a regularisation) scales ∝ s^1/2 in both cases."""
    if not (leg_length_m > 0 and math.isfinite(leg_length_m)):
        raise DesignError(f"leg_length_m must be finite and > 0, got {leg_length_m}")
    d = copy.deepcopy(design)
    s = leg_length_m / design["geometry"]["leg_length_m"]
    mexp = {"l2": 2.0, "l3": 3.0}[mass_law]
    mu = s ** mexp
    time = math.sqrt(s)
    g = d["geometry"]
    g["leg_length_m"] *= s
    g["body_length_m"] *= s
    g["foot_semi_axes_m"] = [a * s for a in g["foot_semi_axes_m"]]
    d["mass"]["total_mass_kg"] *= mu
    c = d["contact"]
    if contact_scaling == "similar":
        c["hydroelastic_modulus_pa"] *= mu / (s * s)
        if "hunt_crossley_dissipation_s_per_m" in c:
            c["hunt_crossley_dissipation_s_per_m"] /= time
        if "relaxation_time_s" in c:
            c["relaxation_time_s"] *= time
    elif contact_scaling != "fixed-material":
        raise DesignError(f"unknown contact scaling {contact_scaling!r}")
    c["stiction_speed_mps"] *= time
    ctl = d["control"]
    ctl["frequency_hz"] /= time
    if ctl["kind"] == "servo_sine":
        ctl["torque_limit_nm"] *= mu * s
    else:
        ctl["torque_nm"] *= mu * s
    d["numerics"]["time_step_s"] *= time
    return d


@dataclass
class Leg:
    mass_kg: float
    com_m: np.ndarray            # leg frame (origin at the hip point)
    inertia_diag_kgm2: np.ndarray  # about the COM, leg axes
    foot_center_m: np.ndarray    # leg frame
    foot_semi_axes_m: np.ndarray


@dataclass
class Model:
    """What `Design::model()` + `Design::controller()` produce, as plain numbers."""
    name: str
    leg_length_m: float
    legs: list                   # [left, right]
    modulus_pa: float
    dissipation_kind: str        # 'kelvin_voigt' | 'hunt_crossley'
    relaxation_time_s: float | None
    hunt_crossley_s_per_m: float | None
    friction_mu: float
    stiction_speed_mps: float
    hardstop: dict | None        # limit_rad, stiffness_nm_per_rad, damping_nms_per_rad
    gravity_mps2: np.ndarray
    ground_contact: bool
    controller: dict             # kind + gains (SI, radians)
    time_step_s: float
    criteria: dict
    initial_roll_deg: float
    slope_deg: float
    extra: dict = field(default_factory=dict)

    @property
    def total_mass_kg(self) -> float:
        return self.legs[0].mass_kg + self.legs[1].mass_kg

    @property
    def mgl_nm(self) -> float:
        return self.total_mass_kg * GRAVITY_MPS2 * self.leg_length_m


def build_model(design: dict, gravity_mps2: float = GRAVITY_MPS2,
                ground_contact: bool = True) -> Model:
    check_supported(design)
    g = design["geometry"]
    m = design["mass"]
    L = g["leg_length_m"]
    leg_mass = 0.5 * m["total_mass_kg"]
    b = [x * L for x in m["leg_inertia_box_over_l"]]
    inertia = np.array([
        leg_mass / 12.0 * (b[1] ** 2 + b[2] ** 2),
        leg_mass / 12.0 * (b[0] ** 2 + b[2] ** 2),
        leg_mass / 12.0 * (b[0] ** 2 + b[1] ** 2),
    ])
    semi = np.array(g["foot_semi_axes_m"], dtype=float)

    def leg(side: float) -> Leg:
        return Leg(
            mass_kg=leg_mass,
            com_m=np.array([m.get("leg_com_forward_over_l", 0.0) * L,
                            side * g["hip_half_width_over_l"] * L,
                            -(1.0 - m["leg_com_height_over_l"]) * L]),
            inertia_diag_kgm2=inertia.copy(),
            foot_center_m=np.array([g.get("foot_center_forward_over_l", 0.0) * L,
                                    side * g["foot_center_lateral_over_l"] * L,
                                    -L + semi[2]]),
            foot_semi_axes_m=semi.copy(),
        )

    total = m["total_mass_kg"]
    mgl = total * GRAVITY_MPS2 * L
    tl = math.sqrt(L / GRAVITY_MPS2)
    hs = design.get("hardstop")
    hardstop = None
    if hs is not None:
        hardstop = dict(limit_rad=math.radians(hs["limit_deg"]),
                        stiffness_nm_per_rad=hs["stiffness_over_mgl"] * mgl,
                        damping_nms_per_rad=hs["damping_over_mgl_sqrt_l_over_g"] * mgl * tl)
    ctl = design["control"]
    if ctl["kind"] == "servo_sine":
        controller = dict(kind="servo_sine",
                          amplitude_rad=math.radians(ctl["amplitude_deg"]),
                          frequency_hz=ctl["frequency_hz"],
                          kp_nm_per_rad=ctl["kp_over_mgl"] * mgl,
                          kd_nms_per_rad=ctl["kd_over_mgl_sqrt_l_over_g"] * mgl * tl,
                          torque_limit_nm=ctl["torque_limit_nm"])
    else:
        controller = dict(kind="bang_bang", torque_nm=ctl["torque_nm"],
                          frequency_hz=ctl["frequency_hz"])
    slope = math.radians(design.get("ground", {}).get("slope_deg", 0.0))
    c = design["contact"]
    kind = contact_dissipation_kind(design)
    return Model(
        name=design["name"],
        leg_length_m=L,
        legs=[leg(1.0), leg(-1.0)],
        modulus_pa=c["hydroelastic_modulus_pa"],
        dissipation_kind=kind,
        relaxation_time_s=c.get("relaxation_time_s"),
        hunt_crossley_s_per_m=c.get("hunt_crossley_dissipation_s_per_m"),
        friction_mu=c["friction_mu"],
        stiction_speed_mps=c["stiction_speed_mps"],
        hardstop=hardstop,
        gravity_mps2=np.array([math.sin(slope), 0.0, -math.cos(slope)]) * gravity_mps2,
        ground_contact=ground_contact,
        controller=controller,
        time_step_s=design["numerics"]["time_step_s"],
        criteria=dict(design["criteria"]),
        initial_roll_deg=design["initial"]["roll_deg"],
        slope_deg=math.degrees(slope),
    )


def controller_torque(ctl: dict, t: float, q: float, qd: float) -> float:
    """`Controller::command(t, q, q̇).torque_nm`."""
    kind = ctl["kind"]
    if kind == "servo_sine":
        w = 2.0 * math.pi * ctl["frequency_hz"]
        q_d = ctl["amplitude_rad"] * math.sin(w * t)
        qd_d = ctl["amplitude_rad"] * w * math.cos(w * t)
        raw = -ctl["kp_nm_per_rad"] * (q - q_d) - ctl["kd_nms_per_rad"] * (qd - qd_d)
        lim = ctl["torque_limit_nm"]
        return raw if abs(raw) <= lim else math.copysign(lim, raw)
    if kind == "bang_bang":
        phase = math.modf(t * ctl["frequency_hz"])[0]
        return ctl["torque_nm"] if phase < 0.5 else -ctl["torque_nm"]
    if kind == "passive":
        return 0.0
    raise DesignError(f"unknown controller {kind!r}")


def hardstop_torque(hs: dict | None, q: float, qd: float) -> float:
    """Generalized force of the one-sided hip stops (model.rs): beyond |q| > limit,
    push = k·e + c·sign(q)·q̇ applied (as −sign(q)·push) only when push > 0."""
    if hs is None:
        return 0.0
    e = abs(q) - hs["limit_rad"]
    if e <= 0.0:
        return 0.0
    sign = math.copysign(1.0, q)
    push = hs["stiffness_nm_per_rad"] * e + hs["damping_nms_per_rad"] * sign * qd
    return -sign * push if push > 0.0 else 0.0


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy_matrix(roll, pitch, yaw):
    """nalgebra `UnitQuaternion::from_euler_angles(roll, pitch, yaw)` = Rz·Ry·Rx
    (= Drake's RollPitchYaw)."""
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def touch_height(model: Model, R: np.ndarray) -> float:
    """Lowest hip height at which every foot is at or above the ground (the highest
    foot-touch height over the legs), legs together (q = 0)."""
    nf = R.T @ np.array([0.0, 0.0, 1.0])
    hip_z = -math.inf
    for leg in model.legs:
        a = leg.foot_semi_axes_m
        support = math.sqrt(float(np.sum(a * a * nf * nf)))
        hip_z = max(hip_z, support - (R @ leg.foot_center_m)[2])
    return hip_z


def design_sinkage_m(model: Model) -> float:
    """The project's initial lowering: static sinkage of one sphere carrying the weight."""
    return math.sqrt(model.total_mass_kg * GRAVITY_MPS2 / (math.pi * model.modulus_pa))


def ellipsoid_force(E: float, semi, delta: float) -> float:
    """Normal force of a compliant ellipsoid (p = E(1 − r)) pressed upright by `delta`
    along its vertical semi-axis c on a rigid plane: (π/3)E·a·b·(1−r0)²(1+2r0)."""
    a, b, c = semi
    r0 = max(0.0, 1.0 - delta / c)
    if r0 >= 1.0:
        return 0.0
    return math.pi / 3.0 * E * a * b * (1 - r0) ** 2 * (1 + 2 * r0)


def solve_sinkage(E: float, semi, load_n: float) -> float:
    """Depth at which one upright ellipsoid carries `load_n` (bisection on the closed form)."""
    lo, hi = 0.0, float(semi[2])
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if ellipsoid_force(E, semi, mid) < load_n:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
