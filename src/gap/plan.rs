//! The benchmark's plan: its options, its suites (conditions and shared walks) and its cases
//! — generated from the design and the library, read back from another points file, or made
//! from folders of Drake trials.
//!
//! An effect's *identification threshold* at a noise level is the smallest magnitude at which
//! the diagnosis names it on its expected (noise-free) trials: the effect alone reaches the
//! criterion's threshold there. Single effects are benchmarked at multiples of it, pairs at
//! twice theirs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::cache::SimCache;
use super::cases::{BenchmarkCases, resolve_design};
use super::diagnose::{DiagnoseOptions, diagnose_conditions};
use super::error::GapError;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::simulate::{Condition, SimMetrics, resolve};
use super::synth::expected_trials;
use super::trials::{Trial, TrialSet};
use super::waveform::LogSample;
use crate::progress::{Observer, Silent};
use crate::sim::Design;

/// The kind of a pair case run on its expected (noise-free) trials.
pub const EXPECTED_PAIR: &str = "pair-expected";

/// Every kind of case a plan holds (`--kinds`).
pub const KINDS: [&str; 7] = [
    "null",
    "effect",
    "pair",
    EXPECTED_PAIR,
    "parameter",
    "compound",
    "drake",
];

/// Drake's no-effect trials (a file stem), the reference of a folder's cases.
pub const DRAKE_NONE: &str = "trials-none";

#[derive(Clone, Debug, Serialize)]
pub struct BenchmarkOptions {
    pub design: String,
    /// Noise levels of the null and single-effect cases.
    pub noise_levels: Vec<f64>,
    /// Null cases per noise level (main suite).
    pub null_cases: u64,
    /// Seeds per non-null case.
    pub seeds: u64,
    /// Single effects at these multiples of their identification threshold.
    pub multiples: Vec<f64>,
    /// Noise of the pair, parameter-error and Drake cases.
    pub pair_noise: f64,
    pub pair_multiple: f64,
    /// Nominal-parameter errors: each a list of `path=value` (the design at 1×).
    pub parameter_errors: Vec<Vec<(String, f64)>>,
    pub parameter_noise: Vec<f64>,
    /// Null cases of the one-robot suite (0: no one-robot suite).
    pub one_robot_null_cases: u64,
    /// Compound cases: each of these errors with every effect at the pair multiple.
    pub compound_errors: Vec<Vec<(String, f64)>>,
    pub effects: Vec<String>,
    /// Folders of Drake trials diagnosed as they are, and through their no-effect trials.
    pub drake_dirs: Vec<PathBuf>,
    pub drake_reference_dirs: Vec<PathBuf>,
    pub drake_seeds: u64,
    /// The design the Drake cases are diagnosed against, in place of their files' (e.g.
    /// `mugatu-ref-sap`, the reference with SAP's convex friction cone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drake_design: Option<String>,
    /// The diagnosis of every case: the undeclared numbers among the suspects, the criterion's
    /// priors, the explanations the search confirms.
    pub undeclared: bool,
    pub prior: super::criterion::ClassPriors,
    pub search_confirm: usize,
    /// Cases whose key holds one of these are diagnosed a second time with every explanation
    /// confirmed by walks, to measure what the search misses.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub exhaustive: Vec<String>,
    /// The cases of this points file instead of planned ones (not part of the signature).
    #[serde(skip)]
    pub cases_from: Option<PathBuf>,
}

impl BenchmarkOptions {
    /// The benchmark of a design: its out-of-library cases from
    /// `dataset/benchmarks/<design>.toml`, or derived from the design ([`BenchmarkCases`]).
    pub fn standard(design: &str) -> Result<BenchmarkOptions, GapError> {
        Self::with_cases(design, BenchmarkCases::for_design(design)?)
    }

    /// The benchmark of a design with these out-of-library cases.
    pub fn with_cases(design: &str, cases: BenchmarkCases) -> Result<BenchmarkOptions, GapError> {
        Ok(BenchmarkOptions {
            design: design.to_string(),
            noise_levels: vec![0.03, 0.05],
            null_cases: 300,
            seeds: 1,
            multiples: vec![1.0, 2.0, 4.0],
            pair_noise: 0.03,
            pair_multiple: 2.0,
            parameter_errors: cases.parameter_errors,
            parameter_noise: vec![0.03, 0.05],
            one_robot_null_cases: 300,
            compound_errors: cases.compound_errors,
            effects: Vec::new(),
            drake_dirs: Vec::new(),
            drake_reference_dirs: Vec::new(),
            drake_seeds: 3,
            drake_design: None,
            undeclared: true,
            prior: super::criterion::Criterion::bundled()?.prior,
            search_confirm: super::posterior::Search::default().confirm,
            exhaustive: Vec::new(),
            cases_from: None,
        })
    }
}

