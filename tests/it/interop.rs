//! `survey sim export` and `survey sim import` through the real binary: the round trip gives
//! the design back, hand-written robot files of known mass properties import to the values
//! worked out by hand, and bad files are refused naming the file and what is missing.

use std::path::{Path, PathBuf};

use robot_survey::sim::{ContactScaling, Design, MassLaw};

use crate::common::{self, stderr, survey};

/// Every number of a design's TOML tree, by dotted path (arrays indexed).
fn leaves(d: &Design) -> Vec<(String, f64)> {
    fn walk(prefix: &str, v: &toml::Value, out: &mut Vec<(String, f64)>) {
        match v {
            toml::Value::Float(x) => out.push((prefix.to_string(), *x)),
            toml::Value::Integer(i) => out.push((prefix.to_string(), *i as f64)),
            toml::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(&format!("{prefix}[{i}]"), x, out);
                }
            }
            toml::Value::Table(t) => {
                for (k, x) in t {
                    let p = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&p, x, out);
                }
            }
            _ => {}
        }
    }
    let mut d = d.clone();
    d.uncertain.clear();
    d.audit = None;
    let mut out = Vec::new();
    walk("", &toml::Value::try_from(&d).expect("tree"), &mut out);
    out
}

/// Asserts two designs have the same numbers within `rel` (absolute `rel`·scale for zeros),
/// the same control kind and friction cone; returns the largest relative difference.
fn assert_same(a: &Design, b: &Design, rel: f64, what: &str) -> f64 {
    let (la, lb) = (leaves(a), leaves(b));
    let paths = |l: &[(String, f64)]| l.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(
        paths(&la),
        paths(&lb),
        "{what}: the designs have different fields"
    );
    let mut worst = 0.0f64;
    for ((p, x), (_, y)) in la.iter().zip(&lb) {
        let scale = x.abs().max(y.abs());
        let d = if scale < 1e-12 {
            (x - y).abs()
        } else {
            (x - y).abs() / scale
        };
        assert!(
            d <= rel,
            "{what}: {p} = {x} exported, {y} imported (relative {d:.2e} > {rel:.0e})"
        );
        worst = worst.max(d);
    }
    assert_eq!(a.contact.friction_cone, b.contact.friction_cone, "{what}");
    assert_eq!(
        a.criteria.walking_direction, b.criteria.walking_direction,
        "{what}"
    );
    worst
}

fn run_ok(args: &[&str]) -> String {
    let o = survey(args);
    assert!(o.status.success(), "survey {args:?} failed: {}", stderr(&o));
    stderr(&o)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf8 path")
}

/// The stated round-trip tolerance: every number within 1e-9 relative. The structure gives
/// geometry, masses, inertia boxes, gains and the stop's angle by exact algebra from the
/// exported bodies (a section-cut foot's ellipsoid is fitted to the exported mesh, whose
/// vertices lie on it); MJCF's custom data and the sidecar carry the rest exactly.
const ROUND_TRIP_REL: f64 = 1e-9;

/// A size to export at: leg length, mass law, contact scaling.
type Scaling = (f64, MassLaw, ContactScaling);

#[test]
fn export_then_import_gives_the_design_back_in_every_format() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [(&str, Option<Scaling>); 7] = [
        ("mugatu", None),
        ("zippy", None),
        ("zippy-spherical", None),
        ("mugatu-ref", None),
        ("mugatu-ref-sap", None),
        ("mugatu", Some((1.0, MassLaw::L2, ContactScaling::Similar))),
        (
            "zippy",
            Some((0.5, MassLaw::L3, ContactScaling::FixedMaterial)),
        ),
    ];
    for (name, scale) in cases {
        let design = Design::builtin(name).expect("bundled");
        let expected = match scale {
            Some((l, m, c)) => design.scaled(l, m, c).expect("scales"),
            None => design.clone(),
        };
        for ext in ["xml", "urdf", "sdf"] {
            let out = dir
                .path()
                .join(format!("{name}-{}.{ext}", scale.map_or(1.0, |s| s.0)));
            let mut args = vec!["sim", "export", "--design", name, "--out", s(&out)];
            let l;
            if let Some((len, m, c)) = scale {
                l = len.to_string();
                args.extend([
                    "--leg-length",
                    &l,
                    "--mass-law",
                    if m == MassLaw::L2 { "l2" } else { "l3" },
                    "--contact",
                    if c == ContactScaling::Similar {
                        "similar"
                    } else {
                        "fixed-material"
                    },
                ]);
            }
            run_ok(&args);
            let toml = out.with_extension(format!("{ext}.toml"));
            let sidecar = PathBuf::from(format!("{}.sidecar.toml", out.display()));
            let mut args = vec![
                "sim",
                "import",
                s(&out),
                "--out",
                s(&toml),
                "--name",
                &expected.name,
            ];
            if ext != "xml" {
                args.extend(["--sidecar", s(&sidecar)]);
            }
            run_ok(&args);
            let text = std::fs::read_to_string(&toml).expect("toml");
            let sha = {
                use sha2::Digest;
                let h = sha2::Sha256::digest(std::fs::read(&out).expect("model"));
                h.iter().map(|b| format!("{b:02x}")).collect::<String>()
            };
            assert!(text.contains(&sha), "the design names the file's sha256");
            for line in text
                .lines()
                .filter(|l| l.contains(" = ") && !l.starts_with('#'))
            {
                assert!(line.contains("  # ["), "a value without its source: {line}");
            }
            let back = Design::from_file(&toml).expect("the imported design is valid");
            assert_same(
                &expected,
                &back,
                ROUND_TRIP_REL,
                &format!("{name} via {ext}"),
            );
        }
    }
}

