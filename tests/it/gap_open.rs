//! The gap diagnosis outside its closed world: a nominal parameter of the design that is
//! wrong (declared uncertain, or not), two effects at once, and trials made by another
//! engine (Drake). The small cases run on a test design with two uncertain parameters
//! (`tests/data/gap/mugatu-two-uncertain.toml`) over six conditions.

use std::sync::OnceLock;

use robot_survey::gap::EffectLibrary;
use robot_survey::gap::benchmark::{BenchmarkOptions, CaseRow, summarize};
use robot_survey::gap::cache::SimCache;
use robot_survey::gap::diagnose::{
    AnswerKind, DiagnoseOptions, Diagnosis, Named, diagnose_conditions,
};
use robot_survey::gap::knob::ModelSetting;
use robot_survey::gap::select::SelectOptions;
use robot_survey::gap::simulate::{Condition, resolve};
use robot_survey::gap::synth::{add_noise, expected_trials, truth_metrics};
use robot_survey::gap::trials::{Metric, TrialSet};
use robot_survey::progress::Silent;
use robot_survey::sim::Design;

use super::common::{bundled_walks, repo, stderr, stdout, survey};

const TEST_DESIGN: &str = "mugatu-two-uncertain";

struct Six {
    lib: EffectLibrary,
    base: TrialSet,
    conditions: Vec<Condition>,
    cache: &'static SimCache,
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
            cache: bundled_walks(),
        }
    })
}

/// Trials of the six conditions with `params` (path, value at 1×) and `effects` (name, SI
/// at 1×), `noise` relative sd; diagnosed with `candidates` as the effect library.
fn case(
    params: &[(&str, f64)],
    effects: &[(&str, f64)],
    noise: f64,
    seed: u64,
    candidates: &[&str],
    calibrate: bool,
) -> Diagnosis {
    case_with(
        params,
        effects,
        noise,
        Some(seed),
        candidates,
        calibrate,
        SelectOptions::default().into(),
    )
}

/// The same with the selection's options and the undeclared-parameter audit on or off, and
/// the expected (noise-free) trials when `seed` is None.
fn case_with(
    params: &[(&str, f64)],
    effects: &[(&str, f64)],
    noise: f64,
    seed: Option<u64>,
    candidates: &[&str],
    calibrate: bool,
    rules: Rules,
) -> Diagnosis {
    let s = six();
    let set = trials_of(params, effects, noise, seed);
    let opts = DiagnoseOptions {
        effects: candidates.iter().map(|e| e.to_string()).collect(),
        calibrate,
        explanations: false,
        identifiability: false,
        select: rules.select,
        audit_undeclared: rules.audit_undeclared,
        ..DiagnoseOptions::default()
    };
    diagnose_conditions(&set, &s.conditions, &s.lib, &opts, s.cache, &Silent)
        .expect("diagnosis")
        .0
}

/// Trials of the six conditions with `params` (path, value at 1×) and `effects` (name, SI at
/// 1×): `noise` relative sd drawn with `seed`, or the expected (noise-free) trials.
fn trials_of(
    params: &[(&str, f64)],
    effects: &[(&str, f64)],
    noise: f64,
    seed: Option<u64>,
) -> TrialSet {
    let s = six();
    let design = &s.conditions[0].design;
    let mut setting = ModelSetting::nominal();
    for (p, v) in params {
        setting
            .params
            .push((design.name.clone(), p.to_string(), *v));
    }
    for (e, si) in effects {
        let def = s.lib.get(e).expect("effect");
        let mut set = def.setting(def.magnitude().default);
        set.nondimensional[0] = si / def.magnitude().scale.value(design);
        setting.effects.push(set);
    }
    let truth = truth_metrics(&s.conditions, &s.lib, &setting, &Silent).expect("truth");
    TrialSet {
        origin: "synthetic".into(),
        base_dir: s.base.base_dir.clone(),
        trials: match seed {
            Some(seed) => add_noise(&s.base.trials, &truth, noise, seed, "test"),
            None => expected_trials(&s.base.trials, &truth, noise, "test"),
        },
    }
}

/// The selection's rules of a `case_with` and the undeclared-parameter audit.
struct Rules {
    select: SelectOptions,
    audit_undeclared: bool,
}

impl From<SelectOptions> for Rules {
    fn from(select: SelectOptions) -> Rules {
        Rules {
            select,
            audit_undeclared: false,
        }
    }
}

fn names(d: &Diagnosis) -> (Vec<String>, Vec<String>) {
    (
        d.answer.parameters.iter().map(|n| n.knob.clone()).collect(),
        d.answer.effects.iter().map(|n| n.knob.clone()).collect(),
    )
}

/// The answer names exactly `params` and `effects`, in the chain's order.
fn assert_names(d: &Diagnosis, params: &[&str], effects: &[&str]) {
    let (named_params, named_effects) = names(d);
    assert_eq!(named_params, params, "{}", d.answer.statement);
    assert_eq!(named_effects, effects, "{}", d.answer.statement);
}

/// Each of `cases` (a table appended to the design text `body`, the field the error must
/// name, why) is refused with an error naming the file, the field and why.
fn assert_rejected(body: &str, cases: &[(&str, &str, &str)]) {
    for (entry, field, why) in cases {
        let text = format!("{body}\n{entry}");
        let e = Design::from_toml_str(&text, "m.toml")
            .expect_err(entry)
            .to_string();
        assert!(
            e.contains("m.toml") && e.contains(field) && e.contains(why),
            "{e}"
        );
    }
}

#[test]
fn uncertain_declarations_are_checked_and_name_the_entry() {
    let base = std::fs::read_to_string(repo().join("dataset/walkers/mugatu.toml")).expect("read");
    let body = &base[..base
        .find("[[uncertain]]")
        .expect("mugatu declares uncertain values")];
    let cases = [
        (
            "[[uncertain]]\npath = \"mass.no_such_field\"\nrange = [0.1, 0.2]\nwhy = \"x\"\n",
            "uncertain[0] (mass.no_such_field)",
            "no field `no_such_field`",
        ),
        (
            "[[uncertain]]\npath = \"mass.leg_com_height_over_l\"\nrange = [0.5, 0.6]\nwhy = \"x\"\n",
            "uncertain[0] (mass.leg_com_height_over_l)",
            "must lie in its plausible range",
        ),
        (
            "[[uncertain]]\npath = \"mass.leg_com_height_over_l\"\nrange = [0.3, 1.2]\nwhy = \"x\"\n",
            "uncertain[0] (mass.leg_com_height_over_l)",
            "not a valid design",
        ),
        (
            "[[uncertain]]\npath = \"ground.slope_deg\"\nrelative_sd = 0.1\nwhy = \"x\"\n",
            "uncertain[0] (ground.slope_deg)",
            "the file's value is 0",
        ),
        (
            "[[uncertain]]\npath = \"mass.leg_com_height_over_l\"\nrange = [0.4, 0.5]\nwhy = \" \"\n",
            "uncertain[0].why",
            "say why",
        ),
        (
            "[[uncertain]]\npath = \"mass.leg_inertia_box_over_l[3]\"\nrange = [0.4, 0.5]\nwhy = \"x\"\n",
            "uncertain[0] (mass.leg_inertia_box_over_l[3])",
            "has no element 3",
        ),
    ];
    assert_rejected(body, &cases);
    // A declared value moves only its own number; the range is checked in field units.
    let d = Design::builtin("mugatu").expect("mugatu");
    let moved = d
        .with_value("mass.leg_inertia_box_over_l[0]", 0.9)
        .expect("valid");
    assert_eq!(moved.mass.leg_inertia_box_over_l, [0.9, 0.2, 1.0]);
    assert_eq!(moved.geometry, d.geometry);
    assert_eq!(moved.contact, d.contact);
    let e = d
        .with_value("mass.leg_com_height_over_l", 1.5)
        .expect_err("COM above the hip");
    assert!(e.to_string().contains("mass.leg_com_height_over_l"), "{e}");
    let u = d.uncertain_params().expect("resolved");
    let slope = u
        .iter()
        .find(|p| p.path == "ground.slope_deg")
        .expect("slope declared");
    assert_eq!(
        (slope.nominal, slope.lo, slope.hi, slope.prior_sd),
        (0.0, -3.0, 3.0, Some(1.0))
    );
}

#[test]
fn cli_synth_set_names_a_bad_path() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("t.csv");
    let o = survey(&[
        "gap",
        "synth",
        "--set",
        "mass.no_such=1",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--set mass.no_such=1"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing written on error");
}

/// A known error of a declared parameter (an unreported 1.5° slope) is named as that
/// parameter, no effect is blamed, and its 95 % interval holds the truth.
#[test]
fn calibration_recovers_a_declared_parameter_error() {
    let d = case(
        &[("ground.slope_deg", 1.5)],
        &[],
        0.03,
        5,
        &["hip_coulomb_friction", "rolling_resistance"],
        true,
    );
    let (params, effects) = names(&d);
    assert!(effects.is_empty(), "no effect: {}", d.answer.statement);
    assert_eq!(
        params,
        vec![format!("{TEST_DESIGN}:ground.slope_deg")],
        "{}",
        d.answer.statement
    );
    assert_eq!(
        d.answer.kind,
        AnswerKind::ParametersOff,
        "{}",
        d.answer.statement
    );
    let [lo, hi] = d.answer.parameters[0].interval;
    assert!(lo <= 1.5 && 1.5 <= hi, "truth 1.5 outside [{lo}, {hi}]");
}

/// An error in a value the design does not declare uncertain (its mass, [PAPER]) shows in
/// the peak torque only; nothing may be named for it.
#[test]
fn an_undeclared_parameter_error_is_not_blamed_on_anything() {
    let d = case(
        &[("mass.total_mass_kg", 1.08)],
        &[],
        0.03,
        6,
        &["hip_coulomb_friction", "rolling_resistance"],
        true,
    );
    let (params, effects) = names(&d);
    assert!(
        params.is_empty() && effects.is_empty(),
        "{}",
        d.answer.statement
    );
    assert_ne!(
        d.answer.kind,
        AnswerKind::WithinNoise,
        "a 20 % mass error is a real gap"
    );
    let torque = d
        .where_
        .iter()
        .find(|g| g.metric == Metric::PeakTorqueNm)
        .expect("torque measured");
    assert!(
        torque.significant && torque.mean_relative_pct < -10.0,
        "{}",
        torque.statement
    );
}

/// Hip Coulomb friction (0.03 N·m) and soft ground (4 MPa) at once, 3 % noise, diagnosed
/// against the friction, damping and soft-ground candidates with the design's uncertain
/// parameters free or fixed: both effects must be named, no parameter.
fn coulomb_and_soft_ground(calibrate: bool) -> Diagnosis {
    let d = case(
        &[],
        &[("hip_coulomb_friction", 0.03), ("soft_ground", 4.0e6)],
        0.03,
        7,
        &["hip_coulomb_friction", "hip_viscous_damping", "soft_ground"],
        calibrate,
    );
    let (params, mut effects) = names(&d);
    effects.sort();
    assert!(params.is_empty(), "{}", d.answer.statement);
    assert_eq!(
        effects,
        vec!["hip_coulomb_friction", "soft_ground"],
        "{}",
        d.answer.statement
    );
    d
}

/// Two library effects at once (the nominal taken as right): both are named.
#[test]
fn two_effects_at_once_are_both_named() {
    let d = coulomb_and_soft_ground(false);
    assert_eq!(d.chain.len(), 2, "{}", d.answer.statement);
}

/// The same two effects with the design's uncertain parameters free: each effect must beat
/// the recalibration (every uncertain parameter free as a nuisance) to be called, and that
/// larger model nests the chain's model with the parameters at their nominal values. Before
/// the test started the larger model's search from the chain's point, a dozen-parameter
/// search from the recalibration's optimum could end worse than the chain and block the
/// second effect (Coulomb friction + backlash at 2× thresholds on Mugatu's expected trials:
/// "does not beat the recalibrated nominal, LR 5.7", against an LR of 1295 for backlash added
/// to the chain). Here both effects are named and their magnitudes recovered within 15 %
/// (interval coverage is a rate, counted by the benchmark: on this draw the Coulomb interval
/// [0.0301, 0.0338] N·m just misses 0.03).
#[test]
fn two_effects_at_once_are_both_named_with_the_parameters_free() {
    let d = coulomb_and_soft_ground(true);
    assert_recovered(
        &d,
        &[("hip_coulomb_friction", 0.03), ("soft_ground", 4.0e6)],
        0.15,
    );
}

