"""Analytic checks of the effects in the Drake model (tests/golden/drake/gap/effect_cases.toml).

Each case is run like an elementary case of cases.py (every step recorded) with the case's
[[effects]] added to the design, then measured and compared with a closed form.
"""

from __future__ import annotations

import math
import time

import numpy as np

import cases as cz
import design as dz
from design import GRAVITY_MPS2

CASE_ORDER = ["hip_viscous_damping_swing", "hip_coulomb_friction_swing", "soft_ground_sinkage",
              "soft_ground_sinkage_soft", "friction_coefficient_slide"]
REFERENCE_CASES = "tests/golden/drake/cases.toml"


def rel_diff(measured, analytic):
    if measured is None or analytic is None or analytic == 0:
        return None
    return (measured - analytic) / abs(analytic)


def _number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def compare(measured: dict, an: dict, keys=None) -> dict:
    """Per measured quantity: every analytic value of the same name or a refinement of it
    (analytic keys 'NAME_<variant>'), with (measured − analytic)/|analytic|."""
    out = {}
    for k, v in measured.items():
        if (keys is not None and k not in keys) or not _number(v):
            continue
        refs = {a: {"value": x, "relative_difference": rel_diff(v, x)}
                for a, x in an.items()
                if (a == k or a.startswith(k + "_")) and _number(x)}
        if refs:
            out[k] = {"measured": v, "analytic": refs}
    return out


def _effect(model, name):
    return next(e for e in model.effects if e["effect"] == name)


# ------------------------------------------------------------------------------ hip swing
def relative_inertia(model):
    """I_rel = 1/(M⁻¹)_qq at q = 0 and the 7×7 mass matrix (cases.effective_hip_inertia)."""
    return cz.effective_hip_inertia(model)


def relative_inertia_at(model, q):
    """I_rel(q) = 1/(M⁻¹)_qq with the right leg turned by q about the hip's y axis
    (cases.hip_mass_matrix)."""
    return 1.0 / np.linalg.inv(cz.hip_mass_matrix(model, q))[6, 6]


def swing_ode(model, q0dot, torque, t_end, dt, mode):
    """The reduced swing on the zero-momentum manifold, L = ½ I(q) q̇²:
    I(q) q̈ + ½ I'(q) q̇² = τ(q̇). mode 'continuous' (RK4, dt/20) or the engine's step at dt:
    'implicit_damping' (τ = -c q̇ implicit, like Drake's joint damping) or 'explicit'
    (τ from the start of the step, like the LeafSystem). Returns (t, q, q̇) arrays."""
    h = 1e-5

    def I_of(q):
        return relative_inertia_at(model, q)

    def dI(q):
        return (I_of(q + h) - I_of(q - h)) / (2 * h)

    def acc(q, w):
        return (torque(w) - 0.5 * dI(q) * w * w) / I_of(q)

    q, w, t = 0.0, q0dot, 0.0
    ts, qs, ws = [0.0], [0.0], [w]
    if mode == "continuous":
        sub = 20
        hh = dt / sub
        n = int(round(t_end / dt))
        for _ in range(n):
            for _ in range(sub):
                k1q, k1w = w, acc(q, w)
                k2q, k2w = w + 0.5 * hh * k1w, acc(q + 0.5 * hh * k1q, w + 0.5 * hh * k1w)
                k3q, k3w = w + 0.5 * hh * k2w, acc(q + 0.5 * hh * k2q, w + 0.5 * hh * k2w)
                k4q, k4w = w + hh * k3w, acc(q + hh * k3q, w + hh * k3w)
                q += hh / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
                w += hh / 6 * (k1w + 2 * k2w + 2 * k3w + k4w)
            t += dt
            ts.append(t)
            qs.append(q)
            ws.append(w)
    else:
        n = int(round(t_end / dt))
        for _ in range(n):
            I = I_of(q)
            bias = -0.5 * dI(q) * w * w
            if mode == "implicit_damping":
                c = torque.c
                w = (I * w + dt * bias) / (I + dt * c)
            else:
                w = w + dt * (torque(w) + bias) / I
            q += dt * w       # symplectic Euler, as Drake's discrete update
            t += dt
            ts.append(t)
            qs.append(q)
            ws.append(w)
    return np.array(ts), np.array(qs), np.array(ws)


