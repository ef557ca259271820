//! Unit tests of `gap::plan`.

use robot_survey::gap::plan::drake_effects;

/// A Drake file's stem names what Drake added; any other name is refused.
#[test]
fn a_drake_file_name_gives_the_effects_drake_added() {
    assert_eq!(drake_effects("trials-none"), Some(vec![]));
    assert_eq!(
        drake_effects("trials-soft_ground-6e6"),
        Some(vec![("soft_ground".into(), 6e6)])
    );
    assert_eq!(
        drake_effects("trials-hip_viscous_damping-0.01+hip_coulomb_friction-0.03"),
        Some(vec![
            ("hip_viscous_damping".into(), 0.01),
            ("hip_coulomb_friction".into(), 0.03)
        ])
    );
    assert_eq!(
        drake_effects("trials-hip_backlash-1e-3"),
        Some(vec![("hip_backlash".into(), 1e-3)])
    );
    for bad in [
        "trials-nothing",
        "trials-x-",
        "trials--1",
        "trials-a-1+",
        "trials-a-nan",
        "none",
    ] {
        assert_eq!(drake_effects(bad), None, "{bad}");
    }
}

/// How a case's truth is labelled: an undeclared number inside the audit's ×/÷ 2 is one of
/// the explanations weighed; beside an effect (undeclared numbers are never paired), or
/// beyond its range, it is "something outside these".
#[test]
fn an_undeclared_number_is_weighed_alone_and_inside_its_range() {
    use robot_survey::gap::benchmark::truth_label;
    use robot_survey::gap::plan::Truth;
    let d = robot_survey::sim::Design::resolve("mugatu").expect("mugatu");
    let a = &d.undeclared_params().expect("audit list")[0];
    let sim = |v: f64, effects: Vec<(String, f64)>| Truth::Sim {
        params: vec![(a.path.clone(), v)],
        effects,
    };
    let inside = a.nominal * 1.1;
    assert_eq!(
        truth_label(&sim(inside, vec![]), &d, true),
        format!("mugatu:{}", a.path)
    );
    let outside = "something outside these";
    let backlash = vec![("hip_backlash".to_string(), 10.0)];
    assert_eq!(truth_label(&sim(inside, backlash), &d, true), outside);
    let far = a.hi.max(a.lo).abs() * 3.0 + 1.0;
    assert_eq!(truth_label(&sim(far, vec![]), &d, true), outside);
}
