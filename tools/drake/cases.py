"""Elementary cases (tests/golden/drake/cases.toml): Drake runs + analytic references."""

from __future__ import annotations

import math
import time

import numpy as np

import design as dz
from design import GRAVITY_MPS2
from drake_model import DrakeWalker
from walk import hip_frame_attitude

CASE_ORDER = ["sinkage_sphere", "sinkage_ellipsoid", "free_rocking", "rolling_incline",
              "spin_down", "slide", "creep", "servo_in_air"]


def load_cases(path) -> dict:
    return dz.load_toml(path)["cases"]


# ------------------------------------------------------------------------------ setup
def case_model(case: dict):
    d = dz.load_toml(case["design"])
    d = dz.apply_overrides(d, case.get("overrides", {}), case.get("remove", []))
    if case.get("effects"):
        # [[effects]] of the case (tests/golden/drake/gap/effect_cases.toml), SI, unscaled.
        d["effects"] = list(d.get("effects", [])) + [dict(e) for e in case["effects"]]
    drive = case.get("drive", "design")
    actuated = True
    if drive == "hold":
        if d["control"]["kind"] != "servo_sine":
            raise dz.DesignError("drive = 'hold' needs a servo_sine design")
        d["control"]["amplitude_deg"] = 0.0
    elif drive == "passive":
        actuated = False
    elif drive != "design":
        raise dz.DesignError(f"unknown drive {drive!r}")
    model = dz.build_model(d, gravity_mps2=case.get("gravity_mps2", GRAVITY_MPS2),
                           ground_contact=case.get("ground_contact", True))
    return d, model, actuated


def static_sinkage(model: dz.Model) -> float:
    """Closed-form depth at which the two upright feet share m|g_z| equally."""
    load = model.total_mass_kg * abs(model.gravity_mps2[2]) / 2.0
    e = model.contact_modulus_pa if model.contact_modulus_pa is not None else model.modulus_pa
    return dz.solve_sinkage(e, model.legs[0].foot_semi_axes_m, load)


def initial_state(model: dz.Model, init: dict):
    roll, pitch, yaw = (init.get(k, 0.0) for k in ("roll_deg", "pitch_deg", "yaw_deg"))
    R = dz.rpy_matrix(math.radians(roll), math.radians(pitch), math.radians(yaw))
    z = dz.touch_height(model, R)
    placement = init.get("placement", "design")
    if placement == "design":
        z -= dz.design_sinkage_m(model)
    elif placement == "static":
        if roll or pitch:
            raise dz.DesignError("placement 'static' is for upright starts")
        z -= static_sinkage(model)
    elif placement != "touch":
        raise dz.DesignError(f"unknown placement {placement!r}")
    v = np.array(init.get("linear_velocity_mps", [0, 0, 0]), dtype=float)
    w = np.array(init.get("angular_velocity_rad_s", [0, 0, 0]), dtype=float)
    qd0 = float(init.get("hip_rate_rad_s", 0.0))
    if qd0 != 0.0:
        # An internal impulse at the hip of the legs at rest: zero linear and angular momentum,
        # ν0 = M⁻¹ e_q q̇0/(M⁻¹)_qq (upright, q = 0: world = leg axes).
        if roll or pitch or yaw or v.any() or w.any():
            raise dz.DesignError("hip_rate_rad_s: for upright starts at rest only")
        _, M = effective_hip_inertia(model)
        col = np.linalg.solve(M, np.eye(7)[:, 6])
        nu = col * qd0 / col[6]
        v, w = nu[0:3], nu[3:6]
    return np.array([0.0, 0.0, z]), R, v, w, qd0


