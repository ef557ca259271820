//! Hip actuation: Mugatu's position servo and Zippy's bang-bang torque.

use serde::{Deserialize, Serialize};

/// Hip controller (acts on the hip angle q; positive torque accelerates q).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Controller {
    /// Position servo tracking q_d = A·sin(2πft) with a PD law and a torque clamp
    /// (a hobby servo such as the Dynamixel XL330 in position mode).
    ServoSine {
        amplitude_rad: f64,
        frequency_hz: f64,
        kp_nm_per_rad: f64,
        kd_nms_per_rad: f64,
        torque_limit_nm: f64,
    },
    /// Torque of fixed magnitude, +τ₀ for the first half of each period and −τ₀ for the
    /// second (an open-loop DC motor); the swing is stopped by the hip hardstops.
    BangBang { torque_nm: f64, frequency_hz: f64 },
    /// No actuation (passive tests).
    Passive,
}

/// Torque command and its (negated) slopes, used by the implicit integrator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Command {
    pub torque_nm: f64,
    /// −∂τ/∂q̇ [N·m·s/rad] (0 when saturated).
    pub damping_nms_per_rad: f64,
    /// −∂τ/∂q [N·m/rad] (0 when saturated).
    pub stiffness_nm_per_rad: f64,
}

impl Controller {
    /// Drive frequency [Hz] (one period = one stride = two steps), if any.
    pub fn frequency_hz(&self) -> Option<f64> {
        match self {
            Controller::ServoSine { frequency_hz, .. }
            | Controller::BangBang { frequency_hz, .. } => Some(*frequency_hz),
            Controller::Passive => None,
        }
    }

    /// The torque limit (servo) or magnitude (bang-bang) [N·m].
    pub fn torque_limit_nm(&self) -> Option<f64> {
        match self {
            Controller::ServoSine {
                torque_limit_nm, ..
            } => Some(*torque_limit_nm),
            Controller::BangBang { torque_nm, .. } => Some(*torque_nm),
            Controller::Passive => None,
        }
    }

    /// Replaces the torque limit (servo) or magnitude (bang-bang).
    pub fn set_torque_limit_nm(&mut self, value: f64) {
        match self {
            Controller::ServoSine {
                torque_limit_nm, ..
            } => *torque_limit_nm = value,
            Controller::BangBang { torque_nm, .. } => *torque_nm = value,
            Controller::Passive => {}
        }
    }

    /// Replaces the drive frequency.
    pub fn set_frequency_hz(&mut self, value: f64) {
        match self {
            Controller::ServoSine { frequency_hz, .. }
            | Controller::BangBang { frequency_hz, .. } => *frequency_hz = value,
            Controller::Passive => {}
        }
    }

    /// The servo's PD command before its torque limit, with its slopes (for the implicit
    /// step, which clamps the torque it actually applies; see `Simulator::step`); the
    /// bang-bang and passive commands as [`Controller::command`].
    pub fn command_unclamped(&self, t: f64, q: f64, qd: f64) -> Command {
        match *self {
            Controller::ServoSine {
                amplitude_rad,
                frequency_hz,
                kp_nm_per_rad,
                kd_nms_per_rad,
                ..
            } => {
                let w = 2.0 * std::f64::consts::PI * frequency_hz;
                let (s, c) = (w * t).sin_cos();
                Command {
                    torque_nm: -kp_nm_per_rad * (q - amplitude_rad * s)
                        - kd_nms_per_rad * (qd - amplitude_rad * w * c),
                    damping_nms_per_rad: kd_nms_per_rad,
                    stiffness_nm_per_rad: kp_nm_per_rad,
                }
            }
            Controller::BangBang { .. } | Controller::Passive => self.command(t, q, qd),
        }
    }

    /// Torque command at time t for hip angle q and rate q̇.
    pub fn command(&self, t: f64, q: f64, qd: f64) -> Command {
        match *self {
            Controller::ServoSine {
                torque_limit_nm, ..
            } => {
                let raw = self.command_unclamped(t, q, qd);
                if raw.torque_nm.abs() <= torque_limit_nm {
                    raw
                } else {
                    Command {
                        torque_nm: torque_limit_nm.copysign(raw.torque_nm),
                        ..Command::default()
                    }
                }
            }
            Controller::BangBang {
                torque_nm,
                frequency_hz,
            } => {
                let phase = (t * frequency_hz).fract();
                Command {
                    torque_nm: if phase < 0.5 { torque_nm } else { -torque_nm },
                    ..Command::default()
                }
            }
            Controller::Passive => Command::default(),
        }
    }
}
