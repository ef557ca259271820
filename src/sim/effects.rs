//! Optional physical effects, described by data and plugged into the dynamics through the
//! [`Effect`] trait: an effect may reshape the actuator torque and/or add generalized
//! forces (with their velocity derivative, so stiff effects stay stable under the implicit
//! integrator). The integrator itself never changes when an effect is added.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use super::error::SimError;
use super::model::{Kinematics, State};

/// What an effect can see at a step.
pub struct EffectContext<'a> {
    pub time_s: f64,
    pub dt_s: f64,
    pub state: &'a State,
    pub kinematics: &'a Kinematics,
}

/// Generalized force added by effects, and −∂force/∂ν (symmetric PSD for dissipative terms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralizedForce {
    pub force: SVector<f64, 7>,
    pub damping: SMatrix<f64, 7, 7>,
}

impl Default for GeneralizedForce {
    fn default() -> Self {
        GeneralizedForce {
            force: SVector::zeros(),
            damping: SMatrix::zeros(),
        }
    }
}

/// A pluggable physical effect.
pub trait Effect: Send {
    /// Name as used in the data files.
    fn name(&self) -> &'static str;
    /// Maps the commanded hip torque to the delivered one; returns (torque, ∂out/∂in) so the
    /// implicit servo slope can be scaled consistently (1 = unchanged, 0 = saturated).
    fn actuator_torque(&mut self, _ctx: &EffectContext<'_>, commanded_nm: f64) -> (f64, f64) {
        (commanded_nm, 1.0)
    }
    /// Adds generalized forces.
    fn generalized_force(&mut self, _ctx: &EffectContext<'_>, _out: &mut GeneralizedForce) {}
}

/// Data description of an effect (a `[[effects]]` entry of a design, or `spec` of a file
/// in `dataset/effects/`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "effect", rename_all = "snake_case", deny_unknown_fields)]
pub enum EffectSpec {
    /// Viscous hip friction τ = −c·q̇.
    HipViscousDamping { damping_nms_per_rad: f64 },
    /// Coulomb hip friction τ = −τ_f·q̇/√(q̇² + ω_s²) (regularised below ω_s).
    HipCoulombFriction {
        friction_torque_nm: f64,
        stiction_rate_rad_s: f64,
    },
    /// Linear DC-motor torque–speed line: while motoring (τ·q̇ > 0) the delivered torque is
    /// the command times (1 − |q̇|/ω₀)₊, ω₀ the no-load speed at the joint.
    MotorTorqueSpeed { no_load_speed_rad_s: f64 },
}

impl EffectSpec {
    /// Scales the effect with the robot: torques ∝ m·g·L, rates ∝ √(g/L) (dynamic similarity).
    pub fn scaled(&self, length_ratio: f64, mass_ratio: f64) -> EffectSpec {
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
        }
    }

    /// Checks parameter signs; `origin` names the file for the error message.
    pub fn validate(&self, origin: &str, field: &str) -> Result<(), SimError> {
        let bad = |name: &str, v: f64, why: &str| SimError::InvalidValue {
            origin: origin.to_string(),
            field: format!("{field}.{name}"),
            value: v.to_string(),
            reason: why.to_string(),
        };
        match *self {
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad,
            } => {
                if !(damping_nms_per_rad >= 0.0 && damping_nms_per_rad.is_finite()) {
                    return Err(bad(
                        "damping_nms_per_rad",
                        damping_nms_per_rad,
                        "must be finite and ≥ 0",
                    ));
                }
            }
            EffectSpec::HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            } => {
                if !(friction_torque_nm >= 0.0 && friction_torque_nm.is_finite()) {
                    return Err(bad(
                        "friction_torque_nm",
                        friction_torque_nm,
                        "must be finite and ≥ 0",
                    ));
                }
                if !(stiction_rate_rad_s > 0.0 && stiction_rate_rad_s.is_finite()) {
                    return Err(bad(
                        "stiction_rate_rad_s",
                        stiction_rate_rad_s,
                        "must be finite and > 0",
                    ));
                }
            }
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s,
            } => {
                if !(no_load_speed_rad_s > 0.0 && no_load_speed_rad_s.is_finite()) {
                    return Err(bad(
                        "no_load_speed_rad_s",
                        no_load_speed_rad_s,
                        "must be finite and > 0",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The runtime effect.
    pub fn build(&self) -> Box<dyn Effect> {
        match *self {
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad,
            } => Box::new(HipViscousDamping {
                damping_nms_per_rad,
            }),
            EffectSpec::HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            } => Box::new(HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            }),
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s,
            } => Box::new(MotorTorqueSpeed {
                no_load_speed_rad_s,
            }),
        }
    }
}

/// One parameter's documentation in an effect file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectParameterDoc {
    pub name: String,
    pub unit: String,
    pub plausible_range: [f64; 2],
    #[serde(default)]
    pub note: String,
}

/// A file of `dataset/effects/`: documentation plus the spec.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectFile {
    pub name: String,
    pub description: String,
    pub parameters: Vec<EffectParameterDoc>,
    pub spec: EffectSpec,
}

impl EffectFile {
    /// Parses an effect file; `origin` names it in errors.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<EffectFile, SimError> {
        let f: EffectFile = toml::from_str(text).map_err(|e| SimError::Parse {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        f.spec.validate(origin, "spec")?;
        Ok(f)
    }
}

/// τ = −c·q̇ at the hip.
#[derive(Clone, Copy, Debug)]
pub struct HipViscousDamping {
    pub damping_nms_per_rad: f64,
}

impl Effect for HipViscousDamping {
    fn name(&self) -> &'static str {
        "hip_viscous_damping"
    }
    fn generalized_force(&mut self, ctx: &EffectContext<'_>, out: &mut GeneralizedForce) {
        out.force[6] -= self.damping_nms_per_rad * ctx.state.hip_rate_rad_s;
        out.damping[(6, 6)] += self.damping_nms_per_rad;
    }
}

/// Regularised Coulomb friction at the hip.
#[derive(Clone, Copy, Debug)]
pub struct HipCoulombFriction {
    pub friction_torque_nm: f64,
    pub stiction_rate_rad_s: f64,
}

impl Effect for HipCoulombFriction {
    fn name(&self) -> &'static str {
        "hip_coulomb_friction"
    }
    fn generalized_force(&mut self, ctx: &EffectContext<'_>, out: &mut GeneralizedForce) {
        let w = ctx.state.hip_rate_rad_s;
        let ws2 = self.stiction_rate_rad_s * self.stiction_rate_rad_s;
        let s2 = w * w + ws2;
        let s = s2.sqrt();
        out.force[6] -= self.friction_torque_nm * w / s;
        out.damping[(6, 6)] += self.friction_torque_nm * ws2 / (s2 * s);
    }
}

/// Linear torque–speed line of a DC motor.
#[derive(Clone, Copy, Debug)]
pub struct MotorTorqueSpeed {
    pub no_load_speed_rad_s: f64,
}

impl Effect for MotorTorqueSpeed {
    fn name(&self) -> &'static str {
        "motor_torque_speed"
    }
    fn actuator_torque(&mut self, ctx: &EffectContext<'_>, commanded_nm: f64) -> (f64, f64) {
        let w = ctx.state.hip_rate_rad_s;
        if commanded_nm * w > 0.0 {
            let f = (1.0 - w.abs() / self.no_load_speed_rad_s).max(0.0);
            (commanded_nm * f, f)
        } else {
            (commanded_nm, 1.0)
        }
    }
}
