//! `robot_survey._core`: the PyO3 binding of the robot-survey library.
//!
//! Every function here calls the library function that the `survey` command line calls for
//! the same command (see `src/cli/*.rs`) and returns what that command prints with
//! `--format json`: the same structs through the same serde serialization
//! (`robot_survey::report::json`), so Python sees the CLI's numbers to the last bit. The
//! Python package around this module (`python/robot_survey/`) turns them into DataFrames and
//! objects. Errors become `robot_survey.SurveyError` (a `ValueError`) with the message the CLI
//! prints after `survey: error: `. Simulations and fits run with the GIL released.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use pyo3::create_exception;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyString};

use robot_survey::analysis::table2::{self, Group};
use robot_survey::dataset::{Dataset, SurveyTable};
use robot_survey::gap::{self, DiagnoseOptions, EffectLibrary, TrialSet};
use robot_survey::progress::Silent;
use robot_survey::regression::Method;
use robot_survey::report;
use robot_survey::sim::{self, ContactScaling, Design, MassLaw, WalkOptions};
use robot_survey::study::table3::{self, Table3Point};
use robot_survey::study::{Shard, Table3Spec};

create_exception!(
    robot_survey,
    SurveyError,
    PyValueError,
    "Bad input or data: the message is the one `survey` prints (file:line:field where known)."
);

/// The CLI's error text (`survey: error: {e:#}` without the prefix) as a SurveyError.
fn survey_err(e: impl Into<anyhow::Error>) -> PyErr {
    SurveyError::new_err(format!("{:#}", e.into()))
}

fn bail<T>(message: String) -> PyResult<T> {
    Err(SurveyError::new_err(message))
}

type Res<T> = anyhow::Result<T>;

/// Runs `f` with the GIL released and turns its error into a SurveyError.
fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> Res<T> + Send) -> PyResult<T> {
    py.detach(f).map_err(survey_err)
}

fn value_enum<T: clap::ValueEnum>(what: &str, s: &str) -> PyResult<T> {
    let key = s.trim().to_ascii_lowercase().replace('_', "-");
    T::from_str(&key, true).or_else(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        bail(format!(
            "{what}: unknown value `{s}` (one of: {})",
            names.join(", ")
        ))
    })
}

fn mass_law(s: &str) -> PyResult<MassLaw> {
    value_enum("mass_law", s)
}

fn contact(s: &str) -> PyResult<ContactScaling> {
    value_enum("contact", s)
}

fn speed_kind(s: &str) -> PyResult<robot_survey::dataset::SpeedKind> {
    use robot_survey::dataset::SpeedKind;
    match SpeedKind::parse(s.trim()) {
        Some(k) => Ok(k),
        None => bail(format!(
            "speed_kind: unknown value `{s}` (one of: {})",
            SpeedKind::ALL.map(|k| k.as_str()).join(", ")
        )),
    }
}

fn method(s: &str) -> PyResult<Method> {
    match s.trim().to_ascii_lowercase().as_str() {
        "ols" => Ok(Method::Ols),
        "ma" => Ok(Method::Ma),
        "sma" => Ok(Method::Sma),
        _ => bail(format!(
            "method: unknown value `{s}` (one of: ols, ma, sma)"
        )),
    }
}

/// As the CLI's `--confidence` parser.
fn confidence(c: f64) -> PyResult<f64> {
    if c > 0.0 && c < 1.0 {
        Ok(c)
    } else {
        bail(format!("confidence must be in (0, 1), got {c}"))
    }
}

/// As the CLI's `parse_group`.
fn group(s: &str) -> PyResult<Group> {
    Group::parse(s).ok_or_else(|| {
        SurveyError::new_err(format!(
            "unknown class `{s}` (one of: lower-biped, full-biped, quadruped, hexapod, all)"
        ))
    })
}

fn load_table(path: Option<&str>, release: Option<&str>) -> Res<(Dataset, SurveyTable)> {
    let ds = Dataset::locate(path.map(Path::new))?;
    let table = ds.table(release)?;
    Ok((ds, table))
}