/// What a case's trials are made from.
#[derive(Clone, Debug, PartialEq)]
pub enum Truth {
    /// The simulator under a setting: parameter values (path, value at 1×) and effects
    /// (name, magnitude in SI at 1×).
    Sim {
        params: Vec<(String, f64)>,
        effects: Vec<(String, f64)>,
    },
    /// A Drake trials file of a folder, and the effects Drake added.
    Drake {
        folder: String,
        file: String,
        reference: bool,
        effects: Vec<(String, f64)>,
    },
}

/// One case to run.
#[derive(Clone, Debug)]
pub struct CaseSpec {
    pub key: String,
    pub suite: String,
    pub kind: String,
    pub noise: f64,
    pub seed: u64,
    pub calibrate: bool,
    pub multiple: Option<f64>,
    pub truth: Truth,
}

/// A suite's conditions and the walks its cases share.
pub struct Suite {
    pub name: String,
    pub base: TrialSet,
    pub conditions: Vec<Condition>,
    pub cache: SimCache,
}

impl Suite {
    fn new(name: &str, base: TrialSet) -> Result<Suite, GapError> {
        let conditions = resolve(&base)?;
        Ok(Suite {
            name: name.into(),
            base,
            conditions,
            cache: SimCache::default(),
        })
    }
}

/// One Drake trials file: its metrics as the truth, and the robot logs its rows name (read
/// once; each case adds its own sensor noise).
pub struct DrakeFile {
    pub truth: Vec<SimMetrics>,
    pub logs: Vec<Option<Vec<LogSample>>>,
}

/// Everything the cases of a run need.
pub struct Plan {
    pub cases: Vec<CaseSpec>,
    /// Identification thresholds (SI) per noise level and effect (empty when the cases come
    /// from a points file).
    pub thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
    pub suites: Vec<Suite>,
    /// Drake files by (folder, file stem).
    pub drake: BTreeMap<(String, String), DrakeFile>,
}

/// The setting a simulated truth is: parameter values and effect magnitudes (SI at 1×).
pub fn truth_setting(
    lib: &EffectLibrary,
    design: &Design,
    params: &[(String, f64)],
    effects: &[(String, f64)],
) -> Result<ModelSetting, GapError> {
    let mut s = ModelSetting::default();
    for (p, v) in params {
        s.params.push((design.name.clone(), p.clone(), *v));
    }
    for (e, v) in effects {
        let def = lib.get(e)?;
        s.effects
            .push(def.setting(v / def.magnitude().scale.value(design)));
    }
    Ok(s)
}

/// Builds the list of cases (deterministic; the same for every shard).
pub fn plan(
    lib: &EffectLibrary,
    opts: &BenchmarkOptions,
    progress: &dyn Observer,
) -> Result<Plan, GapError> {
    let design = resolve_design(&opts.design)?;
    // The Drake folders are read (names, conditions and logs checked) first: a bad file
    // fails at once.
    let mut drake_cases = Vec::new();
    let mut drake = BTreeMap::new();
    let mut suites = Vec::new();
    for (dir, reference) in opts
        .drake_dirs
        .iter()
        .map(|d| (d, false))
        .chain(opts.drake_reference_dirs.iter().map(|d| (d, true)))
    {
        let folder = DrakeFolder::read(opts, dir, reference)?;
        drake_cases.extend(folder.cases(opts));
        if !suites.iter().any(|s: &Suite| s.name == folder.suite) {
            suites.push(Suite::new(&folder.suite, folder.base.clone())?);
        }
        for (stem, f) in folder.files {
            drake.insert((folder.name.clone(), stem), f);
        }
    }
    progress.stage("default conditions");
    let base = |origin: String, trials| TrialSet {
        origin,
        base_dir: PathBuf::from("."),
        trials,
    };
    let main = Suite::new(
        "main",
        base(
            format!("benchmark conditions of {}", opts.design),
            super::synth::default_conditions(&opts.design)?,
        ),
    )?;
    let one = Suite::new(
        "one-robot",
        base(
            format!("one-robot conditions of {}", opts.design),
            one_robot_conditions(&opts.design)?,
        ),
    )?;
    let (mut cases, thresholds) = match &opts.cases_from {
        Some(file) => (cases_from_points(file)?, BTreeMap::new()),
        None => {
            let thr = Thresholds::of_main(lib, opts, &main, progress)?;
            (Planner::new(lib, opts, &design, &thr).cases(), thr.table)
        }
    };
    cases.retain(|c| !c.key.starts_with("drake/"));
    cases.extend(drake_cases);
    suites.push(main);
    suites.push(one);
    let mut seen = std::collections::HashSet::new();
    cases.retain(|c| seen.insert(c.key.clone()));
    Ok(Plan {
        cases,
        thresholds,
        suites,
        drake,
    })
}

