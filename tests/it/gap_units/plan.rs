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