/// The compiled survey table as Parquet bytes (typed by the vocabulary, as the frozen
/// releases' robots.parquet) and its identity (version, sha256, frozen) as JSON.
#[pyfunction]
#[pyo3(signature = (release=None, path=None))]
fn dataset_parquet<'py>(
    py: Python<'py>,
    release: Option<String>,
    path: Option<String>,
) -> PyResult<(Bound<'py, PyBytes>, String)> {
    let (bytes, meta) = detached(py, || {
        let (ds, table) = load_table(path.as_deref(), release.as_deref())?;
        let bytes = table.to_parquet(&ds.vocab)?;
        let meta = serde_json::json!({
            "version": table.version,
            "sha256": table.sha256,
            "frozen": table.frozen,
            "columns": table.columns,
        });
        Ok((bytes, serde_json::to_string(&meta)?))
    })?;
    Ok((PyBytes::new(py, &bytes), meta))
}

/// `survey fit --format json` (the paper's Table 2 and the same fits for every class).
#[pyfunction]
#[pyo3(signature = (release=None, path=None, method_name="ols", confidence_level=0.95, bootstrap=None, seed=1))]
fn fit_json(
    py: Python<'_>,
    release: Option<String>,
    path: Option<String>,
    method_name: &str,
    confidence_level: f64,
    bootstrap: Option<u32>,
    seed: u64,
) -> PyResult<String> {
    let m = method(method_name)?;
    let level = confidence(confidence_level)?;
    if let Some(n) = bootstrap
        && !(100..=1_000_000).contains(&n)
    {
        return bail(format!("bootstrap: {n} resamples is not in 100..=1000000"));
    }
    detached(py, || {
        let (_, table) = load_table(path.as_deref(), release.as_deref())?;
        let bs = bootstrap.map(|n| robot_survey::regression::BootstrapConfig {
            replicates: n as usize,
            seed,
            level,
        });
        let t2 = table2::table2_with_bootstrap(&table, m, level, bs)?;
        Ok(report::json(&t2)?)
    })
}

/// `survey predict --format json` (with the required hip torque and actuators when the
/// reference is a walker design and a leg length is given).
#[pyfunction]
#[pyo3(signature = (leg_length_m=None, mass_budget_kg=None, cls="lower-biped", from_=None, release=None, path=None, confidence_level=0.95, torque_contact="fixed-material", torque_margin=2.0, table3_points=None, speed_kind="top"))]
#[allow(clippy::too_many_arguments)]
fn predict_json(
    py: Python<'_>,
    leg_length_m: Option<f64>,
    mass_budget_kg: Option<f64>,
    cls: &str,
    from_: Option<String>,
    release: Option<String>,
    path: Option<String>,
    confidence_level: f64,
    torque_contact: &str,
    torque_margin: f64,
    table3_points: Option<PathBuf>,
    speed_kind: &str,
) -> PyResult<String> {
    use robot_survey::analysis::prediction as p;
    let class = group(cls)?;
    let speed_kind = self::speed_kind(speed_kind)?;
    let level = confidence(confidence_level)?;
    let torque_contact = contact(torque_contact)?;
    detached(py, || {
        let (ds, table) = load_table(path.as_deref(), release.as_deref())?;
        let reference = match from_.as_deref() {
            None => None,
            Some(r) => Some(match r.strip_prefix("design:") {
                Some(name) => p::reference_from_design(&ds.files, name)?,
                None => p::reference_from_record(&table, r).ok_or_else(|| {
                    anyhow::anyhow!(
                        "--from {r}: no record `{r}` with leg length and mass in dataset {} (or use design:NAME)",
                        table.version
                    )
                })?,
            }),
        };
        let req = p::PredictRequest {
            leg_length_m,
            mass_budget_kg,
            reference,
            confidence: level,
            speed_kind,
        };
        let pred = p::predict(&table, class, &req)?;
        let design = from_.as_deref().and_then(|r| r.strip_prefix("design:"));
        let torque = match (design, leg_length_m) {
            (Some(name), Some(l)) => Some(robot_survey::study::torque_need::for_prediction(
                name,
                torque_contact,
                l,
                &pred.reference_masses(),
                torque_margin,
                table3_points.as_deref(),
            )?),
            _ => None,
        };
        Ok(report::prediction_json(&pred, torque.as_ref())?)
    })
}

/// A walker design (`dataset/walkers/*.toml`): read, change a number, simulate.
#[pyclass(name = "Design", module = "robot_survey._core", frozen, eq)]
#[derive(Clone, PartialEq)]
struct PyDesign {
    inner: Design,
}

