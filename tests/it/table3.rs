//! Table III (`survey sim table3`, src/study/table3.rs) and its sweep machinery
//! (src/study/sweep.rs): similar-contact exponents from dimensional analysis, shards merged
//! = one run, an interrupted run resumed = one run, and refusals of mixed files.

use std::path::PathBuf;
use std::sync::OnceLock;

use robot_survey::sim::{ContactScaling, Design, MassLaw};
use robot_survey::study::sweep::{self, Shard};
use robot_survey::study::table3::{Table3Point, table3_leg_lengths};
use robot_survey::study::{Table3Spec, run_table3};

use crate::common::{stderr, survey};

/// Mugatu at three sizes, both mass laws, similar contact; 12 s at 1× (15 drive cycles),
/// one perturbed start: small enough for a test, long enough to converge.
fn spec() -> Table3Spec {
    let mut s = Table3Spec::paper(
        vec![Design::builtin("mugatu").expect("mugatu")],
        vec![ContactScaling::Similar],
    );
    s.leg_lengths_m = vec![0.05, 0.15, 0.6];
    s.duration_at_design_size_s = 12.0;
    s.seeds = 1;
    s
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robot-survey-table3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

/// One whole run with a points file (shared by the tests below).
fn whole() -> &'static (PathBuf, Vec<u8>, robot_survey::study::Table3) {
    static WHOLE: OnceLock<(PathBuf, Vec<u8>, robot_survey::study::Table3)> = OnceLock::new();
    WHOLE.get_or_init(|| {
        let path = tmp("whole.csv");
        let run = run_table3(&spec(), Shard::WHOLE, Some(&path), &()).expect("table3 runs");
        let bytes = std::fs::read(&path).expect("points file");
        (path, bytes, run.table.expect("a whole run makes the table"))
    })
}

/// Under similar contact every quantity scales by dynamic similarity, so the gait is the
/// same dimensionless simulation at every size: v ∝ √(gL) exactly and τ_min ∝ m·g·L, i.e.
/// L³ for m ∝ L² and L⁴ for m ∝ L³ (a check of the scaling rules, not a finding). The
/// fitted exponents must contain these values in their 95 % intervals (to 1e-6, since the
/// residuals are round-off).
#[test]
fn similar_contact_exponents_are_those_of_dynamic_similarity() {
    let (_, _, t) = whole();
    assert_eq!(t.rows.len(), 2);
    for r in &t.rows {
        assert_eq!(
            r.sizes_walking, 3,
            "{} {:?}: {:?}",
            r.design, r.mass_law, r.points
        );
        let expect_tau = match r.mass_law {
            MassLaw::L2 => 3.0,
            MassLaw::L3 => 4.0,
        };
        let within = |b: Option<f64>, ci: Option<[f64; 2]>, target: f64| {
            let (b, [lo, hi]) = (b.expect("fit"), ci.expect("ci"));
            assert!(
                (b - target).abs() < 1e-3 && lo - 1e-6 <= target && target <= hi + 1e-6,
                "{} {:?}: {b} [{lo}, {hi}] vs {target}",
                r.design,
                r.mass_law
            );
        };
        within(r.velocity_exponent, r.velocity_exponent_ci, 0.5);
        within(r.torque_exponent, r.torque_exponent_ci, expect_tau);
        within(
            r.torque_vs_mass_length_exponent,
            r.torque_vs_mass_length_exponent_ci,
            1.0,
        );
        // Same dimensionless gait: the attitudes do not change with size.
        assert!(r.roll_pp_deg_sd.expect("sd") < 0.05, "{r:?}");
        // Warm starts: after the first size a point costs a few walks.
        assert!(r.walks_evaluated <= 40, "{}", r.walks_evaluated);
    }
}

#[test]
fn shards_merged_equal_one_run() {
    let (_, whole_bytes, _) = whole();
    let s = spec();
    let a = tmp("shard-1.csv");
    let b = tmp("shard-2.csv");
    for (i, p) in [(1, &a), (2, &b)] {
        let run = run_table3(&s, Shard { index: i, count: 2 }, Some(p), &()).expect("shard");
        assert!(run.table.is_none(), "a shard alone makes no table");
        assert_eq!(run.points.len(), 3, "one chain of three sizes per shard");
    }
    let merged = tmp("merged.csv");
    let (a_s, b_s, m_s) = (
        a.display().to_string(),
        b.display().to_string(),
        merged.display().to_string(),
    );
    let out = survey(&["sim", "merge", &a_s, &b_s, "--out", &m_s]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        &std::fs::read(&merged).expect("merged"),
        whole_bytes,
        "merged shards differ from one run"
    );
}

