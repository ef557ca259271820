//! The scaling study against dimensional analysis. When a design is scaled with exact
//! dynamic similarity (lengths ∝ L, inertia ∝ m·L², drive frequency ∝ L^(-1/2), time step
//! ∝ L^(1/2), contact stiffness keeping sinkage/L fixed) every dimensionless quantity of
//! the gait is invariant, whatever the mass law. Hence (hand-derived, Buckingham Π):
//! Froude v/√(gL) constant ⇒ v ∝ L^0.5; τ/(m·g·L) constant ⇒ τ ∝ m·L, i.e. τ ∝ L³ for
//! m ∝ L² and L⁴ for m ∝ L³; attitude angles are unchanged. These are truths from
//! outside the simulator, and they test that its scaling rules are mutually consistent.

use robot_survey::progress::Silent;
use robot_survey::sim::{ContactScaling, Design, MassLaw, WalkOptions};
use robot_survey::study::scaling::scaling_study;

const SIZES: [f64; 3] = [0.05, 0.153, 0.6];

fn study(mass_law: MassLaw) -> robot_survey::study::scaling::ScalingStudy {
    let design = Design::builtin("mugatu").expect("bundled design");
    let base = WalkOptions {
        mass_law,
        duration_s: 15.0,
        ..WalkOptions::default()
    };
    scaling_study(&design, &SIZES, &base, &Silent).expect("study runs")
}

#[test]
fn similar_scaling_gives_v_as_sqrt_l_and_torque_as_m_l() {
    for (law, torque_exponent) in [(MassLaw::L2, 3.0), (MassLaw::L3, 4.0)] {
        let s = study(law);
        assert!(s.walks.iter().all(|w| w.walks), "{law:?}: every size walks");
        let v = s.velocity_law.as_ref().expect("velocity law");
        assert!(
            (v.b - 0.5).abs() < 0.01,
            "{law:?}: v ∝ L^{} (want 0.5)",
            v.b
        );
        let t = s.torque_law.as_ref().expect("torque law");
        assert!(
            (t.b - torque_exponent).abs() < 0.01,
            "{law:?}: τ ∝ L^{}",
            t.b
        );
        let tm = s.torque_vs_mass_length.as_ref().expect("torque vs m·L");
        assert!((tm.b - 1.0).abs() < 0.01, "{law:?}: τ ∝ (m·L)^{}", tm.b);
        // Froude number and attitude are the same at every size.
        let f0 = s.walks[0].froude;
        for w in &s.walks {
            assert!(
                (w.froude - f0).abs() < 0.02 * f0,
                "{law:?}: Froude {} vs {f0}",
                w.froude
            );
            assert!((w.roll_pp_deg - s.walks[0].roll_pp_deg).abs() < 1.0);
        }
    }
}

#[test]
fn scaling_study_is_deterministic_whatever_the_thread_schedule() {
    let design = Design::builtin("mugatu").expect("bundled design");
    let base = WalkOptions {
        duration_s: 6.0,
        seed: Some(3),
        contact_scaling: ContactScaling::FixedMaterial,
        ..WalkOptions::default()
    };
    let a = scaling_study(&design, &SIZES, &base, &Silent).expect("runs");
    let b = scaling_study(&design, &SIZES, &base, &Silent).expect("runs");
    let bits = |s: &robot_survey::study::scaling::ScalingStudy| {
        s.walks
            .iter()
            .map(|w| (w.velocity_mps.to_bits(), w.peak_torque_nm.to_bits()))
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
}