#[pymethods]
impl PyDesign {
    /// A built-in design by name (mugatu, zippy, zippy-spherical, the -ref designs) or a
    /// path to a design TOML.
    #[new]
    #[pyo3(signature = (name_or_path="mugatu"))]
    fn new(name_or_path: &str) -> PyResult<Self> {
        Ok(PyDesign {
            inner: Design::resolve(name_or_path).map_err(survey_err)?,
        })
    }

    /// A design from TOML text; `origin` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, origin="<string>"))]
    fn from_toml(text: &str, origin: &str) -> PyResult<Self> {
        Ok(PyDesign {
            inner: Design::from_toml_str(text, origin).map_err(survey_err)?,
        })
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    #[getter]
    fn leg_length_m(&self) -> f64 {
        self.inner.geometry.leg_length_m
    }

    #[getter]
    fn mass_kg(&self) -> f64 {
        self.inner.mass.total_mass_kg
    }

    /// The number at a dotted path (`mass.total_mass_kg`, `mass.leg_inertia_box_over_l[0]`).
    fn get(&self, path: &str) -> PyResult<f64> {
        self.inner.value_at(path).map_err(survey_err)
    }

    /// A copy with the numbers at the given dotted paths set, validated as a file would be.
    fn with_values(&self, values: Vec<(String, f64)>) -> PyResult<Self> {
        let v: Vec<(&str, f64)> = values.iter().map(|(p, x)| (p.as_str(), *x)).collect();
        Ok(PyDesign {
            inner: self.inner.with_values(&v).map_err(survey_err)?,
        })
    }

    /// A copy with effects of the library switched on (`NAME=VALUE`, `NAME.PARAM=VALUE`, SI
    /// at this design's 1× size, as `survey gap synth --effect`).
    fn with_effects(&self, effects: Vec<String>) -> PyResult<Self> {
        Ok(PyDesign {
            inner: add_effects(&self.inner, &effects).map_err(survey_err)?,
        })
    }

    /// The design as TOML (a file `survey sim walk --design FILE` reads).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.inner).map_err(survey_err)
    }

    /// The design as JSON.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner).map_err(survey_err)
    }

    /// The `[[uncertain]]` parameters resolved (value, bounds, prior) as JSON.
    fn uncertain_json(&self) -> PyResult<String> {
        let u = self.inner.uncertain_params().map_err(survey_err)?;
        serde_json::to_string(&u).map_err(survey_err)
    }

    fn __repr__(&self) -> String {
        format!(
            "Design({:?}: L = {} m, m = {} kg)",
            self.inner.name, self.inner.geometry.leg_length_m, self.inner.mass.total_mass_kg
        )
    }
}

/// `design` with library effects added (values SI at its 1× size), as the gap module does.
fn add_effects(design: &Design, args: &[String]) -> Res<Design> {
    if args.is_empty() {
        return Ok(design.clone());
    }
    let lib = EffectLibrary::bundled()?;
    let settings = gap::library::parse_effect_args(&lib, design, args)?;
    let mut d = design.clone();
    for s in &settings {
        d.effects
            .push(lib.get(&s.effect)?.spec(design, &s.nondimensional)?);
    }
    Ok(d)
}

/// A design argument: a `Design` object, or a built-in name / TOML path.
fn design_of(obj: &Bound<'_, PyAny>) -> PyResult<Design> {
    if let Ok(d) = obj.cast::<PyDesign>() {
        return Ok(d.get().inner.clone());
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Design::resolve(&s.to_cow()?).map_err(survey_err);
    }
    Err(PyTypeError::new_err(
        "design: expected a Design, a built-in design name or a path to a design TOML",
    ))
}