/// Each named effect `knob` within `tol` (relative) of its true magnitude.
fn assert_recovered(d: &Diagnosis, truths: &[(&str, f64)], tol: f64) {
    for &(knob, truth) in truths {
        let named = d
            .answer
            .effects
            .iter()
            .find(|n| n.knob == knob)
            .expect("named");
        assert!(
            (named.value / truth - 1.0).abs() < tol,
            "{knob}: {} against the truth {truth}",
            named.value
        );
    }
}

/// Backlash (10.5°) + hip Coulomb friction (0.0199 N·m), the benchmark's pair at 2× their
/// identification thresholds, on the full Mugatu (12 uncertain parameters, 12 conditions,
/// 3 % noise): `tests/data/gap/backlash-coulomb-3pct-seed0.csv`, made by the command in its
/// `source` column. Coulomb friction alone must beat the recalibration of all 12 parameters
/// to be called, a 13-knob fit against a 12-knob one. Their refinement on the surrogate
/// (one-knob curves, which cannot see how the knobs interact) stopped at χ² 843 against
/// 947 for the recalibration: LR 104.6 with the missing backlash's over-dispersion, p =
/// 4.1e-3 > α/K, and the answer was "unexplained" (measured 2026-11-27 with these three
/// candidates and with all eight). Levenberg–Marquardt on walks (`--walked-lm`) takes both
/// fits further (456 against 871 with all eight candidates), Coulomb friction passes, and
/// backlash follows: both causes named, magnitudes within 10 %, nothing else.
#[test]
#[ignore = "heavy: 107 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn walked_levenberg_marquardt_lets_a_pair_beat_a_dozen_parameter_recalibration() {
    let select = SelectOptions {
        walked_lm: true,
        ..SelectOptions::plain()
    };
    let d = diagnose_committed(
        "backlash-coulomb-3pct-seed0.csv",
        &[
            "hip_coulomb_friction",
            "hip_viscous_damping",
            "hip_backlash",
        ],
        &select,
        false,
        bundled_walks(),
    );
    assert_pair_named(
        &d,
        [("hip_backlash", 10.521), ("hip_coulomb_friction", 0.019881)],
    );
}

/// The full Mugatu's diagnosis (12 uncertain parameters, calibration on) of the committed
/// trials `tests/data/gap/{file}` with these candidate effects.
fn diagnose_committed(
    file: &str,
    effects: &[&str],
    select: &SelectOptions,
    audit_undeclared: bool,
    cache: &SimCache,
) -> Diagnosis {
    let opts = DiagnoseOptions {
        effects: effects.iter().map(|e| e.to_string()).collect(),
        calibrate: true,
        explanations: false,
        identifiability: false,
        select: select.clone(),
        audit_undeclared,
        ..DiagnoseOptions::default()
    };
    diagnose_committed_with(file, &opts, cache)
}

/// The diagnosis of committed trials (`tests/data/gap/<file>`) with `opts`.
fn diagnose_committed_with(file: &str, opts: &DiagnoseOptions, cache: &SimCache) -> Diagnosis {
    let set = TrialSet::read(&repo().join("tests/data/gap").join(file)).expect("trials");
    let conditions = resolve(&set).expect("resolve");
    diagnose_conditions(&set, &conditions, &six().lib, opts, cache, &Silent)
        .expect("diagnosis")
        .0
}

/// The named knob's 95 % interval holds its truth.
fn assert_interval_holds(named: &Named, truth: f64) {
    let [lo, hi] = named.interval;
    assert!(
        lo <= truth && truth <= hi,
        "{}: truth {truth} outside [{lo}, {hi}]",
        named.knob
    );
}

/// Both effects named (as `assert_pair_named`) and each one's 95 % interval holding its truth.
fn assert_pair_named_inside_intervals(d: &Diagnosis, truths: [(&str, f64); 2]) {
    assert_pair_named(d, truths);
    for (knob, truth) in truths {
        let named = d.answer.effects.iter().find(|n| n.knob == knob);
        assert_interval_holds(named.expect("named"), truth);
    }
}

/// The diagnoses of committed trials with the plain selection (`SelectOptions::plain`, the
/// default before 2026-11-28) and with `select` (one walk cache: the second reuses the
/// first's walks).
fn plain_and_with(file: &str, effects: &[&str], select: SelectOptions) -> (Diagnosis, Diagnosis) {
    let (plain, mut with) = plain_and_each(file, effects, &[select]);
    (plain, with.remove(0))
}

/// The diagnoses of committed trials with the plain selection and with each of `selects`,
/// on one walk cache.
fn plain_and_each(
    file: &str,
    effects: &[&str],
    selects: &[SelectOptions],
) -> (Diagnosis, Vec<Diagnosis>) {
    let cache = bundled_walks();
    let plain = diagnose_committed(file, effects, &SelectOptions::plain(), false, cache);
    let with = selects
        .iter()
        .map(|select| diagnose_committed(file, effects, select, false, cache))
        .collect();
    (plain, with)
}

/// Viscous damping and hip Coulomb friction in one group of look-alikes (`context` leads
/// the failure message).
fn assert_damping_and_coulomb_ambiguous(d: &Diagnosis, context: &str) {
    assert!(
        d.answer
            .ambiguous
            .iter()
            .any(|g| g.contains(&"hip_viscous_damping".to_string())
                && g.contains(&"hip_coulomb_friction".to_string())),
        "{context}{}",
        d.answer.statement
    );
}

/// Exactly the two effects `truths` (sorted by name) named, no parameter, each within 10 %
/// of its true magnitude.
fn assert_pair_named(d: &Diagnosis, truths: [(&str, f64); 2]) {
    let (params, mut effects) = names(d);
    effects.sort();
    assert!(params.is_empty(), "{}", d.answer.statement);
    assert_eq!(
        effects,
        truths.map(|(k, _)| k.to_string()).to_vec(),
        "{}",
        d.answer.statement
    );
    assert_recovered(d, &truths, 0.10);
}

/// The benchmark's noisy pair "motor torque–speed line + soft ground" at 2× their
/// identification thresholds (3 % noise, the benchmark's own draw:
/// `tests/data/gap/motor-soft-3pct-bench.csv`, command in its `source` column). Soft ground
/// explains most of the gap alone (LR 2582 against the nominal) but, tested alone against
/// the recalibration of Mugatu's 12 uncertain parameters, its LR of 56 is scaled by an
/// over-dispersion that still holds the missing motor line's misfit: p = 1.4e-3, not
/// called, and the answer was "partly explained, nothing named" (measured 2026-11-27 with
/// every candidate). With the test deferred to the end (`deferred_recalibration`), soft
/// ground is taken, the motor line follows and passes, and soft ground then beats the
/// recalibration with the motor line in (p = 8e-34): both named within 10 %. The plain
/// selection's answer on the same trials is checked too: without the option the pair is
/// not named. The default selection (this option among the four rules) names both.
#[test]
#[ignore = "heavy: 389 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn a_deferred_recalibration_test_names_both_causes_of_a_pair() {
    let (plain, with) = plain_and_each(
        "motor-soft-3pct-bench.csv",
        &[
            "soft_ground",
            "motor_torque_speed",
            "hip_coulomb_friction",
            "hip_viscous_damping",
        ],
        &[
            SelectOptions {
                deferred_recalibration: true,
                ..SelectOptions::plain()
            },
            SelectOptions::default(),
        ],
    );
    assert!(
        names(&plain).1.len() < 2,
        "the plain selection names both: {}",
        plain.answer.statement
    );
    for d in &with {
        assert_pair_named(
            d,
            [("motor_torque_speed", 3.6834), ("soft_ground", 3.1121e6)],
        );
    }
}

/// The benchmark's noisy pair "backlash + hip viscous damping" (2× thresholds, 3 % noise,
/// its own draw: `tests/data/gap/backlash-damping-3pct-bench.csv`). Damping is taken first,
/// with the missing backlash's misfit in its over-dispersion (φ 18.9): the identification
/// distance at that step is 124 in χ², so hip Coulomb friction is "not separable" from it
/// and damping is not named (only backlash was, measured 2026-11-27). In the final model
/// (damping + backlash, φ 1.0) Coulomb friction exchanged for damping fits worse by χ² 125
/// against a distance of 6.6: `rivals_at_end` tells them apart and both causes are named,
/// within 10 %. `look_alikes_at_end`, which searches every knob outside the answer, finds
/// no look-alike of either named knob there and clears the flag too. Without them the
/// plain selection leaves damping unnamed on the same trials; the default selection (with
/// `rivals_at_end` among its four rules) names both.
#[test]
#[ignore = "heavy: 236 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn look_alikes_compared_again_in_the_final_model_name_both_causes_of_a_pair() {
    let (plain, with) = plain_and_each(
        "backlash-damping-3pct-bench.csv",
        &[
            "hip_backlash",
            "hip_viscous_damping",
            "hip_coulomb_friction",
        ],
        &[
            SelectOptions {
                rivals_at_end: true,
                ..SelectOptions::plain()
            },
            SelectOptions {
                look_alikes_at_end: true,
                ..SelectOptions::plain()
            },
            SelectOptions::default(),
        ],
    );
    assert!(
        !names(&plain).1.contains(&"hip_viscous_damping".to_string()),
        "the plain selection names damping: {}",
        plain.answer.statement
    );
    for d in &with {
        assert_pair_named(
            d,
            [("hip_backlash", 10.521), ("hip_viscous_damping", 0.0067636)],
        );
    }
}

/// The benchmark's compound case "unreported 1.5° slope + rolling resistance 0.0013 m" (2×
/// its threshold, 3 % noise, its own draw: `tests/data/gap/rolling-slope-3pct-bench.csv`,
/// made by the command in its `source` column). Both are named, and they trade off: a
/// steeper slope and less rolling resistance both let the walker go faster. The profile of
/// each must re-fit the other; with the other re-fitted on the surrogate only, the walked
/// profile stayed near the conditional one and both 95 % intervals missed their truth
/// (slope [1.438, 1.496], rolling resistance [0.00121, 0.00129] m with all eight effects,
/// measured 2026-11-28). Gauss–Newton steps of the other knobs on walks give [1.43, 1.56]
/// and [0.00121, 0.00137] m, both holding the truth.
#[test]
fn intervals_of_two_named_knobs_that_trade_off_hold_both_truths() {
    let d = diagnose_committed(
        "rolling-slope-3pct-bench.csv",
        &["rolling_resistance", "hip_viscous_damping"],
        &SelectOptions::default(),
        false,
        bundled_walks(),
    );
    assert_eq!(d.answer.kind, AnswerKind::Both, "{}", d.answer.statement);
    assert_names(&d, &["mugatu:ground.slope_deg"], &["rolling_resistance"]);
    assert_interval_holds(&d.answer.parameters[0], 1.5);
    assert_interval_holds(&d.answer.effects[0], 0.001_302_241_198_449_636);
}

/// The benchmark's noisy pair "hip Coulomb friction + motor torque–speed line" (2×
/// thresholds, 3 % noise, its own draw: `tests/data/gap/coulomb-motor-3pct-bench.csv`).
/// Viscous damping is taken first, with the motor line's misfit still in the data (φ 9.6):
/// Coulomb friction alone fits worse by more than that step's distance, so the step flags
/// no rival, the motor line follows, and the default names "damping + motor line" — damping
/// in neither cause, a confident wrong name (measured 2026-11-28, all eight effects). In
/// the final model (φ ≈ 1) Coulomb friction exchanged for damping fits within the
/// identification distance (7.0): `look_alikes_at_end` finds it, and damping is not named
/// (ambiguous with Coulomb friction) while the motor line stays named within 10 %.
#[test]
#[ignore = "heavy: 93 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn a_look_alike_found_again_in_the_final_model_unnames_a_stand_in() {
    let effects = [
        "hip_coulomb_friction",
        "hip_viscous_damping",
        "motor_torque_speed",
    ];
    let (plain, d) = plain_and_with(
        "coulomb-motor-3pct-bench.csv",
        &effects,
        SelectOptions {
            look_alikes_at_end: true,
            ..SelectOptions::plain()
        },
    );
    assert!(
        names(&plain).1.contains(&"hip_viscous_damping".to_string()),
        "the plain selection does not name damping: {}",
        plain.answer.statement
    );
    let (params, named) = names(&d);
    assert!(params.is_empty(), "{}", d.answer.statement);
    assert_eq!(
        named,
        vec!["motor_torque_speed".to_string()],
        "{}",
        d.answer.statement
    );
    assert_recovered(&d, &[("motor_torque_speed", 3.6834)], 0.10);
    assert_damping_and_coulomb_ambiguous(&d, "");
}

