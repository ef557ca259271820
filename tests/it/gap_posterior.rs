//! The diagnosis' posterior on cases whose cause is known by construction: a null answered
//! "no gap", a look-alike pair answered "ambiguous" with both leading, a cause outside what is
//! weighed answered "unexplained", the probabilities' calibration on a small seeded sample,
//! and one answer in text and JSON on trials with robot logs. The cases run on the test
//! design with two uncertain parameters (`tests/data/gap/mugatu-two-uncertain.toml`) over six
//! conditions, sharing one cache of walks.

use std::sync::OnceLock;

use robot_survey::gap::EffectLibrary;
use robot_survey::gap::decide::AnswerKind;
use robot_survey::gap::diagnose::{DiagnoseOptions, Diagnosis, diagnose_conditions};
use robot_survey::gap::hypothesis::NONE_OF_THESE;
use robot_survey::gap::plan::truth_setting;
use robot_survey::gap::simulate::{Condition, resolve};
use robot_survey::gap::synth::{add_noise, expected_trials, truth_metrics};
use robot_survey::gap::trials::TrialSet;
use robot_survey::progress::Silent;

use super::common::{bundled_walks, repo, stderr, stdout, survey};

struct Six {
    lib: EffectLibrary,
    base: TrialSet,
    conditions: Vec<Condition>,
}

fn six() -> &'static Six {
    static S: OnceLock<Six> = OnceLock::new();
    S.get_or_init(|| {
        let base =
            TrialSet::read(&repo().join("tests/data/gap/conditions-6.csv")).expect("conditions");
        let conditions = resolve(&base).expect("resolve");
        Six {
            lib: EffectLibrary::bundled().expect("library"),
            base,
            conditions,
        }
    })
}