/// `survey sim walk --format json`, and the trajectory as columns (None unless asked for).
#[pyfunction]
#[pyo3(signature = (design, leg_length_m=None, mass_law_name="l2", contact_rule="similar", duration_s=25.0, seed=None, torque_limit_nm=None, frequency_hz=None, effects=Vec::new(), trajectory=true))]
#[allow(clippy::too_many_arguments)]
fn walk<'py>(
    py: Python<'py>,
    design: &Bound<'py, PyAny>,
    leg_length_m: Option<f64>,
    mass_law_name: &str,
    contact_rule: &str,
    duration_s: f64,
    seed: Option<u64>,
    torque_limit_nm: Option<f64>,
    frequency_hz: Option<f64>,
    effects: Vec<String>,
    trajectory: bool,
) -> PyResult<(String, Option<Bound<'py, PyDict>>)> {
    let design = design_of(design)?;
    let opts = WalkOptions {
        leg_length_m,
        mass_law: mass_law(mass_law_name)?,
        contact_scaling: contact(contact_rule)?,
        duration_s,
        seed,
        torque_limit_nm,
        frequency_hz,
        record_trajectory: trajectory,
    };
    let result = detached(py, || {
        let d = add_effects(&design, &effects)?;
        Ok(sim::simulate_walk(&d, &opts)?)
    })?;
    let json = report::json(&result.report).map_err(survey_err)?;
    if !trajectory {
        return Ok((json, None));
    }
    let t = &result.trajectory;
    let cols = PyDict::new(py);
    let col = |f: fn(&sim::TrajectorySample) -> f64| -> Vec<f64> { t.iter().map(f).collect() };
    cols.set_item("t_s", col(|s| s.t_s))?;
    cols.set_item("x_m", col(|s| s.x_m))?;
    cols.set_item("y_m", col(|s| s.y_m))?;
    cols.set_item("z_m", col(|s| s.z_m))?;
    cols.set_item("roll_deg", col(|s| s.roll_deg))?;
    cols.set_item("pitch_deg", col(|s| s.pitch_deg))?;
    cols.set_item("yaw_deg", col(|s| s.yaw_deg))?;
    cols.set_item("hip_angle_deg", col(|s| s.hip_angle_deg))?;
    cols.set_item("hip_torque_nm", col(|s| s.hip_torque_nm))?;
    cols.set_item("peak_abs_torque_nm", col(|s| s.peak_abs_torque_nm))?;
    cols.set_item("positive_work_j", col(|s| s.positive_work_j))?;
    cols.set_item(
        "feet_in_contact",
        t.iter()
            .map(|s| u32::from(s.feet_in_contact))
            .collect::<Vec<u32>>(),
    )?;
    cols.set_item("left_normal_force_n", col(|s| s.normal_force_n[0]))?;
    cols.set_item("right_normal_force_n", col(|s| s.normal_force_n[1]))?;
    Ok((json, Some(cols)))
}

/// `survey sim min-torque --format json`.
#[pyfunction]
#[pyo3(signature = (design, leg_length_m=None, mass_law_name="l2", contact_rule="similar", duration_s=25.0, seed=None, seeds=2, tolerance=0.02, cap=2.0, effects=Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn min_torque_json(
    py: Python<'_>,
    design: &Bound<'_, PyAny>,
    leg_length_m: Option<f64>,
    mass_law_name: &str,
    contact_rule: &str,
    duration_s: f64,
    seed: Option<u64>,
    seeds: u64,
    tolerance: f64,
    cap: f64,
    effects: Vec<String>,
) -> PyResult<String> {
    let design = design_of(design)?;
    if seeds > 20 {
        return bail(format!("seeds: {seeds} is not in 0..=20"));
    }
    let opts = robot_survey::study::MinTorqueOptions {
        walk: WalkOptions {
            leg_length_m,
            mass_law: mass_law(mass_law_name)?,
            contact_scaling: contact(contact_rule)?,
            duration_s,
            seed,
            record_trajectory: false,
            ..WalkOptions::default()
        },
        seeds,
        rel_tol: tolerance,
        cap_over_mgl: cap,
        start_nm: None,
        start_bracket_nm: None,
    };
    detached(py, || {
        let d = add_effects(&design, &effects)?;
        let result = robot_survey::study::min_torque(&d, &opts)?;
        Ok(report::json(&result)?)
    })
}

/// Counts Table III points and hands each to a Python callable `(done, total, message)`
/// (taking the GIL for the call only; its errors are ignored: it only shows progress).
struct Progress {
    callback: Option<Py<PyAny>>,
    done: AtomicUsize,
    total: usize,
}

impl table3::Observer for Progress {
    fn point_done(&self, p: &Table3Point, resumed: bool) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let Some(cb) = &self.callback else { return };
        let message = p.progress_label(resumed);
        Python::attach(|py| {
            if let Err(e) = cb.call1(py, (done, self.total, message)) {
                e.print(py);
            }
        });
    }
}