def run_trace(model, actuated, init, duration_s, hint_over_l=0.06, time_step_s=None,
              servo="auto", approximation=None):
    """Runs a case and records every step."""
    w = DrakeWalker(model, resolution_hint_over_l=hint_over_l, actuated=actuated,
                    time_step_s=time_step_s, servo=servo, approximation=approximation)
    p0, R0, v0, w0, qd0 = initial_state(model, init)
    w.set_state(p0, R0, hip_velocity_mps=v0, omega_left_body=w0, hip_rate=qd0)
    plant, pc = w.plant, w.plant_context
    dt = w.time_step_s
    n = int(round(duration_s / dt))
    rec = {k: [] for k in ("t", "p", "roll", "pitch", "yaw", "q", "qd", "omega", "v", "com",
                           "vcom", "feet", "fz", "faces", "area", "tau", "fxy")}

    def push(t, tau, contact):
        p, R, q, qd, om, v = w.pose()
        roll, pitch, yaw = hip_frame_attitude(R, q)
        rec["t"].append(t)
        rec["p"].append(p)
        rec["roll"].append(math.degrees(roll))
        rec["pitch"].append(math.degrees(pitch))
        rec["yaw"].append(math.degrees(yaw))
        rec["q"].append(q)
        rec["qd"].append(qd)
        rec["omega"].append(om)
        rec["v"].append(v)
        rec["com"].append(plant.CalcCenterOfMassPositionInWorld(pc))
        rec["vcom"].append(plant.CalcCenterOfMassTranslationalVelocityInWorld(pc))
        feet, fz, faces, area, force = contact
        rec["feet"].append(feet)
        rec["fz"].append(fz)
        rec["faces"].append(faces)
        rec["area"].append(area)
        rec["fxy"].append([force[0][:2], force[1][:2]])
        rec["tau"].append(tau)

    push(0.0, 0.0, (0, [0.0, 0.0], [0, 0], [0.0, 0.0], [np.zeros(3), np.zeros(3)]))
    t0 = time.perf_counter()
    for i in range(1, n + 1):
        tau, _hs, _ = w.step()
        push(i * dt, tau, w.contact())
    wall = time.perf_counter() - t0
    out = {k: np.array(v) for k, v in rec.items()}
    out["wall_s"] = wall
    out["dt"] = dt
    out["walker"] = w
    return out


# ------------------------------------------------------------------------------ helpers
def zero_crossings(t, y):
    out = []
    for i in range(1, len(y)):
        if (y[i - 1] > 0) != (y[i] > 0) and y[i - 1] != y[i]:
            out.append(t[i - 1] + (t[i] - t[i - 1]) * (0 - y[i - 1]) / (y[i] - y[i - 1]))
    return out


def positive_peaks(t, y):
    """Local maxima > 0 after t = 0, refined by a parabola through 3 samples."""
    pk = []
    for i in range(1, len(y) - 1):
        if y[i] > 0 and y[i] >= y[i - 1] and y[i] > y[i + 1]:
            a, b, c = y[i - 1], y[i], y[i + 1]
            den = a - 2 * b + c
            off = 0.5 * (a - c) / den if den != 0 else 0.0
            pk.append((t[i] + off * (t[i + 1] - t[i]), b - 0.25 * (a - c) * off))
    return pk


def line_fit(t, y):
    A = np.vstack([t, np.ones_like(t)]).T
    s, c = np.linalg.lstsq(A, y, rcond=None)[0]
    return s, c


def first_below(t, y, level):
    for i in range(1, len(y)):
        if y[i] <= level < y[i - 1] or (y[i] <= level and i == 1 and y[0] <= level):
            if y[i - 1] == y[i]:
                return t[i]
            return t[i - 1] + (t[i] - t[i - 1]) * (y[i - 1] - level) / (y[i - 1] - y[i])
    return None


def interp_at(t, y, tq):
    return float(np.interp(tq, t, y))


def leg_inertia_sum(model, axis):
    """Whole-robot inertia about the axis through the hip point (world axis index, upright,
    q = 0): Σ I_leg + m_leg·(distance of the leg COM from the axis)²."""
    tot = 0.0
    for leg in model.legs:
        c = leg.com_m
        d2 = sum(c[k] ** 2 for k in range(3) if k != axis)
        tot += leg.inertia_diag_kgm2[axis] + leg.mass_kg * d2
    return tot


def sphere_pressure(E, R, delta, rho):
    """Hydroelastic sphere p = E(1 - r) on the plane at depth delta, radius rho from the
    deepest point (exact)."""
    return np.maximum(E * (1.0 - np.sqrt((R - delta) ** 2 + rho ** 2) / R), 0.0)


def sphere_force(E, R, delta):
    return math.pi * E * delta ** 2 * (1.0 - 2.0 * delta / (3.0 * R))


def solve_sphere_sinkage(E, R, load):
    lo, hi = 0.0, R
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if sphere_force(E, R, mid) < load:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


# ------------------------------------------------------------------------------ analytics
def analytic_sinkage(model):
    W = model.total_mass_kg * GRAVITY_MPS2
    semi = model.legs[0].foot_semi_axes_m
    a, b, c = semi
    delta = dz.solve_sinkage(model.modulus_pa, semi, W / 2.0)
    out = {"sinkage_m": delta, "left_normal_force_n": W / 2.0, "right_normal_force_n": W / 2.0,
           "feet_in_contact": 2,
           "formula": "(pi/3) E a b (1 - r0)^2 (1 + 2 r0) = m g/2, r0 = 1 - delta/c"
                      + (" (sphere: pi E delta^2 (1 - 2 delta/(3R)))" if a == b == c else ""),
           "sinkage_pi_e_delta2_m": math.sqrt(W / 2.0 / (math.pi * model.modulus_pa * a * b / c ** 2)),
           "patch_radius_m": math.sqrt(a * b) * math.sqrt(1 - (1 - delta / c) ** 2)}
    return out