/// Without the custom data the structure alone gives the geometry, masses and gains, and the
/// contact is the inverse of the export's MuJoCo mapping: the same modulus and relaxation time.
#[test]
fn an_mjcf_without_custom_data_gives_the_structure_and_the_mapped_contact() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("ref.xml");
    run_ok(&["sim", "export", "--design", "mugatu-ref", "--out", s(&out)]);
    let text = std::fs::read_to_string(&out).expect("xml");
    let start = text.find("<custom>").expect("custom");
    let end = text.find("</custom>").expect("custom end") + "</custom>".len();
    let stripped = dir.path().join("stripped.xml");
    std::fs::write(&stripped, format!("{}{}", &text[..start], &text[end..])).expect("write");
    let toml = dir.path().join("stripped.toml");
    let err = run_ok(&[
        "sim",
        "import",
        s(&stripped),
        "--out",
        s(&toml),
        "--set",
        "control.amplitude_deg=25",
        "--set",
        "control.frequency_hz=1.4",
    ]);
    let back = Design::from_file(&toml).expect("valid");
    let d = Design::builtin("mugatu-ref").expect("bundled");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(back.geometry.leg_length_m, d.geometry.leg_length_m) < 1e-9);
    assert!(
        rel(
            back.mass.leg_inertia_box_over_l[0],
            d.mass.leg_inertia_box_over_l[0]
        ) < 1e-9
    );
    assert!(
        rel(
            back.contact.hydroelastic_modulus_pa,
            d.contact.hydroelastic_modulus_pa
        ) < 1e-6,
        "{}",
        back.contact.hydroelastic_modulus_pa
    );
    assert!(
        rel(back.contact.relaxation_time_s, d.contact.relaxation_time_s) < 1e-6,
        "{}",
        back.contact.relaxation_time_s
    );
    let text = std::fs::read_to_string(&toml).expect("toml");
    assert!(
        text.contains("amplitude_deg = 25.0  # [SET] --set control.amplitude_deg=25"),
        "{text}"
    );
    assert!(
        text.contains("initial.roll_deg") || text.contains("roll_deg = 3.0  # [DEFAULT]"),
        "{text}"
    );
    assert!(err.contains("values from the file"), "{err}");
}

/// A hand-written MJCF (not from the exporter): a base leg with a box "battery" in a welded
/// child body, capsule legs given by fromto with a density, sphere feet, degrees (MJCF's
/// default angle unit), a position servo. Its mass properties worked out by hand.
const HAND_MJCF: &str = r#"<mujoco model="hand">
  <default>
    <geom density="500"/>
    <default class="foot"><geom type="sphere" size="0.05" mass="0.1" friction="0.6"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="base" pos="0 0 0.3">
      <freejoint/>
      <geom name="base_leg" type="capsule" fromto="0 0.04 0  0 0.04 -0.25" size="0.01"/>
      <geom name="base_foot" class="foot" pos="0 0.04 -0.25"/>
      <body name="battery" pos="0 0.04 -0.05">
        <geom type="box" size="0.01 0.02 0.03" mass="0.2"/>
      </body>
      <body name="swing" euler="0 0 0">
        <joint name="hip" type="hinge" axis="0 -1 0" range="-30 30"/>
        <geom name="swing_leg" type="capsule" fromto="0 -0.04 0  0 -0.04 -0.25" size="0.01"/>
        <geom name="swing_foot" class="foot" pos="0 -0.04 -0.25"/>
      </body>
    </body>
  </worldbody>
  <actuator><position joint="hip" kp="3" kv="0.1" forcerange="-0.5 0.5"/></actuator>
</mujoco>
"#;

#[test]
fn a_hand_written_mjcf_imports_to_its_hand_worked_values() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = dir.path().join("hand.xml");
    std::fs::write(&f, HAND_MJCF).expect("write");
    let toml = dir.path().join("hand.toml");
    run_ok(&["sim", "import", s(&f), "--out", s(&toml)]);
    let d = Design::from_file(&toml).expect("valid");
    // Capsule: radius 0.01, half length 0.125, density 500.
    let vc = std::f64::consts::PI * 1e-4 * 0.25;
    let vs = 4.0 / 3.0 * std::f64::consts::PI * 1e-6;
    let capsule = 500.0 * (vc + vs);
    let base = capsule + 0.1 + 0.2;
    let swing = capsule + 0.1;
    assert!(
        (d.mass.total_mass_kg - (base + swing)).abs() < 1e-12,
        "{}",
        d.mass.total_mass_kg
    );
    // Hip 0.3 m up; sphere feet 0.05 m at 0.25 m below it: L = 0.30.
    assert!(
        (d.geometry.leg_length_m - 0.30).abs() < 1e-12,
        "{}",
        d.geometry.leg_length_m
    );
    // COMs below the hip: base (capsule 0.125, foot 0.25, battery 0.05), swing (0.125, 0.25).
    let zb = (capsule * 0.125 + 0.1 * 0.25 + 0.2 * 0.05) / base;
    let zs = (capsule * 0.125 + 0.1 * 0.25) / swing;
    let h = 1.0 - 0.5 * (zb + zs) / 0.30;
    assert!(
        (d.mass.leg_com_height_over_l - h).abs() < 1e-12,
        "{} vs {h}",
        d.mass.leg_com_height_over_l
    );
    assert!((d.geometry.hip_half_width_over_l - 0.04 / 0.30).abs() < 1e-12);
    assert_eq!(d.geometry.foot_semi_axes_m, [0.05; 3]);
    assert!((d.geometry.foot_center_lateral_over_l - 0.04 / 0.30).abs() < 1e-12);
    assert_eq!(d.contact.friction_mu, 0.6);
    // Range ±30 degrees: MJCF's default angle unit.
    let lim = d.hardstop.as_ref().expect("a stop").limit_deg;
    assert!((lim - 30.0).abs() < 1e-9, "{lim}");
    let mgl = d.mass.total_mass_kg * 9.81 * 0.30;
    match d.control {
        robot_survey::sim::design::ControlSpec::ServoSine {
            kp_over_mgl,
            torque_limit_nm,
            ..
        } => {
            assert!((kp_over_mgl * mgl - 3.0).abs() < 1e-9);
            assert_eq!(torque_limit_nm, 0.5);
        }
        _ => panic!("a position actuator is a servo"),
    }
    let text = std::fs::read_to_string(&toml).expect("toml");
    assert!(
        text.contains("frequency_hz") && text.contains("[DEFAULT]"),
        "the drive is a tagged default"
    );
}