def measure_swing(name, case, model, tr):
    t, qd = tr["t"], tr["qd"]
    q0 = float(case["initial"]["hip_rate_rad_s"])
    m = {"hip_rate_initial_rad_s": float(qd[0]),
         "hip_angle_travel_deg": float(np.degrees(tr["q"][-1] - tr["q"][0]))}
    if name == "hip_viscous_damping_swing":
        m["hip_rate_at_end_rad_s"] = float(qd[-1])
    # The free system must keep zero momentum: the left leg's yaw/pitch/roll rates follow q̇.
    m["left_leg_angular_velocity_initial_rad_s"] = [float(x) for x in tr["omega"][0]]
    if name == "hip_viscous_damping_swing":
        sel = (qd >= 0.02 * q0) & (qd <= 0.9 * q0) & (t > 0)
        s, _ = cz.line_fit(t[sel], np.log(qd[sel]))
        m["decay_rate_per_s"] = float(-s)
        m["fit_samples"] = int(sel.sum())
        m["hip_rate_at_0.1s_rad_s"] = cz.interp_at(t, qd, 0.1)
        # Decay per step over the fit window (implicit: 1/(1 + h λ), explicit: 1 - h λ).
        m["ratio_per_step_mean"] = float(np.exp(s * tr["dt"]))
    else:
        sel = (qd >= 0.3 * q0) & (qd <= 0.9 * q0) & (t > 0)
        s, _ = cz.line_fit(t[sel], qd[sel])
        m["deceleration_rad_s2"] = float(-s)
        m["fit_samples"] = int(sel.sum())
        m["time_to_0.1_q0dot_s"] = cz.first_below(t, qd, 0.1 * q0)
        m["time_to_0.01_q0dot_s"] = cz.first_below(t, qd, 0.01 * q0)
    return m