def rocker_params(model):
    leg = model.legs[0]
    L = model.leg_length_m
    m = model.total_mass_kg
    a, b, c = leg.foot_semi_axes_m
    R = b * b / c                  # lateral radius of curvature at the sole
    h = L + leg.com_m[2]           # COM height (upright)
    e = abs(leg.foot_center_m[1])  # lateral offset of each foot centre
    Ic = leg_inertia_sum(model, 0) - 0.0  # about the x axis through the hip point ...
    # ... move to the COM: both legs' COMs at the same height, so subtract m (L - h)^2.
    Ic -= m * (L - h) ** 2
    return m, R, h, e, Ic


def rocker_U(m, R, h, e, th):
    th = abs(th)
    return m * GRAVITY_MPS2 * (R - (R - h) * math.cos(th) + e * math.sin(th))


def rocker_J(m, R, h, e, Ic, th):
    th = abs(th)
    py = e * math.cos(th) - (h - R) * math.sin(th)
    pz = R + e * math.sin(th) + (h - R) * math.cos(th)
    return Ic + m * (py * py + pz * pz)


def rocker_period(m, R, h, e, Ic, th0, n=400):
    """Exact period of the rigid two-sphere rocker (no slip, energy conserved) at
    amplitude th0: 4 ∫ sqrt(J/(2(U(th0) - U))) dth, th = th0 sin(phi)."""
    x, w = np.polynomial.legendre.leggauss(n)
    phi = 0.25 * math.pi * (x + 1.0)
    wq = 0.25 * math.pi * w
    U0 = rocker_U(m, R, h, e, th0)
    tot = 0.0
    for ph, ww in zip(phi, wq):
        th = th0 * math.sin(ph)
        dU = U0 - rocker_U(m, R, h, e, th)
        if dU <= 0:
            continue
        tot += ww * th0 * math.cos(ph) * math.sqrt(rocker_J(m, R, h, e, Ic, th) / (2 * dU))
    return 4.0 * tot


def analytic_free_rocking(model, th0_deg, mean_amp_deg=None):
    m, R, h, e, Ic = rocker_params(model)
    g = GRAVITY_MPS2
    w2 = m * g * (R - h) / (Ic + m * h * h)
    th0 = math.radians(th0_deg)
    # Pivot transfer at th = 0 from one sphere's contact point to the other's (plastic,
    # no slip, angular momentum about the new contact point conserved):
    r = (Ic + m * (h * h - e * e)) / (Ic + m * (h * h + e * e))
    U0 = rocker_U(m, R, h, e, 0.0)
    target = U0 + r ** 4 * (rocker_U(m, R, h, e, th0) - U0)
    lo, hi = 0.0, th0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if rocker_U(m, R, h, e, mid) < target:
            lo = mid
        else:
            hi = mid
    out = {
        "roll_period_s_small_oscillation": 2 * math.pi / math.sqrt(w2),
        "formula_small_oscillation": "w^2 = m g (R - h)/(I_c + m h^2), feet offset ignored (e = 0)",
        "roll_period_s_two_sphere_rocker_at_initial_amplitude": rocker_period(m, R, h, e, Ic, th0),
        "formula_two_sphere_rocker": "rigid rocker on two spheres whose centres are +-e off the mid-plane "
                                     "(U = m g (R - (R-h) cos th + e |sin th|), J = I_c + m |PG|^2), "
                                     "exact energy-integral period at the amplitude; no slip",
        "roll_decay_ratio_per_cycle_rigid_pivot_transfer": lo / th0,
        "formula_decay": "two plastic pivot transfers per cycle, w+/w- = (I_c + m(h^2 - e^2))/(I_c + m(h^2 + e^2)); "
                         "contact compliance and its dissipation not included",
        "parameters": {"m_kg": m, "R_m": R, "h_com_m": h, "e_m": e, "I_c_roll_kgm2": Ic},
    }
    # Compliant two-foot rocker: both feet stay loaded while e|th| < delta (sinkage), so
    # the differential sinkage adds a roll stiffness 2 k e^2 (k = dF/ddelta per foot).
    semi = model.legs[0].foot_semi_axes_m
    W = m * g
    delta = dz.solve_sinkage(model.modulus_pa, semi, W / 2.0)
    eps = 1e-3 * delta
    k = (dz.ellipsoid_force(model.modulus_pa, semi, delta + eps)
         - dz.ellipsoid_force(model.modulus_pa, semi, delta - eps)) / (2 * eps)
    K = m * g * (R - h) + 2 * k * e * e
    J = Ic + m * h * h
    out["roll_period_s_compliant_two_foot"] = 2 * math.pi / math.sqrt(K / J)
    out["formula_compliant_two_foot"] = (
        "both feet loaded (valid while e|th| < delta): w^2 = (m g (R - h) + 2 k e^2)/(I_c + m h^2), "
        "k = dF/ddelta of one foot at its static sinkage (m g/2 per foot)")
    out["both_feet_loaded_below_roll_deg"] = math.degrees(math.atan2(delta, e)) if e > 0 else None
    if model.dissipation_kind == "kelvin_voigt":
        tau = model.relaxation_time_s
        c = tau * (R * W + 2 * k * e * e)
        zeta = c / (2 * math.sqrt(K * J))
        out["roll_decay_ratio_per_cycle_compliant_two_foot_kv"] = math.exp(
            -2 * math.pi * zeta / math.sqrt(1 - zeta * zeta))
        out["formula_decay_kv"] = (
            "Kelvin-Voigt (relaxation time tau): rolling resistance tau v F per foot with v = R thdot "
            "(see rolling_incline) plus the differential-sinkage damper 2 tau k e^2: "
            "c = tau (R m g + 2 k e^2), zeta = c/(2 sqrt(K J)), ratio = exp(-2 pi zeta/sqrt(1 - zeta^2))")
    out["parameters"].update({"sinkage_per_foot_m": delta, "k_per_foot_n_per_m": k})
    if mean_amp_deg is not None and mean_amp_deg > 0:
        out["roll_period_s_two_sphere_rocker_at_measured_mean_amplitude"] = rocker_period(
            m, R, h, e, Ic, math.radians(mean_amp_deg))
        out["measured_mean_amplitude_deg_used"] = mean_amp_deg
    return out