/// A hand-written URDF: an extra link fixed to the base leg, Drake ellipsoid feet with
/// hydroelastic properties, PD gains on the transmission.
const HAND_URDF: &str = r#"<robot name="hand" xmlns:drake="http://drake.mit.edu">
  <link name="base">
    <inertial><origin xyz="0 0.05 -0.1"/><mass value="0.4"/><inertia ixx="0.002" iyy="0.002" izz="0.0005"/></inertial>
    <collision><origin xyz="0 0.01 -0.16"/><geometry><drake:ellipsoid a="0.05" b="0.06" c="0.04"/></geometry>
      <drake:proximity_properties><drake:hydroelastic_modulus value="2e6"/><drake:relaxation_time value="0.004"/><drake:mu_dynamic value="0.7"/></drake:proximity_properties>
    </collision>
  </link>
  <link name="pack"><inertial><origin xyz="0 0 0"/><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5"/></inertial></link>
  <joint name="pack_fix" type="fixed"><parent link="base"/><child link="pack"/><origin xyz="0 0.05 -0.02"/></joint>
  <link name="swing">
    <inertial><origin xyz="0 -0.05 -0.1"/><mass value="0.5"/><inertia ixx="0.002" iyy="0.002" izz="0.0005"/></inertial>
    <collision><origin xyz="0 -0.01 -0.16"/><geometry><drake:ellipsoid a="0.05" b="0.06" c="0.04"/></geometry></collision>
  </link>
  <joint name="hip" type="revolute"><parent link="base"/><child link="swing"/><axis xyz="0 1 0"/>
    <limit lower="-0.4" upper="0.5" effort="0.3" velocity="10"/></joint>
  <transmission name="t"><joint name="hip"/><actuator name="a"><drake:controller_gains p="2" d="0.05"/></actuator></transmission>
</robot>
"#;

#[test]
fn a_hand_written_urdf_merges_fixed_links_and_reads_drake_properties() {
    let dir = tempfile::tempdir().expect("tempdir");
    let f = dir.path().join("hand.urdf");
    std::fs::write(&f, HAND_URDF).expect("write");
    let toml = dir.path().join("hand.toml");
    run_ok(&["sim", "import", s(&f), "--out", s(&toml)]);
    let d = Design::from_file(&toml).expect("valid");
    assert!((d.mass.total_mass_kg - 1.0).abs() < 1e-12);
    // Feet bottoms at 0.16 + 0.04 below the hip.
    assert!((d.geometry.leg_length_m - 0.20).abs() < 1e-12);
    assert_eq!(d.geometry.foot_semi_axes_m, [0.05, 0.06, 0.04]);
    assert_eq!(d.contact.hydroelastic_modulus_pa, 2e6);
    assert_eq!(d.contact.relaxation_time_s, 0.004);
    assert_eq!(d.contact.friction_mu, 0.7);
    // The smaller side of the range.
    assert!((d.hardstop.as_ref().expect("stop").limit_deg - 0.4f64.to_degrees()).abs() < 1e-9);
    // The base leg: 0.4 kg at z = −0.1 and the pack 0.1 kg at −0.02 → −0.084; swing −0.1.
    let h = 1.0 - 0.5 * (0.084 + 0.1) / 0.20;
    assert!(
        (d.mass.leg_com_height_over_l - h).abs() < 1e-12,
        "{}",
        d.mass.leg_com_height_over_l
    );
    let text = std::fs::read_to_string(&toml).expect("toml");
    assert!(
        text.contains("Note: the legs differ"),
        "asymmetric legs are said to be averaged"
    );
}

/// The four values a hand-built walker fixes, each to 1e-12: its leg length `l`, its total
/// mass, each leg's COM `com_below` the hip and its feet `foot_y` to either side.
fn assert_hand_walker(d: &Design, l: f64, mass: f64, com_below: f64, foot_y: f64) {
    let close = |got: f64, want: f64, what: &str| {
        assert!((got - want).abs() < 1e-12, "{what}: {got}, by hand {want}");
    };
    close(d.geometry.leg_length_m, l, "leg length");
    close(d.mass.total_mass_kg, mass, "total mass");
    close(
        d.mass.leg_com_height_over_l,
        1.0 - com_below / l,
        "leg COM height / L",
    );
    close(
        d.geometry.foot_center_lateral_over_l,
        foot_y / l,
        "foot lateral / L",
    );
}

/// Writes `text` as `name` in `dir` and checks that `survey sim import` refuses it (exit 2)
/// with an error naming the file and holding `needle`.
fn assert_import_refused(dir: &Path, name: &str, text: &str, needle: &str) {
    let f = dir.join(name);
    std::fs::write(&f, text).expect("write");
    let o = survey(&["sim", "import", s(&f)]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {e}");
    assert!(e.contains(name), "{name}: the error names the file: {e}");
    assert!(e.contains(needle), "{name}: expected `{needle}` in: {e}");
}

#[test]
fn bad_robot_files_are_refused_naming_the_file_and_what_is_missing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [(&str, &str, &str); 8] = [
        (
            "no-hip.xml",
            r#"<mujoco><worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05"/><body name="b"><geom type="sphere" size="0.05"/></body></body></worldbody></mujoco>"#,
            "the revolute hip is missing",
        ),
        (
            "knee.xml",
            r#"<mujoco><worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05"/><body name="b"><joint name="hip"/><geom type="sphere" size="0.05"/><body name="c"><joint name="knee"/><geom type="sphere" size="0.05"/></body></body></body></worldbody></mujoco>"#,
            "more than one revolute joint",
        ),
        (
            "slide.xml",
            r#"<mujoco><worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05"/><body name="b"><joint name="hip"/><geom type="sphere" size="0.05"/></body><body name="c"><joint name="s" type="slide"/><geom type="sphere" size="0.05"/></body></body></worldbody></mujoco>"#,
            "only a free base and a revolute hip",
        ),
        (
            "broken.xml",
            "<mujoco><worldbody><body></mujoco>",
            "not well-formed XML",
        ),
        (
            "mesh.xml",
            r#"<mujoco><asset><mesh name="m" file="missing.stl"/></asset></mujoco>"#,
            "missing.stl",
        ),
        (
            // Leg `a` stands on a box (a foot); leg `b` has no collision geometry at all.
            "no-collision.urdf",
            r#"<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link><link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1"/></inertial></link><joint name="hip" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#,
            "leg `b` has no foot: it has no collision geometry",
        ),
        (
            "vertical.xml",
            r#"<mujoco><worldbody><body name="a"><freejoint/><geom type="sphere" size="0.05" pos="0 0 -0.2"/><body name="b"><joint name="hip" axis="0 0 1"/><geom type="sphere" size="0.05" pos="0 0 -0.2"/></body></body></worldbody></mujoco>"#,
            "hip axis",
        ),
        (
            "bad-number.urdf",
            r#"<robot name="r"><link name="a"><inertial><mass value="heavy"/><inertia ixx="1" iyy="1" izz="1"/></inertial></link></robot>"#,
            "heavy",
        ),
    ];
    for (name, text, needle) in cases {
        assert_import_refused(dir.path(), name, text, needle);
    }
}

