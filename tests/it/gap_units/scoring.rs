//! Unit tests of `gap::scoring`.

use robot_survey::gap::benchmark::CaseRow;
use robot_survey::gap::scoring::{calibration, in_choice_half, interval_holds};

/// A magnitude's interval holds a truth of either sign; a signed one only its own.
#[test]
fn a_magnitude_interval_holds_a_truth_of_either_sign() {
    assert_eq!(interval_holds("1.4..1.6", 1.5), Some(true));
    assert_eq!(interval_holds("1.4..1.6", -1.5), Some(false));
    assert_eq!(interval_holds("±1.4..1.6", -1.5), Some(true));
    assert_eq!(interval_holds("±1.4..1.6", 1.7), Some(false));
    assert_eq!(interval_holds("x..1", 0.5), None);
}

/// A case of one truth "a", stated with the top probability 0.9 on "a" (right) or on "b".
fn row(right: bool) -> CaseRow {
    CaseRow {
        key: String::new(),
        suite: "main".into(),
        kind: "effect".into(),
        noise: 0.03,
        seed: 0,
        calibrate: true,
        multiple: None,
        truth_effects: String::new(),
        truth_params: String::new(),
        truth_declared: false,
        truth: "a".into(),
        answer: String::new(),
        leading: if right {
            "a=0.9;b=0.1".into()
        } else {
            "b=0.9;a=0.1".into()
        },
        truth_probability: if right { 0.9 } else { 0.1 },
        sum_p2: 0.82,
        fit_p: 0.5,
        intervals: String::new(),
        gap_before: 1.0,
        walks: 0,
        logged_trials: 0,
        exhaustive_top: String::new(),
        exhaustive_probability: None,
    }
}

/// Ten cases stated at 0.9 of which nine are right are calibrated (ECE 0); stated at 0.9
/// with five right, ECE 0.4. Brier of a case with p_truth = 0.9 and Σp² = 0.82 is 0.02.
#[test]
fn calibration_by_hand() {
    let rows: Vec<CaseRow> = (0..10).map(|i| row(i < 9)).collect();
    let refs: Vec<&CaseRow> = rows.iter().collect();
    let c = calibration(&refs);
    assert!(c.ece.abs() < 1e-12 && c.bins[9].n == 10, "{c:?}");
    let rows: Vec<CaseRow> = (0..10).map(|i| row(i < 5)).collect();
    let refs: Vec<&CaseRow> = rows.iter().collect();
    assert!((calibration(&refs).ece - 0.4).abs() < 1e-12);
    let one = [row(true)];
    assert!((calibration(&one.iter().collect::<Vec<_>>()).brier - 0.02).abs() < 1e-12);
}

/// The half the decision is chosen on is a fair coin per key: of 600 null keys (the
/// benchmark's main nulls) between 45 % and 55 % fall in each half, and keys one seed apart
/// (s2j, s2j+1) land in different halves about half the time. FNV's low bit, the XOR of the
/// bytes' low bits, puts every such neighbour pair in different halves (a shard taking every
/// n-th key then takes a lopsided half).
#[test]
fn the_choice_half_is_a_fair_coin_per_key() {
    let case = |n: &str, s: u64| CaseRow {
        key: format!("main/null///n{n}/s{s}"),
        ..row(true)
    };
    let rows: Vec<CaseRow> = (0..300)
        .flat_map(|s| [case("0.03", s), case("0.05", s)])
        .collect();
    let k = rows.iter().filter(|r| in_choice_half(r)).count() as f64 / rows.len() as f64;
    assert!((0.45..=0.55).contains(&k), "{k}");
    let apart = (0..150)
        .filter(|j| {
            in_choice_half(&case("0.05", 2 * j)) != in_choice_half(&case("0.05", 2 * j + 1))
        })
        .count() as f64
        / 150.0;
    assert!((0.35..=0.65).contains(&apart), "neighbours apart {apart}");
}