/// `survey sim table3 --format json`; `progress(done, total, message)` after every size.
#[pyfunction]
#[pyo3(signature = (designs, mass_laws, contacts, sizes=36, leg_lengths_m=None, duration_s=25.0, seeds=2, tolerance=0.02, cap=2.0, points=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn table3_json(
    py: Python<'_>,
    designs: Vec<Bound<'_, PyAny>>,
    mass_laws: Vec<String>,
    contacts: Vec<String>,
    sizes: u64,
    leg_lengths_m: Option<Vec<f64>>,
    duration_s: f64,
    seeds: u64,
    tolerance: f64,
    cap: f64,
    points: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let designs = designs
        .iter()
        .map(design_of)
        .collect::<PyResult<Vec<_>>>()?;
    let contacts = contacts
        .iter()
        .map(|c| contact(c))
        .collect::<PyResult<Vec<_>>>()?;
    if !(4..=1000).contains(&sizes) {
        return bail(format!("sizes: {sizes} is not in 4..=1000"));
    }
    if seeds > 20 {
        return bail(format!("seeds: {seeds} is not in 0..=20"));
    }
    let mut spec = Table3Spec::paper(designs, contacts);
    spec.mass_laws = mass_laws
        .iter()
        .map(|m| mass_law(m))
        .collect::<PyResult<Vec<_>>>()?;
    match leg_lengths_m {
        Some(ls) => {
            if let Some(bad) = ls.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
                return bail(format!(
                    "--leg-lengths: {bad} is not a positive length in metres"
                ));
            }
            spec.leg_lengths_m = ls;
        }
        None => spec.leg_lengths_m = table3::table3_leg_lengths(sizes as usize),
    }
    spec.duration_at_design_size_s = duration_s;
    spec.seeds = seeds;
    spec.rel_tol = tolerance;
    spec.cap_over_mgl = cap;
    let observer = Progress {
        callback: progress,
        done: AtomicUsize::new(0),
        total: spec.chains().len() * spec.leg_lengths_m.len(),
    };
    detached(py, || {
        let run =
            robot_survey::study::run_table3(&spec, Shard::WHOLE, points.as_deref(), &observer)?;
        let table = run
            .table
            .ok_or_else(|| anyhow::anyhow!("the run produced no table"))?;
        Ok(report::json(&table)?)
    })
}

/// `survey gap effects --format json`.
#[pyfunction]
#[pyo3(signature = (design=None))]
fn gap_effects_json(design: Option<&Bound<'_, PyAny>>) -> PyResult<String> {
    let d = match design {
        Some(d) => design_of(d)?,
        None => Design::builtin("mugatu").map_err(survey_err)?,
    };
    let lib = EffectLibrary::bundled().map_err(survey_err)?;
    let list: Vec<_> = lib.effects.iter().map(|e| e.summary(&d)).collect();
    report::json(&list).map_err(survey_err)
}

/// Trials from a file (`path`, as `--trials FILE`) or from CSV text (`text`, named `origin`
/// in errors, relative trajectory files resolved against `base_dir`).
fn trials_of(
    path: Option<&Path>,
    text: Option<&str>,
    origin: &str,
    base_dir: &Path,
) -> Res<TrialSet> {
    Ok(match (path, text) {
        (Some(p), _) => TrialSet::read(p)?,
        (None, Some(t)) => TrialSet::parse(t, origin, base_dir)?,
        (None, None) => anyhow::bail!("no trials given"),
    })
}

/// Trials given as a path or a text, or none ([`trials_of`] when either is given): the
/// optional conditions of `gap_synth_csv` and reference of `gap_diagnose_json`.
fn optional_trials_of(
    path: Option<&Path>,
    text: Option<&str>,
    origin: &str,
    base_dir: &Path,
) -> Res<Option<TrialSet>> {
    if path.is_none() && text.is_none() {
        return Ok(None);
    }
    trials_of(path, text, origin, base_dir).map(Some)
}

