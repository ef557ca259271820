//! Optional physical effects, described by data and switched on per design: the
//! unmodelled physics a sim-to-real gap diagnosis tries one at a time.
//!
//! * Hip effects plug into the dynamics through the [`Effect`] trait: an effect may reshape
//!   the actuator torque and/or add generalized forces (with their velocity derivative, so
//!   stiff effects stay stable under the implicit integrator). The integrator itself never
//!   changes when an effect is added. These are `hip_viscous_damping`,
//!   `hip_coulomb_friction`, `motor_torque_speed`, `actuation_latency` and `hip_backlash`.
//! * Contact effects change the foot–floor contact law instead, through the model's
//!   [`ContactParams`] ([`EffectSpec::apply_to_contact`], called by `Design::model`):
//!   `friction_coefficient`, `soft_ground` and `rolling_resistance`.
//!
//! Every effect has a neutral value at which it changes nothing, bit for bit (zero damping,
//! friction, latency, backlash or rolling length; the design's own μ), except `soft_ground`
//! (an infinitely stiff floor) and `motor_torque_speed` (an infinite no-load speed), which
//! validation excludes.

use std::collections::VecDeque;

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use super::contact::ContactParams;
use super::error::SimError;
use super::state::{Kinematics, State};

/// Longest accepted actuation latency [s]: far beyond any servo's, and it bounds the
/// command buffer (latency / time step entries).
pub const MAX_LATENCY_S: f64 = 1.0;
/// Largest accepted hip backlash [deg].
pub const MAX_BACKLASH_DEG: f64 = 45.0;

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
    /// Called exactly once per step, so an effect may keep state.
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
    /// Low foot–floor friction (slip): the contact's Coulomb coefficient μ becomes this.
    FrictionCoefficient { friction_mu: f64 },
    /// A compliant floor under the compliant foot: the contact modulus becomes the series
    /// combination E_foot·E_g/(E_foot + E_g).
    SoftGround { ground_modulus_pa: f64 },
    /// Rolling resistance at the foot: the centre of pressure shifts ahead of the rolling
    /// direction by e, a moment M = −e·Fₙ·ω_t/√(|ω_t|² + ω_s²) in the ground plane.
    RollingResistance { rolling_resistance_length_m: f64 },
    /// The hip actuator delivers the command issued `latency_s` earlier (nothing before).
    ActuationLatency { latency_s: f64 },
    /// Lash in the hip transmission: after a reversal of the command's sign the motor side
    /// crosses the lash at `crossing_rate_rad_s` and delivers no torque until it engages.
    HipBacklash {
        backlash_deg: f64,
        crossing_rate_rad_s: f64,
    },
}

