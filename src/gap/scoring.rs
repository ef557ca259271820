//! The benchmark's scores: what each case's answer named under a decision, the rates the
//! issue's targets are about (false alarms, effects and pairs named, wrong names, interval
//! coverage), the calibration of the top posterior (reliability diagram, expected calibration
//! error, Brier score), and the decision's two numbers chosen on half of the cases and
//! verified on the other half. The same rates are computed for a points file of the retired
//! rule-based selection ([`RulesRow`]) on the same cases, side by side.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::benchmark::{CaseRow, normalise_label, seed_of};
use super::criterion::Decision;
use super::error::GapError;
use super::hypothesis::NONE_OF_THESE;
use super::plan::{EXPECTED_PAIR, parse_pairs, split};
use crate::regression::dist::{binomial_interval, binomial_upper_bound};

/// What an answer named: `named` the knobs of the explanation named (empty: "no gap"; None:
/// nothing named — ambiguous or unexplained), with their intervals (`knob → lo..hi`).
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub named: Option<Vec<String>>,
    pub unexplained: bool,
    pub intervals: BTreeMap<String, String>,
}

/// A row's leading explanations: (sorted label, probability).
pub fn leading(r: &CaseRow) -> Vec<(String, f64)> {
    split(&r.leading)
        .iter()
        .filter_map(|l| {
            let (k, v) = l.rsplit_once('=')?;
            Some((k.to_string(), v.parse().ok()?))
        })
        .collect()
}

fn intervals_of(s: &str) -> BTreeMap<String, String> {
    split(s)
        .iter()
        .filter_map(|iv| iv.split_once('='))
        .map(|(k, r)| (k.to_string(), r.to_string()))
        .collect()
}

impl Outcome {
    /// The answer the posterior of `r` gives under `d`.
    pub fn of_row(r: &CaseRow, d: &Decision) -> Outcome {
        let lead = leading(r);
        let mut out = Outcome {
            named: None,
            unexplained: false,
            intervals: intervals_of(&r.intervals),
        };
        let Some((label, p)) = lead.first() else {
            return out;
        };
        if r.fit_p < d.fit_level || (label == NONE_OF_THESE && *p >= d.threshold) {
            out.unexplained = true;
        } else if *p >= d.threshold {
            out.named = Some(knobs_of(label));
        }
        out
    }
}

/// The knobs of an explanation's label ("nominal": none).
pub fn knobs_of(label: &str) -> Vec<String> {
    let knob = |k: &&str| !k.is_empty() && *k != "nominal";
    label
        .split(" + ")
        .filter(knob)
        .map(str::to_string)
        .collect()
}

/// A row of a points file of the retired rule-based selection (its answer and names).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
pub struct RulesRow {
    pub key: String,
    pub answer: String,
    pub named_effects: String,
    pub named_params: String,
    pub intervals: String,
    #[serde(default)]
    pub logged_trials: usize,
    #[serde(default)]
    pub cycles_named: String,
}

impl crate::checkpoint::SweepPoint for RulesRow {
    fn key(&self) -> String {
        self.key.clone()
    }
}

impl RulesRow {
    /// What the rules named; `aliases` maps an effect to the parameter label it stands for.
    pub fn outcome(&self, aliases: &BTreeMap<String, String>) -> Outcome {
        let mut names: Vec<String> = if self.logged_trials > 0 {
            split(&self.cycles_named)
        } else {
            split(&self.named_effects)
                .into_iter()
                .chain(split(&self.named_params))
                .collect()
        };
        for n in names.iter_mut() {
            if let Some(p) = aliases.get(n.as_str()) {
                *n = p.clone();
            }
        }
        let named = match self.answer.as_str() {
            "WithinNoise" => Some(Vec::new()),
            "ParametersOff" | "EffectMissing" | "Both" => Some(names),
            _ if self.logged_trials > 0 && !names.is_empty() => Some(names),
            _ => None,
        };
        Outcome {
            named,
            unexplained: self.answer == "Unexplained",
            intervals: intervals_of(&self.intervals),
        }
    }
}