/// The conditions of the one-robot suite: the design at its own size, drive frequency
/// 0.97–1.03 × its own, amplitude ±4° (servo designs), payload +10 % and +20 %, slope ±1°.
pub fn one_robot_conditions(design_name: &str) -> Result<Vec<Trial>, GapError> {
    let d = resolve_design(design_name)?;
    let f0 = d.controller().frequency_hz().unwrap_or(1.0);
    let l = d.geometry.leg_length_m;
    let m0 = d.mass.total_mass_kg;
    let a0 = match d.control {
        crate::sim::design::ControlSpec::ServoSine { amplitude_deg, .. } => Some(amplitude_deg),
        _ => None,
    };
    let mut out = Vec::new();
    let mut add = |label: &str, f: f64, a: Option<f64>, m: Option<f64>, s: Option<f64>| {
        let mut t = Trial::condition(design_name, l);
        t.label = label.to_string();
        t.frequency_hz = Some((f0 * f * 1e6).round() / 1e6);
        t.amplitude_deg = a;
        t.mass_kg = m.map(|k| (m0 * k * 1e6).round() / 1e6);
        t.slope_deg = s;
        out.push(t);
    };
    for k in [0.97, 1.0, 1.03] {
        add(&format!("f{k}x"), k, None, None, None);
    }
    if let Some(a) = a0 {
        add("A-4", 1.0, Some(a - 4.0), None, None);
        add("A+4", 1.0, Some(a + 4.0), None, None);
    } else {
        add("f0.985x", 0.985, None, None, None);
        add("f1.015x", 1.015, None, None, None);
    }
    add("m+10%", 1.0, None, Some(1.1), None);
    add("m+20%", 1.0, None, Some(1.2), None);
    add("m+20%-f0.97x", 0.97, None, Some(1.2), None);
    add("m+20%-f1.03x", 1.03, None, Some(1.2), None);
    add("slope+1", 1.0, None, None, Some(1.0));
    add("slope-1", 1.0, None, None, Some(-1.0));
    add("slope+1-m+10%", 1.0, None, Some(1.1), Some(1.0));
    Ok(out)
}

/// The magnitude (SI) `multiple` times as strong as `threshold`, away from the effect's off
/// value (in log), kept inside the plausible range by a margin of 15 % (in log).
pub(crate) fn magnitude_at(
    lib: &EffectLibrary,
    design: &Design,
    effect: &str,
    threshold: f64,
    multiple: f64,
) -> f64 {
    let Ok(def) = lib.get(effect) else {
        return threshold;
    };
    let p = def.magnitude();
    let scale = p.scale.value(design);
    let off = p.off_nondimensional(design, &def.name) * scale;
    let [lo, hi] = [p.range[0] * scale * 1.15, p.range[1] * scale / 1.15];
    let v = if off == 0.0 {
        threshold * multiple
    } else if off.is_infinite() {
        threshold / multiple
    } else {
        (off.ln() + multiple * (threshold.ln() - off.ln())).exp()
    };
    v.clamp(lo, hi)
}

/// The main suite's identification thresholds per noise level (keyed by `{noise}`).
struct Thresholds {
    /// Every effect, `None` when not identifiable within its range (for the report).
    table: BTreeMap<String, Vec<(String, Option<f64>)>>,
    /// With calibration.
    on: BTreeMap<String, BTreeMap<String, f64>>,
}

