//! `survey gap benchmark`: the diagnosis on cases of known cause, scored and calibrated.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use robot_survey::checkpoint::Shard;
use robot_survey::gap::{self, EffectLibrary};
use robot_survey::io::write_atomic;
use robot_survey::progress::Observer;
use robot_survey::report;
use robot_survey::sim::Design;

use super::common::{Progress, print};

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
survey gap benchmark --quick --out /tmp/bench          # a small run (minutes)\n  \
survey gap benchmark --points bench.csv --out reports/  # the whole benchmark (hours; resumes)\n  \
survey gap benchmark --points b-2.csv --shard 2/4        # one slice of four\n  \
survey gap benchmark --merge b-1.csv b-2.csv b-3.csv b-4.csv --points bench.csv --out reports/\n  \
survey gap benchmark --cases-from old.points.csv --compare old.points.csv --points new.csv --out reports/\n\n\
Suites: main (the design's default conditions: nulls, single effects at multiples of their \
identification threshold, pairs, nominal-parameter errors, compound errors), one-robot (one size, \
conditions varied by drive, amplitude, payload, slope), and a suite per folder of Drake trials. \
Every finished case is appended to the points file at once, with its posterior's leading \
explanations: a re-run resumes, shards merge into what one run writes, and the decision is scored \
afterwards at the threshold chosen on half of the cases.")]
pub struct BenchmarkArgs {
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// The out-of-library cases (nominal-parameter and compound errors) from this TOML
    /// (format: dataset/benchmarks/README.md). Default: dataset/benchmarks/<design>.toml when
    /// it exists, else cases derived from the design's declarations.
    #[arg(long, value_name = "FILE")]
    pub cases: Option<PathBuf>,
    /// The simulated cases of another benchmark's points file (the same keys: the same
    /// truths and noise draws) instead of planning them.
    #[arg(long, value_name = "FILE")]
    pub cases_from: Option<PathBuf>,
    /// A small run: 20 nulls at 5 % noise, one seed, no one-robot suite.
    #[arg(long)]
    pub quick: bool,
    /// Null cases per noise level (main suite).
    #[arg(long)]
    pub null_cases: Option<u64>,
    /// Noise seeds per non-null case.
    #[arg(long)]
    pub seeds: Option<u64>,
    /// Null cases of the one-robot suite; 0 leaves the suite out.
    #[arg(long, value_name = "N")]
    pub one_robot_nulls: Option<u64>,
    /// Noise levels (relative sd) of the null and single-effect cases.
    #[arg(long, value_delimiter = ',')]
    pub noise: Option<Vec<f64>>,
    /// A folder of Drake trials files (`trials-none.csv`, `trials-<effect>-<value>.csv`, or
    /// several effects joined by `+`), diagnosed as they are. Repeat for several.
    #[arg(long, value_name = "DIR")]
    pub drake: Vec<PathBuf>,
    /// A folder of Drake trials diagnosed through its `trials-none.csv` (the change the
    /// added effect made). Repeat for several.
    #[arg(long, value_name = "DIR")]
    pub drake_reference: Vec<PathBuf>,
    /// Noisy copies of each Drake trials file (default 3; 1 with --quick).
    #[arg(long, value_name = "N")]
    pub drake_seeds: Option<u64>,
    /// Diagnose the Drake cases against this design instead of their files'.
    #[arg(long, value_name = "DESIGN")]
    pub drake_design: Option<String>,
    /// Effects to benchmark (default: all).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Diagnose the cases whose key contains one of these texts a second time with every
    /// explanation confirmed by walks: how often the search misses the best one.
    #[arg(long, value_delimiter = ',', value_name = "TEXT")]
    pub exhaustive: Vec<String>,
    /// Points file: every finished case is appended; an existing file is resumed.
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// Run one slice i/n of the cases (needs --points).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Points files of shards to merge into --points (no cases are run).
    #[arg(long, num_args = 1.., value_name = "FILE")]
    pub merge: Vec<PathBuf>,
    /// Run only the cases of these kinds (null, effect, pair, pair-expected, parameter,
    /// compound, drake).
    #[arg(long, value_delimiter = ',', value_name = "KIND")]
    pub kinds: Vec<String>,
    /// Run only the cases whose key contains one of these texts.
    #[arg(long, value_delimiter = ',', value_name = "TEXT")]
    pub keys: Vec<String>,
    /// Points files of the retired rule-based selection whose answers to the same cases are
    /// scored beside the criterion's.
    #[arg(long, value_name = "FILE")]
    pub compare: Vec<PathBuf>,
    /// Folder for gap-benchmark.md, .json and the reliability diagram [default: reports]. A
    /// narrowed run (--kinds, --keys) needs it given.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

impl BenchmarkArgs {
    fn out_dir(&self) -> anyhow::Result<PathBuf> {
        match &self.out {
            Some(o) => Ok(o.clone()),
            None if self.kinds.is_empty() && self.keys.is_empty() => Ok(PathBuf::from("reports")),
            None => anyhow::bail!(
                "--kinds/--keys narrow the benchmark: its report would overwrite \
                 reports/gap-benchmark.md; give --out DIR"
            ),
        }
    }

    fn options(&self) -> anyhow::Result<gap::plan::BenchmarkOptions> {
        let mut o = match &self.cases {
            Some(f) => gap::plan::BenchmarkOptions::with_cases(
                &self.design,
                gap::cases::BenchmarkCases::read(f, &self.design)?,
            )?,
            None => gap::plan::BenchmarkOptions::standard(&self.design)?,
        };
        if self.quick {
            o.null_cases = 20;
            o.seeds = 1;
            o.noise_levels = vec![0.05];
            o.one_robot_null_cases = 0;
            o.drake_seeds = 1;
        }
        if let Some(n) = self.null_cases {
            o.null_cases = n;
        }
        if let Some(s) = self.seeds {
            o.seeds = s;
        }
        if let Some(n) = self.one_robot_nulls {
            o.one_robot_null_cases = n;
        }
        if let Some(n) = self.drake_seeds {
            anyhow::ensure!(
                n > 0,
                "--drake-seeds 0: give at least one noisy copy per file"
            );
            o.drake_seeds = n;
        }
        if let Some(n) = &self.noise {
            if let Some(bad) = n.iter().find(|x| !(**x > 0.0 && **x < 1.0)) {
                anyhow::bail!("--noise {bad}: each level must be a fraction in (0, 1)");
            }
            o.noise_levels = n.clone();
        }
        o.drake_dirs = self.drake.clone();
        o.drake_reference_dirs = self.drake_reference.clone();
        o.drake_design = self.drake_design.clone();
        o.effects = self.effects.clone();
        o.exhaustive = self.exhaustive.clone();
        o.cases_from = self.cases_from.clone();
        Ok(o)
    }

    /// The command line of the report (the options that change what was run).
    fn command(&self) -> String {
        let mut c = format!("survey gap benchmark --design {}", self.design);
        let mut flag = |name: &str, v: Option<String>| {
            if let Some(v) = v {
                c.push_str(&format!(" --{name} {v}"));
            }
        };
        flag(
            "cases-from",
            self.cases_from.as_ref().map(|p| p.display().to_string()),
        );
        flag("null-cases", self.null_cases.map(|n| n.to_string()));
        flag("seeds", self.seeds.map(|n| n.to_string()));
        flag(
            "one-robot-nulls",
            self.one_robot_nulls.map(|n| n.to_string()),
        );
        flag("drake-seeds", self.drake_seeds.map(|n| n.to_string()));
        flag("drake-design", self.drake_design.clone());
        flag(
            "noise",
            self.noise.as_ref().map(|n| {
                n.iter()
                    .map(|x| x.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            }),
        );
        for d in &self.drake {
            flag("drake", Some(d.display().to_string()));
        }
        for d in &self.drake_reference {
            flag("drake-reference", Some(d.display().to_string()));
        }
        if !self.exhaustive.is_empty() {
            flag("exhaustive", Some(self.exhaustive.join(",")));
        }
        for f in &self.compare {
            flag("compare", Some(f.display().to_string()));
        }
        if self.quick {
            c.push_str(" --quick");
        }
        c
    }
}

pub fn benchmark(a: &BenchmarkArgs) -> anyhow::Result<ExitCode> {
    let out = a.out_dir()?;
    let lib = EffectLibrary::bundled()?;
    let opts = a.options()?;
    let shard = a.shard.unwrap_or(Shard::WHOLE);
    if shard != Shard::WHOLE && a.points.is_none() {
        anyhow::bail!("--shard needs --points FILE (each slice writes its own points file)");
    }
    if a.merge.is_empty()
        && let Some(p) = &a.points
    {
        robot_survey::checkpoint::check_resumable(p, &gap::benchmark::spec(&opts))?;
    }
    let rules: BTreeMap<String, gap::scoring::RulesRow> = a
        .compare
        .iter()
        .map(|f| gap::scoring::read_rules(f))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect();
    // Hours of cases: a spinner on a terminal, a line per stage in a log.
    let pb = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        let pb = indicatif::ProgressBar::new_spinner();
        pb.enable_steady_tick(std::time::Duration::from_millis(250));
        Progress::Spinner(pb)
    } else {
        Progress::Lines
    };
    pb.stage("planning the cases");
    let mut plan = gap::plan::plan(&lib, &opts, &pb)?;
    select_cases(&mut plan, a)?;
    let rows = if a.merge.is_empty() {
        gap::benchmark::run(&lib, &opts, &plan, a.points.as_deref(), shard, &pb)?
    } else {
        merged_rows(a, &opts)?
    };
    pb.clear();
    if shard != Shard::WHOLE {
        eprintln!(
            "shard {shard}: {} cases; merge the shards with --merge to score them",
            rows.len()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let design = Design::resolve(&opts.design)?;
    let summary = gap::scoring::summarize(
        &rows,
        &rules,
        &aliases(&lib, &design),
        &opts.design,
        gap::criterion::Criterion::bundled()?.decision,
        plan.thresholds.clone(),
    );
    std::fs::create_dir_all(&out)?;
    let files: Vec<String> = a
        .compare
        .iter()
        .map(|p| format!("`{}`", p.display()))
        .collect();
    let md = report::gap_benchmark::benchmark_md(&summary, &a.command(), &files);
    write_atomic(&out.join("gap-benchmark.md"), md.as_bytes())?;
    write_atomic(
        &out.join("gap-benchmark.json"),
        report::json(&serde_json::json!({ "summary": summary, "cases": rows }))?.as_bytes(),
    )?;
    report::gap_benchmark::reliability_plot(&summary.calibration, &out.join("gap-benchmark.svg"))?;
    eprintln!("wrote {}/gap-benchmark.{{md,json,svg}}", out.display());
    print(&md);
    Ok(ExitCode::SUCCESS)
}

/// Keeps the planned cases of the `--kinds` and `--keys` asked for (all when none is
/// given); an unknown kind, or keys that match no case, is an error.
fn select_cases(plan: &mut gap::plan::Plan, a: &BenchmarkArgs) -> anyhow::Result<()> {
    use gap::plan::KINDS;
    if let Some(bad) = a.kinds.iter().find(|k| !KINDS.contains(&k.as_str())) {
        anyhow::bail!(
            "--kinds {bad}: not a case kind (one of {})",
            KINDS.join(", ")
        );
    }
    if !a.kinds.is_empty() {
        plan.cases.retain(|c| a.kinds.contains(&c.kind));
    }
    if !a.keys.is_empty() {
        plan.cases
            .retain(|c| a.keys.iter().any(|k| c.key.contains(k.as_str())));
        anyhow::ensure!(
            !plan.cases.is_empty(),
            "--keys {}: no case has such a key",
            a.keys.join(",")
        );
    }
    Ok(())
}

/// The rows of the `--merge` points files, written to the `--points` file and sorted by
/// key; the files must have been made with these benchmark options.
fn merged_rows(
    a: &BenchmarkArgs,
    opts: &gap::plan::BenchmarkOptions,
) -> anyhow::Result<Vec<gap::benchmark::CaseRow>> {
    let Some(target) = &a.points else {
        anyhow::bail!("--merge needs --points FILE (the merged file)");
    };
    let (header, mut rows) = robot_survey::checkpoint::merge::<gap::benchmark::CaseRow>(&a.merge)?;
    anyhow::ensure!(
        header == gap::benchmark::spec(opts),
        "the merged files were written with other benchmark options than these"
    );
    robot_survey::checkpoint::finish_points(target, &header, &rows)?;
    rows.sort_by(|x, y| x.key.cmp(&y.key));
    Ok(rows)
}

/// Effects that stand for a declared uncertain parameter of the design, as the parameter's
/// label (`friction_coefficient` → `mugatu:contact.friction_mu`).
fn aliases(lib: &EffectLibrary, design: &Design) -> BTreeMap<String, String> {
    lib.effects
        .iter()
        .filter_map(|e| {
            let f = e.replaces.clone()?;
            design
                .uncertain
                .iter()
                .any(|u| u.path == f)
                .then(|| (e.name.clone(), format!("{}:{f}", design.name)))
        })
        .collect()
}