/// A truth: parameter values (path, value at 1×) and effects (name, SI at 1×).
type Truth<'a> = (&'a [(&'a str, f64)], &'a [(&'a str, f64)]);

/// Trials of the six conditions made with `truth` at relative sd `noise`: drawn from `seed`,
/// or the expected values (`None`).
fn trials((params, effects): Truth<'_>, noise: f64, seed: Option<u64>) -> TrialSet {
    let s = six();
    let own = |v: &[(&str, f64)]| {
        v.iter()
            .map(|(k, x)| (k.to_string(), *x))
            .collect::<Vec<_>>()
    };
    let design = &s.conditions[0].design;
    let setting = truth_setting(&s.lib, design, &own(params), &own(effects)).expect("truth");
    let truth = truth_metrics(&s.conditions, &s.lib, &setting, &Silent).expect("walks");
    TrialSet {
        origin: "synthetic".into(),
        base_dir: repo().join("tests/data/gap"),
        trials: match seed {
            Some(seed) => add_noise(&s.base.trials, &truth, noise, seed, "test"),
            None => expected_trials(&s.base.trials, &truth, noise, "test"),
        },
    }
}

/// The diagnosis with these candidate effects, the declared parameters among the suspects,
/// the undeclared numbers not.
fn diagnose(set: &TrialSet, effects: &[&str]) -> Diagnosis {
    let s = six();
    let mut opts = DiagnoseOptions::new().expect("criterion");
    opts.effects = effects.iter().map(|e| e.to_string()).collect();
    opts.undeclared = false;
    diagnose_conditions(set, &s.conditions, &s.lib, &opts, bundled_walks(), &Silent)
        .expect("diagnosis")
        .0
}

fn probability(d: &Diagnosis, explanation: &str) -> f64 {
    d.posterior
        .iter()
        .find(|l| l.explanation == explanation)
        .map_or(0.0, |l| l.probability)
}

const HIP_LOSSES: [&str; 3] = [
    "hip_coulomb_friction",
    "hip_viscous_damping",
    "hip_backlash",
];

/// Noise only: the nominal is the explanation named, with the criterion's threshold or more.
#[test]
fn a_null_is_answered_no_gap() {
    for seed in [3, 4] {
        let d = diagnose(&trials((&[], &[]), 0.03, Some(seed)), &HIP_LOSSES);
        assert_eq!(d.answer.kind, AnswerKind::NoGap, "{}", d.answer.statement);
        assert_eq!(d.answer.explanation.as_deref(), Some("nominal"));
        assert!(probability(&d, "nominal") >= d.criterion.decision.threshold);
        assert!(d.answer.named.is_empty());
    }
}

/// A small hip damping (0.003 N·m·s/rad, expected trials at 3 %) moves the summaries much
/// as a small Coulomb friction would: neither reaches the threshold, and both lead.
#[test]
fn a_look_alike_pair_is_answered_ambiguous_with_both_leading() {
    let set = trials((&[], &[("hip_viscous_damping", 0.003)]), 0.03, None);
    let d = diagnose(&set, &HIP_LOSSES[..2]);
    assert_eq!(
        d.answer.kind,
        AnswerKind::Ambiguous,
        "{}",
        d.answer.statement
    );
    let leading: Vec<&str> = d
        .answer
        .leading
        .iter()
        .map(|l| l.explanation.as_str())
        .collect();
    assert!(
        leading.contains(&"hip_viscous_damping") && leading.contains(&"hip_coulomb_friction"),
        "{leading:?}"
    );
    let (damping, coulomb) = (
        probability(&d, "hip_viscous_damping"),
        probability(&d, "hip_coulomb_friction"),
    );
    assert!(damping > coulomb && coulomb > 0.05, "{damping} {coulomb}");
    assert!(d.answer.named.is_empty());
}

/// Soft ground (3 MPa) made the trials, and only hip losses and the declared parameters are
/// weighed: nothing weighed explains it, and the answer names nothing.
#[test]
fn a_cause_outside_what_is_weighed_is_answered_unexplained() {
    let set = trials((&[], &[("soft_ground", 3.0e6)]), 0.03, Some(5));
    let d = diagnose(&set, &HIP_LOSSES);
    assert_eq!(
        d.answer.kind,
        AnswerKind::Unexplained,
        "{}",
        d.answer.statement
    );
    assert!(d.answer.named.is_empty());
    assert!(
        d.answer.leading[0].explanation == NONE_OF_THESE
            || d.answer.fit_p < d.criterion.decision.fit_level,
        "{}",
        d.answer.statement
    );
}

/// On a small seeded sample (nulls, two hip losses, a declared slope error, at 3 %), the
/// truth's mean posterior is within 0.1 of the mean probability the answers state for their
/// top explanation.
#[test]
fn the_probabilities_are_calibrated_on_a_small_seeded_sample() {
    let cases: Vec<(Truth<'_>, &str, u64)> = vec![
        ((&[], &[]), "nominal", 11),
        ((&[], &[]), "nominal", 12),
        (
            (&[], &[("hip_coulomb_friction", 0.03)]),
            "hip_coulomb_friction",
            13,
        ),
        (
            (&[], &[("hip_coulomb_friction", 0.03)]),
            "hip_coulomb_friction",
            14,
        ),
        (
            (&[], &[("hip_viscous_damping", 0.012)]),
            "hip_viscous_damping",
            15,
        ),
        (
            (&[], &[("hip_viscous_damping", 0.012)]),
            "hip_viscous_damping",
            16,
        ),
        (
            (&[("ground.slope_deg", 1.5)], &[]),
            "mugatu-two-uncertain:ground.slope_deg",
            17,
        ),
        (
            (&[("ground.slope_deg", 1.5)], &[]),
            "mugatu-two-uncertain:ground.slope_deg",
            18,
        ),
    ];
    let (mut truth_p, mut top_p) = (0.0, 0.0);
    for (truth, label, seed) in &cases {
        let d = diagnose(&trials(*truth, 0.03, Some(*seed)), &HIP_LOSSES);
        truth_p += probability(&d, label);
        top_p += d.posterior[0].probability;
    }
    let n = cases.len() as f64;
    let (truth_p, top_p) = (truth_p / n, top_p / n);
    assert!(
        (truth_p - top_p).abs() <= 0.1,
        "truth {truth_p:.3}, stated {top_p:.3}"
    );
}

/// Trials with robot logs (Coulomb friction 0.02 N·m, 3 %): the cycles enter the likelihood,
/// the text answer is the JSON's, and the JSON is the same bit for bit from run to run.
#[test]
fn text_and_json_give_one_answer_on_trials_with_logs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (trials, logs) = (dir.path().join("t.csv"), dir.path().join("logs"));
    let conditions = repo().join("tests/data/gap/conditions-6.csv");
    let p = |x: &std::path::Path| x.to_str().expect("utf-8").to_string();
    std::fs::copy(
        repo().join("tests/data/gap/mugatu-two-uncertain.toml"),
        dir.path().join("mugatu-two-uncertain.toml"),
    )
    .expect("design");
    let o = survey(&[
        "gap",
        "synth",
        "--conditions",
        &p(&conditions),
        "--effect",
        "hip_coulomb_friction=0.02",
        "--noise",
        "0.03",
        "--seed",
        "7",
        "--out",
        &p(&trials),
        "--logs",
        &p(&logs),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let run = |format: &str| {
        let o = survey(&[
            "gap",
            "diagnose",
            "--trials",
            &p(&trials),
            "--effects",
            "hip_coulomb_friction,hip_viscous_damping",
            "--no-undeclared",
            "--format",
            format,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let json = run("json");
    assert_eq!(json, run("json"), "deterministic");
    let d: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert!(d["n_cycle_observations"].as_u64().expect("count") > 100);
    assert_eq!(d["logged_trials"], 6);
    let statement = d["answer"]["statement"].as_str().expect("statement");
    let text = run("text");
    assert!(text.contains(statement), "{statement}\n{text}");
    assert_eq!(
        d["answer"]["explanation"], "hip_coulomb_friction",
        "{statement}"
    );
}

/// A drive the design's time step cannot resolve, and a log file that is not there, are
/// refused with the trials file and line.
#[test]
fn bad_trials_are_refused_with_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p.to_str().expect("utf-8").to_string()
    };
    let head = "label,design,leg_length_m,frequency_hz,velocity_mps,trajectory,source\n";
    let fast = write(
        "fast.csv",
        &format!("{head}a,mugatu,0.153,1.24,0.15,,x\nb,mugatu,0.153,1e9,0.15,,x\n"),
    );
    let o = survey(&["gap", "diagnose", "--trials", &fast]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("fast.csv:3:") && e.contains("cannot resolve"),
        "{e}"
    );
    let missing = write(
        "missing.csv",
        &format!("{head}a,mugatu,0.153,1.24,0.15,logs/none.csv,x\n"),
    );
    let o = survey(&["gap", "diagnose", "--trials", &missing]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("missing.csv:2:") && e.contains("logs/none.csv"),
        "{e}"
    );
}
