//! The motor catalogue (dataset/motors/): its numbers against the sources, the datasheet
//! fit against the research note's independent computation, and validation of forged files.
//!
//! Expected values come from outside the code: ROBOTIS e-Manual pages and
//! ../shared/research/walkers.md §5 (whose fit τ = 83.5·m^1.33, R² 0.948 and peak power
//! 39.7·m^0.82, R² 0.89 were computed there by hand over the 14 DYNAMIXEL servos that
//! have a published mass, each at its recommended voltage).

use std::path::{Path, PathBuf};

use robot_survey::dataset::Severity;
use robot_survey::motors::{MotorCatalogue, MotorError, MotorProblem, SourceKind};
use robot_survey::regression::{Method, fit_power_law};

use crate::common::{copy_tree, repo, stdout, survey};

fn motors_dir() -> PathBuf {
    repo().join("dataset/motors")
}

fn catalogue() -> MotorCatalogue {
    MotorCatalogue::load(&motors_dir()).expect("dataset/motors loads")
}

/// A scratch copy of dataset/motors with `edit(file name, text) -> text` applied.
fn forged(edit: impl Fn(&str, String) -> String) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for f in ["laws.toml", "actuators.toml", "anchors.toml"] {
        let text = std::fs::read_to_string(motors_dir().join(f)).expect("read");
        std::fs::write(dir.path().join(f), edit(f, text)).expect("write");
    }
    dir
}

fn find<'a>(problems: &'a [MotorProblem], id: &str, field: &str) -> &'a MotorProblem {
    problems
        .iter()
        .find(|p| p.id.as_deref() == Some(id) && p.field.as_deref() == Some(field))
        .unwrap_or_else(|| panic!("no problem for {id} {field} in {problems:#?}"))
}

fn line_of(path: &Path, needle: &str) -> usize {
    std::fs::read_to_string(path)
        .expect("read")
        .lines()
        .position(|l| l.contains(needle))
        .expect("needle present")
        + 1
}

#[test]
fn repo_catalogue_loads_from_dir_and_bundled_and_is_valid() {
    let cat = catalogue();
    // 15 DYNAMIXEL servos, 4 Pololu gearmotors, 2 Unitree Go1 joints (model limits),
    // Minitaur's motor; 3 theory + 5 empirical motor-length laws and Marden's group 2.
    assert_eq!(cat.actuators.len(), 22);
    assert_eq!(cat.laws.len(), 9);
    assert_eq!(cat.anchors.len(), 1);
    let problems = cat.validate();
    assert!(problems.is_empty(), "{problems:#?}");

    let bundled = MotorCatalogue::bundled().expect("bundled catalogue");
    assert_eq!(bundled.actuators, cat.actuators);
    assert_eq!(bundled.laws, cat.laws);
    assert_eq!(bundled.anchors, cat.anchors);
}

#[test]
fn xl330_m288_t_matches_its_datasheet() {
    // e-Manual XL330-M288-T, Specifications: 0.52 N·m (at 5.0 V, 1.47 A), 103 rev/min
    // (at 5.0 V), 18 g, 288.4:1, recommended 5.0 V.
    let cat = catalogue();
    let a = cat
        .actuator("dynamixel-xl330-m288-t")
        .expect("XL330-M288-T");
    assert_eq!(a.mass_kg, Some(0.018));
    assert_eq!(a.gear_ratio, Some(288.4));
    let r = a.rating(Some(5.0)).expect("5 V rating");
    assert_eq!(r.stall_torque_nm, 0.52);
    assert_eq!(r.no_load_speed_rpm, Some(103.0));
    assert_eq!(r.stall_current_a, Some(1.47));
    assert_eq!(a.stall_torque_at(None), Some(0.52), "recommended 5.0 V");
    assert_eq!(a.stall_torque_at(Some(3.7)), Some(0.42));
    assert_eq!(a.stall_torque_at(Some(6.0)), Some(0.60));
    assert_eq!(a.stall_torque_at(Some(7.4)), None);
    // 103 rpm = 103·2π/60 = 10.786 rad/s; walkers.md: peak power 0.52 × 10.79 / 4 = 1.40 W,
    // mass-specific stall torque 28.9 N·m/kg.
    let w = a.no_load_speed_rad_s(None).expect("speed");
    assert!((w - 10.786).abs() < 1e-3, "{w}");
    assert!((a.peak_power_w(None).unwrap() - 1.40).abs() < 0.005);
    assert!((a.specific_stall_torque(None).unwrap() - 28.9).abs() < 0.05);
    // walkers.md: XM540-W270 64.2 N·m/kg (10.6 N·m / 0.165 kg at 12 V).
    let w270 = cat.actuator("dynamixel-xm540-w270").unwrap();
    assert!((w270.specific_stall_torque(None).unwrap() - 64.2).abs() < 0.05);
}