def analytic_swing(name, case, model, dt):
    I, M = relative_inertia(model)
    q0 = float(case["initial"]["hip_rate_rad_s"])
    out = {"I_rel_kgm2": I,
           "I_rel_formula": "I_rel = 1/(M⁻¹)_qq, M the 7x7 mass matrix of the two free legs at q = 0 "
                            "in ν = (v_hip, ω_left, q̇): M = Σ_legs m J_v^T J_v + J_ω^T I_c J_ω "
                            "(J_v = [1, -[r]x, e_y x r (right leg)], J_ω = [0, 1, e_y (right leg)]). "
                            "Equivalently the inertia of the relative coordinate when the free system "
                            "keeps zero momentum; it is smaller than (I_yy + m_leg d²)/2 (the two legs "
                            "scissoring about a fixed hip) because the legs' COMs at ±0.2 L make the "
                            "scissoring yaw the body."}
    # The simple scissor estimate, for comparison.
    leg = model.legs[0]
    Iy = leg.inertia_diag_kgm2[1] + leg.mass_kg * (leg.com_m[0] ** 2 + leg.com_m[2] ** 2)
    out["I_scissor_kgm2"] = Iy / 2.0
    if name == "hip_viscous_damping_swing":
        c = _effect(model, "hip_viscous_damping")["damping_nms_per_rad"]
        lam = c / I
        torque = (lambda w: -c * w)
        torque.c = c
        out.update({
            "c_nms_per_rad": c,
            "decay_rate_per_s": lam,
            "decay_rate_per_s_implicit_step": math.log(1.0 + dt * lam) / dt,
            "decay_rate_per_s_explicit_step": -math.log(1.0 - dt * lam) / dt if dt * lam < 1 else None,
            "ratio_per_step_implicit": 1.0 / (1.0 + dt * lam),
            "ratio_per_step_explicit": 1.0 - dt * lam,
            "hip_rate_at_0.1s_rad_s": q0 * math.exp(-lam * 0.1),
            "hip_rate_at_0.1s_rad_s_implicit_step": q0 * (1.0 + dt * lam) ** (-round(0.1 / dt)),
            "hip_angle_travel_deg": math.degrees(q0 / lam),
            "formula": "I_rel q̈ = -c q̇: q̇ = q̇0 exp(-c t/I_rel); implicit step q̇_{k+1} = q̇_k/(1 + dt c/I_rel)",
        })
    else:
        e = _effect(model, "hip_coulomb_friction")
        tf, ws = e["friction_torque_nm"], e["stiction_rate_rad_s"]

        def F(w):
            r = math.sqrt(w * w + ws * ws)
            return r - ws * math.log((ws + r) / w)

        def t_of(w):
            return I / tf * (F(q0) - F(w))

        def torque(w):
            return -tf * w / math.sqrt(w * w + ws * ws)

        # The regularised solution sampled like the measurement and fitted the same way.
        ws_grid = np.linspace(0.3 * q0, 0.9 * q0, 400)
        ts = np.array([t_of(w) for w in ws_grid])
        s, _ = cz.line_fit(ts, ws_grid)
        out.update({
            "tau_f_nm": tf, "stiction_rate_rad_s": ws,
            "deceleration_rad_s2": tf / I,
            "deceleration_rad_s2_regularised_fit": float(-s),
            "time_to_0.1_q0dot_s": 0.9 * q0 * I / tf,
            "time_to_0.1_q0dot_s_regularised": t_of(0.1 * q0),
            "stop_time_s_coulomb": q0 * I / tf,
            "time_to_0.01_q0dot_s_regularised": t_of(0.01 * q0),
            "hip_angle_travel_deg_coulomb": math.degrees(0.5 * q0 * q0 * I / tf),
            "formula": "Coulomb: I_rel q̈ = -tau_f sign(q̇), linear decay at tau_f/I_rel, stop at q̇0 I_rel/tau_f. "
                       "Regularised (the project's law): I_rel q̈ = -tau_f q̇/sqrt(q̇² + ws²), "
                       "t(w) = (I_rel/tau_f)(F(q̇0) - F(w)), F(w) = sqrt(w² + ws²) - ws ln((ws + sqrt(w² + ws²))/w)",
        })
    # Refinement: I_rel grows with q (the swing travels several degrees), so integrate the
    # reduced swing I(q) q̈ + ½ I'(q) q̇² = τ(q̇) and measure it exactly like the Drake trace.
    t_end = case["duration_s"]
    travel = math.radians(out.get("hip_angle_travel_deg", out.get("hip_angle_travel_deg_coulomb", 0.0)))
    out["I_rel_at_travel_end_kgm2"] = relative_inertia_at(model, travel)
    step_mode = "implicit_damping" if name == "hip_viscous_damping_swing" else "explicit"
    for mode in ("continuous", step_mode):
        ts, qs, wv = swing_ode(model, q0, torque, t_end, dt, mode)
        tr = {"t": ts, "qd": wv, "q": qs, "omega": np.zeros((len(ts), 3)), "dt": dt}
        mm = measure_swing(name, case, model, tr)
        tag = "varying_inertia" if mode == "continuous" else f"varying_inertia_{mode}_step"
        for k, v in mm.items():
            if k in ("fit_samples", "left_leg_angular_velocity_initial_rad_s", "hip_rate_initial_rad_s"):
                continue
            out[f"{k}_{tag}"] = v
    out["formula_varying_inertia"] = (
        "zero momentum: kinetic energy ½ I(q) q̇², I(q) = 1/(M⁻¹(q))_qq; Lagrange: "
        "I q̈ + ½ I' q̇² = τ(q̇); integrated (RK4 at dt/20, and stepped at the engine's dt with the "
        "effect implicit (joint damping) or explicit (LeafSystem)), then measured as the Drake trace")
    return out