/// The retired rules' rows of a points file, keyed as this benchmark keys the same cases:
/// a Drake row's key gains its folder (and `-ref` when it was diagnosed through the
/// reference), read from the file's specification line.
pub fn read_rules(path: &Path) -> Result<BTreeMap<String, RulesRow>, GapError> {
    let (header, rows) = crate::checkpoint::read_points::<RulesRow>(path)?;
    let spec: serde_json::Value = header
        .find('[')
        .and_then(|i| serde_json::from_str(&header[i..]).ok())
        .unwrap_or(serde_json::Value::Null);
    let opts = &spec[1];
    let folder = opts["drake_dir"]
        .as_str()
        .and_then(|d| Path::new(d).file_name().and_then(|f| f.to_str()))
        .unwrap_or("drake")
        .to_string();
    let mode = if opts["drake_reference"].as_bool() == Some(true) {
        "-ref"
    } else {
        ""
    };
    Ok(rows
        .into_iter()
        .map(|mut r| {
            if let Some(rest) = r.key.strip_prefix("drake/") {
                r.key = format!("drake/{folder}{mode}/{rest}");
            }
            (r.key.clone(), r)
        })
        .collect())
}

/// One rate with its 95 % Clopper–Pearson interval and one-sided upper bound.
#[derive(Clone, Debug, Serialize)]
pub struct Score {
    pub k: usize,
    pub n: usize,
    pub rate: f64,
    pub interval: [f64; 2],
    pub upper_95: f64,
}

fn score(k: usize, n: usize) -> Score {
    let (interval, upper) = if n > 0 {
        (
            binomial_interval(k as u64, n as u64, 0.95).unwrap_or([f64::NAN; 2]),
            binomial_upper_bound(k as u64, n as u64, 0.95).unwrap_or(f64::NAN),
        )
    } else {
        ([f64::NAN; 2], f64::NAN)
    };
    Score {
        k,
        n,
        rate: if n > 0 { k as f64 / n as f64 } else { f64::NAN },
        interval,
        upper_95: upper,
    }
}

/// One line of the score table: the rules' rate, the criterion's on every case and on the
/// half the decision was not chosen on.
#[derive(Clone, Debug, Serialize)]
pub struct ScoreLine {
    pub what: String,
    pub target: String,
    pub rules: Option<Score>,
    pub criterion: Score,
    pub held_out: Score,
}

/// A case with its row and outcome.
#[derive(Clone)]
pub struct Scored<'a> {
    pub row: &'a CaseRow,
    pub outcome: Outcome,
}

impl Scored<'_> {
    /// Whether something was named, and `test` holds for the knobs named.
    fn named(&self, test: impl Fn(&[String]) -> bool) -> bool {
        self.outcome.named.as_deref().is_some_and(test)
    }
}

/// What the truth is made of: its knobs (sorted labels), or None for "something outside".
fn truth_knobs(r: &CaseRow) -> Option<Vec<String>> {
    (r.truth != NONE_OF_THESE).then(|| knobs_of(&r.truth))
}

fn is_effect(knob: &str) -> bool {
    !knob.contains(':')
}

/// A named knob that is not one of the truth's (truth outside: any knob).
fn names_spurious(s: &Scored) -> bool {
    let truth = truth_knobs(s.row).unwrap_or_default();
    s.named(|n| n.iter().any(|k| !truth.contains(k)))
}

fn names_all_truth(s: &Scored) -> bool {
    let Some(truth) = truth_knobs(s.row) else {
        return false;
    };
    s.named(|n| !truth.is_empty() && truth.iter().all(|k| n.contains(k)))
}

fn names_anything(s: &Scored) -> bool {
    s.named(|n| !n.is_empty())
}

fn names_effect(s: &Scored) -> bool {
    s.named(|n| n.iter().any(|k| is_effect(k)))
}

/// The effects that made a case's trials.
fn truth_effects(r: &CaseRow) -> Vec<String> {
    parse_pairs(&r.truth_effects)
        .into_iter()
        .map(|x| x.0)
        .collect()
}

/// A question asked of a set of cases: which cases, which count, and its target.
struct Question {
    what: String,
    target: &'static str,
    cases: Box<dyn Fn(&CaseRow) -> bool>,
    counts: Box<dyn Fn(&Scored) -> bool>,
}

fn q(
    what: String,
    target: &'static str,
    cases: impl Fn(&CaseRow) -> bool + 'static,
    counts: impl Fn(&Scored) -> bool + 'static,
) -> Question {
    Question {
        what,
        target,
        cases: Box::new(cases),
        counts: Box::new(counts),
    }
}

