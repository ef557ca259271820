//! Walker torque against motor-torque scaling laws (`survey torque-check`): across leg
//! length, the minimum hip torque a design needs (Table III) beside the torque each motor
//! law says an actuator delivers, under an explicit bridge between motor size and robot
//! size — the assumption the paper leaves implicit:
//!
//! * **isometric actuator**: the actuator is scaled with the robot, its length L_m ∝ L, so
//!   a law τ ∝ L_m^k gives τ_avail ∝ L^k (a law F ∝ M^k on actuator mass M ∝ L³, acting
//!   on a lever ∝ L_m, gives L^(3k+1); the catalogue's τ ∝ M^b gives L^(3b));
//! * **fixed actuator mass fraction**: the actuator keeps the same share of the robot's
//!   mass, M ∝ m ∝ L^e (e the mass law), an isometric motor of that mass has L_m ∝ M^(1/3),
//!   so τ ∝ L_m^k gives L^(e·k/3) (F ∝ M^k: L^(e·k + e/3); τ ∝ M^b: L^(e·b)).
//!
//! The motor-length laws have no published coefficients (walkers.md §5.1): every law is
//! pinned to the design's own hip actuator at the design's own size (the anchor of
//! `dataset/motors/anchors.toml`), τ_avail(L) = τ_stall,anchor·(L/L_anchor)^p. Margin =
//! τ_avail/τ_min; a crossover is where it passes 1.

use serde::Serialize;

use super::StudyError;
use super::table3::{Table3Point, Table3Row};
use crate::motors::{Actuator, MotorCatalogue, Quantity, SizeVariable, SourceKind};
use crate::regression::PowerLawFit;
use crate::sim::{ContactScaling, MassLaw};

/// How actuator size follows robot size.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Bridge {
    /// Actuator length ∝ leg length (the literature's L_m laws apply directly).
    IsometricActuator,
    /// Actuator mass a fixed fraction of the robot's mass.
    FixedMassFraction,
}

impl Bridge {
    pub fn describe(self) -> &'static str {
        match self {
            Bridge::IsometricActuator => {
                "isometric actuator: actuator length ∝ L, actuator mass ∝ L³ (the motor laws in L_m apply with L_m ∝ L)"
            }
            Bridge::FixedMassFraction => {
                "fixed actuator mass fraction: actuator mass ∝ robot mass ∝ L^e, an isometric motor of that mass (L_m ∝ M^(1/3))"
            }
        }
    }
}

/// The actuator pinning the laws.
#[derive(Clone, Debug, Serialize)]
pub struct AnchorUsed {
    pub actuator: String,
    pub actuator_name: String,
    pub voltage_v: Option<f64>,
    pub stall_torque_nm: f64,
    pub actuator_mass_kg: Option<f64>,
    pub leg_length_m: f64,
    /// The design's mass at the anchor's leg length [kg].
    pub robot_mass_kg: f64,
    /// The design's minimum torque at the anchor's size (interpolated) [N·m].
    pub required_nm: Option<f64>,
}

