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
    check_effects(design.get("effects", []), "design [[effects]]")
    kind = design["control"]["kind"]
    if kind not in ("servo_sine", "bang_bang"):
        raise DesignError(f"unknown control kind {kind!r}")
    contact_dissipation_kind(design)


# ------------------------------------------------------------------------------ effects
# The physical effects of `src/sim/effects.rs` (`EffectSpec`) the harness models, with their
# fields in the order of the Rust enum variant (the first is the magnitude, as in
# dataset/effects/NAME.toml). The others (motor_torque_speed, actuation_latency, hip_backlash,
# rolling_resistance) are refused.
SUPPORTED_EFFECTS = {
    "hip_viscous_damping": ("damping_nms_per_rad",),
    "hip_coulomb_friction": ("friction_torque_nm", "stiction_rate_rad_s"),
    "soft_ground": ("ground_modulus_pa",),
    "friction_coefficient": ("friction_mu",),
}

EFFECTS_DIR = REPO_ROOT / "dataset" / "effects"


def _effect_library_names() -> list:
    return sorted(p.stem for p in EFFECTS_DIR.glob("*.toml"))


def check_effect(spec: dict, origin: str = "effect") -> dict:
    """`EffectSpec` deserialisation + `validate`: tag `effect`, exactly the variant's fields
    (serde `deny_unknown_fields`, no defaults), finite values with the Rust sign checks.
    Returns a clean copy {effect, field: float, ...}."""
    if not isinstance(spec, dict) or "effect" not in spec:
        raise DesignError(f"{origin}: an effect entry needs an 'effect' tag, got {spec!r}")
    name = spec["effect"]
    if name not in SUPPORTED_EFFECTS:
        known = _effect_library_names()
        what = ("is in the project's library but not modelled by the Drake harness"
                if name in known else "is not an effect of the project's library")
        raise DesignError(
            f"{origin}: effect {name!r} {what}; the Drake harness supports "
            + ", ".join(SUPPORTED_EFFECTS))
    fields = SUPPORTED_EFFECTS[name]
    extra = sorted(set(spec) - set(fields) - {"effect"})
    missing = [f for f in fields if f not in spec]
    if extra or missing:
        raise DesignError(
            f"{origin}: effect {name} takes exactly {', '.join(fields)}"
            + (f"; unknown {', '.join(extra)}" if extra else "")
            + (f"; missing {', '.join(missing)}" if missing else ""))
    out = {"effect": name}
    for f in fields:
        v = spec[f]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise DesignError(f"{origin}: {name}.{f} = {v!r} is not a number")
        v = float(v)
        positive = f in ("stiction_rate_rad_s", "friction_mu", "ground_modulus_pa")
        ok = math.isfinite(v) and (v > 0.0 if positive else v >= 0.0)
        if not ok:
            raise DesignError(f"{origin}: {name}.{f} = {v} must be finite and "
                              + ("> 0" if positive else ">= 0"))
        out[f] = v
    return out


def check_effects(effects, origin: str = "effects") -> list:
    if not isinstance(effects, list):
        raise DesignError(f"{origin}: expected an array of tables ([[effects]])")
    return [check_effect(e, f"{origin}[{i}]") for i, e in enumerate(effects)]


def scaled_effect(spec: dict, length_ratio: float, mass_ratio: float,
                  contact_scaling: str) -> dict:
    """`EffectSpec::scaled`: torques ∝ m·L (m·g·L), viscous damping ∝ m·L·√L
    (m·g·L·√(L/g)), rates ∝ 1/√L, μ unchanged, ground modulus as the foot's (∝ m/L² when
    'similar', unchanged for 'fixed-material')."""
    torque = mass_ratio * length_ratio
    time = math.sqrt(length_ratio)
    e = dict(spec)
    name = e["effect"]
    if name == "hip_viscous_damping":
        e["damping_nms_per_rad"] = spec["damping_nms_per_rad"] * torque * time
    elif name == "hip_coulomb_friction":
        e["friction_torque_nm"] = spec["friction_torque_nm"] * torque
        e["stiction_rate_rad_s"] = spec["stiction_rate_rad_s"] / time
    elif name == "soft_ground":
        if contact_scaling == "similar":
            e["ground_modulus_pa"] = spec["ground_modulus_pa"] * mass_ratio / (
                length_ratio * length_ratio)
    elif name != "friction_coefficient":
        raise DesignError(f"effect {name!r} cannot be scaled by the Drake harness")
    return e