def kv_rolling_moment(E, R, delta, tau, v, n=160):
    """Quasi-steady rolling sphere with Kelvin-Voigt dissipation per contact point
    (SAP: p = (p_e + tau·g·xdot)_+, g = E/R, xdot = v·xi/R): returns (normal force,
    moment about the patch centre, resisting) integrated over the overlap disc."""
    a = math.sqrt(max(R * R - (R - delta) ** 2, 0.0))
    xs = np.linspace(-a, a, n)
    X, Y = np.meshgrid(xs, xs)
    rho = np.hypot(X, Y)
    inside = rho <= a
    pe = sphere_pressure(E, R, delta, rho)
    pd = tau * (E / R) * v * X / R
    p = np.where(inside, np.maximum(pe + pd, 0.0), 0.0)
    dA = (xs[1] - xs[0]) ** 2
    return float(p.sum() * dA), float((p * X).sum() * dA)


def analytic_rolling(model, tau, t_end, windows):
    m = model.total_mass_kg
    g = np.asarray(model.gravity_mps2)
    gx, gz = g[0], -g[2]
    R = model.legs[0].foot_semi_axes_m[2]
    th = math.atan2(gx, gz)
    rigid = 5.0 / 7.0 * gx
    out = {"com_acceleration_mps2_rigid_rolling": rigid,
           "formula_rigid": "(5/7) g sin(theta)"}
    if tau is None:
        return out
    # Linear KV rolling resistance M = tau v F_n (small delta, no clipping).
    A = rigid
    B = 5.0 / 7.0 * gz * tau / R
    tt = np.linspace(0, t_end, 2001)
    x_lin = A / B * (tt - (1 - np.exp(-B * tt)) / B)
    v_lin = A / B * (1 - np.exp(-B * tt))
    # Quasi-steady with clipping of negative pressure, per foot carrying m g_z/2.
    E = model.modulus_pa
    W2 = m * gz / 2.0
    def moment_at(v):
        lo, hi = 0.0, 0.2 * R
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            F, _ = kv_rolling_moment(E, R, mid, tau, v)
            if F < W2:
                lo = mid
            else:
                hi = mid
        F, M = kv_rolling_moment(E, R, 0.5 * (lo + hi), tau, v)
        return M * W2 / F

    # Tabulate M(v) once (smooth in v) and interpolate.
    v_tab = np.linspace(0.0, 1.5 * rigid * t_end + 0.1, 61)
    m_tab = np.array([moment_at(v) for v in v_tab])

    def moment(v):
        return float(np.interp(v, v_tab, m_tab))

    x, v = 0.0, 0.0
    xq, vq = [0.0], [0.0]
    h = tt[1] - tt[0]
    for _ in tt[1:]:
        acc = 5.0 / 7.0 * (gx - 2.0 * moment(v) / (m * R))
        v += acc * h
        x += v * h
        xq.append(x)
        vq.append(v)
    xq, vq = np.array(xq), np.array(vq)

    def fit(xs, lo, hi):
        sel = (tt >= lo) & (tt <= hi + 1e-12)
        A_ = np.vstack([np.ones(sel.sum()), tt[sel], 0.5 * tt[sel] ** 2]).T
        return float(np.linalg.lstsq(A_, xs[sel], rcond=None)[0][2])

    out.update({
        "com_acceleration_mps2_kv_linear": fit(x_lin, *windows["full"]),
        "com_acceleration_early_mps2_kv_linear": fit(x_lin, *windows["early"]),
        "com_velocity_at_end_mps_kv_linear": float(v_lin[-1]),
        "com_acceleration_mps2_kv_clipped": fit(xq, *windows["full"]),
        "com_acceleration_early_mps2_kv_clipped": fit(xq, *windows["early"]),
        "com_velocity_at_end_mps_kv_clipped": float(vq[-1]),
        "com_velocity_at_end_mps_rigid": rigid * t_end,
        "formula_kv": "SAP Kelvin-Voigt per contact point: p = (p_e + tau (E/R) xdot)_+, xdot = v xi/R "
                      "(xi: forward offset in the patch). Unclipped: M = tau v F_n per foot, so "
                      "v' = (5/7)(g sin th - g cos th tau v/R) ('kv_linear'). 'kv_clipped': the same with "
                      "p clipped at 0 and the sinkage re-solved so each foot carries m g cos th/2, integrated "
                      "quasi-statically. Both are fitted with the same windows as the measurement.",
        "terminal_velocity_mps_kv_linear": A / B,
    })
    return out


