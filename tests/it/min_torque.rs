//! The minimum-torque search (`survey sim min-torque`, src/study/min_torque.rs): checked by
//! its definition (re-running the walks at the bracket's ends) and by dimensional analysis
//! (under similar scaling τ_min/(m·g·L) cannot depend on size).

use robot_survey::sim::{Design, MassLaw, WalkOptions, simulate_walk};
use robot_survey::study::{MinTorqueOptions, min_torque};

use crate::common::{stderr, stdout, survey};

fn opts(leg_length_m: Option<f64>, seeds: u64) -> MinTorqueOptions {
    MinTorqueOptions {
        walk: WalkOptions {
            leg_length_m,
            mass_law: MassLaw::L2,
            duration_s: 15.0,
            record_trajectory: false,
            ..WalkOptions::default()
        },
        seeds,
        rel_tol: 0.02,
        ..MinTorqueOptions::default()
    }
}

/// By definition the design walks at the reported minimum and not at the bracket's lower
/// end, within the 2 % tolerance; re-run here, independently of the search.
#[test]
fn mugatu_walks_at_its_minimum_torque_and_not_just_below() {
    let design = Design::builtin("mugatu").expect("mugatu");
    let o = opts(None, 0);
    let r = min_torque(&design, &o).expect("search runs");
    assert!(r.walks, "{r:?}");
    let t = r.min_torque_nm.expect("a minimum");
    let [lo, hi] = r.bracket_nm.expect("a bracket");
    assert_eq!(t, hi);
    assert!((hi - lo) / hi <= 0.02 && lo < hi);
    let walks = |tau: f64| {
        let w = WalkOptions {
            torque_limit_nm: Some(tau),
            ..o.walk.clone()
        };
        simulate_walk(&design, &w).expect("walk").report.walks
    };
    assert!(walks(hi));
    assert!(!walks(lo));
    assert!(
        r.walks_evaluated >= 3 && r.walks_evaluated <= 20,
        "{}",
        r.walks_evaluated
    );
    assert!((r.min_torque_over_mgl.expect("over mgl") - t / r.mgl_nm).abs() < 1e-12);
}

/// Dynamic similarity (every length ∝ L, m ∝ L², E ∝ m/L², times ∝ √L, torques ∝ m·g·L):
/// the equations of motion in units of L, √(L/g) and m·g·L are the same at every size, so
/// τ_min/(m·g·L) is too; the search runs in the same units (its start is the design's torque
/// scaled ∝ m·g·L). Tolerance: the bisection's 2 % on each side.
#[test]
fn minimum_torque_scales_as_m_g_l_under_similarity() {
    let design = Design::builtin("mugatu").expect("mugatu");
    let small = min_torque(&design, &opts(Some(0.153), 0)).expect("1x");
    let large = min_torque(&design, &opts(Some(0.5), 0)).expect("0.5 m");
    let (a, b) = (
        small.min_torque_over_mgl.expect("1x walks"),
        large.min_torque_over_mgl.expect("0.5 m walks"),
    );
    assert!((a - b).abs() <= 0.04 * a, "{a} vs {b} (τ_min/mgL)");
    // In newton-metres the minimum grows as m·L ∝ L³ for m ∝ L².
    let ratio = large.min_torque_nm.expect("t") / small.min_torque_nm.expect("t");
    let expected = (0.5f64 / 0.153).powi(3);
    assert!(
        (ratio / expected - 1.0).abs() <= 0.04,
        "{ratio} vs {expected}"
    );
}

/// A design that walks at no torque up to the cap reports it as such (no number):
/// mugatu-ref scuffs in place at 1.4 Hz with physical friction (reports/drake-crosscheck.md).
#[test]
fn a_design_that_does_not_walk_gets_no_minimum() {
    let design = Design::builtin("mugatu-ref").expect("mugatu-ref");
    let r = min_torque(&design, &opts(None, 0)).expect("search runs");
    assert!(!r.walks);
    assert!(r.min_torque_nm.is_none() && r.bracket_nm.is_none());
    assert!(r.failure_below.is_some());
}

#[test]
fn cli_min_torque_json_has_the_documented_keys() {
    let o = survey(&[
        "sim",
        "min-torque",
        "--design",
        "mugatu",
        "--seeds",
        "0",
        "--duration",
        "15",
        "--tolerance",
        "0.05",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    for k in [
        "min_torque_nm",
        "min_torque_over_mgl",
        "walks",
        "bracket_nm",
        "walks_evaluated",
    ] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    assert_eq!(v["walks"], true);
    let bad = survey(&["sim", "min-torque", "--tolerance", "0.9"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("rel_tol"), "{}", stderr(&bad));
}
