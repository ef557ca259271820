//! Unit tests of `gap::hypothesis`.

use robot_survey::gap::hypothesis::{Class, hypotheses};
use robot_survey::gap::knob::{KnobKind, Knobs};
use robot_survey::gap::library::{EffectDef, EffectLibrary};
use robot_survey::sim::Design;

/// Mugatu with the whole library: 12 declared parameters and 7 effects (μ is declared,
/// so friction_coefficient is not an effect knob) make 19 singles and 171 pairs; the
/// priors sum to 1 and each class holds its mass; an untestable suspect leaves every
/// explanation it is in.
#[test]
fn mugatu_explanations_and_their_priors() {
    let lib = EffectLibrary::bundled().expect("library");
    let d = Design::builtin("mugatu").expect("mugatu");
    let effects: Vec<&EffectDef> = lib.effects.iter().collect();
    let knobs = Knobs::build(&[&d], &effects, true)
        .and_then(|k| k.with_undeclared(&[&d], &lib))
        .expect("knobs");
    let undeclared = knobs
        .list
        .iter()
        .filter(|k| k.kind == KnobKind::Undeclared)
        .count();
    assert!(undeclared > 5, "{undeclared}");
    let priors = robot_survey::gap::criterion::Criterion::bundled()
        .expect("criterion")
        .prior;
    let all = vec![true; knobs.len()];
    let h = hypotheses(&knobs, &all, &priors);
    let count = |c: Class| h.iter().filter(|x| x.class == c).count();
    assert_eq!(count(Class::One), 19);
    assert_eq!(count(Class::Two), 171);
    assert_eq!(count(Class::Undeclared), undeclared);
    let sum: f64 = h.iter().map(|x| x.prior).sum();
    assert!((sum - 1.0).abs() < 1e-12);
    let two: f64 = h
        .iter()
        .filter(|x| x.class == Class::Two)
        .map(|x| x.prior)
        .sum();
    assert!((two - priors.two).abs() < 1e-12);
    assert_eq!(h.last().map(|x| x.class), Some(Class::NoneOfThese));
    let mut some = all.clone();
    some[0] = false;
    let h2 = hypotheses(&knobs, &some, &priors);
    assert_eq!(h2.iter().filter(|x| x.class == Class::Two).count(), 153);
    assert!(h2.iter().all(|x| !x.knobs.contains(&0)));
}