def analytic_spin(model, w0):
    m = model.total_mass_kg
    W = m * GRAVITY_MPS2
    R = model.legs[0].foot_semi_axes_m[2]
    E = model.modulus_pa
    mu = model.friction_mu
    delta = solve_sphere_sinkage(E, R, W / 2.0)
    a = math.sqrt(R * R - (R - delta) ** 2)
    # Polar quadrature over each patch: M = mu ∫ p |c + s| dA, c = patch centre offset.
    x, wq = np.polynomial.legendre.leggauss(200)
    rr = 0.5 * a * (x + 1)
    wr = 0.5 * a * wq
    ang = np.linspace(0, 2 * math.pi, 720, endpoint=False)
    dth = 2 * math.pi / len(ang)
    Mtot = 0.0
    Ftot = 0.0
    for leg in model.legs:
        cy = leg.foot_center_m[1]
        cx = leg.foot_center_m[0]
        for r_, w_ in zip(rr, wr):
            p = float(sphere_pressure(E, R, delta, r_))
            sx = cx + r_ * np.cos(ang)
            sy = cy + r_ * np.sin(ang)
            Mtot += mu * p * np.sum(np.hypot(sx, sy)) * dth * r_ * w_
            Ftot += p * len(ang) * dth * r_ * w_
    Izz = leg_inertia_sum(model, 2)
    F = W / 2.0
    M_closed = 2 * (8.0 / 15.0) * mu * F * a
    decel = Mtot / Izz
    return {
        "yaw_deceleration_rad_s2": decel, "stop_time_s": w0 / decel,
        "torsional_friction_moment_nm": Mtot,
        "torsional_friction_moment_nm_closed_form_no_offset": M_closed,
        "yaw_deceleration_rad_s2_closed_form_no_offset": M_closed / Izz,
        "I_zz_kgm2": Izz, "patch_radius_m": a, "sinkage_per_foot_m": delta,
        "normal_force_check_n": Ftot,
        "derivation": "Sphere p = E(1 - r) pressed delta: on the plane p(rho) = E(1 - sqrt((R-delta)^2 + rho^2)/R) "
                      "~ (E/(2R^2))(a^2 - rho^2), a^2 = 2 R delta (parabolic). Pure spin w about the vertical "
                      "axis through the hip point (the COM; symmetric, so no net friction force): the slip at s "
                      "is w x s, Coulomb traction mu p opposite, moment mu p |s|. With the patch centred on the "
                      "axis and parabolic p: F = pi p0 a^2/2, M = 2 pi mu p0 a^3 (1/3 - 1/5) = (8/15) mu F a. "
                      "Here each patch centre is foot_center_lateral L off the axis, so M = mu sum over feet "
                      "of the integral of p(rho)|c + s| dA (polar quadrature, exact p), each foot carrying m g/2. "
                      "decel = M/I_zz with I_zz = sum of the legs' I_zz + m_leg (x_c^2 + y_c^2); t_stop = w0/decel.",
    }