impl EffectSpec {
    /// Checks parameter signs and ranges; `origin` names the file for the error message.
    pub fn validate(&self, origin: &str, field: &str) -> Result<(), SimError> {
        let check = |name: &str, v: f64, ok: bool, why: &str| {
            if ok && v.is_finite() {
                Ok(())
            } else {
                Err(SimError::InvalidValue {
                    origin: origin.to_string(),
                    field: format!("{field}.{name}"),
                    value: v.to_string(),
                    reason: why.to_string(),
                })
            }
        };
        match *self {
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad,
            } => check(
                "damping_nms_per_rad",
                damping_nms_per_rad,
                damping_nms_per_rad >= 0.0,
                "must be finite and ≥ 0",
            ),
            EffectSpec::HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            } => {
                check(
                    "friction_torque_nm",
                    friction_torque_nm,
                    friction_torque_nm >= 0.0,
                    "must be finite and ≥ 0",
                )?;
                check(
                    "stiction_rate_rad_s",
                    stiction_rate_rad_s,
                    stiction_rate_rad_s > 0.0,
                    "must be finite and > 0",
                )
            }
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s,
            } => check(
                "no_load_speed_rad_s",
                no_load_speed_rad_s,
                no_load_speed_rad_s > 0.0,
                "must be finite and > 0",
            ),
            EffectSpec::FrictionCoefficient { friction_mu } => check(
                "friction_mu",
                friction_mu,
                friction_mu > 0.0,
                "must be finite and > 0",
            ),
            EffectSpec::SoftGround { ground_modulus_pa } => check(
                "ground_modulus_pa",
                ground_modulus_pa,
                ground_modulus_pa > 0.0,
                "must be finite and > 0",
            ),
            EffectSpec::RollingResistance {
                rolling_resistance_length_m,
            } => check(
                "rolling_resistance_length_m",
                rolling_resistance_length_m,
                rolling_resistance_length_m >= 0.0,
                "must be finite and ≥ 0",
            ),
            EffectSpec::ActuationLatency { latency_s } => check(
                "latency_s",
                latency_s,
                (0.0..=MAX_LATENCY_S).contains(&latency_s),
                "must be in [0, 1] s",
            ),
            EffectSpec::HipBacklash {
                backlash_deg,
                crossing_rate_rad_s,
            } => {
                check(
                    "backlash_deg",
                    backlash_deg,
                    (0.0..=MAX_BACKLASH_DEG).contains(&backlash_deg),
                    "must be in [0, 45] deg",
                )?;
                check(
                    "crossing_rate_rad_s",
                    crossing_rate_rad_s,
                    crossing_rate_rad_s > 0.0,
                    "must be finite and > 0",
                )
            }
        }
    }

    /// True for the effects that act through the contact law ([`Self::apply_to_contact`])
    /// rather than as an [`Effect`].
    pub fn is_contact_effect(&self) -> bool {
        matches!(
            self,
            EffectSpec::FrictionCoefficient { .. }
                | EffectSpec::SoftGround { .. }
                | EffectSpec::RollingResistance { .. }
        )
    }

    /// Applies a contact effect to the model's contact parameters (no-op for the others).
    /// `leg_length_m` sets the rolling resistance's regularisation rate v_s/L when the
    /// parameters carry none (hand-built models; `Design::model` sets it).
    pub fn apply_to_contact(&self, contact: &mut ContactParams, leg_length_m: f64) {
        match *self {
            EffectSpec::FrictionCoefficient { friction_mu } => contact.friction_mu = friction_mu,
            EffectSpec::SoftGround { ground_modulus_pa } => {
                // Foot and floor are two compliant layers pressed by the same pressure (the
                // traction is continuous across the interface), and each one's penetration
                // fraction is p/E: the fractions add, 1/E_eff = 1/E_foot + 1/E_g, as springs
                // in series. Drake combines the hydroelastic moduli of two compliant bodies
                // the same way.
                let e = contact.modulus_pa;
                contact.modulus_pa = e * ground_modulus_pa / (e + ground_modulus_pa);
            }
            EffectSpec::RollingResistance {
                rolling_resistance_length_m,
            } => {
                // Several sources of rolling resistance shift the centre of pressure by the
                // sum of their lengths.
                contact.rolling_resistance_m += rolling_resistance_length_m;
                if contact.rolling_resistance_rate_rad_s <= 0.0 && leg_length_m > 0.0 {
                    contact.rolling_resistance_rate_rad_s =
                        contact.stiction_speed_mps / leg_length_m;
                }
            }
            EffectSpec::HipViscousDamping { .. }
            | EffectSpec::HipCoulombFriction { .. }
            | EffectSpec::MotorTorqueSpeed { .. }
            | EffectSpec::ActuationLatency { .. }
            | EffectSpec::HipBacklash { .. } => {}
        }
    }

    /// The runtime effect; `None` for contact effects, which act through the contact law.
    pub fn build(&self) -> Option<Box<dyn Effect>> {
        match *self {
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad,
            } => Some(Box::new(HipViscousDamping {
                damping_nms_per_rad,
            })),
            EffectSpec::HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            } => Some(Box::new(HipCoulombFriction {
                friction_torque_nm,
                stiction_rate_rad_s,
            })),
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s,
            } => Some(Box::new(MotorTorqueSpeed {
                no_load_speed_rad_s,
            })),
            EffectSpec::ActuationLatency { latency_s } => {
                Some(Box::new(ActuationLatency::new(latency_s)))
            }
            EffectSpec::HipBacklash {
                backlash_deg,
                crossing_rate_rad_s,
            } => Some(Box::new(HipBacklash::new(
                backlash_deg.to_radians(),
                crossing_rate_rad_s,
            ))),
            EffectSpec::FrictionCoefficient { .. }
            | EffectSpec::SoftGround { .. }
            | EffectSpec::RollingResistance { .. } => None,
        }
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