/// `survey gap synth`: the trials CSV it writes (default conditions, or those of a trials
/// file/text), with effects (`NAME=VALUE`), wrong parameters (`PATH=VALUE`) and noise.
#[pyfunction]
#[pyo3(signature = (design="mugatu", effects=Vec::new(), set=Vec::new(), noise=0.05, seed=0, conditions_path=None, conditions_text=None, origin="<DataFrame>", base_dir=None))]
#[allow(clippy::too_many_arguments)]
fn gap_synth_csv(
    py: Python<'_>,
    design: &str,
    effects: Vec<String>,
    set: Vec<String>,
    noise: f64,
    seed: u64,
    conditions_path: Option<PathBuf>,
    conditions_text: Option<String>,
    origin: &str,
    base_dir: Option<PathBuf>,
) -> PyResult<String> {
    let origin = origin.to_string();
    let design_name = design.to_string();
    detached(py, || {
        let lib = EffectLibrary::bundled()?;
        let design = Design::resolve(&design_name)?;
        let (opts, command) = gap::synth::SynthOptions::from_args(
            &lib,
            &design,
            &design_name,
            &effects,
            &set,
            noise,
            seed,
        )?;
        let conditions = optional_trials_of(
            conditions_path.as_deref(),
            conditions_text.as_deref(),
            &origin,
            base_dir.as_deref().unwrap_or(Path::new(".")),
        )?;
        let out = gap::synth::synthesize(&lib, &opts, conditions, &command, &Silent)?;
        Ok(out.to_csv()?)
    })
}

/// `survey gap diagnose --format json`, and the wall-clock timing (not part of the result).
/// `reference_*`: the reference trials (`survey gap diagnose --reference`), as path or text
/// like the trials; `undeclared` false is `--no-undeclared`, `criterion` a criterion file
/// (`--criterion`).
#[pyfunction]
#[pyo3(signature = (path=None, text=None, origin="<DataFrame>", base_dir=None, effects=Vec::new(), grid=9, default_sd=0.10, calibrate=true, reference_path=None, reference_text=None, reference_origin="<DataFrame>", undeclared=true, criterion=None))]
#[allow(clippy::too_many_arguments)]
fn gap_diagnose_json(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
    origin: &str,
    base_dir: Option<PathBuf>,
    effects: Vec<String>,
    grid: usize,
    default_sd: f64,
    calibrate: bool,
    reference_path: Option<PathBuf>,
    reference_text: Option<String>,
    reference_origin: &str,
    undeclared: bool,
    criterion: Option<PathBuf>,
) -> PyResult<(String, String)> {
    let origin = origin.to_string();
    let reference_origin = reference_origin.to_string();
    detached(py, || {
        let lib = EffectLibrary::bundled()?;
        let base = base_dir.as_deref().unwrap_or(Path::new("."));
        let set = trials_of(path.as_deref(), text.as_deref(), &origin, base)?;
        let mut opts = DiagnoseOptions::new()?;
        opts.reference = optional_trials_of(
            reference_path.as_deref(),
            reference_text.as_deref(),
            &reference_origin,
            base,
        )?;
        opts.effects = effects;
        opts.grid_points = grid;
        opts.default_relative_sd = default_sd;
        opts.calibrate = calibrate;
        opts.undeclared = undeclared;
        if let Some(c) = criterion {
            opts.criterion = gap::criterion::Criterion::read(&c)?;
        }
        let (d, timing) = gap::diagnose(&set, &lib, &opts, &Silent)?;
        Ok((report::json(&d)?, serde_json::to_string(&timing)?))
    })
}

/// The trials CSV columns, in order (dataset/trials/README.md).
#[pyfunction]
fn trial_columns() -> Vec<String> {
    gap::trials::columns()
}

/// The names of the built-in walker designs.
#[pyfunction]
fn builtin_designs() -> Vec<&'static str> {
    sim::BUILTIN_DESIGNS.iter().map(|(n, _, _)| *n).collect()
}

/// The binding's crate version (the library's version is the same workspace's).
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SurveyError", m.py().get_type::<SurveyError>())?;
    m.add_class::<PyDesign>()?;
    m.add_function(wrap_pyfunction!(dataset_parquet, m)?)?;
    m.add_function(wrap_pyfunction!(fit_json, m)?)?;
    m.add_function(wrap_pyfunction!(predict_json, m)?)?;
    m.add_function(wrap_pyfunction!(walk, m)?)?;
    m.add_function(wrap_pyfunction!(min_torque_json, m)?)?;
    m.add_function(wrap_pyfunction!(table3_json, m)?)?;
    m.add_function(wrap_pyfunction!(gap_effects_json, m)?)?;
    m.add_function(wrap_pyfunction!(gap_synth_csv, m)?)?;
    m.add_function(wrap_pyfunction!(gap_diagnose_json, m)?)?;
    m.add_function(wrap_pyfunction!(trial_columns, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_designs, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