impl Thresholds {
    /// At every noise level of the null and single cases and at the pair noise.
    fn of_main(
        lib: &EffectLibrary,
        opts: &BenchmarkOptions,
        main: &Suite,
        progress: &dyn Observer,
    ) -> Result<Thresholds, GapError> {
        let design = resolve_design(&opts.design)?;
        let search = Identify {
            lib,
            opts,
            design: &design,
            main,
        };
        let mut levels: Vec<f64> = opts.noise_levels.clone();
        levels.push(opts.pair_noise);
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        let mut out = Thresholds {
            table: BTreeMap::new(),
            on: BTreeMap::new(),
        };
        let names: Vec<String> = lib
            .subset(&opts.effects)?
            .iter()
            .map(|e| e.name.clone())
            .collect();
        for &noise in &levels {
            progress.stage(&format!(
                "identification thresholds at {} % noise",
                noise * 100.0
            ));
            let mut row = Vec::new();
            let mut on = BTreeMap::new();
            for e in &names {
                let t = search.threshold(e, noise)?;
                if let Some(t) = t {
                    on.insert(e.clone(), t);
                }
                row.push((e.clone(), t));
            }
            out.table.insert(format!("{noise}"), row);
            out.on.insert(format!("{noise}"), on);
        }
        Ok(out)
    }

    /// Every effect of the table, in library order.
    fn effects(&self) -> Vec<String> {
        let first = self.table.values().next();
        first.map_or_else(Vec::new, |r| r.iter().map(|(e, _)| e.clone()).collect())
    }

    fn get(&self, noise: f64, e: &str) -> Option<f64> {
        self.on
            .get(&format!("{noise}"))
            .and_then(|m| m.get(e))
            .copied()
    }
}

/// The search for the identification thresholds: effects alone on the expected trials of the
/// main suite, diagnosed as the benchmark's cases are.
struct Identify<'a> {
    lib: &'a EffectLibrary,
    opts: &'a BenchmarkOptions,
    design: &'a Design,
    main: &'a Suite,
}

impl Identify<'_> {
    /// The posterior of effect `e` alone on its expected trials at magnitude `m` (SI).
    fn posterior_at(&self, e: &str, m: f64, noise: f64) -> Result<f64, GapError> {
        let (lib, design, main) = (self.lib, self.design, self.main);
        let setting = truth_setting(lib, design, &[], &[(e.to_string(), m)])?;
        let walks = main.cache.get(&main.conditions, lib, &setting, &Silent)?;
        let truth: Vec<SimMetrics> = walks.iter().map(|w| w.metrics).collect();
        let set = TrialSet {
            origin: format!("{e}={m} expected"),
            base_dir: PathBuf::from("."),
            trials: expected_trials(&main.base.trials, &truth, noise, "threshold"),
        };
        let mut d = DiagnoseOptions::new()?;
        d.undeclared = self.opts.undeclared;
        d.criterion.prior = self.opts.prior;
        // Planning magnitudes needs the posterior's order of magnitude, not its last digit: the
        // surrogate's, unrefined.
        d.search.confirm = 0;
        // A magnitude at which the walker falls everywhere leaves nothing to measure.
        let diag = match diagnose_conditions(&set, &main.conditions, lib, &d, &main.cache, &Silent)
        {
            Ok((diag, _)) => diag,
            Err(GapError::File { .. }) => return Ok(0.0),
            Err(e) => return Err(e),
        };
        let alias = lib
            .get(e)
            .ok()
            .and_then(|def| def.replaces.clone())
            .filter(|f| design.uncertain.iter().any(|u| &u.path == f))
            .map(|f| format!("{}:{f}", design.name));
        let label = alias.unwrap_or_else(|| e.to_string());
        Ok(diag
            .posterior
            .iter()
            .find(|l| l.explanation == label)
            .map_or(0.0, |l| l.probability))
    }

    /// The smallest magnitude at which effect `e` alone reaches the criterion's threshold on
    /// its expected trials at `noise`: bisection in log magnitude from just off to the range's
    /// strong end (six halvings). None when even the strong end does not reach it.
    fn threshold(&self, e: &str, noise: f64) -> Result<Option<f64>, GapError> {
        let (lib, design) = (self.lib, self.design);
        let t = super::criterion::Criterion::bundled()?.decision.threshold;
        let def = lib.get(e)?;
        let p = def.magnitude();
        let scale = p.scale.value(design);
        let off = p.off_nondimensional(design, &def.name) * scale;
        let (lo, hi) = (p.range[0] * scale, p.range[1] * scale);
        // From the weak end toward the strong one, in log.
        let (weak, strong) = if off.is_infinite() || off > hi {
            (hi, lo)
        } else if off > 0.0 && off > lo {
            (off, lo)
        } else {
            (lo, hi)
        };
        let at = |u: f64| (weak.ln() + u * (strong.ln() - weak.ln())).exp();
        let strongest = magnitude_at(lib, design, e, at(1.0), 1.0);
        if self.posterior_at(e, strongest, noise)? < t {
            return Ok(None);
        }
        let (mut a, mut b) = (0.0, 1.0);
        for _ in 0..6 {
            let mid = 0.5 * (a + b);
            if self.posterior_at(e, at(mid), noise)? >= t {
                b = mid;
            } else {
                a = mid;
            }
        }
        Ok(Some(super::synth::round_sig(at(b), 3)))
    }
}