def hip_mass_matrix(model, q=0.0):
    """The 7×7 mass matrix of the free two-body system with the right leg turned by q about
    the hip's y axis (left leg upright; ν = v_hip, ω_left, q̇; world = left-leg axes)."""
    ey = np.array([0.0, 1.0, 0.0])
    Ry = dz.rot_y(q)

    def skew(r):
        return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])

    M = np.zeros((7, 7))
    for k, leg in enumerate(model.legs):
        R = Ry if k == 1 else np.eye(3)
        r = R @ leg.com_m
        Ic = R @ np.diag(leg.inertia_diag_kgm2) @ R.T
        Jv = np.zeros((3, 7))
        Jv[:, 0:3] = np.eye(3)
        Jv[:, 3:6] = -skew(r)
        Jw = np.zeros((3, 7))
        Jw[:, 3:6] = np.eye(3)
        if k == 1:
            Jv[:, 6] = np.cross(ey, r)
            Jw[:, 6] = ey
        M += leg.mass_kg * Jv.T @ Jv + Jw.T @ Ic @ Jw
    return M


def effective_hip_inertia(model):
    """1/(M⁻¹)_qq of the free two-body system at q = 0, and M (hip_mass_matrix)."""
    M = hip_mass_matrix(model, 0.0)
    return 1.0 / np.linalg.inv(M)[6, 6], M


def fit_sine(t, q, w):
    A = np.vstack([np.sin(w * t), np.cos(w * t), np.ones_like(t)]).T
    a, b, c = np.linalg.lstsq(A, q, rcond=None)[0]
    return math.hypot(a, b), -math.atan2(b, a), c


def analytic_servo(model, dt, t_end, window):
    ctl = model.controller
    kp, kd, A = ctl["kp_nm_per_rad"], ctl["kd_nms_per_rad"], ctl["amplitude_rad"]
    w = 2 * math.pi * ctl["frequency_hz"]
    I, _ = effective_hip_inertia(model)
    G = (kp + 1j * w * kd) / (kp - I * w * w + 1j * w * kd)
    out = {"amplitude_ratio": abs(G), "phase_lag_deg": -math.degrees(np.angle(G)),
           "amplitude_deg": math.degrees(A * abs(G)), "effective_hip_inertia_kgm2": I,
           "kp_nm_per_rad": kp, "kd_nms_per_rad": kd,
           "formula": "q/q_d = (kp + i w kd)/(kp - I w^2 + i w kd), I = 1/(M^-1)_qq at q = 0"}
    lim = ctl["torque_limit_nm"]
    n = int(round(t_end / dt))
    for mode in ("explicit", "linearly_implicit"):
        q, v = 0.0, 0.0
        ts, qs = [0.0], [0.0]
        for i in range(n):
            t = i * dt
            qd_, vd_ = A * math.sin(w * t), A * w * math.cos(w * t)
            raw = -kp * (q - qd_) - kd * (v - vd_)
            if mode == "explicit" or abs(raw) > lim:
                tau = max(-lim, min(lim, raw))
                dv = dt * tau / I
            else:
                dv = dt * raw / (I + dt * kd + dt * dt * kp)
            v += dv
            q += dt * v
            ts.append((i + 1) * dt)
            qs.append(q)
        ts, qs = np.array(ts), np.array(qs)
        sel = (ts >= window[0]) & (ts <= window[1] + 1e-12)
        amp, lag, _ = fit_sine(ts[sel], qs[sel], w)
        out[f"amplitude_ratio_discrete_{mode}"] = amp / A
        out[f"phase_lag_deg_discrete_{mode}"] = math.degrees(lag)
    out["discrete_note"] = ("the same linear 1-DOF model stepped at the design's dt: 'explicit' = torque from the "
                            "state at the start of the step, held (Drake LeafSystem + symplectic Euler); "
                            "'linearly_implicit' = (I + dt kd + dt^2 kp) dv = dt tau (the project's servo)")
    return out