/// Issue 58, item 7: an error about a design names its file, also when it appears only
/// after scaling (the foot's fixed material at a tiny size cannot be resolved by the step).
#[test]
fn a_design_error_names_the_design_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mugatu =
        std::fs::read_to_string(common::repo().join("dataset/walkers/mugatu.toml")).expect("read");
    let f = dir.path().join("coarse-step.toml");
    std::fs::write(
        &f,
        mugatu.replace("time_step_s = 0.002", "time_step_s = 0.5"),
    )
    .expect("write");
    let o = survey(&["sim", "walk", "--design", s(&f)]);
    let e = stderr(&o);
    assert!(
        e.contains("coarse-step.toml")
            && e.contains("stable limit")
            && e.contains("numerics.time_step_s"),
        "{e}"
    );
    // 6 ms resolves Mugatu's contact at 1× (limit 7 ms); the same rubber on a 0.05 m robot
    // of m ∝ L³ does not (the limit falls as L^0.75, the scaled step as L^0.5).
    let f = dir.path().join("near-limit.toml");
    std::fs::write(
        &f,
        mugatu.replace("time_step_s = 0.002", "time_step_s = 0.006"),
    )
    .expect("write");
    let ok = survey(&["sim", "walk", "--design", s(&f), "--duration", "0.1"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let o = survey(&[
        "sim",
        "walk",
        "--design",
        s(&f),
        "--leg-length",
        "0.05",
        "--mass-law",
        "l3",
        "--contact",
        "fixed-material",
        "--duration",
        "0.1",
    ]);
    let e = stderr(&o);
    assert!(
        e.contains("near-limit.toml") && e.contains("stable limit") && e.contains("L = 0.05"),
        "{e}"
    );
}

/// The bundled `mugatu-lab` (the import of the lab's MuJoCo model, reports/lab-models.md) walks
/// on its crossed whole-sphere feet, and not on the bundled design's half spheres.
#[test]
fn the_lab_mugatu_walks_on_its_crossed_feet_and_not_on_half_spheres() {
    use robot_survey::sim::{WalkOptions, simulate_walk};
    let d = Design::builtin("mugatu-lab").expect("bundled");
    assert!(
        d.geometry.foot_center_lateral_over_l < -0.1,
        "each foot under the other leg"
    );
    let opts = WalkOptions {
        record_trajectory: false,
        ..WalkOptions::default()
    };
    let r = simulate_walk(&d, &opts).expect("walks").report;
    assert!(r.walks && (0.2..0.3).contains(&r.velocity_mps), "{r:?}");
    let mut half = d
        .with_values(&[
            ("geometry.foot_center_lateral_over_l", 0.0),
            ("geometry.foot_center_forward_over_l", 0.0),
        ])
        .expect("valid");
    half.geometry.foot_section_cut_over_l = Some(0.0);
    let r = simulate_walk(&half, &opts).expect("runs").report;
    assert!(!r.walks, "{r:?}");
}

/// Writes `files` (name, text) into a fresh directory, imports the first and returns the
/// design with the TOML text.
fn import_hand(files: &[(&str, &str)]) -> (Design, String) {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).expect("write");
    }
    let f = dir.path().join(files[0].0);
    let toml = dir.path().join("out.toml");
    run_ok(&["sim", "import", s(&f), "--out", s(&toml)]);
    let text = std::fs::read_to_string(&toml).expect("toml");
    (Design::from_file(&toml).expect("valid"), text)
}

fn servo_of(d: &Design) -> (f64, f64) {
    match d.control {
        robot_survey::sim::design::ControlSpec::ServoSine {
            kp_over_mgl,
            torque_limit_nm,
            ..
        } => (kp_over_mgl, torque_limit_nm),
        _ => panic!("expected a servo: {:?}", d.control),
    }
}

/// A hand-written URDF with no `<transmission>`: sphere feet on links fixed 0.3 m below the
/// hip, the hip's `<limit effort="2">`, its `<dynamics>`; the links listed children first.
const EFFORT_URDF: &str = r#"<?xml version="1.0"?>
<robot name="effort">
  <link name="swing_foot">
    <inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="swing">
    <inertial><origin xyz="0 -0.05 -0.15"/><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.001"/></inertial>
    <collision><origin xyz="0 -0.05 -0.15" rpy="1.5707963267948966 0 0"/><geometry><cylinder radius="0.01" length="0.4"/></geometry></collision>
  </link>
  <link name="base_foot">
    <inertial><mass value="0.1"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="base">
    <inertial><origin xyz="0 0.05 -0.15"/><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.001"/></inertial>
  </link>
  <joint name="base_foot_fix" type="fixed"><parent link="base"/><child link="base_foot"/><origin xyz="0 0.05 -0.3"/></joint>
  <joint name="swing_foot_fix" type="fixed"><parent link="swing"/><child link="swing_foot"/><origin xyz="0 -0.05 -0.3"/></joint>
  <joint name="hip" type="revolute">
    <parent link="base"/><child link="swing"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.6" effort="2" velocity="5"/>
    <dynamics damping="0.02" friction="0.01"/>
  </joint>
</robot>
"#;

/// The hip's declared effort limit is the default servo's torque limit, read from the file.
#[test]
fn a_urdf_hip_effort_without_transmission_limits_the_default_servo() {
    let (d, text) = import_hand(&[("effort.urdf", EFFORT_URDF)]);
    assert_eq!(servo_of(&d).1, 2.0, "the hip's <limit effort=\"2\">");
    assert!(
        text.contains("torque_limit_nm = 2.0  # [effort.urdf sha256:")
            && text.contains("<limit effort>"),
        "{text}"
    );
}

