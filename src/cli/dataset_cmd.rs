//! `survey validate` and `survey dataset …`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, Subcommand, ValueEnum};
use robot_survey::dataset::{self, Dataset, upstream};
use robot_survey::motors::{MotorCatalogue, MotorProblem};
use robot_survey::report;

use super::common::{DatasetArgs, EXIT_PROBLEMS, print};

#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TextOrJson {
    #[default]
    Text,
    Json,
}

#[derive(Args, Debug)]
pub struct ValidateArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Output format: `file:line:field: message` lines, or a JSON list of
    /// {file, robot, field, severity, rule, message}.
    #[arg(long, value_enum, default_value_t)]
    pub format: TextOrJson,
    /// With --release: also check the release's rows against the record rules and its
    /// fits for outliers (lists the known problems the release was frozen with);
    /// without it, --release checks the release's integrity only.
    #[arg(long, requires = "release")]
    pub rows: bool,
}

#[derive(Args, Debug)]
pub struct DatasetCmdArgs {
    #[command(subcommand)]
    pub command: DatasetCommand,
}

#[derive(Subcommand, Debug)]
pub enum DatasetCommand {
    /// Read the upstream survey table (robot_scaling_dataset.csv) with all its quirks, and
    /// write one record per robot plus the row ledger, or check them.
    ImportUpstream(ImportArgs),
    /// Rewrite records into canonical form (field order, number format); --check only reports.
    Fmt(FmtArgs),
    /// Freeze the live records as a release (compiled CSV + Parquet, sha256 in the manifest).
    Release(ReleaseArgs),
    /// Regenerate datapackage.json (Frictionless Data Package) from the vocabulary.
    Package(PackageArgs),
}

#[derive(Args, Debug)]
pub struct ImportArgs {
    /// Path of the upstream robot_scaling_dataset.csv.
    pub path: PathBuf,
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Check instead of writing: the import must reproduce frozen release 1.0.0 byte for byte
    /// and the dataset's row ledger (upstream.toml).
    #[arg(long)]
    pub check: bool,
    /// Where to write records (DIR/robots/*.toml and DIR/upstream.toml); default: the dataset directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Overwrite existing records (they may hold corrections made after 1.0.0!).
    #[arg(long)]
    pub force: bool,
    /// Release the import must reproduce with --check.
    #[arg(long, default_value = "1.0.0", value_name = "X.Y.Z")]
    pub against: String,
    #[arg(long, value_enum, default_value_t)]
    pub format: TextOrJson,
}

#[derive(Args, Debug)]
pub struct FmtArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Report records that are not canonical and exit 1, without rewriting them.
    #[arg(long)]
    pub check: bool,
}

#[derive(Args, Debug)]
pub struct ReleaseArgs {
    /// Version to freeze; must equal the live version in dataset.toml and have a CHANGELOG entry.
    pub version: String,
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Release date (default: today, UTC).
    #[arg(long, value_name = "YYYY-MM-DD")]
    pub date: Option<String>,
    /// One-line description for the manifest.
    #[arg(long, default_value = "")]
    pub note: String,
    /// Freeze even with validation errors (only for a table preserved as published, like
    /// 1.0.0); the manifest note records how many.
    #[arg(long)]
    pub allow_errors: bool,
}

#[derive(Args, Debug)]
pub struct PackageArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Only check that datapackage.json is up to date.
    #[arg(long)]
    pub check: bool,
}

fn load(data: &DatasetArgs) -> anyhow::Result<Dataset> {
    Ok(Dataset::locate(data.dataset.as_deref())?)
}

fn dataset_dir(ds: &Dataset) -> anyhow::Result<PathBuf> {
    ds.files
        .dir
        .clone()
        .context("this command writes into the dataset: run it in a checkout or pass --dataset DIR")
}