/// The questions the benchmark answers, for the noise levels present.
fn questions(noise_levels: &[f64]) -> Vec<Question> {
    let mut v = Vec::new();
    for suite in ["main", "one-robot"] {
        for &noise in noise_levels {
            let anything: fn(&Scored) -> bool = names_anything;
            let per_noise = [
                ("false alarms (anything named)", "≤ 1 %", "null", anything),
                ("single effect named", "high", "effect", names_all_truth),
                (
                    "another knob named beside or for a single effect",
                    "low",
                    "effect",
                    names_spurious,
                ),
            ];
            for (what, target, kind, counts) in per_noise {
                v.push(q(
                    format!("{suite}: {what} at {:.0} % noise", noise * 100.0),
                    target,
                    move |r| r.suite == suite && r.kind == kind && r.noise == noise,
                    counts,
                ));
            }
        }
    }
    v.push(q(
        "pairs of effects: both named".into(),
        "≥ 80 %",
        |r| r.kind == "pair",
        names_all_truth,
    ));
    v.push(q(
        "pairs: a spurious knob named".into(),
        "≤ 5 %",
        |r| r.kind == "pair",
        names_spurious,
    ));
    v.push(q(
        "pairs on their expected (noise-free) trials: both named".into(),
        "ceiling of the above",
        |r| r.kind == EXPECTED_PAIR,
        names_all_truth,
    ));
    parameter_questions(&mut v);
    let effect_named: fn(&Scored) -> bool = |s| {
        let e = truth_effects(s.row);
        s.named(|n| e.iter().all(|x| n.contains(x)))
    };
    let compound_counts = [
        ("the effect named", "high", effect_named),
        ("both named", "high", names_all_truth),
        ("a knob in neither named", "≤ 5 %", names_spurious),
    ];
    for declared in [true, false] {
        let tag = if declared { "declared" } else { "undeclared" };
        // An undeclared number beside an effect is not weighed: "both" cannot be named.
        for (what, target, counts) in compound_counts
            .iter()
            .filter(|c| declared || c.0 != "both named")
        {
            v.push(q(
                format!("compound ({tag} parameter error + effect): {what}"),
                target,
                move |r| r.kind == "compound" && r.truth_declared == declared,
                *counts,
            ));
        }
    }
    drake_questions(&mut v);
    v
}

fn parameter_questions(v: &mut Vec<Question>) {
    for suite in ["main", "one-robot"] {
        let p = move |r: &CaseRow| r.suite == suite && r.kind == "parameter";
        v.push(q(
            format!("{suite}: parameter errors: a library effect wrongly called"),
            "≤ 5 %",
            p,
            names_effect,
        ));
        v.push(q(
            format!("{suite}: parameter errors: a wrong parameter named"),
            "≤ 10 %",
            p,
            |s| {
                let t = truth_knobs(s.row).unwrap_or_default();
                s.named(|n| n.iter().any(|k| !is_effect(k) && !t.contains(k)))
            },
        ));
        v.push(q(
            format!("{suite}: parameter errors in a declared parameter: the right one named"),
            "high",
            move |r| p(r) && r.truth_declared,
            names_all_truth,
        ));
        v.push(q(
            format!(
                "{suite}: parameter errors elsewhere: the undeclared number named, or nothing named"
            ),
            "high",
            move |r| p(r) && !r.truth_declared,
            |s| names_all_truth(s) || s.outcome.named.is_none(),
        ));
    }
}

fn drake_questions(v: &mut Vec<Question>) {
    for reference in [false, true] {
        let tag = ["", " (through the no-effect trials)"][reference as usize];
        let d = move |r: &CaseRow| r.kind == "drake" && r.key.contains("-ref/") == reference;
        v.push(q(
            format!("Drake{tag}, no effect added: an effect blamed"),
            "0 %",
            move |r| d(r) && r.truth_effects.is_empty(),
            names_effect,
        ));
        v.push(q(
            format!("Drake{tag}, effect added: that effect named"),
            "high",
            move |r| d(r) && !r.truth_effects.is_empty(),
            |s| {
                let e = truth_effects(s.row);
                s.named(|n| {
                    e.iter().all(|x| {
                        n.contains(x)
                            || n.iter().any(|k| {
                                k.ends_with("contact.friction_mu") && x == "friction_coefficient"
                            })
                    })
                })
            },
        ));
        v.push(q(
            format!("Drake{tag}, effect added: another effect named"),
            "low",
            move |r| d(r) && !r.truth_effects.is_empty(),
            |s| {
                let e = truth_effects(s.row);
                s.named(|n| n.iter().any(|k| is_effect(k) && !e.contains(k)))
            },
        ));
    }
}

