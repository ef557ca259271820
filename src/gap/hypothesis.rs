//! The explanations a diagnosis weighs, as data: the nominal model (nothing off), every
//! suspect alone (a declared `[[uncertain]]` parameter off, or a library effect present),
//! every pair of suspects, each undeclared number of the design alone, and "something outside
//! these" ([`super::evidence::none_of_these`]). Each class's prior mass
//! ([`super::criterion::ClassPriors`]) is spread evenly over its members.
//!
//! A suspect in an explanation is free over its prior (the design's range and sd, or the
//! effect's plausible range, log-uniform); a suspect not in it is at the design's value (a
//! parameter) or absent (an effect). Values the trials cannot tell from the nominal are not
//! part of a suspect's prior ([`super::evidence::Slab`]): an effect too weak to change any
//! measurement is no explanation of a gap.

use serde::Serialize;

use super::criterion::ClassPriors;
use super::knob::{KnobKind, Knobs};

/// The class of an explanation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// Nothing off: the nominal model.
    Nominal,
    /// One declared parameter off, or one effect present.
    One,
    /// Two of them at once.
    Two,
    /// One of the design's undeclared numbers off.
    Undeclared,
    /// Something outside the library and the design's numbers: the most probable
    /// explanation with an unknown discrepancy beside it.
    NoneOfThese,
}

/// One explanation: the knobs it frees (indices into [`Knobs`], at most two) and its prior.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hypothesis {
    pub knobs: Vec<usize>,
    pub class: Class,
    pub prior: f64,
}

impl Hypothesis {
    /// How reports name it: "nominal", the knobs' labels joined by " + ", or
    /// "something outside these".
    pub fn label(&self, knobs: &Knobs) -> String {
        match self.class {
            Class::Nominal => "nominal".into(),
            Class::NoneOfThese => NONE_OF_THESE.into(),
            _ => self
                .knobs
                .iter()
                .map(|k| knobs.list[*k].label())
                .collect::<Vec<_>>()
                .join(" + "),
        }
    }
}

/// The label of the "something outside these" explanation.
pub const NONE_OF_THESE: &str = "something outside these";

/// Every explanation of the knobs that `testable` allows (a suspect the trials cannot
/// detect anywhere in its range is left out, [`super::evidence::Slab::is_empty`]), with its
/// prior; "something outside these" last. A class with no member gives its mass to the
/// others in proportion.
pub fn hypotheses(knobs: &Knobs, testable: &[bool], priors: &ClassPriors) -> Vec<Hypothesis> {
    let suspects: Vec<usize> = (0..knobs.len())
        .filter(|&k| testable[k] && knobs.list[k].kind != KnobKind::Undeclared)
        .collect();
    let undeclared: Vec<usize> = (0..knobs.len())
        .filter(|&k| testable[k] && knobs.list[k].kind == KnobKind::Undeclared)
        .collect();
    let singles = |ks: &[usize]| ks.iter().map(|k| vec![*k]).collect::<Vec<_>>();
    let two = (suspects.iter().enumerate())
        .flat_map(|(i, a)| suspects[i + 1..].iter().map(move |b| vec![*a, *b]));
    let p = priors;
    let mut members: Vec<(Class, f64, Vec<Vec<usize>>)> = vec![
        (Class::Nominal, p.nominal, vec![Vec::new()]),
        (Class::One, p.one, singles(&suspects)),
        (Class::Two, p.two, two.collect()),
        (Class::Undeclared, p.undeclared, singles(&undeclared)),
        (Class::NoneOfThese, p.none_of_these, vec![Vec::new()]),
    ];
    members.retain(|(_, _, m)| !m.is_empty());
    let total: f64 = members.iter().map(|m| m.1).sum();
    members
        .into_iter()
        .flat_map(|(class, mass, sets)| {
            let each = mass / total / sets.len() as f64;
            sets.into_iter().map(move |knobs| Hypothesis {
                knobs,
                class,
                prior: each,
            })
        })
        .filter(|h| h.prior > 0.0)
        .collect()
}