/// Makes the simulated cases of the main and one-robot suites, in the plan's order.
struct Planner<'a> {
    lib: &'a EffectLibrary,
    opts: &'a BenchmarkOptions,
    design: &'a Design,
    thr: &'a Thresholds,
    cases: Vec<CaseSpec>,
}

/// What the cases of one kind in one suite share.
#[derive(Clone, Copy)]
struct Batch<'k> {
    suite: &'k str,
    kind: &'k str,
    noise: f64,
    multiple: Option<f64>,
}

impl<'k> Batch<'k> {
    fn new(suite: &'k str, kind: &'k str, noise: f64, multiple: Option<f64>) -> Self {
        Batch {
            suite,
            kind,
            noise,
            multiple,
        }
    }

    /// The case of `seed` with this truth; its key is the truth.
    fn case(&self, seed: u64, params: &[(String, f64)], effects: &[(String, f64)]) -> CaseSpec {
        let key = format!(
            "{}/{}/{}/{}/n{}/s{seed}",
            self.suite,
            self.kind,
            pairs(effects),
            pairs(params),
            self.noise,
        );
        CaseSpec {
            key,
            suite: self.suite.into(),
            kind: self.kind.into(),
            noise: self.noise,
            seed,
            calibrate: true,
            multiple: self.multiple,
            truth: Truth::Sim {
                params: params.to_vec(),
                effects: effects.to_vec(),
            },
        }
    }
}

/// The `;`-separated items of a points-file cell.
pub fn split(s: &str) -> Vec<String> {
    s.split(';')
        .filter(|x| !x.is_empty())
        .map(str::to_string)
        .collect()
}

/// `name=value` pairs of a points-file cell.
pub fn parse_pairs(s: &str) -> Vec<(String, f64)> {
    split(s)
        .into_iter()
        .filter_map(|p| {
            let (k, v) = p.split_once('=')?;
            Some((k.to_string(), v.parse().ok()?))
        })
        .collect()
}

/// `name=value` pairs as a points-file cell (what [`parse_pairs`] reads).
pub fn pairs(v: &[(String, f64)]) -> String {
    v.iter()
        .map(|(k, x)| format!("{k}={x}"))
        .collect::<Vec<_>>()
        .join(";")
}

impl<'a> Planner<'a> {
    fn new(
        lib: &'a EffectLibrary,
        opts: &'a BenchmarkOptions,
        design: &'a Design,
        thr: &'a Thresholds,
    ) -> Self {
        Planner {
            lib,
            opts,
            design,
            thr,
            cases: Vec::new(),
        }
    }

    fn push(
        &mut self,
        batch: Batch,
        seeds: u64,
        params: &[(String, f64)],
        effects: &[(String, f64)],
    ) {
        self.cases
            .extend((0..seeds).map(|seed| batch.case(seed, params, effects)));
    }

    fn mag(&self, e: &str, noise: f64, k: f64) -> Option<f64> {
        let t = self.thr.get(noise, e)?;
        Some(magnitude_at(self.lib, self.design, e, t, k))
    }