# ------------------------------------------------------------------------------ cases
def measure(name, case, model, tr):
    t = tr["t"]
    m = {}
    if name.startswith("sinkage"):
        sel = t >= t[-1] - 0.2 - 1e-12
        z0 = tr["p"][0][2]
        m["sinkage_m"] = float(z0 - tr["p"][sel, 2].mean())
        m["left_normal_force_n"] = float(tr["fz"][sel, 0].mean())
        m["right_normal_force_n"] = float(tr["fz"][sel, 1].mean())
        m["feet_in_contact"] = int(round(tr["feet"][sel].mean()))
        m["hip_z_start_m"] = float(z0)
        m["hip_z_end_m"] = float(tr["p"][sel, 2].mean())
        m["contact_polygons_per_foot"] = [int(x) for x in tr["faces"][-1]]
        m["contact_area_per_foot_m2"] = [float(x) for x in tr["area"][-1]]
        m["roll_end_deg"] = float(tr["roll"][-1])
        m["hip_angle_end_deg"] = math.degrees(tr["q"][-1])
    elif name == "free_rocking":
        roll = tr["roll"]
        zc = zero_crossings(t, roll)
        pk = [(0.0, float(roll[0]))] + positive_peaks(t, roll)
        if len(zc) >= 9:
            m["roll_period_s"] = float(np.mean([zc[k + 2] - zc[k] for k in range(0, 7)]))
        elif len(zc) >= 3:
            m["roll_period_s"] = float(np.mean([zc[k + 2] - zc[k] for k in range(len(zc) - 2)]))
        else:
            m["roll_period_s"] = None
        if len(pk) >= 5:
            m["roll_decay_ratio_per_cycle"] = float((pk[4][1] / pk[0][1]) ** 0.25)
        else:
            m["roll_decay_ratio_per_cycle"] = None
        m["roll_peaks_deg"] = [[round(a, 5), round(b, 5)] for a, b in pk[:12]]
        m["zero_crossings_s"] = [round(x, 5) for x in zc[:16]]
        amps = [b for _, b in pk[:5]]
        m["mean_positive_peak_first_4_cycles_deg"] = float(np.mean(amps)) if amps else None
        m["contact_polygons_per_foot_max"] = [int(x) for x in tr["faces"].max(axis=0)]
        m["both_feet_in_contact_fraction"] = float(np.mean(tr["feet"][1:] == 2))
    elif name == "rolling_incline":
        x = tr["com"][:, 0]
        for key, (lo, hi) in (("com_acceleration_mps2", (0.05, 1.0)),
                              ("com_acceleration_early_mps2", (0.05, 0.25))):
            sel = (t >= lo - 1e-12) & (t <= hi + 1e-12)
            A = np.vstack([np.ones(sel.sum()), t[sel], 0.5 * t[sel] ** 2]).T
            m[key] = float(np.linalg.lstsq(A, x[sel], rcond=None)[0][2])
        R = model.legs[0].foot_semi_axes_m[2]
        m["com_velocity_at_end_mps"] = float(tr["vcom"][-1, 0])
        m["slip_velocity_at_end_mps"] = float(tr["vcom"][-1, 0] - tr["omega"][-1, 1] * R)
        # v = w (R - delta_eff): the sunk sphere rolls on a slightly smaller radius.
        m["effective_rolling_radius_m"] = float(tr["vcom"][-1, 0] / tr["omega"][-1, 1])
        m["com_distance_m"] = float(x[-1] - x[0])
        m["com_lateral_drift_m"] = float(tr["com"][-1, 1] - tr["com"][0, 1])
        m["hip_angle_max_abs_deg"] = float(np.degrees(np.abs(tr["q"]).max()))
    elif name == "spin_down":
        wz = tr["omega"][:, 2]
        w0 = float(case["initial"]["angular_velocity_rad_s"][2])
        sel = (wz >= 0.1 * w0) & (wz <= 0.9 * w0) & (t > 0)
        s, _ = line_fit(t[sel], wz[sel])
        m["yaw_deceleration_rad_s2"] = float(-s)
        m["stop_time_s"] = first_below(t, wz, 0.01 * w0)
        m["yaw_rate_at_end_rad_s"] = float(wz[-1])
        m["fit_samples"] = int(sel.sum())
        m["com_horizontal_drift_m"] = float(np.hypot(*(tr["com"][-1, :2] - tr["com"][0, :2])))
    elif name == "slide":
        v = tr["vcom"][:, 0]
        v0 = float(case["initial"]["linear_velocity_mps"][0])
        sel = (v >= 0.1 * v0) & (v <= 0.9 * v0) & (t > 0)
        s, _ = line_fit(t[sel], v[sel])
        ts = first_below(t, v, 0.01 * v0)
        m["stop_time_s"] = ts
        x = tr["com"][:, 0]
        m["stopping_distance_m"] = float(interp_at(t, x, ts) - x[0]) if ts is not None else None
        m["deceleration_mps2"] = v0 / ts if ts else None
        m["deceleration_from_distance_mps2"] = (v0 * v0 / (2 * m["stopping_distance_m"])
                                                if m["stopping_distance_m"] else None)
        m["deceleration_linefit_mps2"] = float(-s)
        m["max_hop_height_m"] = float(tr["p"][:, 2].max() - tr["p"][0, 2])
        m["max_vertical_velocity_mps"] = float(tr["vcom"][:, 2].max())
        m["airborne_fraction_while_sliding"] = float(np.mean(tr["feet"][1:][t[1:] < (ts or 0)] == 0)) if ts else None
        m["velocity_at_end_mps"] = float(v[-1])
        m["displacement_at_end_m"] = float(x[-1] - x[0])
        m["pitch_max_abs_deg"] = float(np.abs(tr["pitch"]).max())
        m["fit_samples"] = int(sel.sum())
        m["contact_polygons_per_foot_at_end"] = [int(x) for x in tr["faces"][-1]]
    elif name == "creep":
        x = tr["com"][:, 0]
        m["creep_speed_mps"] = float((interp_at(t, x, 1.0) - interp_at(t, x, 0.5)) / 0.5)
        m["creep_speed_at_end_mps"] = float(tr["vcom"][-1, 0])
        m["displacement_m"] = float(x[-1] - x[0])
        m["pitch_end_deg"] = float(tr["pitch"][-1])
    elif name == "servo_in_air":
        ctl = model.controller
        w = 2 * math.pi * ctl["frequency_hz"]
        sel = (t >= 2.0 - 1e-12) & (t <= 3.0 + 1e-12)
        amp, lag, off = fit_sine(t[sel], tr["q"][sel], w)
        m["amplitude_deg"] = math.degrees(amp)
        m["amplitude_ratio"] = amp / ctl["amplitude_rad"]
        m["phase_lag_deg"] = math.degrees(lag)
        m["offset_deg"] = math.degrees(off)
        m["peak_abs_torque_nm_last_second"] = float(np.abs(tr["tau"][sel]).max())
        m["yaw_drift_deg"] = float(tr["yaw"][-1] - tr["yaw"][0])
    else:
        raise KeyError(name)
    return m