# ------------------------------------------------------------------------------ run
def measure(name, case, model, tr):
    if name.endswith("_swing"):
        return measure_swing(name, case, model, tr)
    if name.startswith("soft_ground_sinkage"):
        return cz.measure("sinkage_sphere", case, model, tr)
    if name == "friction_coefficient_slide":
        return cz.measure("slide", case, model, tr)
    raise KeyError(name)


def analytic(name, case, model, measured, dt):
    if name.endswith("_swing"):
        return analytic_swing(name, case, model, dt)
    if name.startswith("soft_ground_sinkage"):
        W = model.total_mass_kg * GRAVITY_MPS2
        semi = model.legs[0].foot_semi_axes_m
        E, Eg, Ee = model.modulus_pa, model.ground_modulus_pa, model.contact_modulus_pa
        delta = dz.solve_sinkage(Ee, semi, W / 2.0)
        return {
            "sinkage_m": delta, "left_normal_force_n": W / 2.0, "right_normal_force_n": W / 2.0,
            "feet_in_contact": 2,
            "E_foot_pa": E, "E_ground_pa": Eg, "E_series_pa": Ee,
            "sinkage_rigid_ground_m": dz.solve_sinkage(E, semi, W / 2.0),
            "formula": "pi E_eff delta^2 (1 - 2 delta/(3R)) = m g/2, E_eff = E_foot E_g/(E_foot + E_g)",
        }
    if name == "friction_coefficient_slide":
        out = cz.analytic("slide", case, model, measured, dt)
        out["friction_mu"] = model.friction_mu
        return out
    raise KeyError(name)


def run_case(name, case, hint_over_l=0.06):
    d, model, actuated = cz.case_model(case)
    tr = cz.run_trace(model, actuated, case["initial"], case["duration_s"], hint_over_l)
    measured = measure(name, case, model, tr)
    an = analytic(name, case, model, measured, tr["dt"])
    comparison = compare(measured, an)
    w = tr["walker"]
    out = {
        "case": name, "definition": case, "measured": measured, "analytic": an,
        "comparison": comparison,
        "engine": {
            "approximation": w.approximation, "time_step_s": tr["dt"],
            "mesh_resolution_hint_over_l": hint_over_l,
            "effects": model.effects,
            "hip_joint_damping_nms_per_rad": model.hip_damping_nms_per_rad,
            "ground": ("rigid HalfSpace" if model.ground_modulus_pa is None else
                       "compliant Box slab, thickness %.6g m, E_g = %.6g Pa"
                       % (2 * model.legs[0].foot_semi_axes_m[2], model.ground_modulus_pa)),
            "friction_mu": model.friction_mu,
        },
        "wall_s": tr["wall_s"],
    }
    ref = case.get("reference")
    if ref:
        rcase = cz.load_cases(REFERENCE_CASES)[ref]
        r = cz.run_case(ref, rcase, hint_over_l)
        out["reference"] = {"case": ref, "measured": r["measured"], "analytic": r["analytic"],
                            "comparison": compare(r["measured"], r["analytic"], case["measure"])}
    return out


def run_all(cases_path, hint_over_l=0.06, variants=True):
    cases = dz.load_toml(cases_path)["cases"]
    names = [n for n in CASE_ORDER if n in cases] + [n for n in cases if n not in CASE_ORDER]
    res = {"cases": {}, "variants": []}
    for n in names:
        t0 = time.perf_counter()
        res["cases"][n] = run_case(n, cases[n], hint_over_l)
        print(f"effect case {n}: {time.perf_counter() - t0:.1f} s", flush=True)
    if variants:
        # The foot's mesh error shrinks with a finer mesh (as for sinkage_sphere).
        for n in ("soft_ground_sinkage",):
            r = run_case(n, cases[n], 0.03)
            res["variants"].append({"case": n, "variant": "hint_0.03L",
                                    "measured": r["measured"], "comparison": r["comparison"],
                                    "reference": r.get("reference"), "wall_s": r["wall_s"]})
            print(f"effect case {n} at 0.03 L done", flush=True)
    return res