    /// Nulls, single effects, pairs, compounds, parameter errors; then the one-robot suite.
    fn cases(mut self) -> Vec<CaseSpec> {
        let (o, b) = (self.opts, Batch::new);
        let pair = |kind| b("main", kind, o.pair_noise, Some(o.pair_multiple));
        let names = self.thr.effects();
        for &noise in &o.noise_levels {
            self.push(b("main", "null", noise, None), o.null_cases, &[], &[]);
        }
        for &noise in &o.noise_levels {
            for e in &names {
                for &k in &o.multiples {
                    if let Some(m) = self.mag(e, noise, k) {
                        let effect = [(e.clone(), m)];
                        self.push(b("main", "effect", noise, Some(k)), o.seeds, &[], &effect);
                    }
                }
            }
        }
        for (i, x) in names.iter().enumerate() {
            for y in &names[i + 1..] {
                let (Some(mx), Some(my)) = (
                    self.mag(x, o.pair_noise, o.pair_multiple),
                    self.mag(y, o.pair_noise, o.pair_multiple),
                ) else {
                    continue;
                };
                let effects = [(x.clone(), mx), (y.clone(), my)];
                self.push(pair("pair"), o.seeds, &[], &effects);
                self.push(pair(EXPECTED_PAIR), 1, &[], &effects);
            }
        }
        for params in &o.compound_errors {
            for e in &names {
                if let Some(m) = self.mag(e, o.pair_noise, o.pair_multiple) {
                    self.push(pair("compound"), o.seeds, params, &[(e.clone(), m)]);
                }
            }
        }
        for params in &o.parameter_errors {
            for &noise in &o.parameter_noise {
                self.push(b("main", "parameter", noise, None), o.seeds, params, &[]);
            }
        }
        if o.one_robot_null_cases > 0 {
            self.one_robot(&names);
        }
        self.cases
    }

    /// The one-robot suite: nulls, every effect at twice its threshold, parameter errors.
    fn one_robot(&mut self, names: &[String]) {
        let o = self.opts;
        let one = |kind, multiple| Batch::new("one-robot", kind, 0.05, multiple);
        self.push(one("null", None), o.one_robot_null_cases, &[], &[]);
        for e in names {
            if let Some(m) = self.mag(e, 0.05, 2.0) {
                self.push(one("effect", Some(2.0)), o.seeds, &[], &[(e.clone(), m)]);
            }
        }
        for params in &o.parameter_errors {
            self.push(one("parameter", None), o.seeds, params, &[]);
        }
    }
}

/// The simulated cases of another benchmark's points file: each key names its suite, kind,
/// truth, noise and seed (`suite/kind/effects/params/n{noise}/s{seed}[/nocal]`), so the same
/// truths and noise draws are diagnosed again. Drake rows are left to the Drake folders.
pub fn cases_from_points(file: &Path) -> Result<Vec<CaseSpec>, GapError> {
    let (_, rows) = crate::checkpoint::read_points::<KeyOnly>(file)?;
    let bad =
        |key: &str, why: &str| GapError::file(file.display(), format!("case key {key:?}: {why}"));
    let mut out = Vec::new();
    for r in rows {
        let key = r.key;
        if key.starts_with("drake/") {
            continue;
        }
        let parts: Vec<&str> = key.split('/').collect();
        if parts.len() < 6 {
            return Err(bad(&key, "expected suite/kind/effects/params/nNOISE/sSEED"));
        }
        let noise: f64 = parts[4]
            .strip_prefix('n')
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| bad(&key, "no noise"))?;
        let seed: u64 = parts[5]
            .strip_prefix('s')
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| bad(&key, "no seed"))?;
        let calibrate = parts.get(6) != Some(&"nocal");
        out.push(CaseSpec {
            suite: parts[0].to_string(),
            kind: parts[1].to_string(),
            noise,
            seed,
            calibrate,
            multiple: r.multiple,
            truth: Truth::Sim {
                effects: parse_pairs(parts[2]),
                params: parse_pairs(parts[3]),
            },
            key,
        });
    }
    Ok(out)
}

/// The key and multiple of a row of any benchmark's points file.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, Serialize)]
struct KeyOnly {
    key: String,
    multiple: Option<f64>,
}

impl crate::checkpoint::SweepPoint for KeyOnly {
    fn key(&self) -> String {
        self.key.clone()
    }
}

/// A folder of Drake trials files: the suite of their conditions and every file's truth.
struct DrakeFolder {
    name: String,
    suite: String,
    reference: bool,
    base: TrialSet,
    files: Vec<(String, DrakeFile)>,
    effects: Vec<(String, Vec<(String, f64)>)>,
}