/// Interval coverage: over the cases that name a true knob with an interval, how often the
/// interval holds the truth's value.
fn coverage(scored: &[Scored]) -> Score {
    let mut cov = (0, 0);
    for s in scored {
        if s.row.kind == "drake" || s.row.kind == EXPECTED_PAIR {
            continue;
        }
        let Some(named) = &s.outcome.named else {
            continue;
        };
        let truths = parse_pairs(&s.row.truth_effects)
            .into_iter()
            .chain(parse_pairs(&s.row.truth_params));
        for (name, v) in truths {
            let Some((_, iv)) = s.outcome.intervals.iter().find(|(k, _)| {
                named.contains(k) && (**k == name || k.ends_with(&format!(":{name}")))
            }) else {
                continue;
            };
            if let Some(h) = interval_holds(iv, v) {
                cov.1 += 1;
                cov.0 += h as usize;
            }
        }
    }
    score(cov.0, cov.1)
}

/// Does the interval `lo..hi` (or the magnitudes `±lo..hi`) hold `v`?
pub fn interval_holds(interval: &str, v: f64) -> Option<bool> {
    let (r, v) = match interval.strip_prefix('±') {
        Some(m) => (m, v.abs()),
        None => (interval, v),
    };
    let (lo, hi) = r.split_once("..")?;
    let (lo, hi): (f64, f64) = (lo.parse().ok()?, hi.parse().ok()?);
    Some(v >= lo.min(hi) * (1.0 - 1e-9) - 1e-12 && v <= hi.max(lo) * (1.0 + 1e-9) + 1e-12)
}

/// One bin of the reliability diagram.
#[derive(Clone, Debug, Serialize)]
pub struct Bin {
    pub lo: f64,
    pub hi: f64,
    pub n: usize,
    /// Mean top probability in the bin.
    pub confidence: f64,
    /// Share of its cases whose top explanation is the truth.
    pub accuracy: f64,
}

/// The calibration of the top posterior.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    pub cases: usize,
    pub bins: Vec<Bin>,
    /// Σ_b (n_b/N)·|accuracy_b − confidence_b|.
    pub ece: f64,
    /// Mean over cases of Σ_h (p_h − [h = truth])².
    pub brier: f64,
    pub mean_top_probability: f64,
    pub top_is_truth: f64,
    pub mean_truth_probability: f64,
}

/// The cases calibration is measured on: every case with a known truth label, but the
/// noise-free pairs and rows not diagnosed.
fn calibrated_cases(rows: &[&CaseRow]) -> Vec<(f64, bool, f64, f64)> {
    rows.iter()
        .filter(|r| r.kind != EXPECTED_PAIR && r.truth_probability.is_finite())
        .filter_map(|r| {
            let (label, p) = leading(r).into_iter().next()?;
            Some((
                p,
                normalise_label(&label) == r.truth,
                r.truth_probability,
                r.sum_p2,
            ))
        })
        .collect()
}

/// Reliability diagram (ten bins of the top probability), ECE and Brier score of `rows`.
pub fn calibration(rows: &[&CaseRow]) -> Calibration {
    let cases = calibrated_cases(rows);
    let n = cases.len().max(1) as f64;
    let mut bins: Vec<Bin> = (0..10)
        .map(|b| Bin {
            lo: b as f64 / 10.0,
            hi: (b + 1) as f64 / 10.0,
            n: 0,
            confidence: 0.0,
            accuracy: 0.0,
        })
        .collect();
    for &(p, right, _, _) in &cases {
        let b = ((p * 10.0) as usize).min(9);
        bins[b].n += 1;
        bins[b].confidence += p;
        bins[b].accuracy += right as u8 as f64;
    }
    for b in bins.iter_mut().filter(|b| b.n > 0) {
        b.confidence /= b.n as f64;
        b.accuracy /= b.n as f64;
    }
    let ece = bins
        .iter()
        .map(|b| b.n as f64 / n * (b.accuracy - b.confidence).abs())
        .sum();
    Calibration {
        cases: cases.len(),
        ece,
        brier: cases.iter().map(|c| c.3 - 2.0 * c.2 + 1.0).sum::<f64>() / n,
        mean_top_probability: cases.iter().map(|c| c.0).sum::<f64>() / n,
        top_is_truth: cases.iter().filter(|c| c.1).count() as f64 / n,
        mean_truth_probability: cases.iter().map(|c| c.2).sum::<f64>() / n,
        bins,
    }
}