/// Hip Coulomb friction (0.02 N·m) with the floor's μ 3 % below the design's (0.34 for
/// 0.35), on the six conditions' expected trials (3 % sd): the benchmark's pair "μ +
/// Coulomb" in small. Viscous damping alone fits these a little better than Coulomb
/// friction alone (both raise the cost of transport), and once damping is in, μ is not
/// significant, so forward selection names damping — a knob in neither cause (the
/// benchmark's "spurious third"). The look-ahead check weighs one size up: Coulomb
/// friction + μ fits these trials exactly, damping plus any one knob does not, so damping
/// is not identified and must not be named. Nothing outside the truth may be named, and the
/// check must leave a true single cause named: damping alone (0.007 N·m·s/rad) and Coulomb
/// friction alone (0.02 N·m), same conditions and noise, 3 % noise draws too.
#[test]
#[ignore = "heavy: 117 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn the_look_ahead_check_unnames_a_look_alike_that_won_the_first_step() {
    let candidates = [
        "hip_coulomb_friction",
        "hip_viscous_damping",
        "friction_coefficient",
    ];
    let look = SelectOptions {
        look_ahead: true,
        ..SelectOptions::plain()
    };
    let pair = [
        ("friction_coefficient", 0.34),
        ("hip_coulomb_friction", 0.02),
    ];
    let truth = ["friction_coefficient", "hip_coulomb_friction"];
    let plain = case_with(
        &[],
        &pair,
        0.03,
        None,
        &candidates,
        false,
        SelectOptions::plain().into(),
    );
    assert_eq!(
        names(&plain).1,
        vec!["hip_viscous_damping"],
        "the case no longer shows the look-alike first step: {}",
        plain.answer.statement
    );
    for seed in [None, Some(1), Some(2)] {
        let d = case_with(
            &[],
            &pair,
            0.03,
            seed,
            &candidates,
            false,
            look.clone().into(),
        );
        let (params, effects) = names(&d);
        assert!(params.is_empty(), "{}", d.answer.statement);
        assert!(
            effects.iter().all(|e| truth.contains(&e.as_str())),
            "seed {seed:?}: a knob outside the truth named: {}",
            d.answer.statement
        );
        assert_damping_and_coulomb_ambiguous(&d, &format!("seed {seed:?}: "));
    }
    for (effect, si) in [
        ("hip_viscous_damping", 0.007),
        ("hip_coulomb_friction", 0.02),
    ] {
        for seed in [None, Some(1)] {
            let d = case_with(
                &[],
                &[(effect, si)],
                0.03,
                seed,
                &candidates,
                false,
                look.clone().into(),
            );
            assert_eq!(
                names(&d).1,
                vec![effect],
                "seed {seed:?}: {}",
                d.answer.statement
            );
        }
    }
}

/// The look-ahead check outside what it assumes (a model one size up holds the truth): hip
/// Coulomb friction (0.02 N·m) on a robot 5 % lighter than its design (0.95 kg for 0.9),
/// a mass the test design does not declare, so no model of any size holds the truth. The
/// check must not take the true effect's name away, nor name anything else: Coulomb friction
/// named with its interval holding 0.02 N·m, no parameter named (expected trials and one
/// 3 % draw).
#[test]
#[ignore = "heavy: 99 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn the_look_ahead_check_keeps_a_true_effect_beside_an_undeclared_error() {
    let look = SelectOptions {
        look_ahead: true,
        ..SelectOptions::plain()
    };
    for seed in [None, Some(1)] {
        let d = case_with(
            &[("mass.total_mass_kg", 0.95)],
            &[("hip_coulomb_friction", 0.02)],
            0.03,
            seed,
            &[
                "hip_coulomb_friction",
                "hip_viscous_damping",
                "friction_coefficient",
            ],
            true,
            look.clone().into(),
        );
        let (params, effects) = names(&d);
        assert!(params.is_empty(), "seed {seed:?}: {}", d.answer.statement);
        assert_eq!(
            effects,
            vec!["hip_coulomb_friction"],
            "seed {seed:?}: {}",
            d.answer.statement
        );
        let iv = d.answer.effects[0].interval;
        assert!(
            iv[0] <= 0.02 && 0.02 <= iv[1],
            "seed {seed:?}: interval {iv:?} misses 0.02"
        );
    }
}

/// Trials made by Drake on the reference design, no effect added (the committed golden file
/// `tests/golden/drake/gap/trials-none.csv`, made by the command in its README), plus 3 %
/// noise: the engines' difference must not be blamed on a physical effect.
#[test]
#[ignore = "heavy: 2,716 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn a_drake_made_null_case_is_not_blamed_on_an_effect() {
    let lib = EffectLibrary::bundled().expect("library");
    let golden =
        TrialSet::read(&repo().join("tests/golden/drake/gap/trials-none.csv")).expect("golden");
    let conditions = resolve(&golden).expect("resolve");
    let truth: Vec<_> = golden
        .trials
        .iter()
        .map(robot_survey::gap::simulate::SimMetrics::measured_by)
        .collect();
    let set = TrialSet {
        origin: "drake null".into(),
        base_dir: golden.base_dir.clone(),
        trials: add_noise(&golden.trials, &truth, 0.03, 3, "drake"),
    };
    let opts = DiagnoseOptions {
        effects: vec![
            "actuation_latency".into(),
            "hip_viscous_damping".into(),
            "hip_coulomb_friction".into(),
        ],
        explanations: false,
        identifiability: false,
        ..DiagnoseOptions::default()
    };
    let (d, _) = diagnose_conditions(&set, &conditions, &lib, &opts, bundled_walks(), &Silent)
        .expect("diagnosis");
    assert!(!d.within_noise, "the engines differ: a real gap");
    assert!(
        d.answer.effects.is_empty(),
        "an effect blamed: {}",
        d.answer.statement
    );
}