impl DrakeFolder {
    /// Reads every `trials-*.csv` of `dir` (named by the effects Drake added,
    /// [`drake_effects`]); they must share their conditions.
    fn read(opts: &BenchmarkOptions, dir: &Path, reference: bool) -> Result<DrakeFolder, GapError> {
        let name = dir
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or("drake")
            .to_string();
        let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(GapError::read(dir))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|f| f.to_str())
                    .is_some_and(|f| f.starts_with("trials-") && f.ends_with(".csv"))
            })
            .collect();
        paths.sort();
        if reference
            && !paths
                .iter()
                .any(|f| f.file_stem() == Some(DRAKE_NONE.as_ref()))
        {
            return Err(GapError::file(
                dir.display(),
                format!("a folder diagnosed through its reference needs {DRAKE_NONE}.csv"),
            ));
        }
        let mut files = Vec::new();
        let mut effects = Vec::new();
        let mut base: Option<TrialSet> = None;
        for f in paths {
            let mut set = TrialSet::read(&f)?;
            if let Some(d) = &opts.drake_design {
                for t in set.trials.iter_mut() {
                    t.design = d.clone();
                }
            }
            let stem = f
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("")
                .to_string();
            let added = drake_effects(&stem).ok_or_else(|| GapError::File {
                path: f.display().to_string(),
                message: format!(
                    "a Drake trials file is named {DRAKE_NONE}.csv or \
                     trials-<effect>-<value>[+<effect>-<value>…].csv (the effects Drake added)"
                ),
            })?;
            if let Some(b) = &base
                && !same_conditions(b, &set)?
            {
                return Err(GapError::file(
                    f.display(),
                    format!(
                        "its conditions differ from the other trials files in {}",
                        dir.display()
                    ),
                ));
            }
            let truth = set.trials.iter().map(SimMetrics::measured_by).collect();
            let logs = set
                .trials
                .iter()
                .map(|t| {
                    t.trajectory
                        .as_ref()
                        .map(|rel| super::waveform::read_log_csv(&set.base_dir.join(rel)))
                        .transpose()
                })
                .collect::<Result<Vec<_>, _>>()?;
            if base.is_none() {
                let mut b = set.clone();
                for t in b.trials.iter_mut() {
                    t.measured = [None; 8];
                }
                base = Some(b);
            }
            files.push((stem.clone(), DrakeFile { truth, logs }));
            effects.push((stem, added));
        }
        let base = base.ok_or_else(|| GapError::file(dir.display(), "no trials-*.csv here"))?;
        Ok(DrakeFolder {
            suite: format!("drake/{name}"),
            name,
            reference,
            base,
            files,
            effects,
        })
    }

    /// `drake_seeds` noisy copies of each file (the no-effect file too, also through the
    /// reference: its change is nothing).
    fn cases(&self, opts: &BenchmarkOptions) -> Vec<CaseSpec> {
        let mode = if self.reference { "-ref" } else { "" };
        let mut out = Vec::new();
        for (stem, effects) in &self.effects {
            for seed in 0..opts.drake_seeds {
                out.push(CaseSpec {
                    key: format!(
                        "drake/{}{mode}/{stem}/n{}/s{seed}",
                        self.name, opts.pair_noise
                    ),
                    suite: self.suite.clone(),
                    kind: "drake".into(),
                    noise: opts.pair_noise,
                    seed,
                    calibrate: true,
                    multiple: None,
                    truth: Truth::Drake {
                        folder: self.name.clone(),
                        file: stem.clone(),
                        reference: self.reference,
                        effects: effects.clone(),
                    },
                });
            }
        }
        out
    }
}

/// The effects Drake added to a trials file, from its stem: `trials-none` none,
/// `trials-<effect>-<value>` one, `+` between several; `None` for any other name.
pub fn drake_effects(stem: &str) -> Option<Vec<(String, f64)>> {
    let rest = stem.strip_prefix("trials-")?;
    if stem == DRAKE_NONE {
        return Some(Vec::new());
    }
    rest.split('+')
        .map(|part| {
            let (effect, value) = part.split_once('-')?;
            let value = value.parse::<f64>().ok().filter(|v| v.is_finite())?;
            (!effect.is_empty()).then(|| (effect.to_string(), value))
        })
        .collect()
}

/// Two trials files hold the same conditions, whatever they measured.
fn same_conditions(a: &TrialSet, b: &TrialSet) -> Result<bool, GapError> {
    let (ca, cb) = (resolve(a)?, resolve(b)?);
    Ok(ca.len() == cb.len()
        && ca
            .iter()
            .zip(&cb)
            .all(|(x, y)| super::reference::same_condition(x, y)))
}