#[test]
fn stall_torque_vs_mass_reproduces_the_research_note() {
    // Rule: datasheet sources, datasheet stall torques (no extrapolations), a published
    // mass, the rating at the recommended voltage. That selects the 14 DYNAMIXEL servos
    // walkers.md §5.2 fitted (XM430-W350 has no mass; the Pololu stall torques are
    // extrapolations), at 5 V (XL330, XC330), 7.4 V (XL-320) and 12 V (the rest, including
    // XC430 whose e-Manual recommends 12.0 V).
    let cat = catalogue();
    let pts = cat.stall_torque_mass_points(&[SourceKind::Datasheet]);
    let mut ids: Vec<&str> = pts.iter().map(|p| p.id.as_str()).collect();
    ids.sort_unstable();
    assert_eq!(
        ids,
        [
            "dynamixel-mx-106",
            "dynamixel-mx-28ar",
            "dynamixel-mx-64ar",
            "dynamixel-xc330-m181-t",
            "dynamixel-xc330-m288-t",
            "dynamixel-xc430-w150-t",
            "dynamixel-xc430-w240-t",
            "dynamixel-xh430-w350",
            "dynamixel-xl-320",
            "dynamixel-xl330-m077-t",
            "dynamixel-xl330-m288-t",
            "dynamixel-xm540-w150",
            "dynamixel-xm540-w270",
            "dynamixel-xw540-t140",
        ]
    );
    // 16.7–185 g, as walkers.md states.
    let (lo, hi) = pts.iter().fold((f64::MAX, 0.0f64), |(lo, hi), p| {
        (lo.min(p.mass_kg), hi.max(p.mass_kg))
    });
    assert_eq!((lo, hi), (0.0167, 0.185));

    // walkers.md §5.2: τ_stall = 83.5·m^1.33 N·m (m in kg), R² = 0.948.
    let fit = cat
        .stall_torque_vs_mass(&[SourceKind::Datasheet])
        .expect("fit");
    assert_eq!(fit.n, 14);
    assert!((fit.a - 83.5).abs() < 0.05, "A = {}", fit.a);
    assert!((fit.b - 1.33).abs() < 0.005, "b = {}", fit.b);
    assert!((fit.r2 - 0.948).abs() < 0.0005, "R² = {}", fit.r2);
    // With m ∝ L³ that is τ ∝ L^3.98 (walkers.md): 3b rounds to 3.98.
    assert!((3.0 * fit.b - 3.98).abs() < 0.005);

    // walkers.md §5.2: peak power τ_stall·ω₀/4 = 39.7·m^0.82 W, R² = 0.89.
    let m: Vec<f64> = pts.iter().map(|p| p.mass_kg).collect();
    let p: Vec<f64> = pts
        .iter()
        .map(|p| cat.actuator(&p.id).unwrap().peak_power_w(None).unwrap())
        .collect();
    let pf = fit_power_law(&m, &p, Method::Ols, 0.95).expect("power fit");
    assert!((pf.a - 39.7).abs() < 0.05, "A = {}", pf.a);
    assert!((pf.b - 0.82).abs() < 0.005, "b = {}", pf.b);
    assert!((pf.r2 - 0.89).abs() < 0.005, "R² = {}", pf.r2);

    // No source kind selected: no points, and the fit says why.
    assert!(matches!(
        cat.stall_torque_vs_mass(&[]),
        Err(MotorError::Fit { points: 0, .. })
    ));
}