pub fn validate(a: &ValidateArgs) -> anyhow::Result<ExitCode> {
    let ds = load(&a.data)?;
    let mut rep = dataset::validate::validate(&ds);
    let mut checked = None;
    if let Some(v) = &a.data.release {
        // With --release, that release's integrity is in question, and with --rows its rows.
        let table = ds.table(Some(v))?;
        rep.problems.retain(|p| {
            p.rule == dataset::Rule::ReleaseIntegrity && p.file.contains(&format!("releases/{v}/"))
        });
        if a.rows {
            rep.problems
                .extend(dataset::validate::validate_release_rows(&ds, v)?);
        }
        rep.dataset = ds.files.display(&format!("releases/{v}"));
        rep.version = v.clone();
        rep.records = table.rows.len();
        checked = Some(if a.rows {
            format!(
                "checked release {v}: integrity (sha256 against the manifest) and its {} rows against the record rules",
                table.rows.len()
            )
        } else {
            format!(
                "checked release {v}: integrity only (sha256 against the manifest); add --rows to check its rows against the record rules"
            )
        });
    }
    // The motor catalogue (<dataset>/motors/), when the dataset has one; not with --release.
    let motors: Option<(Vec<dataset::Problem>, String)> = match &a.data.release {
        Some(_) => None,
        None => MotorCatalogue::from_dataset_files(&ds.files).map(|read| match read {
            Ok(cat) => {
                let problems = cat.validate();
                let summary = cat.summary_line(&problems);
                (
                    problems.iter().map(MotorProblem::to_problem).collect(),
                    summary,
                )
            }
            Err(e) => (vec![e.to_problem()], "motors: not read: 1 error(s)".into()),
        }),
    };
    let motor_errors =
        dataset::problem::count(motors.iter().flat_map(|(p, _)| p), dataset::Severity::Error);
    match a.format {
        TextOrJson::Text => {
            let mut text = report::validation_text(&rep);
            match checked {
                Some(c) => text.push_str(&format!("{c}\n")),
                None => text.push_str(&dataset::validate::coverage_text(
                    &dataset::validate::coverage(&ds),
                )),
            }
            if let Some((problems, summary)) = &motors {
                for p in problems {
                    text.push_str(&format!("{}\n", p.to_line()));
                }
                text.push_str(&format!("{summary}\n"));
            }
            print(&text)
        }
        TextOrJson::Json => {
            let mut all = rep.problems.clone();
            all.extend(motors.iter().flat_map(|(p, _)| p.iter().cloned()));
            print(&report::json(&all)?)
        }
    }
    Ok(if rep.errors() + motor_errors > 0 {
        ExitCode::from(EXIT_PROBLEMS)
    } else {
        ExitCode::SUCCESS
    })
}

pub fn run(a: &DatasetCmdArgs) -> anyhow::Result<ExitCode> {
    match &a.command {
        DatasetCommand::ImportUpstream(i) => import_upstream(i),
        DatasetCommand::Fmt(f) => fmt(f),
        DatasetCommand::Release(r) => release(r),
        DatasetCommand::Package(p) => package(p),
    }
}

