//! The designer's torque question (`survey predict --from design:NAME`): how much hip
//! torque does a walker of this design need at leg length L, and which catalogued actuator
//! delivers it with margin?
//!
//! Table III gives the minimum torque in units of m·g·L along the design's chain (nearly
//! constant under similarity; it drifts with size under fixed material). At the target L it
//! is interpolated (log–log) between the walking sizes, with the bisection bracket as its
//! uncertainty, and multiplied by m·g·L for each candidate mass: the survey class fit's
//! prediction (with its prediction interval) and the design scaled by m ∝ L² and L³.

use serde::Serialize;

use super::StudyError;
use super::table3::Table3Point;
use super::torque_check::interpolate;
use crate::motors::MotorCatalogue;
use crate::sim::{ContactScaling, GRAVITY_MPS2, MassLaw};

#[derive(Clone, Debug, Serialize)]
pub struct TorqueAtMass {
    /// Where the mass comes from.
    pub mass_from: String,
    pub mass_kg: f64,
    /// The mass's own interval (the class fit's prediction interval), when it has one.
    pub mass_interval_kg: Option<[f64; 2]>,
    pub required_nm: f64,
    /// Bracket of τ_min/(mgL) × the mass interval.
    pub required_interval_nm: [f64; 2],
}

#[derive(Clone, Debug, Serialize)]
pub struct ActuatorOption {
    pub id: String,
    pub name: String,
    pub mass_kg: Option<f64>,
    pub voltage_v: Option<f64>,
    pub stall_torque_nm: f64,
    pub continuous_torque_nm: Option<f64>,
    /// Stall torque / required torque (of the first mass).
    pub margin: f64,
    /// False for the strongest actuators listed when none meets the margin.
    pub meets_margin: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct TorqueNeed {
    pub design: String,
    pub leg_length_m: f64,
    /// The Table III chain used.
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    /// τ_min/(m·g·L) at L and its bracket [failing, walking].
    pub min_torque_over_mgl: f64,
    pub bracket_over_mgl: [f64; 2],
    /// Walking sizes of the chain [m] (the range interpolated over).
    pub walking_range_m: [f64; 2],
    pub torques: Vec<TorqueAtMass>,
    /// Required margin of stall torque over the requirement.
    pub torque_margin: f64,
    /// Catalogued actuators whose stall torque ≥ margin × the first requirement, lightest first.
    pub actuators: Vec<ActuatorOption>,
}

/// `survey predict --from design:NAME`'s torque (the CLI and the Python package): Table
/// III's m ∝ L² chain under `contact`, read from `points_file` (None: the bundled
/// points), at the candidate `masses`, with the actuators of the catalogue
/// (`MotorCatalogue::locate`: a `./dataset/motors` that does not load is an error, not a
/// prediction silently without the motor comparison).
pub fn for_prediction(
    design: &str,
    contact: ContactScaling,
    leg_length_m: f64,
    masses: &[(String, f64, Option<[f64; 2]>)],
    torque_margin: f64,
    points_file: Option<&std::path::Path>,
) -> Result<TorqueNeed, StudyError> {
    if !(torque_margin.is_finite() && torque_margin > 0.0) {
        return Err(StudyError::TorqueMargin(torque_margin));
    }
    let points = super::table3::points(points_file)?;
    let motors = MotorCatalogue::locate(None)?;
    torque_need(
        &points,
        design,
        MassLaw::L2,
        contact,
        leg_length_m,
        masses,
        Some(&motors),
        torque_margin,
    )
}

/// `masses`: (label, mass, interval) candidates; the first one sizes the actuators.
#[allow(clippy::too_many_arguments)]
pub fn torque_need(
    points: &[Table3Point],
    design: &str,
    mass_law: MassLaw,
    contact: ContactScaling,
    leg_length_m: f64,
    masses: &[(String, f64, Option<[f64; 2]>)],
    catalogue: Option<&MotorCatalogue>,
    torque_margin: f64,
) -> Result<TorqueNeed, StudyError> {
    let chain: Vec<Table3Point> = points
        .iter()
        .filter(|p| p.design == design && p.mass_law == mass_law && p.contact == contact)
        .cloned()
        .collect();
    let walking = || chain.iter().filter(|p| p.walks).map(|p| p.leg_length_m);
    let (Some(first), Some(last)) = (
        walking().min_by(f64::total_cmp),
        walking().max_by(f64::total_cmp),
    ) else {
        return Err(StudyError::InvalidOption {
            option: "design".into(),
            reason: format!(
                "Table III has no walking size for design `{design}` ({mass_law:?}, {contact:?} contact)"
            ),
        });
    };
    let range = [first, last];
    let interp = |get: fn(&Table3Point) -> Option<f64>| interpolate(&chain, leg_length_m, get);
    let outside = || StudyError::InvalidOption {
        option: "leg_length".into(),
        reason: format!(
            "{leg_length_m} m is outside the sizes at which {design} walks in Table III \
             ({}–{} m, {mass_law:?}, {contact:?} contact): no interpolation there",
            range[0], range[1]
        ),
    };
    let ratio = interp(|p| p.min_torque_over_mgl).ok_or_else(outside)?;
    let lo =
        interp(|p| p.bracket_lo_nm.map(|v| v / p.mgl_nm).filter(|v| *v > 0.0)).unwrap_or(ratio);
    let hi = interp(|p| p.bracket_hi_nm.map(|v| v / p.mgl_nm)).unwrap_or(ratio);
    let torques = required_torques(masses, leg_length_m, ratio, [lo, hi]);
    let actuators = match (catalogue, torques.first()) {
        (Some(cat), Some(need)) => actuator_options(cat, need.required_nm, torque_margin),
        _ => Vec::new(),
    };
    Ok(TorqueNeed {
        design: design.to_string(),
        leg_length_m,
        mass_law,
        contact,
        min_torque_over_mgl: ratio,
        bracket_over_mgl: [lo, hi],
        walking_range_m: range,
        torques,
        torque_margin,
        actuators,
    })
}

/// The torque each candidate mass needs at leg length L: τ_min/(m·g·L) times m·g·L, with a
/// bracket that spans both the ratio's bracket `[lo, hi]` and the mass's own interval.
fn required_torques(
    masses: &[(String, f64, Option<[f64; 2]>)],
    leg_length_m: f64,
    ratio: f64,
    [lo, hi]: [f64; 2],
) -> Vec<TorqueAtMass> {
    let gl = GRAVITY_MPS2 * leg_length_m;
    masses
        .iter()
        .map(|(label, m, iv)| {
            let [m_lo, m_hi] = iv.unwrap_or([*m, *m]);
            TorqueAtMass {
                mass_from: label.clone(),
                mass_kg: *m,
                mass_interval_kg: *iv,
                required_nm: ratio * m * gl,
                required_interval_nm: [lo.min(ratio) * m_lo * gl, hi.max(ratio) * m_hi * gl],
            }
        })
        .collect()
}

/// The catalogued actuators whose stall torque (at the recommended voltage, or the only
/// rating) is at least `torque_margin` × `required_nm`, lightest first; when none is, the
/// three strongest, so the shortfall shows.
fn actuator_options(
    cat: &MotorCatalogue,
    required_nm: f64,
    torque_margin: f64,
) -> Vec<ActuatorOption> {
    let all: Vec<ActuatorOption> = cat
        .actuators
        .iter()
        .filter_map(|a| {
            let r = a.rating(None)?;
            let margin = r.stall_torque_nm / required_nm;
            Some(ActuatorOption {
                id: a.id.clone(),
                name: a.name.clone(),
                mass_kg: a.mass_kg,
                voltage_v: r.voltage_v,
                stall_torque_nm: r.stall_torque_nm,
                continuous_torque_nm: a.continuous_torque_nm,
                margin,
                meets_margin: margin >= torque_margin,
            })
        })
        .collect();
    let mut actuators: Vec<ActuatorOption> =
        all.iter().filter(|a| a.meets_margin).cloned().collect();
    actuators.sort_by(|a, b| {
        a.mass_kg
            .unwrap_or(f64::INFINITY)
            .total_cmp(&b.mass_kg.unwrap_or(f64::INFINITY))
            .then(a.stall_torque_nm.total_cmp(&b.stall_torque_nm))
    });
    if actuators.is_empty() {
        // None is strong enough: show the strongest, so the shortfall is visible.
        let mut strongest = all;
        strongest.sort_by(|a, b| b.stall_torque_nm.total_cmp(&a.stall_torque_nm));
        strongest.truncate(3);
        actuators = strongest;
    }
    actuators
}