/// The half of the cases the decision is chosen on (the other verifies it).
pub fn in_choice_half(r: &CaseRow) -> bool {
    // The top bit after splitmix64's finalizer, which mixes every bit of the key's hash.
    let mut z = seed_of(&r.key);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    (z ^ (z >> 31)) >> 63 == 0
}

/// Thresholds and levels the choice considers.
const THRESHOLDS: [f64; 13] = [
    0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.93, 0.95, 0.97, 0.98, 0.99,
];
const LEVELS: [f64; 8] = [0.05, 0.01, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10];

/// The decision chosen on `rows`: the largest posterior-predictive level at which at most
/// 1 % of the null cases fail the check, then the smallest threshold at which at most 5 % of
/// the names given to cases with a gap are wrong (not the truth) and at most 1 % of the nulls
/// name anything. Nulls' "no gap" names are judged by the second bound only, so the number
/// of nulls a benchmark runs does not loosen the first. The flag says whether a threshold of
/// the grid met both bounds (if none did, the grid's end, 0.99).
pub fn choose(rows: &[&CaseRow]) -> (Decision, bool) {
    let nulls: Vec<&&CaseRow> = rows.iter().filter(|r| r.kind == "null").collect();
    let level = LEVELS
        .iter()
        .copied()
        .find(|&l| nulls.iter().filter(|r| r.fit_p < l).count() as f64 <= 0.01 * nulls.len() as f64)
        .unwrap_or(LEVELS[LEVELS.len() - 1]);
    let judged: Vec<&&CaseRow> = rows
        .iter()
        .filter(|r| r.kind != EXPECTED_PAIR && (r.kind != "drake" || r.key.contains("-ref/")))
        .collect();
    let threshold = THRESHOLDS.iter().copied().find(|&t| {
        let d = Decision {
            threshold: t,
            fit_level: level,
        };
        let (mut named, mut wrong, mut alarms) = (0, 0, 0);
        for r in &judged {
            let o = Outcome::of_row(r, &d);
            let Some(n) = &o.named else { continue };
            let mut n = n.clone();
            n.sort();
            let right = truth_knobs(r) == Some(n);
            if r.kind == "null" {
                alarms += usize::from(!right);
            } else {
                named += 1;
                wrong += usize::from(!right);
            }
        }
        wrong as f64 <= 0.05 * named.max(1) as f64 && alarms as f64 <= 0.01 * nulls.len() as f64
    });
    let decision = Decision {
        threshold: threshold.unwrap_or(THRESHOLDS[THRESHOLDS.len() - 1]),
        fit_level: level,
    };
    (decision, threshold.is_some())
}

/// Scores, calibration and the chosen decision of a benchmark's rows.
#[derive(Clone, Debug, Serialize)]
pub struct BenchmarkSummary {
    pub design: String,
    pub cases: usize,
    /// Cases per suite and kind (suite, kind, count).
    pub cases_by_kind: Vec<(String, String, usize)>,
    /// The decision the criterion file holds, and the one chosen on half of these cases.
    pub decision_file: Decision,
    pub decision_chosen: Decision,
    /// Whether a threshold met the choice's bounds (else `decision_chosen` holds the grid's end).
    pub threshold_met: bool,
    pub scores: Vec<ScoreLine>,
    pub coverage: ScoreLine,
    /// Calibration on every case, on the half the decision was not chosen on, and on the
    /// cases with a gap (every kind but the nulls, which dominate the first two).
    pub calibration: Calibration,
    pub calibration_held_out: Calibration,
    pub calibration_gap: Calibration,
    /// Cases diagnosed again with every explanation confirmed, and how often the search's
    /// most probable explanation differed.
    pub search_misses: Option<Score>,
    /// Mean posterior of the added effect on Drake cases through the reference, per file.
    pub drake_truth_probability: Vec<(String, f64, usize)>,
    pub thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
}