/// One law under one bridge.
#[derive(Clone, Debug, Serialize)]
pub struct LawCheck {
    pub law: String,
    pub basis: String,
    /// Exponent of the law in its own size variable.
    pub law_exponent: f64,
    /// p in τ_avail ∝ L^p under the bridge.
    pub exponent_vs_leg_length: f64,
    /// τ_avail at each walking size [N·m].
    pub available_nm: Vec<f64>,
    /// τ_avail/τ_min at each walking size.
    pub margin: Vec<f64>,
    /// Leg lengths at which the margin passes 1 (log–log interpolation).
    pub crossovers_m: Vec<f64>,
    /// Sizes (of the study) at which the requirement exceeds the law.
    pub short_at_m: Vec<f64>,
    pub verdict: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct BridgeCheck {
    pub bridge: Bridge,
    pub description: String,
    pub laws: Vec<LawCheck>,
    /// Actuator mass / robot mass at each walking size (the anchor's ratio carried by the
    /// bridge): above 1 the bridge is physically impossible.
    pub actuator_mass_fraction: Vec<Option<f64>>,
}

#[derive(Clone, Debug, Serialize)]
pub struct TorqueCheck {
    pub design: String,
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    pub anchor: AnchorUsed,
    /// Walking sizes of Table III [m] and their minimum torques [N·m].
    pub leg_lengths_m: Vec<f64>,
    pub required_nm: Vec<f64>,
    /// τ_min ∝ L^b over the walking sizes.
    pub required_exponent: Option<f64>,
    /// The catalogue's τ_stall ∝ M^b (datasheet stall torques at the recommended voltage).
    pub actuator_fit_exponent: Option<f64>,
    pub actuator_fit_exponent_ci: Option<[f64; 2]>,
    pub actuator_fit_r2: Option<f64>,
    pub actuator_fit_n: usize,
    pub bridges: Vec<BridgeCheck>,
}

/// Log–log interpolation of the minimum torque over a chain's walking sizes (None outside
/// them or where a neighbour does not walk).
pub fn interpolate_min_torque(points: &[Table3Point], leg_length_m: f64) -> Option<f64> {
    interpolate(points, leg_length_m, |p| p.min_torque_nm)
}

/// Log–log interpolation of a column over the walking points (exact at a point; None
/// outside them).
pub(crate) fn interpolate(
    points: &[Table3Point],
    l: f64,
    get: fn(&Table3Point) -> Option<f64>,
) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.walks)
        .filter_map(|p| get(p).map(|y| (p.leg_length_m, y)))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(&(_, y)) = pts.iter().find(|(x, _)| *x == l) {
        return Some(y);
    }
    let w = pts.windows(2).find(|w| w[0].0 < l && l < w[1].0)?;
    let t = (l / w[0].0).ln() / (w[1].0 / w[0].0).ln();
    Some((w[0].1.ln() + t * (w[1].1 / w[0].1).ln()).exp())
}

/// Checks one Table III chain against every law of the catalogue under both bridges.
/// `anchor`: (actuator id, voltage) to pin the laws with, else the catalogue's anchor of
/// the design.
pub fn torque_check(
    row: &Table3Row,
    catalogue: &MotorCatalogue,
    anchor: Option<(&str, Option<f64>)>,
    anchor_leg_length_m: Option<f64>,
    design_mass_at: &dyn Fn(f64) -> f64,
) -> Result<TorqueCheck, StudyError> {
    let (actuator, voltage, l0) = resolve_anchor(row, catalogue, anchor, anchor_leg_length_m)?;
    let tau0 = anchor_stall_torque(actuator, voltage)?;
    let m0 = design_mass_at(l0);
    let walking: Vec<&Table3Point> = row
        .points
        .iter()
        .filter(|p| p.walks && p.min_torque_nm.is_some())
        .collect();
    let ls: Vec<f64> = walking.iter().map(|p| p.leg_length_m).collect();
    let req: Vec<f64> = walking.iter().filter_map(|p| p.min_torque_nm).collect();
    let e = row.mass_law.exponent();
    let fit = catalogue
        .stall_torque_vs_mass(&[SourceKind::Datasheet])
        .ok();
    let n_fit = catalogue
        .stall_torque_mass_points(&[SourceKind::Datasheet])
        .len();
    let mut bridges = Vec::new();
    for bridge in [Bridge::IsometricActuator, Bridge::FixedMassFraction] {
        let checks = laws_under(bridge, catalogue, fit.as_ref(), e)
            .into_iter()
            .map(|(id, basis, k, p)| law_check(id, basis, k, p, tau0, l0, &ls, &req))
            .collect();
        let fraction = actuator_mass_fractions(bridge, actuator, (l0, m0), &ls, design_mass_at);
        bridges.push(BridgeCheck {
            bridge,
            description: format!("{} (here e = {e})", bridge.describe()),
            laws: checks,
            actuator_mass_fraction: fraction,
        });
    }
    Ok(TorqueCheck {
        design: row.design.clone(),
        mass_law: row.mass_law,
        contact: row.contact,
        anchor: AnchorUsed {
            actuator: actuator.id.clone(),
            actuator_name: actuator.name.clone(),
            voltage_v: voltage,
            stall_torque_nm: tau0,
            actuator_mass_kg: actuator.mass_kg,
            leg_length_m: l0,
            robot_mass_kg: m0,
            required_nm: interpolate_min_torque(&row.points, l0),
        },
        leg_lengths_m: ls,
        required_nm: req,
        required_exponent: row.torque_exponent,
        actuator_fit_exponent: fit.as_ref().map(|f| f.b),
        actuator_fit_exponent_ci: fit.as_ref().map(|f| [f.b_ci.lower, f.b_ci.upper]),
        actuator_fit_r2: fit.as_ref().map(|f| f.r2),
        actuator_fit_n: n_fit,
        bridges,
    })
}

