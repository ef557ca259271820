//! The answer, from the posterior by one rule ([`super::criterion::Decision`]):
//!
//! * **unexplained** when even the most probable explanation fails the posterior-predictive
//!   check (p below `fit_level`), or "something outside these" is the explanation named;
//! * otherwise the top explanation is **named** when its probability reaches `threshold`:
//!   *no gap* (the nominal), *parameters off*, *effect missing* or *both*, with its values'
//!   95 % credible intervals;
//! * otherwise **ambiguous**, with the leading explanations and their probabilities.

use serde::Serialize;

use super::criterion::Decision;
use super::hypothesis::{Class, NONE_OF_THESE};
use super::knob::{Knob, KnobKind, Knobs};
use super::posterior::{Posterior, Weighed};
use super::simulate::Condition;

/// The kind of answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AnswerKind {
    /// The nominal model is the explanation: nothing is off.
    NoGap,
    /// Design numbers are off (declared or not).
    ParametersOff,
    /// Library effects are missing from the model.
    EffectMissing,
    /// A parameter off and an effect missing, together.
    Both,
    /// No explanation reaches the threshold: the leading ones are listed.
    Ambiguous,
    /// Nothing in the library or the design explains the trials.
    Unexplained,
}

/// A knob of an explanation with its most probable value and 95 % credible interval (SI,
/// the design at 1×).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Named {
    pub knob: String,
    pub kind: KnobKind,
    pub value: f64,
    pub interval: [f64; 2],
    /// Parameters: the design file's value, and the change in % of it.
    pub nominal: Option<f64>,
    pub change_pct: Option<f64>,
    pub unit: String,
    /// False for a fore–aft mirror-odd parameter of a design that walks either way, where
    /// the start sets the direction ([`sign_identified`]): `value` and `interval` are then
    /// magnitudes.
    pub sign_identified: bool,
}

/// An explanation and its posterior probability.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Lead {
    pub explanation: String,
    pub probability: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Answer {
    pub kind: AnswerKind,
    /// The explanation named (None: ambiguous or unexplained).
    pub explanation: Option<String>,
    /// Its knobs, values and intervals.
    pub named: Vec<Named>,
    /// The most probable explanations, with "something outside these" among them where it
    /// leads, until their probabilities add up to the threshold (at most five).
    pub leading: Vec<Lead>,
    /// P(something outside these).
    pub outside: f64,
    /// The posterior-predictive p-value of the most probable explanation.
    pub fit_p: f64,
    pub statement: String,
}

/// Whether trials at `conditions` identify the sign of `knob`. Not for a parameter that
/// changes sign under the fore–aft mirror ([`crate::sim::MIRROR_ODD_PATHS`]) of a design that
/// walks either way, when every condition where it acts leaves the direction to the start
/// ([`Condition::direction_free`]): the mirrored design walks the mirror image of the gait
/// the walker's other start walks, and which start the robot took is not in the model.
pub fn sign_identified(knob: &Knob, conditions: &[Condition]) -> bool {
    if knob.kind == KnobKind::Effect
        || knob.log
        || !crate::sim::MIRROR_ODD_PATHS.contains(&knob.name.as_str())
    {
        return true;
    }
    let mut acting = conditions
        .iter()
        .filter(|c| c.design.name == knob.design)
        .filter(|c| !(knob.name == "ground.slope_deg" && c.slope_deg.is_some()))
        .peekable();
    acting.peek().is_none() || !acting.all(|c| c.direction_free())
}

/// A signed interval's magnitudes: |x| over [lo, hi].
pub fn magnitude_interval(lo: f64, hi: f64) -> [f64; 2] {
    let top = lo.abs().max(hi.abs());
    if lo <= 0.0 && hi >= 0.0 {
        [0.0, top]
    } else {
        [lo.abs().min(hi.abs()), top]
    }
}

/// The knobs of a weighed explanation, with values and intervals as the answer states them.
pub fn named(w: &Weighed, knobs: &Knobs, conditions: &[Condition]) -> Vec<Named> {
    w.hypothesis
        .knobs
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            let knob = &knobs.list[k];
            let si = |u: f64| knob.si(knob.from_unit(u));
            let value = si(w.evidence.mode[i]);
            let [a, b] = w.evidence.intervals[i];
            let (lo, hi) = (si(a).min(si(b)), si(a).max(si(b)));
            let signed = sign_identified(knob, conditions);
            let (value, interval) = if signed {
                (value, [lo, hi])
            } else {
                (value.abs(), magnitude_interval(lo, hi))
            };
            let nominal = knob
                .is_parameter()
                .then(|| knob.nominal.map(|x| knob.si(x)))
                .flatten();
            Named {
                knob: knob.label(),
                kind: knob.kind,
                value,
                interval,
                change_pct: nominal
                    .filter(|n| *n != 0.0)
                    .map(|n| 100.0 * (value - n) / n.abs()),
                nominal,
                unit: knob.unit.clone(),
                sign_identified: signed,
            }
        })
        .collect()
}

