//! Loading arbitrary bytes never panics: as a record, as a whole upstream table, as a
//! release table (property tests with proptest).

use crate::common;
use proptest::prelude::*;
use robot_survey::dataset::{
    Vocabulary, record::parse_record, release::parse_table_csv, upstream::import,
};

fn vocab() -> Vocabulary {
    Vocabulary::parse(robot_survey::dataset::BUNDLED_VOCABULARY, "vocabulary.toml")
        .expect("bundled vocabulary")
}

/// Byte strings biased towards TOML/CSV punctuation so the parsers get past line 1.
fn tomlish() -> impl Strategy<Value = Vec<u8>> {
    let atoms = prop_oneof![
        Just(b"id = \"x\"\n".to_vec()),
        Just(b"[values]\n".to_vec()),
        Just(b"[[sources]]\nkey = \"s1\"\n".to_vec()),
        Just(b"leg_length_m = { value = 1e309, source = [1, \"s1\"] }\n".to_vec()),
        Just(b"mass_kg = { min = -1, max = \"x\" }\n".to_vec()),
        Just(b"fit = 3\nclass = \"hexapod\"\n".to_vec()),
        Just(b"\xff\xfe\x00".to_vec()),
        proptest::collection::vec(any::<u8>(), 0..40),
    ];
    proptest::collection::vec(atoms, 0..12).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(common::reproducible_proptest(400))]

    #[test]
    fn parse_record_never_panics(bytes in tomlish()) {
        let text = String::from_utf8_lossy(&bytes);
        let mut problems = Vec::new();
        let _ = parse_record(&text, "fuzz.toml", &vocab(), &mut problems);
    }

    #[test]
    fn upstream_import_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400), prefix in 0usize..3) {
        let header = b"robot_name,reference,type,year,cost_dollars,total_length_inm,leg_length_inm,min_mass_inkg,max_mass_inkg,average_mass_inkg,normal_speed_inmps,walking_speed_inmps,running_speed_inmps,DOF,payload_inkg,actuator_mass_inkg,accuator_count,highest_stall_torqueorforce_on_actuators_inNm,actuator_name,actuation_type,reported_COT,battery_life_hours,battery_wt_inkg,\n";
        let mut input = Vec::new();
        if prefix > 0 { input.extend_from_slice(header); }
        if prefix > 1 { input.extend_from_slice(b"X,,quadruped,"); }
        input.extend_from_slice(&bytes);
        let _ = import(&input, "fuzz.csv");
    }

    #[test]
    fn release_table_parse_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        let mut input = b"id,name,class,fit,exclusion,leg_length_m\n".to_vec();
        input.extend_from_slice(&bytes);
        let _ = parse_table_csv(&input, "fuzz.csv", "0.0.0");
    }
}
