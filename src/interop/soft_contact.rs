//! The closest MuJoCo soft contact to a design's pressure-field contact, and back.
//!
//! MuJoCo's contact is a soft constraint: with the impedance d at its maximum the penetration
//! r obeys r̈ = −(1/(τζ))²·r − (2/τ)·ṙ per unit of effective mass (solref = (τ, ζ), Todorov
//! 2014; the MuJoCo docs' "Solver parameters"), i.e. a linear spring-damper of natural
//! frequency ω = 1/(τζ) and damping ratio ζ whatever the mass, and the weight sinks it by
//! (1 − d)·g/ω². The pressure field is nonlinear (F = π·E·a·b·δ²/c² for an ellipsoid
//! pressed by δ), so no MuJoCo setting is the same law. The closest match kept here is the
//! one that preserves the contact's time scales: ω and ζ of the whole robot bouncing on one
//! foot about its static sinkage (the linearised pressure field: ω² = (dF/dδ)/m; its damping
//! d_HC·F + τ_d·dF/dδ, Hunt–Crossley and Kelvin–Voigt). What this leaves different is
//! stated by [`SoftContact`]: the static sinkage (MuJoCo's (1 − d)·g/ω² against the field's
//! δ, about 40× smaller at d = 0.95), a frequency that does not change with load, and a
//! point contact with torsional friction in place of a patch.

use crate::sim::{Design, GRAVITY_MPS2, upright_sinkage_m, upright_stiffness_n_per_m};

/// MuJoCo's impedance, held constant (dmin = dmax) so that ω and ζ hold at every depth;
/// 0.95 is MuJoCo's default dmax.
pub const IMPEDANCE: f64 = 0.95;
/// The foot's torsional friction length is μ·(8/15)·a, a the patch radius: the spin moment
/// of a parabolic pressure over a disc (Johnson 1985), the pressure field's near the bottom.
pub const TORSION_FACTOR: f64 = 8.0 / 15.0;

/// The MuJoCo contact of a design and the pressure-field numbers it was matched to.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SoftContact {
    /// solref = (timeconst, dampratio).
    pub timeconst_s: f64,
    pub dampratio: f64,
    /// Torsional friction length (MuJoCo's friction[1]) [m].
    pub torsional_m: f64,
    /// The pressure field's linearised bounce on one foot: ω [rad/s] and ζ.
    pub frequency_rad_s: f64,
    pub damping_ratio: f64,
    /// Static sinkage of the whole weight on one foot: the pressure field's and MuJoCo's [m].
    pub sinkage_m: f64,
    pub mujoco_sinkage_m: f64,
    /// The patch radius at that load (geometric mean of the patch's semi-axes) [m].
    pub patch_radius_m: f64,
    /// True when τ was below MuJoCo's safe limit 2·dt, which MuJoCo then uses instead.
    pub timeconst_clamped: bool,
}

/// The closest MuJoCo soft contact to the (scaled) design's foot contact.
pub fn soft_contact(d: &Design) -> SoftContact {
    let m = d.mass.total_mass_kg;
    let model = d.model();
    let c = &model.contact;
    let semi = d.geometry.foot_semi_axes_m;
    let load = m * GRAVITY_MPS2;
    let sinkage = upright_sinkage_m(c.modulus_pa, semi, load);
    let k = upright_stiffness_n_per_m(c.modulus_pa, semi, sinkage);
    let omega = (k / m).sqrt();
    let damping = c.dissipation_s_per_m * load + c.relaxation_time_s * k;
    // Undamped contacts still need a finite time constant: a ratio of 10⁻³ is a bounce
    // that keeps 99.4 % of its energy.
    let zeta = (damping / (2.0 * m * omega)).max(1e-3);
    let timeconst = 1.0 / (zeta * omega);
    // Patch semi-axes √(2ρδ) with the bottom's curvature radii ρ = a²/c, b²/c.
    let rx = semi[0] * semi[0] / semi[2];
    let ry = semi[1] * semi[1] / semi[2];
    let patch = (2.0 * rx * sinkage).sqrt().sqrt() * (2.0 * ry * sinkage).sqrt().sqrt();
    SoftContact {
        timeconst_s: timeconst,
        dampratio: zeta,
        torsional_m: c.friction_mu * TORSION_FACTOR * patch,
        frequency_rad_s: omega,
        damping_ratio: zeta,
        sinkage_m: sinkage,
        mujoco_sinkage_m: (1.0 - IMPEDANCE) * GRAVITY_MPS2 / (omega * omega),
        patch_radius_m: patch,
        timeconst_clamped: timeconst < 2.0 * d.numerics.time_step_s,
    }
}

/// The inverse of [`soft_contact`]: the hydroelastic modulus [Pa] and Kelvin–Voigt relaxation
/// time [s] whose linearised bounce of `mass_kg` on one foot (semi-axes `semi`) has MuJoCo's
/// ω = 1/(τζ) and ζ. (Which dissipation law the original used is not in the MJCF; the
/// relaxation time is the one that maps one to one.)
pub fn pressure_field_of(
    timeconst_s: f64,
    dampratio: f64,
    mass_kg: f64,
    semi: [f64; 3],
) -> (f64, f64) {
    let omega = 1.0 / (timeconst_s * dampratio);
    let k = mass_kg * omega * omega;
    let load = mass_kg * GRAVITY_MPS2;
    // dF/dδ at the static sinkage is ∝ E^(1/2) to first order; solve for E by bisection
    // on log E so the exact closed form holds.
    let stiffness = |e: f64| upright_stiffness_n_per_m(e, semi, upright_sinkage_m(e, semi, load));
    let (mut lo, mut hi) = (1e0f64.ln(), 1e13f64.ln());
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if stiffness(mid.exp()) < k {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let e = (0.5 * (lo + hi)).exp();
    // ζ = τ_d·k/(2mω) ⇒ τ_d = 2ζ/ω.
    (e, 2.0 * dampratio / omega)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mapping_inverts() {
        let d = Design::builtin("mugatu-ref").unwrap();
        let s = soft_contact(&d);
        let (e, tau) = pressure_field_of(
            s.timeconst_s,
            s.dampratio,
            d.mass.total_mass_kg,
            d.geometry.foot_semi_axes_m,
        );
        assert!(
            (e / d.contact.hydroelastic_modulus_pa - 1.0).abs() < 1e-9,
            "{e}"
        );
        assert!(
            (tau / d.contact.relaxation_time_s - 1.0).abs() < 1e-9,
            "{tau}"
        );
        // The sphere's bounce: δ ≪ R, so k = 2F/δ and ω² = 2g/δ.
        let w = (2.0 * GRAVITY_MPS2 / s.sinkage_m).sqrt();
        assert!(
            (s.frequency_rad_s / w - 1.0).abs() < 0.01,
            "{} vs {w}",
            s.frequency_rad_s
        );
    }
}