def effect_definition(name: str) -> dict:
    """dataset/effects/NAME.toml (the project's effect library)."""
    p = EFFECTS_DIR / f"{name}.toml"
    if not p.exists():
        raise DesignError(f"unknown effect {name!r}; the library has "
                          + ", ".join(_effect_library_names()))
    with open(p, "rb") as f:
        return tomllib.load(f)


def scale_unit_value(scale: str, design: dict) -> float:
    """`ParamScale::value` for `design` at its own size."""
    L = design["geometry"]["leg_length_m"]
    mgl = design["mass"]["total_mass_kg"] * GRAVITY_MPS2 * L
    tl = math.sqrt(L / GRAVITY_MPS2)
    table = {
        "none": 1.0, "mgl": mgl, "mgl_sqrt_l_over_g": mgl * tl, "sqrt_g_over_l": 1.0 / tl,
        "sqrt_l_over_g": tl, "leg_length": L,
        "foot_modulus": design["contact"]["hydroelastic_modulus_pa"],
    }
    if scale not in table:
        raise DesignError(f"unknown parameter scale {scale!r}")
    return table[scale]


def parse_effect_args(design: dict, args) -> list:
    """`src/gap/library.rs` `parse_effect_args`: 'NAME=VALUE' sets the effect's first
    parameter (its magnitude), 'NAME.PARAM=VALUE' one parameter; values in SI at the 1×
    `design`; the other parameters at the library default (in scale units) × the scale unit
    of `design`. One setting per effect named, in the order first named. Returns
    [(name, nondimensional values)] (scale units, like the Rust `EffectSetting`)."""
    out = []
    for a in args or []:
        if "=" not in a:
            raise DesignError(f"--effect {a}: expected NAME=VALUE or NAME.PARAM=VALUE")
        key, value = a.split("=", 1)
        try:
            v = float(value.strip())
        except ValueError:
            raise DesignError(f"--effect {a}: {value!r} is not a number") from None
        if not math.isfinite(v):
            raise DesignError(f"--effect {a}: the value must be finite")
        if "." in key:
            name, param = (x.strip() for x in key.split(".", 1))
        else:
            name, param = key.strip(), None
        try:
            d = effect_definition(name)
        except DesignError as e:
            raise DesignError(f"--effect {a}: {e}") from None
        params = d["parameters"]
        if param is None:
            idx = 0
        else:
            names = [p["name"] for p in params]
            if param not in names:
                raise DesignError(f"--effect {a}: effect {name} has no parameter {param!r}; "
                                  f"it has {', '.join(names)}")
            idx = names.index(param)
        pos = next((i for i, (n, _) in enumerate(out) if n == name), None)
        if pos is None:
            out.append((name, [float(p["default"]) for p in params]))
            pos = len(out) - 1
        out[pos][1][idx] = v / scale_unit_value(params[idx]["scale"], design)
        effect_spec(design, *out[pos], origin=f"--effect {a}")
    return out


def effect_spec(design: dict, name: str, nondimensional, origin: str = "effect") -> dict:
    """`EffectDef::spec`: the effect's fields in SI for `design` at its own size (value =
    nondimensional × scale unit), checked as the simulator checks them."""
    d = effect_definition(name)
    spec = {"effect": name}
    for p, v in zip(d["parameters"], nondimensional):
        spec[p["name"]] = v * scale_unit_value(p["scale"], design)
    return check_effect(spec, origin)


