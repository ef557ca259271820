//! Dynamic similarity: how a design and its effects scale with leg length. Lengths ∝ L,
//! mass by a [`MassLaw`], times ∝ √(L/g) with g fixed ([`GRAVITY_MPS2`](super::GRAVITY_MPS2)),
//! contact by a [`ContactScaling`]. The rules live together here so that a change to one
//! (say, how damping scales) is made beside the others.

use serde::{Deserialize, Serialize};

use super::design::{ControlSpec, Design};
use super::effects::EffectSpec;
use super::error::SimError;

/// How mass follows leg length when a design is scaled.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum MassLaw {
    /// m ∝ L² (the survey's lower-biped trend).
    #[default]
    L2,
    /// m ∝ L³ (isometric, constant density).
    L3,
}

impl MassLaw {
    pub fn exponent(self) -> f64 {
        match self {
            MassLaw::L2 => 2.0,
            MassLaw::L3 => 3.0,
        }
    }
}

/// Rule for the contact parameters when a design is scaled.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum ContactScaling {
    /// Dynamic similarity: the foot's static sinkage stays the same fraction of L and the
    /// Hunt–Crossley damping the same fraction of the gait's speeds, so E ∝ m/L²
    /// (since F = πEδ² must scale like m·g with δ ∝ L) and d ∝ L^(−1/2) (d·v constant with
    /// v ∝ √(gL)); μ unchanged. For m ∝ L² this keeps E fixed. Default: isolates the effect
    /// of size on the gait from that of foot softness.
    #[default]
    Similar,
    /// Same foot material at every size (what a real robot built of the same rubber has):
    /// E, d, μ unchanged. For m ∝ L³ large robots then sink relatively deeper
    /// (δ/L ∝ L^(1/2)).
    FixedMaterial,
}

impl Design {
    /// The design scaled to leg length `leg_length_m`: lengths ∝ L, mass ∝ L² or L³
    /// (inertia ∝ m·L² follows from the box fractions), frequencies ∝ L^(−1/2), torques
    /// ∝ m·L, time step ∝ L^(1/2), contact by `contact_scaling`.
    pub fn scaled(
        &self,
        leg_length_m: f64,
        mass_law: MassLaw,
        contact_scaling: ContactScaling,
    ) -> Result<Design, SimError> {
        if !(leg_length_m > 0.0 && leg_length_m.is_finite()) {
            return Err(SimError::InvalidOption {
                option: "leg_length_m".into(),
                reason: format!("must be finite and > 0, got {leg_length_m}"),
            });
        }
        let s = leg_length_m / self.geometry.leg_length_m;
        let mu = s.powf(mass_law.exponent());
        let time = s.sqrt();
        let mut d = self.clone();
        d.geometry.leg_length_m *= s;
        d.geometry.body_length_m *= s;
        for a in d.geometry.foot_semi_axes_m.iter_mut() {
            *a *= s;
        }
        d.mass.total_mass_kg *= mu;
        match contact_scaling {
            ContactScaling::Similar => {
                d.contact.hydroelastic_modulus_pa *= mu / (s * s);
                d.contact.hunt_crossley_dissipation_s_per_m /= time;
                // A time scale: ∝ the gait's √(L/g) (walker-models.json's rule).
                d.contact.relaxation_time_s *= time;
            }
            ContactScaling::FixedMaterial => {}
        }
        // Numerical regularisation, not a material property: keep it a fixed fraction of √(gL).
        d.contact.stiction_speed_mps *= time;
        match &mut d.control {
            ControlSpec::ServoSine {
                frequency_hz,
                torque_limit_nm,
                ..
            } => {
                *frequency_hz /= time;
                *torque_limit_nm *= mu * s;
            }
            ControlSpec::BangBang {
                torque_nm,
                frequency_hz,
            } => {
                *frequency_hz /= time;
                *torque_nm *= mu * s;
            }
        }
        d.numerics.time_step_s *= time;
        for e in d.effects.iter_mut() {
            *e = e.scaled(s, mu, contact_scaling);
        }
        Ok(d)
    }
}

impl EffectSpec {
    /// Scales the effect with the robot by dynamic similarity (lengths ∝ L, times ∝ √(L/g)):
    /// * torques ∝ m·g·L (Coulomb friction torque);
    /// * viscous damping (torque per rate) ∝ m·g·L·√(L/g);
    /// * rates ∝ √(g/L) (stiction rate, no-load speed, lash crossing rate);
    /// * times ∝ √(L/g) (latency);
    /// * lengths ∝ L (rolling-resistance length);
    /// * μ and angles unchanged (friction coefficient, backlash);
    /// * the ground modulus as the foot's modulus under `contact_scaling`: ∝ m/L² when
    ///   similar (the floor's share of the sinkage stays the same fraction of L), unchanged
    ///   for a fixed material (the same floor).
    pub fn scaled(
        &self,
        length_ratio: f64,
        mass_ratio: f64,
        contact_scaling: ContactScaling,
    ) -> EffectSpec {
        let torque = mass_ratio * length_ratio;
        let time = length_ratio.sqrt();
        match *self {
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad,
            } => EffectSpec::HipViscousDamping {
                damping_nms_per_rad: damping_nms_per_rad * torque * time,
            },
            EffectSpec::HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            } => EffectSpec::HipCoulombFriction {
                friction_torque_nm: friction_torque_nm * torque,
                stiction_rate_rad_s: stiction_rate_rad_s / time,
            },
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s,
            } => EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s: no_load_speed_rad_s / time,
            },
            EffectSpec::FrictionCoefficient { friction_mu } => {
                EffectSpec::FrictionCoefficient { friction_mu }
            }
            EffectSpec::SoftGround { ground_modulus_pa } => EffectSpec::SoftGround {
                ground_modulus_pa: match contact_scaling {
                    ContactScaling::Similar => {
                        ground_modulus_pa * mass_ratio / (length_ratio * length_ratio)
                    }
                    ContactScaling::FixedMaterial => ground_modulus_pa,
                },
            },
            EffectSpec::RollingResistance {
                rolling_resistance_length_m,
            } => EffectSpec::RollingResistance {
                rolling_resistance_length_m: rolling_resistance_length_m * length_ratio,
            },
            EffectSpec::ActuationLatency { latency_s } => EffectSpec::ActuationLatency {
                latency_s: latency_s * time,
            },
            EffectSpec::HipBacklash {
                backlash_deg,
                crossing_rate_rad_s,
            } => EffectSpec::HipBacklash {
                backlash_deg,
                crossing_rate_rad_s: crossing_rate_rad_s / time,
            },
        }
    }
}