/// Every explanation and its probability, and "something outside these" at `outside` (None:
/// left out), most probable first.
pub fn leads(post: &Posterior, knobs: &Knobs, outside: Option<f64>) -> Vec<Lead> {
    let mut v: Vec<Lead> = post
        .weighed
        .iter()
        .map(|w| Lead {
            explanation: w.hypothesis.label(knobs),
            probability: w.probability,
        })
        .collect();
    v.extend(outside.map(|probability| Lead {
        explanation: NONE_OF_THESE.into(),
        probability,
    }));
    v.sort_by(|a, b| b.probability.total_cmp(&a.probability));
    v
}

/// The answer the posterior gives under `decision`.
pub fn decide(
    post: &Posterior,
    knobs: &Knobs,
    conditions: &[Condition],
    decision: &Decision,
) -> Answer {
    let outside = post.outside.as_ref().map_or(0.0, |o| o.2);
    let fit_p = post.best().map_or(0.0, |w| w.evidence.fit_p);
    let mut leading = Vec::new();
    let mut acc = 0.0;
    for l in leads(post, knobs, Some(outside)).iter().take(5) {
        leading.push(l.clone());
        acc += l.probability;
        if acc >= decision.threshold {
            break;
        }
    }
    let top = &leading[0];
    let mut answer = Answer {
        kind: AnswerKind::Ambiguous,
        explanation: None,
        named: Vec::new(),
        leading: leading.clone(),
        outside,
        fit_p,
        statement: String::new(),
    };
    if fit_p < decision.fit_level
        || (top.explanation == NONE_OF_THESE && top.probability >= decision.threshold)
    {
        answer.kind = AnswerKind::Unexplained;
    } else if top.probability >= decision.threshold
        && let Some(w) = post.best()
    {
        answer.kind = kind_of(w, knobs);
        answer.explanation = Some(top.explanation.clone());
        answer.named = named(w, knobs, conditions);
    }
    answer.statement = statement(&answer, decision);
    answer
}

fn kind_of(w: &Weighed, knobs: &Knobs) -> AnswerKind {
    if w.hypothesis.class == Class::Nominal {
        return AnswerKind::NoGap;
    }
    let effects = w
        .hypothesis
        .knobs
        .iter()
        .filter(|k| knobs.list[**k].kind == KnobKind::Effect)
        .count();
    match (effects, w.hypothesis.knobs.len() - effects) {
        (0, _) => AnswerKind::ParametersOff,
        (_, 0) => AnswerKind::EffectMissing,
        _ => AnswerKind::Both,
    }
}

fn pct(p: f64) -> String {
    format!("{:.*}", if p >= 0.995 { 3 } else { 2 }, p)
}

/// The answer in one sentence.
fn statement(a: &Answer, decision: &Decision) -> String {
    let leads = a
        .leading
        .iter()
        .map(|l| format!("{} {}", l.explanation, pct(l.probability)))
        .collect::<Vec<_>>()
        .join("; ");
    match a.kind {
        AnswerKind::NoGap => format!(
            "no gap: the nominal model explains the trials (probability {})",
            pct(a.leading[0].probability)
        ),
        AnswerKind::Unexplained if a.fit_p < decision.fit_level => format!(
            "unexplained: even the most probable explanation does not fit the trials \
             (posterior-predictive p = {:.1e} < {}); leading: {leads}",
            a.fit_p, decision.fit_level
        ),
        AnswerKind::Unexplained => format!(
            "unexplained: something outside the library and the design's numbers \
             (probability {})",
            pct(a.outside)
        ),
        AnswerKind::Ambiguous => format!(
            "ambiguous: no explanation reaches probability {}; leading: {leads}",
            decision.threshold
        ),
        _ => {
            let what = match a.kind {
                AnswerKind::ParametersOff => "parameters off",
                AnswerKind::EffectMissing => "effect missing",
                _ => "parameters off and effect missing",
            };
            let values = a
                .named
                .iter()
                .map(|n| {
                    format!(
                        "{} = {} [{}, {}]{}",
                        n.knob,
                        super::locate::sig3(n.value),
                        super::locate::sig3(n.interval[0]),
                        super::locate::sig3(n.interval[1]),
                        if n.unit.is_empty() {
                            String::new()
                        } else {
                            format!(" {}", n.unit)
                        }
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            format!(
                "{what}: {values} (probability {})",
                pct(a.leading[0].probability)
            )
        }
    }
}