def scaled(design: dict, leg_length_m: float, mass_law: str = "l2",
           contact_scaling: str = "similar") -> dict:
    """`Design::scaled`: lengths ∝ s, mass ∝ s² (l2) or s³ (l3), frequency ∝ s^-1/2,
    torque ∝ m·L, time step ∝ s^1/2; contact 'similar': E ∝ m/L², HC d ∝ s^-1/2,
    relaxation time ∝ s^1/2; 'fixed-material': E, d, relaxation time unchanged.
    The stiction speed (a regularisation) scales ∝ s^1/2 in both cases. [[effects]] are
    scaled by `EffectSpec::scaled` (`scaled_effect`)."""
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
    if d.get("effects"):
        d["effects"] = [scaled_effect(check_effect(e), s, mu, contact_scaling)
                        for e in d["effects"]]
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
    # Effects ([[effects]] after scaling, `check_effect` form) and what they do here:
    effects: list = field(default_factory=list)
    hip_damping_nms_per_rad: float = 0.0   # Σ hip_viscous_damping (Drake joint damping)
    hip_coulomb: list = field(default_factory=list)  # [(τ_f, ω_s)] hip_coulomb_friction
    ground_modulus_pa: float | None = None  # soft_ground (series of all E_g); None = rigid
    # The contact modulus of the project's law (`apply_to_contact`: foot in series with the
    # soft ground); = modulus_pa without soft_ground. Used for the initial lowering.
    contact_modulus_pa: float | None = None

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
    effects = check_effects(design.get("effects", []), "design [[effects]]")
    mu = c["friction_mu"]
    e_contact = c["hydroelastic_modulus_pa"]
    inv_ground = 0.0
    damping = 0.0
    coulomb = []
    for e in effects:     # in order, like `apply_to_contact` (the last μ wins)
        if e["effect"] == "friction_coefficient":
            mu = e["friction_mu"]
        elif e["effect"] == "soft_ground":
            eg = e["ground_modulus_pa"]
            e_contact = e_contact * eg / (e_contact + eg)
            inv_ground += 1.0 / eg
        elif e["effect"] == "hip_viscous_damping":
            damping += e["damping_nms_per_rad"]
        elif e["effect"] == "hip_coulomb_friction":
            coulomb.append((e["friction_torque_nm"], e["stiction_rate_rad_s"]))
    return Model(
        name=design["name"],
        leg_length_m=L,
        legs=[leg(1.0), leg(-1.0)],
        modulus_pa=c["hydroelastic_modulus_pa"],
        dissipation_kind=kind,
        relaxation_time_s=c.get("relaxation_time_s"),
        hunt_crossley_s_per_m=c.get("hunt_crossley_dissipation_s_per_m"),
        friction_mu=mu,
        stiction_speed_mps=c["stiction_speed_mps"],
        hardstop=hardstop,
        gravity_mps2=np.array([math.sin(slope), 0.0, -math.cos(slope)]) * gravity_mps2,
        ground_contact=ground_contact,
        controller=controller,
        time_step_s=design["numerics"]["time_step_s"],
        criteria=dict(design["criteria"]),
        initial_roll_deg=design["initial"]["roll_deg"],
        slope_deg=math.degrees(slope),
        effects=effects,
        hip_damping_nms_per_rad=damping,
        hip_coulomb=coulomb,
        ground_modulus_pa=(1.0 / inv_ground) if inv_ground > 0.0 else None,
        contact_modulus_pa=e_contact,
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
    """The project's initial lowering: static sinkage of one sphere carrying the weight
    (with the contact modulus of the project's law, i.e. in series with a soft ground)."""
    e = model.contact_modulus_pa if model.contact_modulus_pa is not None else model.modulus_pa
    return math.sqrt(model.total_mass_kg * GRAVITY_MPS2 / (math.pi * e))


def hip_coulomb_torque(coulomb, qd: float) -> float:
    """`HipCoulombFriction`: Σ −τ_f·q̇/√(q̇² + ω_s²) (regularised below ω_s)."""
    tau = 0.0
    for tf, ws in coulomb:
        tau -= tf * qd / math.sqrt(qd * qd + ws * ws)
    return tau


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