fn import_upstream(a: &ImportArgs) -> anyhow::Result<ExitCode> {
    let bytes = std::fs::read(&a.path).with_context(|| format!("reading {}", a.path.display()))?;
    let imp = upstream::import(&bytes, &a.path.display().to_string())?;
    let ds = load(&a.data)?;
    if a.check {
        let outcome = upstream::check(&ds, &imp, &a.against)?;
        match a.format {
            TextOrJson::Text => print(&format!(
                "{}{}",
                report::quirks_text(&imp),
                report::import_check_text(&outcome)
            )),
            TextOrJson::Json => print(&report::json(
                &serde_json::json!({"quirks": imp.quirks, "ledger": imp.ledger, "check": outcome}),
            )?),
        }
        return Ok(if outcome.ok() {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(EXIT_PROBLEMS)
        });
    }
    let out = match &a.out {
        Some(o) => o.clone(),
        None => dataset_dir(&ds)?,
    };
    let robots_dir = out.join("robots");
    // Refuse before writing anything, so a refused import leaves no partial state.
    if !a.force {
        let clashes: Vec<_> = imp
            .robots
            .iter()
            .map(|r| robots_dir.join(format!("{}.toml", r.id)))
            .filter(|p| p.exists())
            .collect();
        if !clashes.is_empty() {
            bail!(
                "{} record(s) already exist (first: {}); they may hold corrections made after 1.0.0. Use --out DIR for a fresh import, or --force",
                clashes.len(),
                clashes[0].display()
            );
        }
    }
    std::fs::create_dir_all(&robots_dir)
        .with_context(|| format!("creating {}", robots_dir.display()))?;
    for r in &imp.robots {
        let text = dataset::canonical::to_toml(r, &ds.vocab);
        dataset::canonical::write_atomic(
            &robots_dir.join(format!("{}.toml", r.id)),
            text.as_bytes(),
        )?;
    }
    dataset::canonical::write_atomic(
        &out.join(upstream::LEDGER_FILE),
        imp.ledger().to_toml().as_bytes(),
    )?;
    match a.format {
        TextOrJson::Text => print(&format!(
            "{}wrote {} records to {} and the row ledger to {}\n",
            report::quirks_text(&imp),
            imp.robots.len(),
            robots_dir.display(),
            out.join(upstream::LEDGER_FILE).display()
        )),
        TextOrJson::Json => print(&report::json(
            &serde_json::json!({"quirks": imp.quirks, "ledger": imp.ledger}),
        )?),
    }
    Ok(ExitCode::SUCCESS)
}

fn fmt(a: &FmtArgs) -> anyhow::Result<ExitCode> {
    let ds = load(&a.data)?;
    let rep = dataset::canonical::fmt(&ds, a.check)?;
    for f in &rep.changed {
        print(&format!(
            "{}{f}",
            if a.check {
                "not canonical: "
            } else {
                "formatted: "
            }
        ));
    }
    for f in &rep.unparsable {
        eprintln!("skipped (does not parse; see `survey validate`): {f}");
    }
    print(&format!(
        "{} canonical, {} {}, {} unparsable",
        rep.canonical.len(),
        rep.changed.len(),
        if a.check {
            "not canonical"
        } else {
            "rewritten"
        },
        rep.unparsable.len()
    ));
    let failed = (a.check && !rep.changed.is_empty()) || !rep.unparsable.is_empty();
    Ok(if failed {
        ExitCode::from(EXIT_PROBLEMS)
    } else {
        ExitCode::SUCCESS
    })
}

fn release(a: &ReleaseArgs) -> anyhow::Result<ExitCode> {
    let ds = load(&a.data)?;
    let date = a.date.clone().unwrap_or_else(dataset::publish::today_utc);
    let out = dataset::publish::cut_release(&ds, &a.version, &date, &a.note, a.allow_errors)?;
    print(&format!(
        "released {} ({} robots, {} fitted)\n{}",
        out.version,
        out.rows,
        out.fitted,
        out.files
            .iter()
            .map(|f| format!("  {}  {}", f.sha256, f.path))
            .collect::<Vec<_>>()
            .join("\n")
    ));
    Ok(ExitCode::SUCCESS)
}

fn package(a: &PackageArgs) -> anyhow::Result<ExitCode> {
    let ds = load(&a.data)?;
    let want = dataset::datapackage::datapackage_json(&ds);
    let current = ds.files.bytes(dataset::datapackage::FILE);
    if a.check {
        let ok = current == Some(want.as_bytes());
        print(if ok {
            "datapackage.json is up to date"
        } else {
            "datapackage.json is out of date (run `survey dataset package`)"
        });
        return Ok(if ok {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(EXIT_PROBLEMS)
        });
    }
    let dir = dataset_dir(&ds)?;
    dataset::canonical::write_atomic(&dir.join(dataset::datapackage::FILE), want.as_bytes())?;
    print(&format!(
        "wrote {}",
        dir.join(dataset::datapackage::FILE).display()
    ));
    Ok(ExitCode::SUCCESS)
}