/// RMS z of a design's nominal walks against Drake-SAP's no-effect trials (3 % sd on each
/// value, as the benchmark's noise); velocity as |v| when `speed_only`.
fn drake_sap_nominal_rms_z(design: &str, speed_only: bool) -> f64 {
    let lib = EffectLibrary::bundled().expect("library");
    let mut set =
        TrialSet::read(&repo().join("tests/golden/drake/gap/trials-none.csv")).expect("golden");
    for t in set.trials.iter_mut() {
        t.design = design.to_string();
    }
    let conditions = resolve(&set).expect("resolve");
    let (mut sum, mut n) = (0.0, 0usize);
    for (t, c) in set.trials.iter().zip(&conditions) {
        let sim = c.simulate(&lib, &ModelSetting::nominal()).expect("walk");
        for m in Metric::ALL {
            let Some(meas) = t.measured(m) else { continue };
            let (mut a, mut b) = (sim.get(m), meas.value);
            if speed_only && m == Metric::VelocityMps {
                (a, b) = (a.abs(), b.abs());
            }
            let z = (a - b) / (0.03 * b.abs());
            sum += z * z;
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}

/// The engines' difference on the Drake gap trials is mostly friction: diagnosed against
/// `mugatu-ref-sap` (the reference with SAP's convex friction cone) instead of `mugatu-ref`,
/// the nominal model's gap to Drake-SAP's no-effect trials (9 conditions, 3 sizes × 3
/// drive frequencies) falls from 65.3 to 16.0 RMS z at 3 % sd. Most of the rest is the
/// walking direction at the design frequency (Drake walks these three backward, the
/// project forward: set by the first cycles, reports/drake-crosscheck.md); compared as
/// |v| the gap is 7.0 (with Coulomb friction 59.3), and |v| is how the diagnosis compares
/// them, since `mugatu-ref-sap` walks either way (`criteria.walking_direction`). Bounds: a
/// ratio below 0.3, below 10, and Coulomb's |v| gap above 5× the convex one. (The same
/// figures come from `survey gap synth --expected` at the file's conditions, computed
/// outside this code.)
#[test]
fn the_convex_cone_removes_most_of_the_drake_sap_engine_gap() {
    let coulomb = drake_sap_nominal_rms_z("mugatu-ref", false);
    let convex_speed = drake_sap_nominal_rms_z("mugatu-ref-sap", true);
    assert!(
        convex_speed < 0.3 * coulomb,
        "convex {convex_speed} vs Coulomb {coulomb}"
    );
    let coulomb_speed = drake_sap_nominal_rms_z("mugatu-ref", true);
    assert!(convex_speed < 10.0, "convex, |v|: {convex_speed}");
    assert!(
        coulomb_speed > 5.0 * convex_speed,
        "Coulomb, |v|: {coulomb_speed}"
    );
}

/// A design that walks either way (`criteria.walking_direction = "either"`, mugatu-ref-sap)
/// has its measured velocities compared as speeds: Drake-SAP walks three of the nine
/// no-effect conditions backward (negative velocity in the committed file), and against
/// mugatu-ref-sap each measured value becomes |v| while every other metric is kept; against
/// mugatu-ref (forward) the signs stay. A sloped condition sets the direction, so there the
/// sign is kept too. The speed comparison itself rests on the mirror symmetry of
/// `a_fore_aft_symmetric_walker_driven_half_a_period_later_walks_the_mirror_gait`.
#[test]
fn a_walker_that_walks_either_way_is_compared_on_its_speed() {
    let lib = EffectLibrary::bundled().expect("library");
    let raw =
        TrialSet::read(&repo().join("tests/golden/drake/gap/trials-none.csv")).expect("golden");
    let velocity = |set: &TrialSet| -> Vec<f64> {
        set.trials
            .iter()
            .map(|t| t.measured(Metric::VelocityMps).expect("velocity").value)
            .collect()
    };
    let drake = velocity(&raw);
    let backward = drake.iter().filter(|v| **v < 0.0).count();
    assert!(
        backward >= 1,
        "the committed file walks backward somewhere: {drake:?}"
    );
    for (design, either) in [("mugatu-ref-sap", true), ("mugatu-ref", false)] {
        let mut set = raw.clone();
        for t in set.trials.iter_mut() {
            t.design = design.to_string();
        }
        let conditions = resolve(&set).expect("resolve");
        let (filled, _, _) =
            robot_survey::gap::diagnose::measured(&set, &conditions, &lib, 0.03).expect("measured");
        let expected: Vec<f64> = drake
            .iter()
            .map(|v| if either { v.abs() } else { *v })
            .collect();
        assert_eq!(velocity(&filled), expected, "{design}");
        for (a, b) in filled.trials.iter().zip(&set.trials) {
            for m in [Metric::RollPpDeg, Metric::PitchPpDeg, Metric::Cot] {
                assert_eq!(a.measured(m), b.measured(m), "{design} {m:?}");
            }
        }
    }
    // On a slope the direction is the model's: the sign is kept.
    let mut sloped = raw.clone();
    for t in sloped.trials.iter_mut() {
        t.design = "mugatu-ref-sap".into();
        t.slope_deg = Some(1.0);
    }
    let conditions = resolve(&sloped).expect("resolve");
    let (filled, _, _) =
        robot_survey::gap::diagnose::measured(&sloped, &conditions, &lib, 0.03).expect("measured");
    assert_eq!(velocity(&filled), drake);
}

/// `walking_direction = "either"` is refused, naming the file and the field, on a design
/// that is not fore–aft symmetric as written.
#[test]
fn walking_either_way_needs_a_fore_aft_symmetric_design() {
    let text =
        std::fs::read_to_string(repo().join("dataset/walkers/reference/mugatu-ref-sap.toml"))
            .expect("read");
    assert!(Design::from_toml_str(&text, "m.toml").is_ok());
    for (from, to, field) in [
        (
            "leg_com_forward_over_l = 0.0 ",
            "leg_com_forward_over_l = 0.02 ",
            "mass.leg_com_forward_over_l",
        ),
        (
            "foot_center_forward_over_l = 0.0 ",
            "foot_center_forward_over_l = 0.01 ",
            "geometry.foot_center_forward_over_l",
        ),
        ("slope_deg = 0.0", "slope_deg = 0.5", "ground.slope_deg"),
    ] {
        assert!(text.contains(from), "{from}");
        let e = Design::from_toml_str(&text.replacen(from, to, 1), "m.toml")
            .expect_err(field)
            .to_string();
        assert!(
            e.contains("m.toml") && e.contains(field) && e.contains("either"),
            "{e}"
        );
    }
}

/// A knife-edge gait: the one-robot benchmark's COM height 0.495 L (the file's 0.45, +10 %;
/// 5 % noise, the benchmark's own draw: `tests/data/gap/com-height-knife-edge-5pct-bench.csv`,
/// command in its `source` column, conditions `gap::benchmark::one_robot_conditions`). At
/// this COM two of the twelve conditions (f1.03x, A+4) stop walking, and no COM near the
/// truth reproduces the others closer than 22 RMS z by the measurements' sds: a nudge of
/// 1/256 of the range changes the metrics as much. Without the stop at the simulator's
/// resolution the search went on and named the servo's damping gain too, 1.17–1.34
/// against the file's 2.0 (gap left 5.6, 49,104 walks; reports/gap-benchmark.md,
/// fifteenth session), a wrong parameter. With it the COM height alone is named, its
/// interval holding the truth.
#[test]
fn a_knife_edge_gait_stops_the_search_at_the_simulators_resolution() {
    let opts = DiagnoseOptions {
        explanations: false,
        identifiability: false,
        audit_undeclared: false,
        ..DiagnoseOptions::default()
    };
    assert!(opts.select.stop_at_resolution, "on by default");
    let d = diagnose_committed_with(
        "com-height-knife-edge-5pct-bench.csv",
        &opts,
        bundled_walks(),
    );
    assert_eq!(
        d.answer.kind,
        AnswerKind::ParametersOff,
        "{}",
        d.answer.statement
    );
    assert_names(&d, &["mugatu:mass.leg_com_height_over_l"], &[]);
    assert_interval_holds(&d.answer.parameters[0], 0.495);
    assert!(
        d.notes.iter().any(|n| n.contains("simulator's resolution")),
        "the stop is the rule's: {:?}",
        d.notes
    );
}

/// The paths the bundled Mugatu declares uncertain (read once for every hand-made row).
fn mugatu_uncertain() -> &'static [String] {
    static PATHS: OnceLock<Vec<String>> = OnceLock::new();
    PATHS.get_or_init(|| {
        Design::builtin("mugatu")
            .expect("mugatu")
            .uncertain
            .into_iter()
            .map(|u| u.path)
            .collect()
    })
}

fn row(
    kind: &str,
    truth_effects: &str,
    truth_params: &str,
    named_effects: &str,
    named_params: &str,
    intervals: &str,
) -> CaseRow {
    CaseRow {
        key: format!("{kind}/{truth_effects}/{truth_params}/{named_effects}/{named_params}"),
        suite: "main".into(),
        kind: kind.into(),
        noise: 0.05,
        seed: 0,
        calibrate: true,
        multiple: None,
        truth_effects: truth_effects.into(),
        truth_params: truth_params.into(),
        // As the benchmark sets it: every erred parameter declared uncertain by the bundled
        // Mugatu (its total mass is; the lateral edge of the leg's inertia box is not).
        truth_declared: !truth_params.is_empty()
            && truth_params.split(';').all(|pv| {
                let path = pv.split('=').next().unwrap_or(pv);
                mugatu_uncertain().iter().any(|u| u == path)
            }),
        answer: String::new(),
        named_effects: named_effects.into(),
        named_params: named_params.into(),
        intervals: intervals.into(),
        ambiguous: String::new(),
        leads: String::new(),
        gap_before: 1.0,
        gap_after: None,
        walks: 0,
        logged_trials: 0,
        cycles: String::new(),
        cycles_named: String::new(),
    }
}

/// The benchmark's scores on hand-made case rows: counts, rates and Clopper–Pearson bounds
/// as computed by hand (0 of 300: upper bound 0.99361 %, R's qbeta(0.95, 1, 300)).
#[test]
fn benchmark_scores_count_what_the_rows_say() {
    let lib = EffectLibrary::bundled().expect("library");
    let mut rows: Vec<CaseRow> = (0..300)
        .map(|i| {
            let mut r = row("null", "", "", "", "", "");
            r.key = format!("null/{i}");
            r
        })
        .collect();
    rows.push(row(
        "pair",
        "hip_coulomb_friction=0.02;soft_ground=3000000",
        "",
        "hip_coulomb_friction;soft_ground",
        "",
        "",
    ));
    rows.push(row(
        "pair",
        "hip_coulomb_friction=0.02;rolling_resistance=0.002",
        "",
        "hip_coulomb_friction;hip_backlash",
        "",
        "",
    ));
    // friction_coefficient is named through the parameter it stands for in mugatu.
    rows.push(row(
        "pair",
        "friction_coefficient=0.3;soft_ground=3000000",
        "",
        "soft_ground",
        "mugatu:contact.friction_mu",
        "",
    ));
    rows.push(row(
        "parameter",
        "",
        "ground.slope_deg=1.5",
        "",
        "mugatu:ground.slope_deg",
        "mugatu:ground.slope_deg=1.2..1.8",
    ));
    rows.push(row(
        "parameter",
        "",
        "mass.total_mass_kg=1.08",
        "rolling_resistance",
        "mugatu:ground.slope_deg",
        "",
    ));
    // Expected (noise-free) pairs: scored apart, the ceiling of the noisy pairs.
    rows.push(row(
        "pair-expected",
        "hip_coulomb_friction=0.02;hip_viscous_damping=0.007",
        "",
        "hip_viscous_damping",
        "",
        "",
    ));
    rows.push(row(
        "pair-expected",
        "hip_coulomb_friction=0.02;soft_ground=3000000",
        "",
        "hip_coulomb_friction;soft_ground",
        "",
        "",
    ));
    // Compound cases: a declared parameter error plus an effect.
    rows.push(row(
        "compound",
        "hip_backlash=10",
        "ground.slope_deg=1.5",
        "hip_backlash",
        "mugatu:ground.slope_deg",
        "",
    ));
    rows.push(row(
        "compound",
        "soft_ground=5000000",
        "ground.slope_deg=1.5",
        "rolling_resistance",
        "mugatu:ground.slope_deg",
        "",
    ));
    // The effect named through its parameter alias, the slope missed: nothing spurious.
    rows.push(row(
        "compound",
        "friction_coefficient=0.34",
        "ground.slope_deg=1.5",
        "",
        "mugatu:contact.friction_mu",
        "",
    ));
    // Compound cases with an undeclared parameter error (nothing can name it): the effect
    // named alone is right; a look-alike parameter beside it is a knob in neither.
    for named_param in ["", "mugatu:mass.leg_inertia_box_over_l[2]"] {
        rows.push(row(
            "compound",
            "hip_coulomb_friction=0.02",
            "mass.leg_inertia_box_over_l[1]=0.26",
            "hip_coulomb_friction",
            named_param,
            "",
        ));
    }
    let opts = BenchmarkOptions::standard("mugatu").expect("the bundled cases");
    let s = summarize(&rows, &lib, &opts, Default::default());
    let get = |what: &str| {
        s.scores
            .iter()
            .find(|x| x.what.starts_with(what))
            .unwrap_or_else(|| panic!("no score {what}"))
    };
    let fa = get("main: false alarms");
    assert_eq!((fa.k, fa.n), (0, 300));
    assert!((fa.upper_95 - 0.0099361).abs() < 1e-6, "{}", fa.upper_95);
    let both = get("pairs of effects");
    assert_eq!((both.k, both.n), (2, 3));
    let third = get("pairs: a spurious third");
    assert_eq!((third.k, third.n), (1, 3));
    let wrong_effect = get("main: parameter errors: a library effect wrongly called");
    assert_eq!((wrong_effect.k, wrong_effect.n), (1, 2));
    let wrong_param = get("main: parameter errors: a wrong parameter named");
    assert_eq!((wrong_param.k, wrong_param.n), (1, 2));
    // Both parameter rows' errors are declared by the bundled Mugatu; only the slope's is
    // named.
    let right_param = get("main: parameter errors in a declared parameter: the right one named");
    assert_eq!((right_param.k, right_param.n), (1, 2));
    let ceiling = get("pairs of effects at 2× thresholds, on their expected");
    assert_eq!((ceiling.k, ceiling.n), (1, 2));
    let ceiling_third = get("pairs on their expected trials: a spurious");
    assert_eq!((ceiling_third.k, ceiling_third.n), (0, 2));
    let compound = |kind: &str, what: &str| {
        let x = get(&format!(
            "compound ({kind} parameter error + effect at 2× threshold): {what}"
        ));
        (x.k, x.n)
    };
    assert_eq!(compound("declared", "the effect named"), (2, 3));
    assert_eq!(compound("declared", "the parameter named"), (2, 3));
    assert_eq!(compound("declared", "both named"), (1, 3));
    assert_eq!(compound("declared", "a knob in neither named"), (1, 3));
    assert_eq!(compound("undeclared", "the effect named"), (2, 2));
    assert_eq!(compound("undeclared", "a knob in neither named"), (1, 2));
    assert!(
        !s.scores
            .iter()
            .any(|x| x.what.starts_with("compound (undeclared") && x.what.contains("both")),
        "an undeclared error cannot be named: no 'both' score"
    );
    let cov = get("95 % intervals holding the truth");
    assert_eq!((cov.k, cov.n), (1, 1));
    assert!(
        !s.scores.iter().any(|x| x.what.contains("logged cycles")),
        "no Drake row with logs: no cycles score"
    );
}

/// The Drake scores with the logged cycles, on hand-made rows: the names that stand after
/// the cycles replace the answer's (a name the cycles withdrew no longer counts, a name they
/// added does); μ named through its parameter in a Drake design is the truth's alias, any
/// other parameter is another knob; rows without logs are not scored with the cycles.
#[test]
fn benchmark_scores_the_drake_answers_with_the_logged_cycles() {
    let lib = EffectLibrary::bundled().expect("library");
    let drake = |truth: &str, named: &str, logged: usize, cycles_named: &str| {
        let mut r = row("drake", truth, "", named, "", "");
        r.key = format!("drake/{truth}/{named}/{cycles_named}/{logged}");
        r.logged_trials = logged;
        r.cycles_named = cycles_named.into();
        r
    };
    let rows = vec![
        // No effect, nothing named with or without the cycles.
        drake("", "", 3, ""),
        // The summaries named the look-alike; the cycles withdrew it: no longer "another".
        drake("hip_coulomb_friction=0.05", "hip_viscous_damping", 3, ""),
        // The cycles named the truth in the look-alike group.
        drake("hip_coulomb_friction=0.05", "", 3, "hip_coulomb_friction"),
        drake("hip_viscous_damping=0.02", "", 3, "hip_viscous_damping"),
        // μ through its parameter: the truth; a slope: another knob.
        drake(
            "friction_coefficient=0.4",
            "",
            3,
            "mugatu-ref-hc40:contact.friction_mu",
        ),
        drake(
            "friction_coefficient=0.6",
            "",
            3,
            "mugatu-ref-hc40:ground.slope_deg",
        ),
        // No logs: scored without the cycles only.
        drake("hip_viscous_damping=0.02", "hip_viscous_damping", 0, ""),
    ];
    let opts = BenchmarkOptions::standard("mugatu").expect("the bundled cases");
    let s = summarize(&rows, &lib, &opts, Default::default());
    let get = |what: &str| {
        let x = s
            .scores
            .iter()
            .find(|x| x.what.starts_with(what))
            .unwrap_or_else(|| panic!("no score {what}"));
        (x.k, x.n)
    };
    assert_eq!(get("Drake, effect added: that effect named"), (1, 6));
    assert_eq!(get("Drake, effect added: another effect named"), (1, 6));
    assert_eq!(
        get("Drake with logged cycles, no effect added: anything named"),
        (0, 1)
    );
    assert_eq!(
        get("Drake with logged cycles, effect added: that effect named"),
        (3, 5)
    );
    assert_eq!(
        get("Drake with logged cycles, effect added: another knob named"),
        (1, 5)
    );
}

/// `survey gap explore`: a walking speed above the Froude limit of walking, v ≤ √(g·L)
/// (the inverted-pendulum bound, 0.49 m/s for Zippy's 24.7 mm legs), is out of reach of every
/// plausible setting; nothing is plausible; the same seed gives the same bytes.
#[test]
fn explore_finds_no_setting_beyond_the_froude_limit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trials = dir.path().join("fast.csv");
    std::fs::write(
        &trials,
        "label,design,leg_length_m,velocity_mps,velocity_mps_sd,source\n\
         too-fast,zippy,0.0247,1.0,0.05,hand-made: twice the Froude limit\n",
    )
    .expect("write");
    let args = [
        "gap",
        "explore",
        "--trials",
        trials.to_str().expect("utf-8"),
        "--samples",
        "24",
        "--seed",
        "4",
        "--format",
        "json",
    ];
    let o = survey(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let e: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    assert_eq!(e["plausible"], 0);
    let m = &e["metrics"][0];
    assert_eq!(m["reachable"], false);
    let froude_limit = (9.81f64 * 0.0247).sqrt();
    let top = m["reach"][1].as_f64().expect("reach");
    assert!(top < froude_limit, "a walk at {top} m/s beats √(gL)");
    assert_eq!(
        e["parameters"].as_array().map(Vec::len),
        Some(8),
        "zippy declares 8"
    );
    let again = survey(&args);
    assert_eq!(stdout(&o), stdout(&again), "deterministic in the seed");
}

#[test]
fn explore_rejects_designs_without_uncertain_parameters_and_tiny_samples() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trials = dir.path().join("t.csv");
    std::fs::write(
        &trials,
        "label,design,leg_length_m,velocity_mps,source\n\
         a,zippy-ref,0.0247,0.1,hand-made\n",
    )
    .expect("write");
    let t = trials.to_str().expect("utf-8");
    let o = survey(&["gap", "explore", "--trials", t]);
    assert_ne!(o.status.code(), Some(0));
    assert!(stderr(&o).contains("[[uncertain]]"), "{}", stderr(&o));
    let o = survey(&["gap", "explore", "--trials", t, "--samples", "1"]);
    assert_ne!(o.status.code(), Some(0));
    assert!(stderr(&o).contains("at least 2 samples"), "{}", stderr(&o));
}