/// The anchor actuator's stall torque at `voltage` (None: its recommended voltage); an
/// error when it has no rating there.
fn anchor_stall_torque(actuator: &Actuator, voltage: Option<f64>) -> Result<f64, StudyError> {
    actuator
        .stall_torque_at(voltage)
        .ok_or_else(|| StudyError::InvalidOption {
            option: "voltage".into(),
            reason: format!(
                "actuator `{}` has no rating at {}",
                actuator.id,
                voltage
                    .map(|v| format!("{v} V"))
                    .unwrap_or("its recommended voltage".into())
            ),
        })
}

/// Every law of the catalogue as (id, basis, exponent in its own size variable, exponent
/// p vs leg length under `bridge`), then the catalogue's own τ_stall ∝ M^b fit when there
/// is one; `e` is the robot's mass-law exponent.
fn laws_under(
    bridge: Bridge,
    catalogue: &MotorCatalogue,
    fit: Option<&PowerLawFit>,
    e: f64,
) -> Vec<(String, String, f64, f64)> {
    let mut laws: Vec<(String, String, f64, f64)> = catalogue
        .laws
        .iter()
        .map(|law| {
            let k = law.exponent;
            let p = bridge_exponent(bridge, law.size_variable, law.quantity, k, e);
            (
                law.id.clone(),
                format!("{:?}", law.basis).to_lowercase(),
                k,
                p,
            )
        })
        .collect();
    if let Some(f) = fit {
        let p = match bridge {
            Bridge::IsometricActuator => 3.0 * f.b,
            Bridge::FixedMassFraction => e * f.b,
        };
        laws.push(("catalogue-fit".into(), "catalogue".into(), f.b, p));
    }
    laws
}

/// Actuator mass / robot mass at each leg length in `ls`, starting from the anchor's ratio
/// at (leg length, robot mass) `(l0, m0)` and carried by `bridge`; None without an
/// actuator mass.
fn actuator_mass_fractions(
    bridge: Bridge,
    actuator: &Actuator,
    (l0, m0): (f64, f64),
    ls: &[f64],
    design_mass_at: &dyn Fn(f64) -> f64,
) -> Vec<Option<f64>> {
    ls.iter()
        .map(|&l| {
            let f0 = actuator.mass_kg? / m0;
            Some(match bridge {
                Bridge::IsometricActuator => f0 * (l / l0).powf(3.0) * m0 / design_mass_at(l),
                Bridge::FixedMassFraction => f0,
            })
        })
        .collect()
}

/// The actuator, voltage and leg length the laws are pinned at: the one named, else the
/// catalogue's anchor of the design.
fn resolve_anchor<'c>(
    row: &Table3Row,
    catalogue: &'c MotorCatalogue,
    anchor: Option<(&str, Option<f64>)>,
    anchor_leg_length_m: Option<f64>,
) -> Result<(&'c Actuator, Option<f64>, f64), StudyError> {
    let found = match anchor {
        Some((id, v)) => {
            let a = catalogue
                .actuator(id)
                .ok_or_else(|| StudyError::InvalidOption {
                    option: "actuator".into(),
                    reason: format!(
                        "no actuator `{id}` in the motor catalogue (dataset/motors/actuators.toml)"
                    ),
                })?;
            let l0 = anchor_leg_length_m.ok_or_else(|| StudyError::InvalidOption {
                option: "anchor_leg_length".into(),
                reason: "an explicit actuator needs the leg length it drives".into(),
            })?;
            (a, v, l0)
        }
        None => {
            let (an, a, _) = catalogue.anchor_stall_torque(&row.design).ok_or_else(|| {
                StudyError::InvalidOption {
                    option: "actuator".into(),
                    reason: format!(
                        "design `{}` has no anchor actuator in dataset/motors/anchors.toml \
                     (its motor is not catalogued); name one with --actuator ID",
                        row.design
                    ),
                }
            })?;
            (a, Some(an.voltage_v), an.leg_length_m)
        }
    };
    Ok(found)
}