/// The summary of `rows` (and, beside them, the retired rules' rows of the same keys).
pub fn summarize(
    rows: &[CaseRow],
    rules: &BTreeMap<String, RulesRow>,
    aliases: &BTreeMap<String, String>,
    design: &str,
    decision_file: Decision,
    thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
) -> BenchmarkSummary {
    let diagnosed: Vec<&CaseRow> = rows.iter().filter(|r| !r.leading.is_empty()).collect();
    let (choice, held): (Vec<&CaseRow>, Vec<&CaseRow>) =
        diagnosed.iter().copied().partition(|r| in_choice_half(r));
    let mut gap = diagnosed.clone();
    gap.retain(|r| r.kind != "null");
    let (chosen, threshold_met) = choose(&choice);
    // Without a threshold meeting the bounds, the scores are those of the file's decision.
    let scored_with = if threshold_met { chosen } else { decision_file };
    let crit: Vec<Scored> = diagnosed
        .iter()
        .map(|r| Scored {
            row: r,
            outcome: Outcome::of_row(r, &scored_with),
        })
        .collect();
    let heldout: Vec<Scored> = crit
        .iter()
        .filter(|s| !in_choice_half(s.row))
        .cloned()
        .collect();
    let rules_scored: Vec<Scored> = crit
        .iter()
        .filter_map(|s| {
            rules.get(&s.row.key).map(|r| Scored {
                row: s.row,
                outcome: r.outcome(aliases),
            })
        })
        .collect();
    let mut levels: Vec<f64> = diagnosed.iter().map(|r| r.noise).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let rate = |ss: &[Scored], qn: &Question| {
        let cases: Vec<&Scored> = ss.iter().filter(|s| (qn.cases)(s.row)).collect();
        score(cases.iter().filter(|s| (qn.counts)(s)).count(), cases.len())
    };
    let scores: Vec<ScoreLine> = questions(&levels)
        .iter()
        .map(|qn| ScoreLine {
            what: qn.what.clone(),
            target: qn.target.into(),
            rules: (!rules_scored.is_empty())
                .then(|| rate(&rules_scored, qn))
                .filter(|s| s.n > 0),
            criterion: rate(&crit, qn),
            held_out: rate(&heldout, qn),
        })
        .filter(|l| l.criterion.n > 0)
        .collect();
    let coverage = ScoreLine {
        what: "95 % intervals holding the truth (cases naming a true knob)".into(),
        target: "90–97 %".into(),
        rules: (!rules_scored.is_empty()).then(|| coverage(&rules_scored)),
        criterion: coverage(&crit),
        held_out: coverage(&heldout),
    };
    BenchmarkSummary {
        design: design.to_string(),
        cases: rows.len(),
        cases_by_kind: cases_by_kind(rows),
        decision_file,
        decision_chosen: chosen,
        threshold_met,
        scores,
        coverage,
        calibration: calibration(&diagnosed),
        calibration_held_out: calibration(&held),
        calibration_gap: calibration(&gap),
        search_misses: search_misses(&diagnosed),
        drake_truth_probability: drake_truth(&diagnosed),
        thresholds,
    }
}

/// How many cases of each suite and kind `rows` holds.
fn cases_by_kind(rows: &[CaseRow]) -> Vec<(String, String, usize)> {
    let mut n: BTreeMap<(String, String), usize> = BTreeMap::new();
    for r in rows {
        *n.entry((r.suite.clone(), r.kind.clone())).or_default() += 1;
    }
    n.into_iter().map(|((s, k), c)| (s, k, c)).collect()
}

/// How often the search's most probable explanation differed from the one found with every
/// explanation confirmed, over the cases diagnosed both ways (None: no such case).
fn search_misses(rows: &[&CaseRow]) -> Option<Score> {
    let exhaustive: Vec<&&CaseRow> = rows
        .iter()
        .filter(|r| !r.exhaustive_top.is_empty())
        .collect();
    let miss = exhaustive
        .iter()
        .filter(|r| {
            leading(r).first().map(|l| normalise_label(&l.0)) != Some(r.exhaustive_top.clone())
        })
        .count();
    (!exhaustive.is_empty()).then(|| score(miss, exhaustive.len()))
}

/// Mean posterior of the effect Drake added, per file, over the cases through the reference.
fn drake_truth(rows: &[&CaseRow]) -> Vec<(String, f64, usize)> {
    let mut by: BTreeMap<String, (f64, usize)> = BTreeMap::new();
    for r in rows
        .iter()
        .filter(|r| r.kind == "drake" && r.key.contains("-ref/"))
    {
        let file = r.key.split('/').take(3).collect::<Vec<_>>().join("/");
        let e = by.entry(file).or_default();
        e.0 += r.truth_probability;
        e.1 += 1;
    }
    by.into_iter()
        .map(|(k, (s, n))| (k, s / n as f64, n))
        .collect()
}