/// URDF links may come in any order: children listed before their parents read the same.
#[test]
fn a_urdf_listing_child_links_first_imports_to_its_hand_worked_values() {
    let (d, _) = import_hand(&[("effort.urdf", EFFORT_URDF)]);
    // Feet 0.3 m below the hip, radius 0.03: L = 0.33; 2 × (1.0 + 0.1) kg; each leg's COM
    // (1.0·0.15 + 0.1·0.3)/1.1 below the hip; the feet at y = ±0.05.
    assert_hand_walker(&d, 0.33, 2.2, 0.18 / 1.1, 0.05);
}

/// The body's extent is exact for turned primitives: the swing leg's cylinder, 0.4 m long,
/// rolled 90° to lie along y from −0.25 to 0.15 m (not 0.4 + 2 × its radius).
#[test]
fn the_body_length_is_the_exact_extent_of_a_turned_cylinder() {
    let (d, _) = import_hand(&[("effort.urdf", EFFORT_URDF)]);
    assert!(
        (d.geometry.body_length_m - 0.4).abs() < 1e-12,
        "{}",
        d.geometry.body_length_m
    );
}

/// A hand-written MJCF: radians with eulerseq zyx (the base turned 90° about z, so the
/// hip axis, the body's y, lies along the world's −x), a default class as childclass,
/// `fromto` capsules by density, ellipsoid feet turned by `xyaxes`, `<joint type="free">`,
/// the hip's `actuatorfrcrange`, `<option timestep>`, and the actuator in an `<include>`d
/// file (`ACTUATOR` replaced by each case's).
const RAD_MJCF: &str = r#"<mujoco model="rad">
  <compiler angle="radian" eulerseq="zyx"/>
  <option timestep="0.0005"/>
  <default>
    <default class="leg">
      <geom type="capsule" size="0.01" density="800"/>
      <joint type="hinge" damping="0.01"/>
    </default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base" pos="0 0 0.4" euler="1.5707963267948966 0 0" childclass="leg">
      <joint name="root" type="free"/>
      <geom name="base_leg" fromto="0 0.05 0  0 0.05 -0.35"/>
      <geom name="base_foot" type="ellipsoid" pos="0 0.05 -0.35" size="0.04 0.03 0.02" xyaxes="0 1 0 -1 0 0" mass="0.05"/>
      <body name="swing">
        <joint name="hip" axis="0 1 0" range="-0.4 0.4" actuatorfrcrange="-1.5 1.5"/>
        <inertial pos="0 -0.05 -0.2" mass="0.3" fullinertia="0.004 0.004 0.0002 0 0 0"/>
        <geom name="swing_leg" fromto="0 -0.05 0  0 -0.05 -0.35"/>
        <geom name="swing_foot" type="ellipsoid" pos="0 -0.05 -0.35" size="0.04 0.03 0.02" xyaxes="0 1 0 -1 0 0" mass="0.05"/>
      </body>
    </body>
  </worldbody>
  <include file="act.xml"/>
</mujoco>
"#;

fn rad_with(actuator: &str) -> (Design, String) {
    import_hand(&[
        ("rad.xml", RAD_MJCF),
        (
            "act.xml",
            &format!("<mujoco><actuator>{actuator}</actuator></mujoco>"),
        ),
    ])
}

#[test]
fn a_hand_written_radian_mjcf_with_an_include_imports_to_its_hand_worked_values() {
    let (d, _) = rad_with("");
    // Capsule r 0.01, length 0.35, density 800; base = capsule + foot 0.05; swing 0.3.
    let capsule =
        800.0 * (std::f64::consts::PI * 1e-4 * 0.35 + 4.0 / 3.0 * std::f64::consts::PI * 1e-6);
    let base = capsule + 0.05;
    assert!((d.mass.total_mass_kg - (base + 0.3)).abs() < 1e-12);
    // Feet 0.35 below the hip, semi z 0.02; xyaxes puts 0.04 along the body's y (the hip axis).
    assert!((d.geometry.leg_length_m - 0.37).abs() < 1e-12);
    assert_eq!(d.geometry.foot_semi_axes_m, [0.03, 0.04, 0.02]);
    assert!((d.geometry.hip_half_width_over_l - 0.05 / 0.37).abs() < 1e-12);
    let zb = (capsule * 0.175 + 0.05 * 0.35) / base;
    let h = 1.0 - 0.5 * (zb + 0.2) / 0.37;
    assert!((d.mass.leg_com_height_over_l - h).abs() < 1e-12);
    assert!((d.hardstop.as_ref().expect("stop").limit_deg - 0.4f64.to_degrees()).abs() < 1e-9);
    assert_eq!(d.numerics.time_step_s, 0.0005);
    // No actuator: the joint's actuatorfrcrange ±1.5 N·m limits the default servo.
    assert_eq!(servo_of(&d).1, 1.5);
}