/// The exponent of available torque in leg length that a motor law of exponent `k` gives
/// under a bridge (`e`: the mass law's exponent).
fn bridge_exponent(
    bridge: Bridge,
    size_variable: SizeVariable,
    quantity: Quantity,
    k: f64,
    e: f64,
) -> f64 {
    match (bridge, size_variable, quantity) {
        (Bridge::IsometricActuator, SizeVariable::MotorLength, Quantity::Torque) => k,
        (Bridge::IsometricActuator, SizeVariable::MotorLength, Quantity::Force) => k + 1.0,
        (Bridge::IsometricActuator, SizeVariable::MotorMass, Quantity::Torque) => 3.0 * k,
        (Bridge::IsometricActuator, SizeVariable::MotorMass, Quantity::Force) => 3.0 * k + 1.0,
        (Bridge::FixedMassFraction, SizeVariable::MotorLength, Quantity::Torque) => e * k / 3.0,
        (Bridge::FixedMassFraction, SizeVariable::MotorLength, Quantity::Force) => {
            e * (k + 1.0) / 3.0
        }
        (Bridge::FixedMassFraction, SizeVariable::MotorMass, Quantity::Torque) => e * k,
        (Bridge::FixedMassFraction, SizeVariable::MotorMass, Quantity::Force) => e * k + e / 3.0,
    }
}

#[allow(clippy::too_many_arguments)]
fn law_check(
    id: String,
    basis: String,
    k: f64,
    p: f64,
    tau0: f64,
    l0: f64,
    ls: &[f64],
    req: &[f64],
) -> LawCheck {
    let available: Vec<f64> = ls.iter().map(|&l| tau0 * (l / l0).powf(p)).collect();
    let margin: Vec<f64> = available.iter().zip(req).map(|(a, r)| a / r).collect();
    let mut crossovers = Vec::new();
    for i in 1..margin.len() {
        let (a, b) = (margin[i - 1].ln(), margin[i].ln());
        if a * b < 0.0 || (b == 0.0 && a != 0.0) {
            let t = a / (a - b);
            crossovers.push((ls[i - 1].ln() + t * (ls[i] / ls[i - 1]).ln()).exp());
        }
    }
    let short: Vec<f64> = ls
        .iter()
        .zip(&margin)
        .filter(|(_, m)| **m < 1.0)
        .map(|(l, _)| *l)
        .collect();
    let verdict = match (short.is_empty(), ls.first(), ls.last()) {
        (true, Some(a), Some(b)) => {
            format!("delivers the requirement at every walking size ({a}–{b} m)")
        }
        (_, None, _) | (_, _, None) => "no walking sizes".into(),
        (false, _, _) if short.len() == ls.len() => {
            "short of the requirement at every walking size".into()
        }
        (false, Some(&first), Some(&last)) => {
            let below = short
                .iter()
                .all(|l| *l < crossovers.first().copied().unwrap_or(last));
            let above = short
                .iter()
                .all(|l| *l > crossovers.last().copied().unwrap_or(first));
            let cross = crossovers
                .iter()
                .map(|c| format!("{c:.3}"))
                .collect::<Vec<_>>()
                .join(", ");
            if below {
                format!("short below L ≈ {cross} m")
            } else if above {
                format!("short above L ≈ {cross} m")
            } else {
                format!("short on part of the range (crossovers at {cross} m)")
            }
        }
    };
    LawCheck {
        law: id,
        basis,
        law_exponent: k,
        exponent_vs_leg_length: p,
        available_nm: available,
        margin,
        crossovers_m: crossovers,
        short_at_m: short,
        verdict,
    }
}
