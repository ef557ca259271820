//! Unit tests of `gap::knob`.

use robot_survey::gap::knob::{KnobKind, Knobs, ModelSetting};
use robot_survey::gap::library::{EffectDef, EffectLibrary};
use robot_survey::sim::Design;

/// The knobs of the bundled Mugatu: its declared parameters (nominal inside the range),
/// then the effects — damping (off = 0) strengthening upward, the motor line (off = ∞)
/// downward — and friction_coefficient left out because the design calibrates μ.
#[test]
fn mugatu_knobs_and_their_directions() {
    let lib = EffectLibrary::bundled().expect("library");
    let d = Design::builtin("mugatu").expect("mugatu");
    let effects: Vec<&EffectDef> = lib.effects.iter().collect();
    let k = Knobs::build(&[&d], &effects, true).expect("knobs");
    let n_params = d.uncertain.len();
    assert!(
        k.list[..n_params]
            .iter()
            .all(|x| x.kind == KnobKind::Parameter)
    );
    assert_eq!(
        k.aliased,
        vec![(
            "friction_coefficient".to_string(),
            "contact.friction_mu".to_string()
        )]
    );
    let slope = &k.list[k.index_of("mugatu:ground.slope_deg").expect("slope")];
    assert_eq!((slope.lo, slope.hi, slope.nominal), (-3.0, 3.0, Some(0.0)));
    // The prior in unit coordinates: N(v; 0, 1°) over [−3°, 3°] (mass 0.9973), ×6 for
    // the unit interval: at 2° (unit 5/6), ln(6·φ(2)/0.9973).
    let want = (6.0 * (-2.0f64).exp() / (2.0 * std::f64::consts::PI).sqrt() / 0.997_300_2).ln();
    assert!(
        (slope.log_prior_unit(5.0 / 6.0) - want).abs() < 1e-6,
        "{}",
        slope.log_prior_unit(5.0 / 6.0)
    );
    let damping = &k.list[k.index_of("hip_viscous_damping").expect("damping")];
    let path = damping.strengthening_path(4);
    assert!(path[0] < path[4] && damping.nominal.is_none());
    let motor = &k.list[k.index_of("motor_torque_speed").expect("motor")];
    let path = motor.strengthening_path(4);
    assert!(path[0] > path[4], "a slower motor is a stronger effect");
    // Coordinates: ln for effects; a knob at its nominal is the nominal model.
    assert!((damping.value(damping.coordinate(0.02)) - 0.02).abs() < 1e-15);
    let mut p = k.nominal_point();
    p[k.index_of("mugatu:ground.slope_deg").expect("slope")] = Some(0.0);
    assert_eq!(k.setting(&lib, &p), ModelSetting::nominal());
    let off = Knobs::build(&[&d], &effects, false).expect("no calibration");
    assert!(off.list.iter().all(|x| x.kind == KnobKind::Effect));
    assert!(off.aliased.is_empty(), "without calibration μ is an effect");
}