#[test]
fn laws_and_anchor() {
    let cat = catalogue();
    let mut theory: Vec<f64> = Vec::new();
    let mut empirical: Vec<f64> = Vec::new();
    for l in cat
        .laws
        .iter()
        .filter(|l| l.size_variable == robot_survey::motors::SizeVariable::MotorLength)
    {
        assert!(
            l.coefficient.is_none(),
            "{}: L_m coefficients are unknown",
            l.id
        );
        match l.basis {
            robot_survey::motors::Basis::Theory => theory.push(l.exponent),
            robot_survey::motors::Basis::Empirical => empirical.push(l.exponent),
        }
    }
    // S1 §I-A: theory L^3.5, L^4, L^5; empirical L^3, L^3.5, L^3.8, L^4, L^5.
    assert_eq!(theory, [3.5, 4.0, 5.0]);
    assert_eq!(empirical, [3.0, 3.5, 3.8, 4.0, 5.0]);
    // Marden 2005, group 2: F_max = 55·M^0.999 N (M in kg): ≈ 55 N at 1 kg.
    let marden = cat.law("marden-2005-group-2").expect("Marden");
    assert!((marden.predict(1.0).unwrap() - 55.0).abs() < 1e-9);
    assert!((marden.predict(0.018).unwrap() - 55.0 * 0.018f64.powf(0.999)).abs() < 1e-12);

    // Mugatu's hip servo: XL330-M288-T at 5 V, leg 0.153 m (walkers.md §1).
    let (anchor, act, tau) = cat.anchor_stall_torque("mugatu").expect("mugatu anchor");
    assert_eq!(act.id, "dynamixel-xl330-m288-t");
    assert_eq!(
        (anchor.voltage_v, anchor.leg_length_m, tau),
        (5.0, 0.153, 0.52)
    );
    // Zippy's motor data were not found: no anchor.
    assert!(cat.anchor("zippy").is_none());
    // L^4 pinned at Mugatu: twice the leg length, 16 times the torque.
    let l4 = cat.law("theory-lm-4").unwrap();
    assert!((l4.pinned(tau, 0.153, 0.306) - 0.52 * 16.0).abs() < 1e-12);
}

#[test]
fn validation_catches_forged_problems_naming_file_id_field_and_line() {
    let dir = forged(|f, text| match f {
        // A negative mass, and a copy of the XL-320 entry under the XL330-M288-T's id.
        "actuators.toml" => {
            let text = text.replacen(
                "id = \"dynamixel-xl330-m077-t\"\nname = \"DYNAMIXEL XL330-M077-T\"\nmaker = \"ROBOTIS\"\nkind = \"servo\"\nmass_kg = 0.018",
                "id = \"dynamixel-xl330-m077-t\"\nname = \"DYNAMIXEL XL330-M077-T\"\nmaker = \"ROBOTIS\"\nkind = \"servo\"\nmass_kg = -0.018",
                1,
            );
            text.replacen(
                "id = \"dynamixel-xl-320\"",
                "id = \"dynamixel-xl330-m288-t\"",
                1,
            )
        }
        "anchors.toml" => text.replacen(
            "actuator = \"dynamixel-xl330-m288-t\"",
            "actuator = \"dynamixel-xl330-m999-t\"",
            1,
        ),
        _ => text,
    });
    let cat = MotorCatalogue::load(dir.path()).expect("still parses");
    let problems = cat.validate();
    let actuators = dir.path().join("actuators.toml");
    let anchors = dir.path().join("anchors.toml");

    let neg = find(&problems, "dynamixel-xl330-m077-t", "mass_kg");
    assert_eq!(neg.severity, Severity::Error);
    assert_eq!(neg.file, actuators.display().to_string());
    assert_eq!(neg.line, Some(line_of(&actuators, "mass_kg = -0.018")));
    assert!(neg.message.contains("-0.018"), "{}", neg.message);

    let dup = find(&problems, "dynamixel-xl330-m288-t", "id");
    assert_eq!(dup.severity, Severity::Error);
    assert!(dup.message.contains("duplicate"), "{}", dup.message);
    assert!(dup.file.ends_with("actuators.toml"));

    let unknown = find(&problems, "mugatu", "actuator");
    assert_eq!(unknown.severity, Severity::Error);
    assert_eq!(unknown.file, anchors.display().to_string());
    assert_eq!(
        unknown.line,
        Some(line_of(&anchors, "dynamixel-xl330-m999-t"))
    );
    assert!(unknown.message.contains("dynamixel-xl330-m999-t"));

    // The text form is `file:line:field: error: message [rule]`.
    let line = neg.to_line();
    assert!(
        line.starts_with(&format!(
            "{}:{}:mass_kg: error:",
            neg.file,
            neg.line.unwrap()
        )),
        "{line}"
    );
}