def analytic(name, case, model, measured, dt):
    if name.startswith("sinkage"):
        return analytic_sinkage(model)
    if name == "free_rocking":
        return analytic_free_rocking(model, case["initial"]["roll_deg"],
                                     measured.get("mean_positive_peak_first_4_cycles_deg"))
    if name == "rolling_incline":
        return analytic_rolling(model, model.relaxation_time_s if model.dissipation_kind == "kelvin_voigt" else None,
                                case["duration_s"], {"full": (0.05, 1.0), "early": (0.05, 0.25)})
    if name == "spin_down":
        return analytic_spin(model, float(case["initial"]["angular_velocity_rad_s"][2]))
    if name == "slide":
        mu, g = model.friction_mu, GRAVITY_MPS2
        v0 = float(case["initial"]["linear_velocity_mps"][0])
        return {"deceleration_mps2": mu * g, "deceleration_from_distance_mps2": mu * g,
                "stopping_distance_m": v0 * v0 / (2 * mu * g),
                "stop_time_s": v0 / (mu * g), "velocity_at_end_mps": 0.0}
    if name == "creep":
        mu = model.friction_mu
        th = math.atan2(model.gravity_mps2[0], -model.gravity_mps2[2])
        s = math.tan(th) / mu
        vs = model.stiction_speed_mps
        return {"creep_speed_mps": 0.0, "creep_speed_at_end_mps": 0.0, "displacement_m": 0.0,
                "project_regularised_creep_speed_mps": vs * s / math.sqrt(1 - s * s),
                "note": "Coulomb: 0. 'project_regularised_creep_speed_mps' is the steady slip of the law "
                        "t = mu p v/sqrt(v^2 + v_s^2) at tan(theta)/mu (the project's regularisation, also "
                        "Drake 'similar' with stiction_tolerance = v_s); SAP's own regularisation gives "
                        "slip ~ sigma dt g-scale (sigma = 1e-3) per point."}
    if name == "servo_in_air":
        return analytic_servo(model, dt, case["duration_s"], (2.0, 3.0))
    raise KeyError(name)


def run_case(name, case, hint_over_l=0.06, time_step_s=None, servo="auto",
             approximation=None):
    d, model, actuated = case_model(case)
    tr = run_trace(model, actuated, case["initial"], case["duration_s"], hint_over_l,
                   time_step_s, servo=servo, approximation=approximation)
    measured = measure(name, case, model, tr)
    an = analytic(name, case, model, measured, tr["dt"])
    w = tr["walker"]
    return {
        "case": name,
        "definition": case,
        "measured": measured,
        "analytic": an,
        "engine": {
            "approximation": w.approximation,
            "time_step_s": tr["dt"],
            "mesh_resolution_hint_over_l": hint_over_l,
            "mesh_resolution_hint_m": w.resolution_hint_m,
            "relaxation_time_s": model.relaxation_time_s,
            "hunt_crossley_dissipation_s_per_m": model.hunt_crossley_s_per_m,
            "friction_mu": model.friction_mu,
            "servo": w.servo if actuated else "passive (hardstop only)",
        },
        "wall_s": tr["wall_s"],
    }


def run_case_by_name(name, cases_path, hint_over_l=0.06, **kw):
    cases = load_cases(cases_path)
    return run_case(name, cases[name], hint_over_l, **kw)


def run_all_cases(cases_path, hint_over_l=0.06):
    cases = load_cases(cases_path)
    names = [n for n in CASE_ORDER if n in cases] + [n for n in cases if n not in CASE_ORDER]
    return {"cases": {n: run_case(n, cases[n], hint_over_l) for n in names}}
