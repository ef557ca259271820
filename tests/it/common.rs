//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `../shared/upstream/robot-dataset/` beside the checkout (CI puts shared/ there).
pub fn upstream_dir() -> PathBuf {
    repo().join("../shared/upstream/robot-dataset")
}

pub fn upstream_csv() -> PathBuf {
    upstream_dir().join("robot_scaling_dataset.csv")
}

/// Runs the real `survey` binary.
pub fn survey(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_survey"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("the survey binary runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scratch dataset: the repo's dataset.toml, vocabulary.toml and datapackage.json, and
/// the given record files under robots/.
pub fn scratch_dataset(records: &[&Path]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for f in ["dataset.toml", "vocabulary.toml", "datapackage.json"] {
        std::fs::copy(repo().join("dataset").join(f), dir.path().join(f))
            .expect("copy dataset metadata");
    }
    std::fs::create_dir_all(dir.path().join("robots")).expect("robots dir");
    for r in records {
        let name = r.file_name().expect("file name");
        std::fs::copy(r, dir.path().join("robots").join(name)).expect("copy record");
    }
    dir
}

/// Copies a whole directory tree.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("read_dir") {
        let e = e.expect("entry");
        let p = e.path();
        if p.is_dir() {
            copy_tree(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).expect("copy");
        }
    }
}

/// A full copy of the repo's dataset in a temp dir.
pub fn dataset_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    copy_tree(&repo().join("dataset"), dir.path());
    dir
}

/// Property tests run on a fixed seed so CI is reproducible bit for bit; set
/// `PROPTEST_RNG_SEED=N` (and explore) to draw other samples locally. A random seed on
/// a fresh CI machine once found the MA cancellation bug (regression_hand.rs,
/// `ma_slope_of_a_shallow_line_keeps_its_digits`): worth exploring, not worth a flaky CI.
pub fn reproducible_proptest(cases: u32) -> proptest::test_runner::Config {
    use proptest::test_runner::{Config, RngSeed};
    let mut config = Config::with_cases(cases);
    if config.rng_seed == RngSeed::Random {
        config.rng_seed = RngSeed::Fixed(20_261_123);
    }
    config.failure_persistence = None;
    config
}

/// One walk cache for every diagnosis in this test binary that uses the bundled effect
/// library. The cache keys a walk by its condition's content and the model setting, and a
/// walk is deterministic, so a test that finds its walks there gets the same bits it would
/// walk itself: the committed benchmark trials share their conditions, and their diagnoses
/// share the surrogate's walks instead of each walking them again.
pub fn bundled_walks() -> &'static robot_survey::gap::cache::SimCache {
    static WALKS: std::sync::OnceLock<robot_survey::gap::cache::SimCache> =
        std::sync::OnceLock::new();
    WALKS.get_or_init(Default::default)
}