/// MuJoCo's joint torque is gear × the actuator force: a motor's is bounded by gear ×
/// ctrlrange (and forcerange), a position servo's stiffness is gear²·kp; a `general` with
/// an affine bias −kp·q − kv·q̇ is a position servo; the joint's actuatorfrcrange binds
/// when smaller.
#[test]
fn mjcf_actuator_gear_and_ranges_give_the_hip_torque() {
    let torque = |d: &Design| match d.control {
        robot_survey::sim::design::ControlSpec::BangBang { torque_nm, .. } => torque_nm,
        _ => panic!("a motor is driven bang-bang: {:?}", d.control),
    };
    // gear 2 × ctrlrange 0.5 = 1 N·m (the joint's 1.5 is larger).
    let (d, _) = rad_with(r#"<motor joint="hip" gear="2" ctrlrange="-0.5 0.5"/>"#);
    assert_eq!(torque(&d), 1.0);
    // gear 2 × forcerange 1 = 2 N·m, the joint's 1.5 binds.
    let (d, _) = rad_with(r#"<motor joint="hip" gear="2" forcerange="-1 1"/>"#);
    assert_eq!(torque(&d), 1.5);
    let mgl = |d: &Design| d.mass.total_mass_kg * 9.81 * d.geometry.leg_length_m;
    // kp 4 through gear 2: 16 N·m/rad; forcerange 0.5 × 2 = 1 N·m.
    let (d, _) = rad_with(r#"<position joint="hip" kp="4" gear="2" forcerange="-0.5 0.5"/>"#);
    let (kp, limit) = servo_of(&d);
    assert!((kp * mgl(&d) - 16.0).abs() < 1e-9, "{kp}");
    assert_eq!(limit, 1.0);
    // MuJoCo Menagerie's servo: gain 3, bias (0, −3, −0.1).
    let (d, _) = rad_with(
        r#"<general joint="hip" gainprm="3" biastype="affine" biasprm="0 -3 -0.1" forcerange="-0.7 0.7" ctrlrange="-1 1"/>"#,
    );
    let (kp, limit) = servo_of(&d);
    assert!((kp * mgl(&d) - 3.0).abs() < 1e-9, "{kp}");
    assert_eq!(limit, 0.7);
}

#[test]
fn more_bad_robot_files_are_refused_naming_the_file_and_the_element() {
    let dir = tempfile::tempdir().expect("tempdir");
    let swing = r#"<body name="s"><joint name="hip" axis="0 1 0"/><geom type="sphere" size="0.05" pos="0 -0.05 -0.3"/></body>"#;
    let mjcf = |base_attrs: &str, geom: &str| {
        format!(
            r#"<mujoco><worldbody><body name="a" pos="0 0 0.35"{base_attrs}><freejoint/>{geom}{swing}</body></worldbody></mujoco>"#
        )
    };
    let foot = r#"<geom type="sphere" size="0.05" pos="0 0.05 -0.3"/>"#;
    let link = |n: &str| {
        format!(
            r#"<link name="{n}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1"/></inertial><collision><geometry><sphere radius="0.1"/></geometry></collision></link>"#
        )
    };
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "zero-quat.xml",
            mjcf(r#" quat="0 0 0 0""#, foot),
            "<body>: `quat` is zero",
        ),
        (
            "zero-fromto.xml",
            mjcf(
                "",
                &format!(r#"{foot}<geom type="capsule" size="0.01" fromto="0 0 0 0 0 0"/>"#),
            ),
            "`fromto` has zero length",
        ),
        (
            "negative-size.xml",
            mjcf(
                "",
                r#"<geom type="sphere" size="-0.05" pos="0 0.05 -0.3"/>"#,
            ),
            "is negative",
        ),
        (
            "missing-include.xml",
            r#"<mujoco><include file="nope.xml"/></mujoco>"#.into(),
            "<include>: cannot read",
        ),
        (
            "loop.urdf",
            format!(
                r#"<robot name="r">{}{}{}<joint name="a" type="fixed"><parent link="b"/><child link="c"/></joint><joint name="b" type="fixed"><parent link="c"/><child link="b"/></joint></robot>"#,
                link("a"),
                link("b"),
                link("c")
            ),
            "form a loop",
        ),
        (
            "bad-damping.urdf",
            format!(
                r#"<robot name="r">{}{}<joint name="hip" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/><dynamics damping="lots"/></joint></robot>"#,
                link("a"),
                link("b")
            ),
            "lots",
        ),
    ];
    for (name, text, needle) in cases {
        assert_import_refused(dir.path(), name, &text, needle);
    }
}

/// A compass-gait walker as MuJoCo users write it: each leg one capsule, `fromto` 0.3 m
/// straight down from the hip, radius 0.02, mass from MuJoCo's default density 1000 kg/m³;
/// the legs 0.1 m apart on the hip axis.
const COMPASS_MJCF: &str = r#"<mujoco model="compass">
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="left" pos="0 0.05 0.32">
      <freejoint/>
      <geom name="left_leg" type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02"/>
      <body name="right" pos="0 -0.1 0">
        <joint name="hip" type="hinge" axis="0 1 0" range="-0.5 0.5"/>
        <geom name="right_leg" type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"#;

/// An upright capsule leg stands on the sphere of its radius about its lower end point.
#[test]
fn a_two_capsule_compass_walker_stands_on_its_capsule_ends() {
    let (d, text) = import_hand(&[("compass.xml", COMPASS_MJCF)]);
    // By hand: the hip on the capsules' upper end points; each lower end point 0.3 m below,
    // its hemisphere reaching 0.02 lower: L = 0.32. The foot is that end's sphere: 0.02.
    for s in d.geometry.foot_semi_axes_m {
        assert!((s - 0.02).abs() < 1e-12, "{text}");
    }
    // Each capsule: a cylinder π·0.02²·0.3 plus a ball 4/3·π·0.02³, times 1000 kg/m³;
    // its COM at its middle, 0.15 m below the hip. The feet under the legs, 0.05 m either
    // side of the hip point, straight below it.
    let leg = 1000.0 * std::f64::consts::PI * (0.02f64.powi(2) * 0.3 + 4.0 / 3.0 * 0.02f64.powi(3));
    assert_hand_walker(&d, 0.32, 2.0 * leg, 0.15, 0.05);
    assert!(d.geometry.foot_center_forward_over_l.abs() < 1e-12);
    assert!(
        text.contains("capsule `left_leg` within 5° of vertical")
            && text.contains("capsule `right_leg` within 5° of vertical"),
        "{text}"
    );
}

/// A hand-written URDF whose feet are boxes 0.1 × 0.06 × 0.02 m, their centres 0.3 m below
/// the hip, 0.02 m ahead of it and 0.05 m to either side.
const BOX_FEET_URDF: &str = r#"<?xml version="1.0"?>
<robot name="box_feet">
  <link name="left">
    <inertial><origin xyz="0 0.05 -0.15"/><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.001"/></inertial>
    <collision name="left_foot"><origin xyz="0.02 0.05 -0.3"/><geometry><box size="0.1 0.06 0.02"/></geometry></collision>
  </link>
  <link name="right">
    <inertial><origin xyz="0 -0.05 -0.15"/><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.001"/></inertial>
    <collision name="right_foot"><origin xyz="0.02 -0.05 -0.3"/><geometry><box size="0.1 0.06 0.02"/></geometry></collision>
  </link>
  <joint name="hip" type="revolute">
    <parent link="left"/><child link="right"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="2" velocity="5"/>
  </joint>
</robot>
"#;

/// A box foot is replaced by the best-fitting ellipsoid of its corners a floor touches, set
/// down where the box stands.
#[test]
fn box_feet_are_read_as_the_ellipsoid_of_their_hull_standing_where_the_box_does() {
    let (d, text) = import_hand(&[("box_feet.urdf", BOX_FEET_URDF)]);
    // By hand: the box's bottom face 0.3 + 0.02/2 = 0.31 m below the hip.
    assert!(
        (d.geometry.leg_length_m - 0.31).abs() < 1e-12,
        "{}",
        d.geometry.leg_length_m
    );
    // Any ellipsoid fitted to the box's corners lies within the sphere through all eight:
    // no semi-axis beyond the half-diagonal √(0.05² + 0.03² + 0.01²).
    let half_diagonal = (0.05f64.powi(2) + 0.03f64.powi(2) + 0.01f64.powi(2)).sqrt();
    for s in d.geometry.foot_semi_axes_m {
        assert!(
            s.is_finite() && s > 0.0 && s <= half_diagonal,
            "{s}: {text}"
        );
    }
    // The corners are symmetric about the box's vertical centre line, so is the fit.
    assert!((d.geometry.foot_center_forward_over_l - 0.02 / 0.31).abs() < 1e-9);
    assert!((d.geometry.foot_center_lateral_over_l - 0.05 / 0.31).abs() < 1e-9);
    assert!(
        text.contains("convex-hull points of box `left_foot`")
            && text.contains("so its lowest point is the box's")
            && text.contains("mm as placed"),
        "{text}"
    );
}

/// A hand-written SDFormat 1.9 walker: two legs of a 1.0 kg shin link and a 0.1 kg foot link
/// (welded), placed with `relative_to` (the swing leg turned half a turn about z relative to
/// the base, its foot relative to it, the swing foot's collision relative to `__model__`), a
/// shin cylinder rolled 90° (once in degrees) to lie along y, sphere feet, and a revolute hip
/// whose axis is expressed in `__model__` and whose `<limit><effort>` is 2 N·m. No gains: the
/// servo is the default one, limited by the effort.
const HAND_SDF: &str = r#"<?xml version="1.0"?>
<sdf version="1.9">
  <model name="hand">
    <pose>0.2 -0.1 0.4 0 0 0.5</pose>
    <link name="base">
      <pose relative_to="__model__">0 0 0.33 0 0 0</pose>
      <inertial>
        <pose>0 0.05 -0.15 0 0 0</pose>
        <mass>1.0</mass>
        <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.001</izz></inertia>
      </inertial>
      <collision name="base_shin">
        <pose degrees="true">0 0.05 -0.15 90 0 0</pose>
        <geometry><cylinder><radius>0.01</radius><length>0.4</length></cylinder></geometry>
      </collision>
    </link>
    <link name="base_foot">
      <pose relative_to="base">0 0.05 -0.3 0 0 0</pose>
      <inertial><mass>0.1</mass><inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial>
      <collision name="base_sole"><geometry><sphere><radius>0.03</radius></sphere></geometry></collision>
    </link>
    <link name="swing">
      <pose relative_to="base">0 0 0 0 0 3.141592653589793</pose>
      <inertial>
        <pose>0 0.05 -0.15 0 0 0</pose>
        <mass>1.0</mass>
        <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.001</izz></inertia>
      </inertial>
      <collision name="swing_shin">
        <pose>0 0.05 -0.15 1.5707963267948966 0 0</pose>
        <geometry><cylinder><radius>0.01</radius><length>0.4</length></cylinder></geometry>
      </collision>
    </link>
    <link name="swing_foot">
      <pose relative_to="swing">0 0.05 -0.3 0 0 0</pose>
      <inertial><mass>0.1</mass><inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial>
      <collision name="swing_sole">
        <pose relative_to="__model__">0 -0.05 0.03 0 0 0</pose>
        <geometry><sphere><radius>0.03</radius></sphere></geometry>
      </collision>
    </link>
    <joint name="base_foot_fix" type="fixed"><parent>base</parent><child>base_foot</child></joint>
    <joint name="swing_foot_fix" type="fixed"><parent>swing</parent><child>swing_foot</child></joint>
    <joint name="hip" type="revolute">
      <pose relative_to="base">0 0 0 0 0 0</pose>
      <parent>base</parent>
      <child>swing</child>
      <axis>
        <xyz expressed_in="__model__">0 1 0</xyz>
        <limit><lower>-0.5</lower><upper>0.6</upper><effort>2</effort></limit>
        <dynamics><damping>0.02</damping><friction>0.01</friction></dynamics>
      </axis>
    </joint>
  </model>
</sdf>
"#;

/// A walker as Gazebo writes SDFormat 1.6: every pose with an empty `frame=''` (the default
/// frame), both links at the model's origin, the axis in the joint frame.
const GAZEBO_SDF: &str = r#"<?xml version="1.0"?>
<sdf version="1.6">
  <model name="gz_walker">
    <pose frame=''>0 0 0.33 0 -0 0</pose>
    <link name="base">
      <pose frame=''>0 0 0 0 -0 0</pose>
      <inertial>
        <pose frame=''>0 0.05 -0.15 0 -0 0</pose>
        <mass>1.0</mass>
        <inertia><ixx>0.01</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.01</iyy><iyz>0</iyz><izz>0.001</izz></inertia>
      </inertial>
      <collision name="base_foot">
        <pose frame=''>0 0.05 -0.3 0 -0 0</pose>
        <geometry><sphere><radius>0.03</radius></sphere></geometry>
      </collision>
    </link>
    <link name="swing">
      <pose frame=''>0 0 0 0 -0 0</pose>
      <inertial>
        <pose frame=''>0 -0.05 -0.15 0 -0 0</pose>
        <mass>1.0</mass>
        <inertia><ixx>0.01</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.01</iyy><iyz>0</iyz><izz>0.001</izz></inertia>
      </inertial>
      <collision name="swing_foot">
        <pose frame=''>0 -0.05 -0.3 0 -0 0</pose>
        <geometry><sphere><radius>0.03</radius></sphere></geometry>
      </collision>
    </link>
    <joint name="hip" type="revolute">
      <parent>base</parent>
      <child>swing</child>
      <axis>
        <xyz>0 1 0</xyz>
        <limit><lower>-0.5</lower><upper>0.5</upper><effort>1.5</effort><velocity>10</velocity></limit>
        <dynamics><damping>0.01</damping><friction>0</friction><spring_reference>0</spring_reference><spring_stiffness>0</spring_stiffness></dynamics>
        <use_parent_model_frame>0</use_parent_model_frame>
      </axis>
    </joint>
  </model>
</sdf>
"#;

#[test]
fn a_gazebo_style_sdf_with_empty_frame_attributes_imports() {
    let (d, _) = import_hand(&[("gz.sdf", GAZEBO_SDF)]);
    // Both sphere feet (r = 0.03) centred 0.3 below the hip at the links' common origin:
    // L = 0.33; the legs' COMs 0.15 below it; 2 × 1.0 kg; the feet at y = ±0.05.
    assert_hand_walker(&d, 0.33, 2.0, 0.15, 0.05);
    // The hip's `<effort>1.5</effort>`.
    assert_eq!(servo_of(&d).1, 1.5);
}

#[test]
fn a_hand_written_sdf_imports_to_its_hand_worked_values() {
    let (d, text) = import_hand(&[("hand.sdf", HAND_SDF)]);
    // In the model frame the hip (the base's origin, where the joint sits) is at z = 0.33; the
    // base foot link at base + (0, 0.05, −0.3); the swing leg is the base turned by π about z,
    // so its foot link at base + Rz(π)·(0, 0.05, −0.3) = (0, −0.05, 0.03), where its sphere's
    // `__model__` pose puts the collision too. Both spheres (r = 0.03) are centred 0.3 below
    // the hip: L = 0.3 + 0.03 = 0.33 (had the 90° rolls been ignored, the 0.4 m shins would
    // reach 0.15 + 0.2 = 0.35 below the hip and be the feet).
    // 2 × (1.0 kg shin + 0.1 kg foot); each leg's COM (1.0 · 0.15 + 0.1 · 0.3) / 1.1 below
    // the hip; the feet at y = ±0.05 (the swing one mirrored by the half turn).
    assert_hand_walker(&d, 0.33, 2.2, 0.18 / 1.1, 0.05);
    assert_eq!(d.geometry.foot_semi_axes_m, [0.03, 0.03, 0.03]);
    // The hip's `<limit><effort>2</effort>`; its range's smaller side 0.5 rad.
    assert_eq!(servo_of(&d).1, 2.0);
    assert!(
        text.contains("torque_limit_nm = 2.0  # [hand.sdf sha256:")
            && text.contains("<limit><effort>"),
        "{text}"
    );
    assert!((d.hardstop.as_ref().expect("stop").limit_deg - 0.5f64.to_degrees()).abs() < 1e-9);
    assert!(text.contains("(SDF file)"), "{text}");
}

/// The same walker inside a `<world>`, the hip at its default pose (the child link's frame)
/// with its axis in that frame (the swing link's, turned by π: its −y is the model's +y) and the swing foot's collision relative to
/// its link, imports to the same values.
#[test]
fn an_sdf_world_with_one_model_and_the_axis_in_the_joint_frame_reads_the_same() {
    let text = HAND_SDF
        .replace(
            r#"<sdf version="1.9">"#,
            r#"<sdf version="1.9"><world name="w">"#,
        )
        .replace("</sdf>", "</world></sdf>")
        .replace(
            r#"<xyz expressed_in="__model__">0 1 0</xyz>"#,
            "<xyz>0 -1 0</xyz>",
        )
        .replace(
            "<pose relative_to=\"base\">0 0 0 0 0 0</pose>\n      <parent>",
            "<parent>",
        )
        .replace(
            r#"<pose relative_to="__model__">0 -0.05 0.03 0 0 0</pose>"#,
            "<pose>0 0 0 0 0 0</pose>",
        );
    for gone in [
        "expressed_in",
        "relative_to=\"base\">0 0 0 0 0 0",
        "0 -0.05 0.03",
    ] {
        assert!(!text.contains(gone), "the variant drops `{gone}`");
    }
    let (d, _) = import_hand(&[("world.sdf", &text)]);
    let (a, _) = import_hand(&[("hand.sdf", HAND_SDF)]);
    assert_same(&a, &d, 1e-12, "world.sdf against hand.sdf");
}

#[test]
fn bad_sdf_files_are_refused_naming_the_file_and_the_element() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh_foot = HAND_SDF.replace(
        "<geometry><sphere><radius>0.03</radius></sphere></geometry></collision>\n    </link>\n    <link name=\"swing\">",
        "<geometry><mesh><uri>model://walker/foot.stl</uri></mesh></geometry></collision>\n    </link>\n    <link name=\"swing\">",
    );
    assert_ne!(mesh_foot, HAND_SDF);
    let cases: Vec<(&str, String, &str)> = vec![
        (
            // Line 6: the base link's pose.
            "unknown-frame.sdf",
            HAND_SDF.replace(
                r#"relative_to="__model__">0 0 0.33"#,
                r#"relative_to="hip">0 0 0.33"#,
            ),
            "unknown-frame.sdf:6: <pose>: relative_to=\"hip\" is not a link of this model: only a link of this model or `__model__` is supported",
        ),
        (
            // Line 20: the base foot's collision.
            "model-uri.sdf",
            mesh_foot,
            "model-uri.sdf:20: <uri>: mesh `model://walker/foot.stl`: model://, package:// and other URIs are not resolved",
        ),
        (
            "frame.sdf",
            HAND_SDF.replace(
                "<link name=\"base\">",
                "<frame name=\"f\"/><link name=\"base\">",
            ),
            "<frame>: <frame> in a model is not read",
        ),
        (
            "world-joint.sdf",
            HAND_SDF.replace(
                "<parent>base</parent>\n      <child>swing</child>",
                "<parent>world</parent>\n      <child>swing</child>",
            ),
            "<parent>: the joint fixes the model to the world",
        ),
        (
            "old.sdf",
            HAND_SDF.replace(r#"version="1.9""#, r#"version="1.4""#),
            "SDFormat 1.5 to 1.11 is read",
        ),
        (
            "pose-loop.sdf",
            HAND_SDF.replace(
                r#"relative_to="__model__">0 0 0.33"#,
                r#"relative_to="swing">0 0 0.33"#,
            ),
            "relative to each other in a loop",
        ),
    ];
    for (name, text, needle) in cases {
        assert_ne!(text, HAND_SDF, "{name}: the case changes the file");
        assert_import_refused(dir.path(), name, &text, needle);
    }
}
