//! The benchmark's out-of-library cases as data (`dataset/benchmarks/`, `src/gap/cases.rs`):
//! the bundled Mugatu file is the list the committed benchmark ran, a design without a file
//! gets cases derived by hand-checkable rules, and bad files are refused by name.

use robot_survey::gap::cases::BenchmarkCases;
use robot_survey::sim::Design;

use crate::common::{repo, stderr, survey};

/// The retired rules' benchmark (its points file's first line) holds the parameter and
/// compound errors it ran with: the bundled file must give exactly those, in order, so that
/// the posterior criterion's benchmark plans the same cases.
#[test]
fn the_bundled_mugatu_cases_are_those_of_the_committed_benchmark() {
    let points =
        std::fs::read_to_string(repo().join("reports/gap-benchmark-rules/main.points.csv"))
            .expect("read");
    let header = points.lines().next().expect("a header");
    let json = &header[header.find('[').expect("a JSON signature")..];
    let (_, opts): (String, serde_json::Value) = serde_json::from_str(json).expect("JSON");
    let list = |key: &str| -> Vec<Vec<(String, f64)>> {
        serde_json::from_value(opts[key].clone()).expect(key)
    };
    let cases = BenchmarkCases::for_design("mugatu").expect("bundled cases");
    assert_eq!(cases.origin, "dataset/benchmarks/mugatu.toml");
    assert_eq!(cases.parameter_errors, list("parameter_errors"));
    assert_eq!(cases.compound_errors, list("compound_errors"));
    assert_eq!(cases.parameter_errors.len(), 20);
}

/// Zippy has no cases file: its cases follow from dataset/walkers/zippy.toml by the rules of
/// dataset/benchmarks/README.md, worked here by hand from the file's values and ranges
/// (rounded to six significant digits).
#[test]
fn a_design_without_a_file_gets_cases_from_its_declarations() {
    let cases = BenchmarkCases::for_design("zippy").expect("derived cases");
    assert!(
        cases.origin.starts_with("derived from zippy"),
        "{}",
        cases.origin
    );
    let declared: Vec<(String, f64)> = [
        // 2.5 Hz in [1.5, 4.0]: the farther end is 4.0 → 2.5 + (4.0 − 2.5)/2.
        ("control.frequency_hz", 3.25),
        // 20° in [12, 30] → 25.
        ("hardstop.limit_deg", 25.0),
        // 4 mN·m on a log range [2, 8]: both ends a factor 2 away, the upper taken → 4·√2.
        ("control.torque_nm", 0.004 * 2f64.sqrt()),
        // 0.85 in [0.45, 0.9]: the lower end is farther → 0.65.
        ("mass.leg_com_height_over_l", 0.65),
        // 0.2 in [0.1, 0.3]: equal, the upper → 0.25.
        ("geometry.hip_half_width_over_l", 0.25),
        // 0.35 in [0.2, 1.0] → 0.675.
        ("mass.leg_inertia_box_over_l[0]", 0.675),
        // μ 0.4 in [0.2, 1.2] → 0.8.
        ("contact.friction_mu", 0.8),
        // 14 rad/s on a log range [8, 30]: 30/14 > 14/8 → 14·√(30/14) = √420.
        ("effects[0].no_load_speed_rad_s", 420f64.sqrt()),
    ]
    .iter()
    .map(|(p, v)| (p.to_string(), *v))
    .collect();
    for (i, (path, value)) in declared.iter().enumerate() {
        let got = &cases.parameter_errors[i];
        assert_eq!(got.len(), 1);
        assert_eq!(&got[0].0, path);
        assert!(
            (got[0].1 - value).abs() <= 5e-6 * value.abs(),
            "{path}: {} vs {value}",
            got[0].1
        );
    }
    // Undeclared: every audited number ×1.3, a zero offset in leg lengths + 0.015 L; the
    // 1× leg length and the declared values never.
    let undeclared = &cases.parameter_errors[declared.len()..];
    let find = |p: &str| {
        undeclared
            .iter()
            .find(|e| e[0].0 == p)
            .map(|e| e[0].1)
            .unwrap_or_else(|| panic!("{p} not among the undeclared errors"))
    };
    // Exactly the decimal products (0.0004 × 1.3 = 0.00052, not 0.0005200000000000001).
    assert_eq!(find("geometry.body_length_m"), 0.04732);
    assert_eq!(find("geometry.foot_semi_axes_m[1]"), 0.039);
    assert_eq!(find("contact.stiction_speed_mps"), 0.00052);
    assert_eq!(find("mass.total_mass_kg"), 0.0325);
    assert_eq!(find("mass.leg_inertia_box_over_l[2]"), 1.17);
    assert_eq!(find("geometry.foot_center_lateral_over_l"), 0.015);
    let design = Design::resolve("zippy").expect("zippy");
    let audited = design.undeclared_params().expect("audit list");
    assert_eq!(undeclared.len(), audited.len());
    for e in undeclared {
        assert!(!e[0].0.starts_with("geometry.leg_length_m"));
        assert!(!declared.iter().any(|(p, _)| *p == e[0].0), "{}", e[0].0);
    }
    // The compound error is the first undeclared one.
    assert_eq!(cases.compound_errors, vec![undeclared[0].clone()]);
}