#[test]
fn validation_flags_a_unit_slip_and_a_datasheet_without_url() {
    let dir = forged(|f, text| {
        match f {
        // 18 "kg" for an 18 g servo: within 1 g–20 kg but 0.029 N·m/kg.
        "actuators.toml" => text
            .replacen("mass_kg = 0.018", "mass_kg = 18.0", 1)
            .replacen(
                "source = { kind = \"datasheet\", url = \"https://emanual.robotis.com/docs/en/dxl/x/xl330-m077/\", ",
                "source = { kind = \"datasheet\", ",
                1,
            ),
        _ => text,
    }
    });
    let problems = MotorCatalogue::load(dir.path()).unwrap().validate();
    let slip = find(
        &problems,
        "dynamixel-xl330-m288-t",
        "ratings[1].stall_torque_nm",
    );
    assert_eq!(slip.severity, Severity::Warning);
    assert!(slip.message.contains("N·m/kg"), "{}", slip.message);
    let url = find(&problems, "dynamixel-xl330-m077-t", "source.url");
    assert_eq!(url.severity, Severity::Error);
}

#[test]
fn unknown_fields_are_rejected_with_file_and_line() {
    let dir = forged(|f, text| match f {
        "actuators.toml" => text.replacen(
            "maker = \"ROBOTIS\"",
            "maker = \"ROBOTIS\"\ncolour = \"blue\"",
            1,
        ),
        _ => text,
    });
    match MotorCatalogue::load(dir.path()) {
        Err(MotorError::Parse {
            file,
            line,
            message,
        }) => {
            assert!(file.ends_with("actuators.toml"), "{file}");
            assert!(message.contains("colour"), "{message}");
            let expected = line_of(&dir.path().join("actuators.toml"), "colour");
            // toml reports the span of the offending table or key.
            assert!(
                line.is_some_and(|l| l <= expected && l + 20 >= expected),
                "{line:?}"
            );
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn survey_validate_reports_the_motor_catalogue() {
    let out = survey(&["validate"]);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("motors: 22 actuator(s), 9 law(s), 1 anchor(s): 0 error(s), 0 warning(s)"),
        "{text}"
    );

    // A dataset whose motor anchor names an unknown actuator fails validation (exit 1).
    let tmp = tempfile::tempdir().expect("tempdir");
    let ds = tmp.path().join("dataset");
    copy_tree(&repo().join("dataset"), &ds);
    let anchors = ds.join("motors/anchors.toml");
    let text = std::fs::read_to_string(&anchors).unwrap().replacen(
        "dynamixel-xl330-m288-t",
        "no-such-servo",
        1,
    );
    std::fs::write(&anchors, text).unwrap();
    let out = survey(&["validate", "--dataset", ds.to_str().unwrap()]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(
        text.contains("motors: 22 actuator(s), 9 law(s), 1 anchor(s): 1 error(s)"),
        "{text}"
    );
    let expected = format!(
        "{}:{}:actuator: error: unknown actuator `no-such-servo`",
        anchors.display(),
        line_of(&anchors, "no-such-servo")
    );
    assert!(text.contains(&expected), "{text}");
}