/// Where `explore`'s assumption fails — a sample too sparse for tight trials, made by an error
/// in a value the design does not declare (its mass, +20 %) with every declared parameter at
/// its file value — the best sampled setting fits worse than the file's values, and the
/// verdict must say "cannot tell", not "no plausible setting".
#[test]
fn explore_says_cannot_tell_when_its_sample_is_too_sparse() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trials = dir.path().join("mass.csv");
    let t = trials.to_str().expect("utf-8");
    let o = survey(&[
        "gap",
        "synth",
        "--set",
        "mass.total_mass_kg=1.08",
        "--noise",
        "0.03",
        "--seed",
        "21",
        "--out",
        t,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = survey(&[
        "gap",
        "explore",
        "--trials",
        t,
        "--samples",
        "16",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    let (best, nominal) = (
        e["best_chi2"].as_f64().expect("best"),
        e["nominal_chi2"].as_f64().expect("nominal"),
    );
    assert!(best > nominal, "best sample {best} vs nominal {nominal}");
    assert_eq!(e["too_sparse"], true);
    let o = survey(&["gap", "explore", "--trials", t, "--samples", "16"]);
    assert!(stdout(&o).contains("**Cannot tell"), "{}", stdout(&o));
}

/// The selection's rules are part of a benchmark's signature when the run uses them. The
/// standard run has the diagnosis' default (one exchange round, the look-ahead check, the
/// deferred recalibration test, look-alikes compared at the end, the within-noise subset,
/// the stop at the simulator's resolution),
/// as the committed points file does; a run with the plain selection has the signature of
/// the points files written before the rules were the default
/// (`reports/gap-benchmark-plain.points.csv`); a run with any other set of rules cannot be
/// resumed into the committed file.
#[test]
fn a_benchmark_with_other_selection_rules_is_another_benchmark() {
    let mut opts = BenchmarkOptions::standard("mugatu").expect("the bundled cases");
    let standard = serde_json::to_string(&opts).expect("options serialise");
    for on in [
        "\"exchange_rounds\":1",
        "\"look_ahead\":true",
        "\"deferred_recalibration\":true",
        "\"rivals_at_end\":true",
        "\"within_noise_subset\":true",
        "\"stop_at_resolution\":true",
    ] {
        assert!(standard.contains(on), "{on}: {standard}");
    }
    for off in ["joint_step", "walked_lm", "look_alikes_at_end"] {
        assert!(!standard.contains(off), "{off}: {standard}");
    }
    let tail = |json: &str| {
        // The rules close the options' object: compare from the first of them on.
        json[json.find("\"effects\"").expect("effects")..].to_string()
    };
    let committed = std::fs::read_to_string(repo().join("reports/gap-benchmark.points.csv"))
        .expect("committed points file");
    let header = committed.lines().next().unwrap_or_default();
    assert!(header.contains("\"one_robot_null_cases\":300"), "{header}");
    assert!(
        header.ends_with(&format!("{}]", tail(&standard))),
        "{header}"
    );
    opts.select = SelectOptions::plain();
    let plain = serde_json::to_string(&opts).expect("options serialise");
    assert!(plain.ends_with("\"effects\":[]}"), "{plain}");
    let plain_file = std::fs::read_to_string(repo().join("reports/gap-benchmark-plain.points.csv"))
        .expect("the plain selection's points file");
    let plain_header = plain_file.lines().next().unwrap_or_default();
    assert!(plain_header.ends_with("\"effects\":[]}]"), "{plain_header}");
    opts.select = SelectOptions {
        joint_step: true,
        walked_lm: true,
        look_alikes_at_end: true,
        ..SelectOptions::default()
    };
    let with = serde_json::to_string(&opts).expect("options serialise");
    assert!(with.contains("\"joint_step\":true"), "{with}");
    assert!(with.contains("\"walked_lm\":true"), "{with}");
    assert!(with.contains("\"look_alikes_at_end\":true"), "{with}");
    // The undeclared-parameter audit: in the signature only when on, as in its own points
    // file (reports/gap-benchmark-audit.points.csv). That file was run before the
    // within-noise subset and the stop at the resolution were default rules (tenth
    // session), so its signature is the audit's with the four rules of then.
    assert!(!standard.contains("audit_undeclared"), "{standard}");
    let mut audit_opts = BenchmarkOptions::standard("mugatu").expect("the bundled cases");
    audit_opts.audit_undeclared = true;
    audit_opts.select.within_noise_subset = false;
    audit_opts.select.stop_at_resolution = false;
    let audited = serde_json::to_string(&audit_opts).expect("options serialise");
    let audit_file = std::fs::read_to_string(repo().join("reports/gap-benchmark-audit.points.csv"))
        .expect("the audit's points file");
    let audit_header = audit_file.lines().next().unwrap_or_default();
    assert!(
        audited.ends_with("\"audit_undeclared\":true}")
            && audit_header.ends_with(&format!("{}]", tail(&audited))),
        "{audit_header}"
    );
    // The audit's declared partners are another rule: in the signature when > 0, as
    // `gap benchmark --audit-undeclared` sets them (the diagnosis' default).
    audit_opts.audit_partners = robot_survey::gap::audit::PARTNERS as u64;
    let partnered = serde_json::to_string(&audit_opts).expect("options serialise");
    assert!(
        partnered.ends_with("\"audit_undeclared\":true,\"audit_partners\":2}"),
        "{partnered}"
    );
    // The real binary, resuming a copy of the committed points file with the standard run's
    // options but one rule switched: refused at once (before the planning's minutes), naming
    // the file, and the file left as it was.
    let dir = tempfile::tempdir().expect("tempdir");
    let points = dir.path().join("gap-benchmark.points.csv");
    std::fs::write(&points, &committed).expect("copy");
    let points_arg = points.display().to_string();
    let out_arg = dir.path().join("out").display().to_string();
    for rule in [
        &["--plain-selection"][..],
        &["--no-look-ahead"],
        &["--exchange-rounds", "0"],
        &["--joint-step"],
        &["--walked-lm"],
        &["--no-deferred-recalibration"],
        &["--no-rivals-at-end"],
        &["--look-alikes-at-end"],
        &["--no-within-noise-subset"],
        &["--no-stop-at-resolution"],
        &["--audit-undeclared"],
    ] {
        let mut args = vec![
            "gap",
            "benchmark",
            "--design",
            "mugatu",
            "--quick",
            "--noise",
            "0.03,0.05",
            "--null-cases",
            "300",
            "--one-robot-nulls",
            "100",
            "--drake",
            "tests/golden/drake/gap",
            "--points",
            &points_arg,
            "--out",
            &out_arg,
        ];
        args.extend_from_slice(rule);
        let o = survey(&args);
        assert!(
            !o.status.success(),
            "{:?} resumed the standard run's file",
            rule
        );
        let err = stderr(&o);
        assert!(
            err.contains("different study") && err.contains("gap-benchmark.points.csv"),
            "{err}"
        );
        assert_eq!(
            std::fs::read_to_string(&points).expect("read back"),
            committed,
            "the refused file was changed"
        );
    }
}

/// The bundled Mugatu's undeclared numbers as the audit weighs them, hand-listed from
/// `dataset/walkers/mugatu.toml`: every number of its geometry, mass, contact, control,
/// hardstop and ground that is neither declared `[[uncertain]]` nor listed known in its
/// `[audit]` table (body length, feet, the stop's stiffness and damping) nor the 1× leg
/// length, over ×/÷ 2 around the file's value (log scale), and the three foot offsets the
/// file leaves at 0 over ± 0.03 L.
#[test]
fn the_audit_weighs_every_undeclared_number_of_the_design() {
    let d = Design::builtin("mugatu").expect("mugatu");
    let mut got: Vec<(String, f64, f64, f64, bool)> = d
        .undeclared_params()
        .expect("undeclared")
        .into_iter()
        .map(|u| (u.path, u.nominal, u.lo, u.hi, u.log))
        .collect();
    got.sort_by(|a, b| a.0.cmp(&b.0));
    let want = [
        ("contact.hydroelastic_modulus_pa", 3.0e6, 1.5e6, 6.0e6, true),
        ("contact.stiction_speed_mps", 0.001, 0.0005, 0.002, true),
        ("control.frequency_hz", 1.24, 0.62, 2.48, true),
        ("control.torque_limit_nm", 1.0, 0.5, 2.0, true),
        (
            "geometry.foot_center_forward_over_l",
            0.0,
            -0.03,
            0.03,
            false,
        ),
        (
            "geometry.foot_center_lateral_over_l",
            0.0,
            -0.03,
            0.03,
            false,
        ),
        ("geometry.foot_section_cut_over_l", 0.0, -0.03, 0.03, false),
        ("hardstop.limit_deg", 60.0, 30.0, 120.0, true),
        ("mass.leg_inertia_box_over_l[1]", 0.2, 0.1, 0.4, true),
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((path, nominal, lo, hi, log), w) in got.iter().zip(want) {
        assert_eq!(path, w.0);
        for (a, b) in [(*nominal, w.1), (*lo, w.2), (*hi, w.3)] {
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                "{path}: {a} vs {b}"
            );
        }
        assert_eq!(*log, w.4, "{path}");
    }
    // The [audit] table is not physics: a study's design hash ignores it.
    let bare = Design {
        audit: None,
        ..d.clone()
    };
    assert_eq!(
        robot_survey::study::table3::design_hash(&bare),
        robot_survey::study::table3::design_hash(&d)
    );
}

/// A bad `[audit]` table is an error naming the file and the field.
#[test]
fn audit_tables_are_checked_and_name_the_field() {
    let base = std::fs::read_to_string(repo().join("dataset/walkers/mugatu.toml")).expect("read");
    let body = &base[..base.find("[audit]").expect("mugatu has an [audit] table")];
    let cases = [
        (
            "[audit]\nfixed = [{ path = \"mass.no_such\", why = \"x\" }]\n",
            "audit.fixed[0].path",
            "names no number",
        ),
        (
            "[audit]\nfixed = [{ path = \"numerics.time_step_s\", why = \"x\" }]\n",
            "audit.fixed[0].path",
            "names no number",
        ),
        (
            "[audit]\nfixed = [{ path = \"hardstop\", why = \" \" }]\n",
            "audit.fixed[0].why",
            "say why",
        ),
        ("[audit]\nfactor = 1.0\n", "audit.factor", "> 1"),
        (
            "[audit]\noffset_over_l = -0.1\n",
            "audit.offset_over_l",
            "> 0",
        ),
    ];
    assert_rejected(body, &cases);
    // A section covers its numbers; the factor and offset set the ranges.
    let text = format!(
        "{body}\n[audit]\nfixed = [{{ path = \"hardstop\", why = \"x\" }}, {{ path = \"contact\", why = \"x\" }}]\nfactor = 1.5\noffset_over_l = 0.01\n"
    );
    let d = Design::from_toml_str(&text, "m.toml").expect("valid");
    let u = d.undeclared_params().expect("undeclared");
    assert!(
        !u.iter()
            .any(|p| p.path.starts_with("hardstop.") || p.path.starts_with("contact.")),
        "{u:?}"
    );
    let torque = u
        .iter()
        .find(|p| p.path == "control.torque_limit_nm")
        .expect("torque limit audited");
    assert!((torque.lo - 1.0 / 1.5).abs() < 1e-12 && (torque.hi - 1.5).abs() < 1e-12);
    let lateral = u
        .iter()
        .find(|p| p.path == "geometry.foot_center_lateral_over_l")
        .expect("lateral offset audited");
    assert_eq!((lateral.lo, lateral.hi), (-0.01, 0.01));
}

/// The audit on the benchmark's kind of case it was built for: an undeclared error (the
/// leg's lateral inertia-box edge +30 %) beside a small declared one (μ 3 % low), 12
/// conditions, 3 % noise (`tests/data/gap/roll-inertia-mu-3pct.csv`). The selection can
/// only name a declared look-alike, and does: the hip width, +3 % with an interval of
/// ±0.5 % that the truth (0.2, untouched) lies outside — a confident wrong name. With the
/// audit, the hip width exchanged for each undeclared number is walked: a lateral foot
/// offset fits as well (measured 2026-11-28: χ² +5.0 within the identification distance
/// 8.5), so the hip width is not named and the answer lists the undeclared look-alike.
/// Nothing may be named: the truth's parameter is undeclared, and μ's share is within
/// noise once the hip width stands in.
#[test]
fn the_audit_unnames_a_stand_in_for_an_undeclared_number() {
    let cache = bundled_walks();
    let effects = ["rolling_resistance", "hip_viscous_damping"];
    let select = SelectOptions::default();
    let run = |audit: bool| {
        diagnose_committed("roll-inertia-mu-3pct.csv", &effects, &select, audit, cache)
    };
    assert_hip_width_stands_in(&run(false), "without the audit");
    let d = run(true);
    assert_stand_in_unnamed(&d, "mugatu:geometry.hip_half_width_over_l", None);
    assert!(
        d.notes
            .iter()
            .any(|n| n.contains("Declare a number [[uncertain]]")),
        "{:?}",
        d.notes
    );
}

/// The hip width named alone, with an interval the file's 0.2 lies outside: the confident
/// wrong name of the roll-inertia + μ trials (`when`: the diagnosis that gives it).
fn assert_hip_width_stands_in(d: &Diagnosis, when: &str) {
    assert_eq!(
        names(d).0,
        vec!["mugatu:geometry.hip_half_width_over_l".to_string()],
        "{when} the hip width stands in: {}",
        d.answer.statement
    );
    let [lo, hi] = d.answer.parameters[0].interval;
    assert!(
        !(lo..=hi).contains(&0.2),
        "a confident wrong name: [{lo}, {hi}]"
    );
}

/// The audit's declared partner, on the benchmark's own draw of the compound case it fails
/// without it (`tests/data/gap/roll-inertia-mu-3pct-bench.csv`, command in its header): the
/// leg's lateral inertia-box edge +30 % (undeclared) and μ 3 % low (declared) at once. One
/// number at a time cannot reproduce the pair: the audit of the shipped default before the
/// partners (measured 2026-12-01: 4,740 walks, the benchmark's case) left the hip width
/// named, with an interval the file's 0.2 lies outside. An undeclared number that explains
/// part of the gap in the hip width's place is walked again beside the declared knobs the
/// surrogate ranks best: the inertia edge with μ fits within the identification distance
/// (measured: 0.2423 with 0.3382, the truths 0.26 and 0.3398), so the hip width is not
/// named and its group lists the pair. Each of the pair must also be significant beside the
/// other. The signs are the truth's: the edge above the file's 0.2, μ below its 0.35. (With
/// only two effects as candidates the contact modulus with the contact damping is among the
/// three partial exchanges closest to the answer instead of the inertia edge: the hip width
/// is still not named, but the truth's pair is not walked.)
#[test]
#[ignore = "heavy: 101 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn the_audits_declared_partner_unnames_a_stand_in_for_two_numbers() {
    // The benchmark's options: every effect of the library a candidate beside the calibration.
    let cache = bundled_walks();
    let run = |partners: usize| {
        let opts = DiagnoseOptions {
            explanations: false,
            identifiability: false,
            audit_partners: partners,
            ..DiagnoseOptions::default()
        };
        diagnose_committed_with("roll-inertia-mu-3pct-bench.csv", &opts, cache)
    };
    let hip_width = "mugatu:geometry.hip_half_width_over_l";
    assert_hip_width_stands_in(&run(0), "one number at a time");
    let d = run(robot_survey::gap::audit::PARTNERS);
    let pair = "mugatu:mass.leg_inertia_box_over_l[1] (undeclared) with mugatu:contact.friction_mu";
    assert_stand_in_unnamed(&d, hip_width, Some(pair));
    let note = d
        .notes
        .iter()
        .find(|n| n.starts_with(&format!("{hip_width} is not told apart")))
        .expect("the audit's note");
    // "… mugatu:mass.leg_inertia_box_over_l[1] at 0.2423 with mugatu:contact.friction_mu at
    // 0.3382 (χ² …)": the number after each label of the pair.
    let pair_at = &note[note
        .find("mugatu:mass.leg_inertia_box_over_l[1] at ")
        .expect("the pair in the note")..];
    let after = |label: &str| -> f64 {
        let rest = &pair_at[pair_at.find(label).expect("a label") + label.len()..];
        rest.split_whitespace()
            .next()
            .and_then(|x| x.parse().ok())
            .expect("a number")
    };
    let edge = after("inertia_box_over_l[1] at ");
    let mu = after("friction_mu at ");
    assert!(edge > 0.2 && edge <= 0.4, "the edge's sign: {note}");
    assert!((0.25..0.35).contains(&mu), "μ's sign: {note}");
}

/// The audit where its rule's premise fails: the true cause *is* declared (an unreported
/// 1.5° slope, the six conditions, 3 % noise, as `calibration_recovers_a_declared_parameter_error`).
/// The test design has no `[audit]` table, so every undeclared number of its file is weighed
/// (the feet, the body, the stop, the inertia box's other edges …); none of them in the
/// slope's place fits as well, so the slope stays named, its interval holding the truth.
#[test]
fn the_audit_keeps_a_declared_cause_named() {
    let d = case_with(
        &[("ground.slope_deg", 1.5)],
        &[],
        0.03,
        Some(5),
        &["hip_coulomb_friction", "rolling_resistance"],
        true,
        Rules {
            select: SelectOptions::default(),
            audit_undeclared: true,
        },
    );
    assert_eq!(
        names(&d),
        (vec![format!("{TEST_DESIGN}:ground.slope_deg")], Vec::new()),
        "{}",
        d.answer.statement
    );
    let [lo, hi] = d.answer.parameters[0].interval;
    assert!(lo <= 1.5 && 1.5 <= hi, "truth 1.5 outside [{lo}, {hi}]");
    assert!(
        d.notes
            .iter()
            .any(|n| n.starts_with("undeclared-parameter audit: none of")),
        "{:?}",
        d.notes
    );
}

/// The diagnosis' default on a truth held out from every rule (`tools/gap-heldout-check.sh`,
/// case stic05; `tests/data/gap/stiction-half-3pct.csv`): the friction's stiction speed
/// halved, a number Mugatu does not declare. Without the audit the full diagnosis names μ
/// +5 % with an interval of ±0.8 % that excludes the file's 0.35 (measured 2026-11-28: a
/// confident stand-in). The default audits the answer: μ is not named and its group holds
/// the undeclared truth.
#[test]
fn by_default_a_stand_in_for_an_undeclared_number_is_not_named() {
    let default = DiagnoseOptions::default();
    assert!(
        default.audit_undeclared,
        "the audit is the diagnosis' default"
    );
    assert_mu_stands_in_for_stiction(&default_diagnosis_of("stiction-half-3pct.csv"));
}

/// A held-out truth beyond the audit's default range (tools/gap-heldout-check.sh, case
/// stic03x, written down before it was diagnosed): the stiction speed / 3.3, at 5 % noise.
/// The audit weighed the number over ×/÷ 2 only; its fit in μ's place stopped at ÷ 2, so μ
/// stayed named, 0.380 [0.376, 0.386] against the file's 0.35 (measured 2026-11-29, the full
/// diagnosis). A number whose fit stops at an end is weighed again beyond it: μ is not named
/// and its group holds the undeclared stiction speed.
#[test]
fn the_audit_weighs_a_number_again_beyond_the_end_its_fit_stopped_at() {
    let d = default_diagnosis_of("stiction-third-5pct.csv");
    assert_mu_stands_in_for_stiction(&d);
    // Found at the truth, outside the default range [0.0005, 0.002].
    assert!(
        d.notes
            .iter()
            .any(|n| n.contains("stiction_speed_mps at 0.0003")),
        "{:?}",
        d.notes
    );
}

/// The default diagnosis (the audit on) of committed Mugatu trials, with the two effects
/// the held-out stiction tests weigh beside the calibration.
fn default_diagnosis_of(file: &str) -> Diagnosis {
    let default = DiagnoseOptions::default();
    diagnose_committed(
        file,
        &["rolling_resistance", "hip_viscous_damping"],
        &default.select,
        default.audit_undeclared,
        bundled_walks(),
    )
}

/// The held-out stiction truths' right answer: μ not named, grouped with the undeclared
/// stiction speed.
fn assert_mu_stands_in_for_stiction(d: &Diagnosis) {
    assert_stand_in_unnamed(
        d,
        "mugatu:contact.friction_mu",
        Some("mugatu:contact.stiction_speed_mps (undeclared)"),
    );
}

/// Nothing named, and a "not told apart" group holds the declared stand-in beside an
/// undeclared number (`undeclared`, or any).
fn assert_stand_in_unnamed(d: &Diagnosis, declared: &str, undeclared: Option<&str>) {
    let (params, named) = names(d);
    assert!(
        params.is_empty() && named.is_empty(),
        "{}",
        d.answer.statement
    );
    assert!(
        d.answer.ambiguous.iter().any(|g| {
            g.iter().any(|k| k == declared)
                && g.iter().any(|k| match undeclared {
                    Some(u) => k == u,
                    None => k.ends_with(" (undeclared)"),
                })
        }),
        "{}",
        d.answer.statement
    );
}

/// `gap diagnose --reference`, worked by hand: each metric carried onto the nominal model as
/// nominal + (trial − reference), its sd the two sds (a stated sd, or the default 10 % of the
/// value) and the change × the model's relative miss of the reference combined; a metric the reference lacks is left out with a note naming it; a
/// trial whose condition has no reference trial is refused by file and line (line 9 of the
/// conditions file: three comment lines and the header before it).
#[test]
fn a_reference_carries_each_metric_onto_the_nominal() {
    use robot_survey::gap::reference::carry;
    use robot_survey::gap::simulate::SimMetrics;
    use robot_survey::gap::trials::Measurement;
    let s = six();
    let m = |value: f64, sd: Option<f64>| Some(Measurement { value, sd });
    let mut set = s.base.clone();
    let mut reference = s.base.clone();
    let (v, roll) = (Metric::VelocityMps.index(), Metric::RollPpDeg.index());
    set.trials[0].measured[v] = m(0.2, Some(0.01));
    set.trials[0].measured[roll] = m(20.0, None);
    reference.trials[0].measured[v] = m(0.15, Some(0.02));
    reference.trials[0].measured[roll] = m(25.0, None);
    // The second trial's velocity has no reference: left out.
    set.trials[1].measured[v] = m(0.3, Some(0.01));
    let mut values = [f64::NAN; 8];
    values[v] = 0.18;
    values[roll] = 22.0;
    let nominal = vec![
        SimMetrics {
            values,
            fell: false
        };
        6
    ];
    let c = carry(
        &set,
        &s.conditions,
        &reference,
        &s.conditions,
        &nominal,
        0.10,
    )
    .expect("carried");
    let t0 = &c.set.trials[0];
    let cv = t0.measured[v].expect("velocity carried");
    assert!((cv.value - 0.23).abs() < 1e-12, "{cv:?}"); // 0.18 + (0.2 − 0.15)
    // √(0.01² + 0.02² + (0.05 · ρ)²), ρ = |0.15 − 0.18| / 0.15 = 0.2
    assert!((cv.sd.expect("sd") - 0.0006f64.sqrt()).abs() < 1e-12);
    let cr = t0.measured[roll].expect("roll carried");
    assert!((cr.value - 17.0).abs() < 1e-12, "{cr:?}"); // 22 + (20 − 25)
    // √(2² + 2.5² + (5 · ρ)²), ρ = |25 − 22| / 25 = 0.12
    assert!((cr.sd.expect("sd") - 10.61f64.sqrt()).abs() < 1e-12);
    assert!(c.set.trials[1].measured.iter().all(Option::is_none));
    assert!(
        c.notes
            .iter()
            .any(|n| n.contains("not carried") && n.contains("L1x-f1x velocity_mps")),
        "{:?}",
        c.notes
    );
    // A reference without the last condition.
    let mut short = reference.clone();
    short.trials.pop();
    let mut short_conditions = s.conditions.clone();
    short_conditions.pop();
    let e = carry(
        &set,
        &s.conditions,
        &short,
        &short_conditions,
        &nominal,
        0.10,
    )
    .expect_err("a trial without a reference");
    let text = e.to_string();
    assert!(
        text.contains("conditions-6.csv:9:")
            && text.contains("L2x-f1.03x")
            && text.contains("no reference trial"),
        "{text}"
    );
}

/// A change diagnosed through a reference where the model misses the robot everywhere: the
/// robot's foot–floor μ is 0.5, not the design's 0.35 — a number the test design does not
/// declare, and friction_coefficient is no candidate — so the model cannot be brought within
/// noise of it. Reference: the robot at 3 % noise; trials (other seeds): the robot with hip
/// Coulomb friction 0.02 N·m added, with a soft floor (5 MPa) instead, and unchanged.
/// Without the reference the Coulomb trials are far beyond noise (RMS z > 10). Through it:
/// the unchanged robot shows no gap; the Coulomb friction's change is explained and put in
/// one group with its look-alike, hip viscous damping, neither named (carried through a
/// wrong μ the two marks differ by less than the carrying's own error); the soft floor,
/// whose mark depends on the friction it acts with (the carrying's premise fails), gets no
/// name at all.
#[test]
#[ignore = "heavy: 190 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn a_reference_carries_a_change_where_the_model_misses_the_robot() {
    let s = six();
    let robot = [("contact.friction_mu", 0.5)];
    let candidates: Vec<String> = [
        "hip_viscous_damping",
        "hip_coulomb_friction",
        "rolling_resistance",
        "soft_ground",
    ]
    .iter()
    .map(|e| e.to_string())
    .collect();
    let reference = trials_of(&robot, &[], 0.03, Some(11));
    let diagnose = |set: &TrialSet, reference: Option<&TrialSet>| {
        let opts = DiagnoseOptions {
            effects: candidates.clone(),
            explanations: false,
            identifiability: false,
            reference: reference.cloned(),
            ..DiagnoseOptions::default()
        };
        diagnose_conditions(set, &s.conditions, &s.lib, &opts, s.cache, &Silent)
            .expect("diagnosis")
            .0
    };
    let coulomb = trials_of(&robot, &[("hip_coulomb_friction", 0.02)], 0.03, Some(12));
    let plain = diagnose(&coulomb, None);
    assert!(plain.gap_before > 10.0, "{}", plain.summary);
    let d = diagnose(&coulomb, Some(&reference));
    assert_eq!(
        d.answer.kind,
        AnswerKind::Ambiguous,
        "{}",
        d.answer.statement
    );
    assert_eq!(names(&d), (vec![], vec![]), "{}", d.answer.statement);
    let mut group = d.answer.ambiguous.concat();
    group.sort();
    assert_eq!(
        group,
        vec!["hip_coulomb_friction", "hip_viscous_damping"],
        "{}",
        d.answer.statement
    );
    let soft = trials_of(&robot, &[("soft_ground", 5e6)], 0.03, Some(12));
    let d = diagnose(&soft, Some(&reference));
    assert_eq!(names(&d), (vec![], vec![]), "{}", d.answer.statement);
    let unchanged = trials_of(&robot, &[], 0.03, Some(13));
    let null = diagnose(&unchanged, Some(&reference));
    assert_eq!(
        null.answer.kind,
        AnswerKind::WithinNoise,
        "{}",
        null.answer.statement
    );
}

/// The real binary: `gap diagnose --reference` with a reference of other conditions is
/// refused (exit 2) by the trials file and line, naming the reference, before any fit.
#[test]
fn a_reference_of_other_conditions_is_refused_by_line() {
    let out = survey(&[
        "gap",
        "diagnose",
        "--trials",
        "tests/golden/drake/gap-lagged/trials-hip_viscous_damping-0.02.csv",
        "--reference",
        "tests/data/gap/backlash-coulomb-3pct-seed0.csv",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.contains("trials-hip_viscous_damping-0.02.csv:2:")
            && e.contains("L0.5x-f1.5")
            && e.contains("no reference trial")
            && e.contains("backlash-coulomb-3pct-seed0.csv"),
        "{e}"
    );
}

/// Held-out Drake data where the carrying's premise fails: Drake-Lagged with a soft floor
/// (4 MPa, a magnitude no rule was developed on, `tests/golden/drake/gap-lagged-heldout/`),
/// diagnosed through Drake's own no-effect trials at 3 % sd, as they are (no noise drawn).
/// At 1.6 Hz and at four of the suggested conditions the project's walker on that floor
/// reverses where Drake's walks on, so Drake's change carried onto our model is no knob's
/// mark: the gap is real (the change is far beyond noise), and no effect may be named —
/// rolling resistance and viscous damping each take part of it and lead the search.
#[test]
#[ignore = "heavy: 386 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn a_drake_change_our_model_does_not_share_gets_no_name() {
    let lib = EffectLibrary::bundled().expect("library");
    let dir = repo().join("tests/golden/drake/gap-lagged-heldout");
    let set = TrialSet::read(&dir.join("trials-soft_ground-4e6.csv")).expect("golden");
    let reference = TrialSet::read(&dir.join("trials-none.csv")).expect("golden");
    let conditions = resolve(&set).expect("resolve");
    let opts = DiagnoseOptions {
        effects: [
            "soft_ground",
            "rolling_resistance",
            "hip_viscous_damping",
            "hip_coulomb_friction",
        ]
        .iter()
        .map(|e| e.to_string())
        .collect(),
        default_relative_sd: 0.03,
        explanations: false,
        identifiability: false,
        reference: Some(reference),
        ..DiagnoseOptions::default()
    };
    let (d, _) = diagnose_conditions(&set, &conditions, &lib, &opts, bundled_walks(), &Silent)
        .expect("diagnosis");
    assert!(d.gap_before > 3.0, "{}", d.summary);
    assert_ne!(
        d.answer.kind,
        AnswerKind::WithinNoise,
        "{}",
        d.answer.statement
    );
    assert_eq!(names(&d), (vec![], vec![]), "{}", d.answer.statement);
}

/// Hip backlash 10.52° + the motor's torque–speed line at ω₀ = 3.683 rad/s (the benchmark's
/// pair at 2× their thresholds), on its expected trials (`tests/data/gap/
/// backlash-motor-expected.csv`, command in its `source` column): at the truth the gap is 0.
/// Both act on the hip's motion near the motor's no-load speed, and together they have a
/// narrow diagonal valley (RMS z 0.04 at the truth, 3.9 at ω₀ −4 % and 3.7 at +9 %, walked
/// by hand with `gap synth --expected`) that the surrogate's sum of one-knob curves does
/// not hold (it predicted χ² 547 where the walks gave 1,022) and the compass's axis steps
/// cannot follow (χ² 617): the pair was "partly explained, nothing named" (measured
/// 2026-11-29). Nelder–Mead on the walks, started where the surrogate missed, finds the
/// valley: both named, within 10 %, and their intervals hold the truth.
#[test]
fn a_simplex_on_walks_finds_the_narrow_valley_of_two_interacting_effects() {
    let opts = DiagnoseOptions {
        effects: vec!["hip_backlash".into(), "motor_torque_speed".into()],
        calibrate: false,
        explanations: false,
        identifiability: false,
        audit_undeclared: false,
        ..DiagnoseOptions::default()
    };
    let d = diagnose_committed_with("backlash-motor-expected.csv", &opts, bundled_walks());
    assert_pair_named_inside_intervals(
        &d,
        [("hip_backlash", 10.521), ("motor_torque_speed", 3.6834)],
    );
}

/// The benchmark's noisy pair "hip backlash 10.52° + motor no-load speed 3.683 rad/s" (2×
/// their identification thresholds, 3 % noise, its own draw:
/// `tests/data/gap/backlash-motor-3pct-bench.csv`, command in its `source` column),
/// diagnosed as the benchmark does (every effect, the 12 uncertain parameters calibrated,
/// no audit). Forward selection takes actuation latency first, a look-alike of backlash;
/// the look-ahead then unnames it because a model one knob larger without it fits better,
/// but only takes names away: without the within-noise subset the answer is "partly
/// explained" with nothing named (measured 2026-11-29: latency, the COM's forward offset,
/// backlash and the slope in one group). With it, the models of the answer's size inside
/// that larger one are walked, backlash + the motor line fits within noise and forms a
/// chain every rule accepts, and both are named with their truths inside their intervals
/// (reports/gap-benchmark.md, fourteenth session).
#[test]
#[ignore = "heavy: 673 s in the suite on 2 threads; tools/heavy-tests.sh"]
fn the_within_noise_subset_names_the_true_pair_behind_a_look_alike_taken_first() {
    let cache = bundled_walks();
    let base = DiagnoseOptions {
        calibrate: true,
        explanations: false,
        identifiability: false,
        audit_undeclared: false,
        ..DiagnoseOptions::default()
    };
    let without = DiagnoseOptions {
        select: SelectOptions {
            within_noise_subset: false,
            ..SelectOptions::default()
        },
        ..base.clone()
    };
    let file = "backlash-motor-3pct-bench.csv";
    let d = diagnose_committed_with(file, &without, cache);
    assert!(
        names(&d).1.len() < 2,
        "both named without the rule: {}",
        d.answer.statement
    );
    let d = diagnose_committed_with(file, &base, cache);
    assert_pair_named_inside_intervals(
        &d,
        [("hip_backlash", 10.521), ("motor_torque_speed", 3.6834)],
    );
}

/// An unreported 1.5° slope with hip viscous damping 0.0068 N·m·s/rad, on the expected trials
/// of a test design whose uncertain parameters are the slope and the leg's fore–aft COM
/// offset (`tests/data/gap/viscous-slope-expected.csv`, command in its `source` column). The
/// COM offset alone explains more of the gap than either cause alone, so greedy forward
/// selection takes it first and stops beyond noise; the look-ahead unnames it because slope +
/// damping fits better (χ² 2.2 against 296 for the COM offset, measured 2026-12-03), but only
/// takes names away: "partly explained, nothing named". With the within-noise rules the larger
/// model itself, which fits within noise and whose knobs form a chain every rule accepts,
/// replaces the answer and is weighed against the models of its size: both causes named,
/// their truths inside their intervals, the stand-in not named.
#[test]
fn a_pair_within_noise_replaces_a_stand_in_a_greedy_first_step_took() {
    let cache = bundled_walks();
    let effects = ["hip_viscous_damping", "hip_coulomb_friction"];
    let without = SelectOptions {
        within_noise_subset: false,
        ..SelectOptions::default()
    };
    let file = "viscous-slope-expected.csv";
    let d = diagnose_committed(file, &effects, &without, false, cache);
    assert_eq!(
        d.answer.kind,
        AnswerKind::PartlyExplained,
        "{}",
        d.answer.statement
    );
    assert!(
        d.answer.effects.is_empty() && d.answer.parameters.is_empty(),
        "named without the rule: {}",
        d.answer.statement
    );
    let d = diagnose_committed(file, &effects, &SelectOptions::default(), false, cache);
    assert_eq!(d.answer.kind, AnswerKind::Both, "{}", d.answer.statement);
    assert_names(
        &d,
        &["mugatu-slope-com:ground.slope_deg"],
        &["hip_viscous_damping"],
    );
    assert_interval_holds(&d.answer.parameters[0], 1.5);
    assert_interval_holds(&d.answer.effects[0], 0.0068);
}

/// The same trials where the rule's premise fails: the true effect is not offered (hip
/// Coulomb friction and backlash only). Slope + Coulomb friction, damping's look-alike, fits
/// within noise (χ² 17.3 on 42 values, measured 2026-12-03), and the rule names it. This is
/// what forward selection does whenever only a look-alike is offered (damping alone with
/// Coulomb friction offered: Coulomb named, checked below), so the rule adds no new kind of
/// wrong name; `gap diagnose` offers the whole library by default, where the look-alike
/// search in the final model weighs damping against Coulomb friction. The test pins the
/// limit so that a change to it is seen.
#[test]
fn a_look_alike_is_named_when_the_truth_is_not_offered() {
    let cache = bundled_walks();
    let effects = ["hip_coulomb_friction", "hip_backlash"];
    let select = SelectOptions::default();
    let diagnose = |file: &str| diagnose_committed(file, &effects, &select, false, cache);
    let d = diagnose("viscous-slope-expected.csv");
    assert_names(
        &d,
        &["mugatu-slope-com:ground.slope_deg"],
        &["hip_coulomb_friction"],
    );
    let d = diagnose("viscous-expected.csv");
    assert_names(&d, &[], &["hip_coulomb_friction"]);
}

/// The benchmark's compound cases "unreported 1.5° slope + hip Coulomb friction 0.0199 N·m"
/// and "+ hip viscous damping 0.00676 N·m·s/rad" (2× thresholds, 3 % noise, their own draws:
/// `tests/data/gap/coulomb-slope-3pct-bench.csv`, `viscous-slope-3pct-bench.csv`), diagnosed
/// as the benchmark does (every effect, the 12 uncertain parameters calibrated, no audit).
/// Forward selection takes the leg's fore–aft COM offset first (−57 %, each cause alone
/// 8–16 %) and stops beyond noise: both were "partly explained, nothing named" (measured
/// 2026-12-03). Coulomb: the look-ahead finds slope + Coulomb (the slope is significant
/// alone), which no chain accepts (the slope alone is not one value for all conditions,
/// Coulomb alone not significant) but the joint step's rules do. Damping: neither cause is
/// significant alone, the look-ahead never sees the pair, and the joint search from the
/// nominal finds it. Both named each time, truths inside their intervals.
#[test]
#[ignore = "heavy: about 300 s on 2 threads; tools/heavy-tests.sh"]
fn a_slope_and_a_hip_loss_are_both_named_where_a_stand_in_explains_more_alone() {
    let cache = bundled_walks();
    let select = SelectOptions::default();
    for (file, effect, truth) in [
        (
            "coulomb-slope-3pct-bench.csv",
            "hip_coulomb_friction",
            0.019_881_386_413_663_705,
        ),
        (
            "viscous-slope-3pct-bench.csv",
            "hip_viscous_damping",
            0.006_763_572_191_301_286,
        ),
    ] {
        // No effects listed: the whole library, as the benchmark diagnoses.
        let d = diagnose_committed(file, &[], &select, false, cache);
        assert_eq!(
            d.answer.kind,
            AnswerKind::Both,
            "{file}: {}",
            d.answer.statement
        );
        assert_names(&d, &["mugatu:ground.slope_deg"], &[effect]);
        assert_interval_holds(&d.answer.parameters[0], 1.5);
        assert_interval_holds(&d.answer.effects[0], truth);
    }
}

/// Where the start sets the direction, the sign of a fore–aft mirror-odd parameter is not
/// identified, and the diagnosis says so (`sign_identified`): the rule behind the speed
/// comparison of `criteria.walking_direction = "either"` tested where its assumptions fail —
/// the model off its symmetry (a calibrated slope) and the walker's other start. Physics,
/// not this code, gives the truths on mugatu-ref-sap at 1×:
/// - the mirror: the walker on +1.5° started half a drive period later (amplitude −25°)
///   walks the mirror image of the walker on −1.5° from the file's start — every metric
///   the same, the velocity negated (exactly: the model's equations are mirror-symmetric);
/// - the two starts on a slope walk different gaits (measured: |v| 0.034 vs 0.075 m/s on
///   1.5°), so a fitted slope's sign only says which start matched: not a finding;
/// - a condition's own slope sets the direction (the "either" rule keeps the sign there):
///   both starts walk uphill on ±0.5° and ±1.5° (measured 2026-12-02; if a change to the
///   model breaks this, the rule must be revisited, not the test).
#[test]
fn the_sign_of_a_mirror_odd_parameter_is_not_identified_where_the_start_sets_the_direction() {
    use robot_survey::gap::diagnose::sign_identified;
    use robot_survey::gap::knob::Knobs;
    let lib = EffectLibrary::bundled().expect("library");
    let csv = "label,design,leg_length_m,slope_deg,source\n\
               flat,mugatu-ref-sap,0.153,,t\n\
               up-0.5,mugatu-ref-sap,0.153,-0.5,t\n\
               down-0.5,mugatu-ref-sap,0.153,0.5,t\n\
               up-1.5,mugatu-ref-sap,0.153,-1.5,t\n\
               down-1.5,mugatu-ref-sap,0.153,1.5,t\n";
    let set = TrialSet::parse(csv, "slopes.csv", &repo()).expect("trials");
    let conditions = resolve(&set).expect("resolve");
    let with = |params: &[(&str, f64)]| {
        let mut s = ModelSetting::nominal();
        for (p, v) in params {
            s.params
                .push(("mugatu-ref-sap".to_string(), p.to_string(), *v));
        }
        s
    };
    let walk = |c: &Condition, params: &[(&str, f64)]| -> [f64; 8] {
        let m = c.simulate(&lib, &with(params)).expect("walk");
        assert!(!m.fell, "{params:?} fell");
        m.values
    };
    let late = ("control.amplitude_deg", -25.0);
    // The mirror, at the flat condition with the slope as the design's (a calibrated knob).
    let flat = &conditions[0];
    let a_minus = walk(flat, &[("ground.slope_deg", -1.5)]);
    let b_plus = walk(flat, &[("ground.slope_deg", 1.5), late]);
    let a_plus = walk(flat, &[("ground.slope_deg", 1.5)]);
    for m in Metric::SIMULATED {
        let (x, y) = (a_minus[m.index()], b_plus[m.index()]);
        assert!(
            (x - y).abs() <= 1e-6 * x.abs().max(1e-9),
            "{m:?}: {x} vs the mirror's {y}"
        );
    }
    let v = Metric::VelocityMps.index();
    let (slow, fast) = (a_plus[v].min(a_minus[v]), a_plus[v].max(a_minus[v]));
    assert!(
        fast > 1.5 * slow,
        "the two starts on 1.5° walk alike: {} vs {}",
        a_plus[v],
        a_minus[v]
    );
    // A condition's slope sets the direction: both starts walk uphill (sign of v = −sign of
    // the downhill-along-+x slope).
    for c in &conditions[1..] {
        let slope = c.slope_deg.expect("sloped");
        for start in [&[][..], &[late][..]] {
            let v = walk(c, start)[Metric::VelocityMps.index()];
            assert!(v * slope < 0.0, "{v} m/s on {slope}° with {start:?}");
        }
    }
    // The diagnosis's reading of it.
    let design = &conditions[0].design;
    let knobs = Knobs::build(&[design], &[], true).expect("knobs");
    let slope = &knobs.list[knobs
        .index_of("mugatu-ref-sap:ground.slope_deg")
        .expect("slope uncertain")];
    let width = &knobs.list[knobs
        .index_of("mugatu-ref-sap:geometry.hip_half_width_over_l")
        .expect("width uncertain")];
    // The design's slope acts only where a condition sets none: there the start rules.
    assert!(!sign_identified(slope, &conditions));
    assert!(!sign_identified(slope, &conditions[..1]));
    assert!(sign_identified(width, &conditions[..1]), "not mirror-odd");
    // A mirror-odd parameter acting on a sloped condition has its sign given there.
    let u = robot_survey::sim::design::UncertainParam {
        path: "mass.leg_com_forward_over_l".into(),
        nominal: 0.0,
        lo: -0.05,
        hi: 0.05,
        prior_sd: None,
        log: false,
        why: "test".into(),
    };
    let com = robot_survey::gap::knob::Knob::parameter("mugatu-ref-sap", &u);
    assert!(!sign_identified(&com, &conditions[..1]));
    assert!(sign_identified(&com, &conditions));
    // A design that walks forward predicts its direction: every sign is identified.
    let forward = six();
    let knobs = Knobs::build(&[&forward.conditions[0].design], &[], true).expect("knobs");
    let k = &knobs.list[knobs
        .index_of(&format!("{TEST_DESIGN}:ground.slope_deg"))
        .expect("slope uncertain")];
    assert!(sign_identified(k, &forward.conditions));
}

/// One walk cache over two lists of the same conditions in other orders (the six reversed,
/// then every second one): each condition gets its own walk, the one `Condition::simulate`
/// walks directly, and the second and third lists walk nothing new. (A cache keyed by a
/// condition's place in its list would hand the reversed list its mirror's walks.)
#[test]
fn a_shared_walk_cache_keys_a_condition_by_what_it_is_not_where_it_stands() {
    let s = six();
    let cache = SimCache::default();
    let nominal = ModelSetting::nominal();
    let values = |m: &robot_survey::gap::simulate::SimMetrics| m.values.map(f64::to_bits);
    let first = cache
        .get(&s.conditions, &s.lib, &nominal, &Silent)
        .expect("walks");
    let walked = cache.walks();
    let reversed: Vec<Condition> = s.conditions.iter().rev().cloned().collect();
    let again = cache
        .get(&reversed, &s.lib, &nominal, &Silent)
        .expect("walks");
    let every_second = cache
        .get_at(&reversed, &[1, 3, 5], &s.lib, &nominal, &Silent)
        .expect("walks");
    assert_eq!(cache.walks(), walked, "the reordered lists walked again");
    for (i, c) in s.conditions.iter().enumerate() {
        let direct = c.simulate(&s.lib, &nominal).expect("walk");
        assert_eq!(values(&first[i]), values(&direct), "condition {i}");
        assert_eq!(
            values(&again[5 - i]),
            values(&direct),
            "reversed, condition {i}"
        );
    }
    for (k, at) in [1, 3, 5].iter().enumerate() {
        assert_eq!(values(&every_second[k]), values(&again[*at]), "get_at {at}");
    }
}

/// Nested models never fit worse than the models they nest: the recalibration of every
/// uncertain parameter holds each parameter alone (the others at their nominal), and the
/// effect with the recalibration holds the effect alone. Zippy with hip viscous damping
/// (`tests/data/gap/zippy-damping-5pct-8.csv`, 8 conditions, 5 %): its parameters
/// interact and its gait is rugged, so the surrogate's joint optimum walked far worse than
/// one parameter alone — the recalibration's χ² was 372 where μ alone walked 259, and the
/// effect with the recalibration 289 where the effect alone walked 56. The competing
/// explanations then showed "parameters off" weaker than it is, and the effects' test
/// against the recalibration was made against a weak baseline.
#[test]
fn a_recalibration_fits_no_worse_than_one_parameter_or_the_effect_alone() {
    let lib = EffectLibrary::bundled().expect("library");
    let set =
        TrialSet::read(&repo().join("tests/data/gap/zippy-damping-5pct-8.csv")).expect("trials");
    let conditions = resolve(&set).expect("resolve");
    let opts = DiagnoseOptions {
        effects: vec!["hip_viscous_damping".into(), "hip_coulomb_friction".into()],
        default_relative_sd: 0.05,
        audit_undeclared: false,
        identifiability: false,
        ..DiagnoseOptions::default()
    };
    let d = diagnose_conditions(&set, &conditions, &lib, &opts, bundled_walks(), &Silent)
        .expect("diagnosis")
        .0;
    let chi2 = |model: &str| {
        d.explanations
            .iter()
            .find(|e| e.model.starts_with(model))
            .unwrap_or_else(|| panic!("no {model} row: {:?}", d.explanations))
            .chi2
    };
    let slack = |x: f64| x + 1e-9 * (1.0 + x.abs());
    // The parameters the first step confirmed with walks, each alone from the nominal:
    // its walked χ² is the nominal's less its LR.
    let first = d.chain.first().expect("a step");
    let walked: Vec<(String, f64)> = first
        .candidates
        .iter()
        .filter(|c| c.kind == robot_survey::gap::knob::KnobKind::Parameter)
        .filter(|c| !c.verdict.starts_with("next step"))
        .filter(|c| c.verdict.contains("once walked") || c.verdict.starts_with("chosen"))
        .map(|c| (c.knob.clone(), chi2("nominal") - c.lr))
        .collect();
    assert!(
        walked
            .iter()
            .any(|(k, _)| k.contains("contact.friction_mu")),
        "{:?}",
        first.candidates
    );
    let recal = chi2("parameters off");
    for (k, c) in &walked {
        assert!(
            recal <= slack(*c),
            "recalibration χ² {recal} > {k} alone {c}"
        );
    }
    let alone = chi2("effect alone");
    let with = chi2("effect with the parameters recalibrated");
    assert!(
        with <= slack(alone),
        "effect with the recalibration χ² {with} > alone {alone}"
    );
    assert_eq!(
        d.answer.kind,
        AnswerKind::EffectMissing,
        "{}",
        d.answer.statement
    );
}