#[test]
fn cases_files_are_checked_and_name_the_entry() {
    let design = Design::resolve("mugatu").expect("mugatu");
    let ok = "[[parameter_error]]\nset = [{ path = \"mass.total_mass_kg\", value = 1.0 }]\nwhy = \"x\"\n";
    let cases = BenchmarkCases::parse(ok, "c.toml", &design).expect("a valid file");
    assert_eq!(
        cases.parameter_errors,
        vec![vec![("mass.total_mass_kg".to_string(), 1.0)]]
    );
    assert!(cases.compound_errors.is_empty());
    let bad = [
        (
            format!("{ok}[[parameter_error]]\nset = [{{ path = \"mass.no_such\", value = 1.0 }}]\nwhy = \"x\"\n"),
            "[[parameter_error]] #2",
            "no_such",
        ),
        (
            "[[compound_error]]\nset = [{ path = \"mass.total_mass_kg\", value = -1.0 }]\nwhy = \"x\"\n".to_string(),
            "[[compound_error]] #1",
            "total_mass_kg",
        ),
        (
            "[[parameter_error]]\nset = [{ path = \"mass.total_mass_kg\", value = 1.0 }]\nwhy = \" \"\n".to_string(),
            "[[parameter_error]] #1",
            "`why` is empty",
        ),
        (
            "[[parameter_error]]\nset = []\nwhy = \"x\"\n".to_string(),
            "[[parameter_error]] #1",
            "`set` is empty",
        ),
        (
            "[[parameter_errors]]\nset = []\nwhy = \"x\"\n".to_string(),
            "c.toml",
            "parameter_errors",
        ),
    ];
    for (text, entry, why) in &bad {
        let e = BenchmarkCases::parse(text, "c.toml", &design)
            .expect_err(text)
            .to_string();
        assert!(
            e.contains("c.toml") && e.contains(entry) && e.contains(why),
            "{e}"
        );
    }
}

/// Through the real binary: a bad `--cases` file is refused before any planning, with the
/// file and entry named once (the error's cause is not repeated after it).
#[test]
fn the_benchmark_refuses_a_bad_cases_file_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = dir.path().join("cases.toml");
    std::fs::write(
        &f,
        "[[parameter_error]]\nset = [{ path = \"control.kp_over_mgl\", value = 1.0 }]\nwhy = \"x\"\n",
    )
    .expect("write");
    let out = survey(&[
        "gap",
        "benchmark",
        "--design",
        "zippy",
        "--cases",
        f.to_str().expect("utf-8 path"),
        "--quick",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.contains("cases.toml")
            && e.contains("[[parameter_error]] #1")
            && e.contains("kp_over_mgl"),
        "{e}"
    );
    assert_eq!(e.matches("no field `kp_over_mgl`").count(), 1, "{e}");
}

/// A narrowed benchmark run (here `--kinds drake`) without `--out` is refused before any case
/// runs, naming the narrowing flags: its report would otherwise replace the committed
/// reports/gap-benchmark.{md,json,svg}.
#[test]
fn a_narrowed_benchmark_needs_an_out_folder() {
    let report = repo().join("reports/gap-benchmark.md");
    let before = std::fs::read_to_string(&report).expect("committed report");
    let out = survey(&[
        "gap",
        "benchmark",
        "--design",
        "mugatu",
        "--quick",
        "--drake",
        "tests/golden/drake/gap",
        "--kinds",
        "drake",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("--kinds") && e.contains("--out DIR"), "{e}");
    assert_eq!(std::fs::read_to_string(&report).expect("read"), before);
}

/// A Drake trials file whose name does not say what Drake added is refused, naming it,
/// before any walk (it used to be taken for a file with no effect: a null case whose truth
/// nobody knew), and nothing is written.
#[test]
fn a_drake_file_not_named_by_its_effects_is_refused_at_once() {
    let dir = tempfile::tempdir().expect("tempdir");
    let drake = dir.path().join("drake");
    std::fs::create_dir(&drake).expect("mkdir");
    let none = repo().join("tests/golden/drake/gap-lagged/trials-none.csv");
    let designs = repo().join("tests/golden/drake/designs/");
    let text = std::fs::read_to_string(&none)
        .expect("golden trials")
        .replace("../designs/", designs.to_str().expect("utf-8"));
    std::fs::write(drake.join("trials-none.csv"), &text).expect("write");
    std::fs::write(drake.join("trials-softer.csv"), &text).expect("write");
    let out_dir = dir.path().join("out");
    let points = dir.path().join("points.csv");
    let out = survey(&[
        "gap",
        "benchmark",
        "--design",
        "mugatu",
        "--quick",
        "--drake",
        drake.to_str().expect("utf-8"),
        "--kinds",
        "drake",
        "--points",
        points.to_str().expect("utf-8"),
        "--out",
        out_dir.to_str().expect("utf-8"),
    ]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.contains("trials-softer.csv") && e.contains("trials-<effect>-<value>"),
        "{e}"
    );
    assert!(!out_dir.exists() && !points.exists(), "nothing written");
}