#[test]
fn interrupted_run_resumed_equals_one_run() {
    let (_, whole_bytes, whole_table) = whole();
    let text = String::from_utf8(whole_bytes.clone()).expect("utf8");
    // Keep the spec line, the column names, two points, and half of the third point: what
    // a kill during a write leaves.
    let lines: Vec<&str> = text.lines().collect();
    let mut cut = lines[..4].join("\n");
    cut.push('\n');
    cut.push_str(&lines[4][..lines[4].len() / 2]);
    let path = tmp("resumed.csv");
    std::fs::write(&path, cut).expect("write");
    let run = run_table3(&spec(), Shard::WHOLE, Some(&path), &()).expect("resume");
    assert_eq!(run.simulated, 4, "two points were done, four remain");
    let table = run.table.expect("table");
    assert_eq!(
        serde_json::to_string(&table).expect("json"),
        serde_json::to_string(whole_table).expect("json"),
        "resumed table differs from one run"
    );
}

#[test]
fn points_file_of_another_study_is_refused_naming_it() {
    let (path, _, _) = whole();
    let mut other = spec();
    other.seeds = 2;
    let copy = tmp("other.csv");
    std::fs::copy(path, &copy).expect("copy");
    let err = match run_table3(&other, Shard::WHOLE, Some(&copy), &()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a points file of another specification was accepted"),
    };
    assert!(
        err.contains(&copy.display().to_string()) && err.contains("different study"),
        "{err}"
    );
}

#[test]
fn merge_refuses_disagreeing_points() {
    let (path, bytes, _) = whole();
    let text = String::from_utf8(bytes.clone()).expect("utf8");
    // Same specification, one velocity changed.
    let lines: Vec<&str> = text.lines().collect();
    let mut fields: Vec<String> = lines[2].split(',').map(str::to_string).collect();
    fields[17] = "9.99".into();
    let mut forged: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    forged[2] = fields.join(",");
    let bad = tmp("forged.csv");
    std::fs::write(&bad, forged.join("\n") + "\n").expect("write");
    let err = sweep::merge::<Table3Point>(&[path.clone(), bad.clone()])
        .map(|_| ())
        .expect_err("disagreeing points merged");
    assert!(err.to_string().contains("differs"), "{err}");
}

#[test]
fn shard_syntax_is_checked() {
    assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
    for bad in ["0/4", "5/4", "2", "a/b", "1/0"] {
        assert!(bad.parse::<Shard>().is_err(), "{bad}");
    }
    let out = survey(&["sim", "table3", "--shard", "2/2", "--sizes", "4"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--points"), "{}", stderr(&out));
}

/// The paper's protocol: 36 log-spaced sizes over 0.02–1.2 m with its three anchor sizes.
#[test]
fn paper_sizes_are_log_spaced_and_include_the_anchors() {
    let ls = table3_leg_lengths(36);
    assert_eq!(ls.len(), 36);
    assert_eq!(ls[0], 0.02);
    assert_eq!(*ls.last().expect("last"), 1.2);
    for anchor in [0.025, 0.15, 1.0] {
        assert!(ls.contains(&anchor), "{anchor} missing from {ls:?}");
    }
    let step = (60f64).ln() / 35.0;
    for w in ls.windows(2) {
        let r = (w[1] / w[0]).ln();
        assert!(w[1] > w[0] && (r - step).abs() < 0.5 * step, "{ls:?}");
    }
}

/// The committed study (reports/table3.points.csv, read by `survey predict` and
/// `survey torque-check`): all 3 designs × 2 mass laws × 2 contact rules at 36 sizes; under
/// similar contact the exponents of dynamic similarity (0.5; 3 for m ∝ L², 4 for m ∝ L³; 1
/// against m·L) lie within 0.01 of the fits; under fixed material every row says which
/// sizes walk.
#[test]
fn bundled_table3_covers_every_chain_and_obeys_similarity() {
    let points = robot_survey::study::table3::bundled_points().expect("bundled points");
    let rows = robot_survey::study::table3::rows_from_points(&points);
    assert_eq!(rows.len(), 12);
    for r in &rows {
        assert_eq!(
            r.sizes_total, 36,
            "{} {:?} {:?}",
            r.design, r.mass_law, r.contact
        );
        assert_eq!(r.sizes_walking + r.sizes_not_walking_m.len(), 36);
        if r.contact == ContactScaling::Similar {
            assert_eq!(r.sizes_walking, 36);
            let tau = if r.mass_law == MassLaw::L2 { 3.0 } else { 4.0 };
            for (got, want) in [
                (r.velocity_exponent, 0.5),
                (r.torque_exponent, tau),
                (r.torque_vs_mass_length_exponent, 1.0),
            ] {
                let got = got.expect("fit");
                assert!(
                    (got - want).abs() < 0.01,
                    "{} {:?}: {got} vs {want}",
                    r.design,
                    r.mass_law
                );
            }
        }
    }
}