/// Dead time between the hip command and the delivered torque.
#[derive(Clone, Debug)]
pub struct ActuationLatency {
    pub latency_s: f64,
    /// (issue time, command) of the commands still needed, oldest first.
    buffer: VecDeque<(f64, f64)>,
}

impl ActuationLatency {
    pub fn new(latency_s: f64) -> Self {
        ActuationLatency {
            latency_s,
            buffer: VecDeque::new(),
        }
    }
}

impl Effect for ActuationLatency {
    fn name(&self) -> &'static str {
        "actuation_latency"
    }
    fn actuator_torque(&mut self, ctx: &EffectContext<'_>, commanded_nm: f64) -> (f64, f64) {
        // Exactly the identity at zero, so the neutral value reproduces the plain model.
        if self.latency_s == 0.0 {
            return (commanded_nm, 1.0);
        }
        self.buffer.push_back((ctx.time_s, commanded_nm));
        let t = ctx.time_s - self.latency_s;
        // Keep one command issued at or before t (the interpolation's left end).
        while self.buffer.len() >= 2 && self.buffer[1].0 <= t {
            self.buffer.pop_front();
        }
        // The slope is 0 once the latency spans a step: what arrives now was fixed
        // latency_s ago, whatever this step does.
        match (self.buffer.front(), self.buffer.get(1)) {
            (Some(&(t0, c0)), Some(&(t1, c1))) if t >= t0 => {
                // Linear between the buffered commands, so a latency that is not a whole
                // number of steps gives results that vary smoothly with it. Below one step
                // the right end is this step's command, which keeps its share w of the
                // implicit servo slope: the effect then tends continuously to the plain
                // (implicit) servo as the latency goes to 0.
                let w = (t - t0) / (t1 - t0);
                let slope = if t1 == ctx.time_s { w } else { 0.0 };
                (c0 + w * (c1 - c0), slope)
            }
            (Some(&(t0, c0)), None) if t >= t0 => (c0, 0.0),
            // Nothing issued latency_s ago: the first command has not arrived yet.
            _ => (0.0, 0.0),
        }
    }
}

/// Lash in the hip transmission, with a massless motor side.
#[derive(Clone, Copy, Debug)]
pub struct HipBacklash {
    pub backlash_rad: f64,
    pub crossing_rate_rad_s: f64,
    /// Motor side's position in the lash relative to the leg, in [−b/2, +b/2]; engaged on
    /// side s when it equals s·b/2.
    gap_rad: f64,
}

impl HipBacklash {
    /// Starts engaged on the positive side.
    pub fn new(backlash_rad: f64, crossing_rate_rad_s: f64) -> Self {
        HipBacklash {
            backlash_rad,
            crossing_rate_rad_s,
            gap_rad: 0.5 * backlash_rad,
        }
    }
}

impl Effect for HipBacklash {
    fn name(&self) -> &'static str {
        "hip_backlash"
    }
    fn actuator_torque(&mut self, ctx: &EffectContext<'_>, commanded_nm: f64) -> (f64, f64) {
        let half = 0.5 * self.backlash_rad;
        let target = if commanded_nm > 0.0 {
            half
        } else if commanded_nm < 0.0 {
            -half
        } else {
            // No command: the motor side stays where it is.
            let engaged = if self.gap_rad.abs() == half { 1.0 } else { 0.0 };
            return (commanded_nm, engaged);
        };
        let distance = (target - self.gap_rad).abs();
        let closing_s = distance / self.crossing_rate_rad_s;
        // Deliver the command for the part of the step after the lash closes, so results
        // are smooth in b (and b = 0 gives exactly the fraction 1).
        let fraction = if closing_s >= ctx.dt_s {
            self.gap_rad += (target - self.gap_rad).signum() * self.crossing_rate_rad_s * ctx.dt_s;
            0.0
        } else {
            self.gap_rad = target;
            (ctx.dt_s - closing_s) / ctx.dt_s
        };
        (commanded_nm * fraction, fraction)
    }
}
