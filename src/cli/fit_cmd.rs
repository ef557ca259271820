//! `survey fit`, `survey predict`, `survey test`, `survey laws`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use robot_survey::analysis::table2::{self, Group};
use robot_survey::dataset::Dataset;
use robot_survey::report::{self, Format};

use super::common::{DatasetArgs, MethodArg, parse_confidence, parse_var, print, report_written};

#[derive(Args, Debug)]
pub struct FitArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Output format of the table.
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Line-fitting method in log–log space (OLS reproduces the paper's Table 2).
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// Confidence level of the intervals.
    #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
    pub confidence: f64,
    /// Write table2.{md,tex,csv,json}, the survey figure (SVG and PNG) and the interactive
    /// page survey.html (self-contained, hover for each robot's values) into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Add seeded case-resampling bootstrap intervals of every exponent (N resamples):
    /// the percentile interval and the bias-corrected and accelerated (BCa) one, as R's
    /// boot.ci. BCa needs N well above the sample size; 2000 or more is usual.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(100..=1_000_000))]
    pub bootstrap: Option<u32>,
    /// Seed of the bootstrap (same seed, same intervals).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// List the robots of CLASS that move each exponent most (leave-one-out change in b).
    #[arg(long, value_name = "CLASS")]
    pub explain: Option<String>,
    /// Fit one relation instead of Table 2: y ∝ x^b per class, with the slope tests of the
    /// scaling laws (dataset/laws/table1.toml) and of no trend (b = 0). `speed` fits the
    /// speed of --speed-kind, and adds each class's Froude numbers v²/(gL); with --out it
    /// writes the speed report (speed.md, speed.json, speed-froude.svg/.png).
    #[arg(long, value_name = "VAR")]
    pub y: Option<String>,
    /// Explanatory variable of --y: leg_length or body_length.
    #[arg(long, value_name = "VAR", default_value = "leg_length", requires = "y")]
    pub x: String,
    /// Which speeds `--y speed` fits: top (the highest reported), typical, walking, running,
    /// or unstated (the survey's speeds of unknown kind, releases up to 1.4.0).
    #[arg(long, value_enum, default_value_t)]
    pub speed_kind: robot_survey::dataset::SpeedKind,
}

pub fn parse_group(s: &str) -> anyhow::Result<Group> {
    Group::parse(s).with_context(|| {
        format!("unknown class `{s}` (one of: lower-biped, full-biped, quadruped, hexapod, all)")
    })
}

pub fn fit(a: &FitArgs) -> anyhow::Result<ExitCode> {
    let ds = Dataset::locate(a.data.dataset.as_deref())?;
    let table = ds.table(a.data.release.as_deref())?;
    if let Some(y) = &a.y {
        return fit_relation(a, &ds, &table, y);
    }
    if let Some(class) = &a.explain {
        let g = parse_group(class)?;
        let ex = table2::explain(&table, g, a.method.into())?;
        print(&match a.format {
            Format::Json => report::json(&ex)?,
            _ => report::explain_text(&ex),
        });
        return Ok(ExitCode::SUCCESS);
    }
    let bootstrap = a
        .bootstrap
        .map(|n| robot_survey::regression::BootstrapConfig {
            replicates: n as usize,
            seed: a.seed,
            level: a.confidence,
        });
    let t2 = table2::table2_with_bootstrap(&table, a.method.into(), a.confidence, bootstrap)?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let mut written = Vec::new();
        for (fmt, name) in [
            (Format::Md, "table2.md"),
            (Format::Tex, "table2.tex"),
            (Format::Csv, "table2.csv"),
            (Format::Json, "table2.json"),
        ] {
            let path = dir.join(name);
            robot_survey::dataset::canonical::write_atomic(
                &path,
                report::table2(&t2, fmt)?.as_bytes(),
            )?;
            written.push(path);
        }
        let panels = report::plot::survey_panels(&table, &t2);
        for name in ["survey.svg", "survey.png"] {
            let path = dir.join(name);
            report::plot::draw_panels(&path, &panels, (1400, 620))?;
            written.push(path);
        }
        let path = dir.join("survey.html");
        let page =
            report::html::survey_html(&robot_survey::analysis::figure::survey_figure(&table, &t2));
        robot_survey::dataset::canonical::write_atomic(&path, page.as_bytes())?;
        written.push(path);
        report_written(&written);
    }
    print(&report::table2(&t2, a.format)?);
    Ok(ExitCode::SUCCESS)
}

/// `survey fit --y VAR`: one relation per class (its influence with --explain), and with
/// --out its files (the speed report for a speed against leg length).
fn fit_relation(
    a: &FitArgs,
    ds: &Dataset,
    table: &robot_survey::dataset::SurveyTable,
    y: &str,
) -> anyhow::Result<ExitCode> {
    use robot_survey::analysis::relation::{RelationSpec, default_hypotheses, relation_fits};
    let (x, y) = (parse_var(&a.x, a.speed_kind)?, parse_var(y, a.speed_kind)?);
    if let Some(class) = &a.explain {
        let g = parse_group(class)?;
        let ex = table2::explain_relations(table, g, a.method.into(), &[(x, y)])?;
        print(&match a.format {
            Format::Json => report::json(&ex)?,
            _ => report::explain_text(&ex),
        });
        return Ok(ExitCode::SUCCESS);
    }
    let spec = RelationSpec {
        x,
        y,
        method: a.method.into(),
        confidence: a.confidence,
        hypotheses: default_hypotheses(ds, x, y)?,
        bootstrap: a
            .bootstrap
            .map(|n| robot_survey::regression::BootstrapConfig {
                replicates: n as usize,
                seed: a.seed,
                level: a.confidence,
            }),
    };
    let fits = relation_fits(table, &spec)?;
    if let Some(dir) = &a.out {
        write_relation_files(dir, a, ds, table, &spec, &fits)?;
    }
    print(&report::speed::relation(&fits, a.format)?);
    Ok(ExitCode::SUCCESS)
}

/// The files of `survey fit --y VAR --out DIR`: for a speed against leg length the speed
/// report (speed.md, speed.json, speed-froude.svg and .png), else the relation's table
/// (Y-vs-X.md, .csv, .json).
fn write_relation_files(
    dir: &std::path::Path,
    a: &FitArgs,
    ds: &Dataset,
    table: &robot_survey::dataset::SurveyTable,
    spec: &robot_survey::analysis::relation::RelationSpec,
    fits: &robot_survey::analysis::relation::RelationFits,
) -> anyhow::Result<()> {
    use robot_survey::dataset::canonical::write_atomic;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut written = Vec::new();
    if spec.y.speed_kind().is_some() && spec.x == table2::Var::LegLength {
        let live = a.data.release.is_none();
        let rep = robot_survey::analysis::speed::speed_report(ds, table, live, spec)?;
        for (name, text) in [
            ("speed.md", report::speed::speed_report_md(&rep)),
            ("speed.json", report::json(&rep)?),
        ] {
            let path = dir.join(name);
            write_atomic(&path, text.as_bytes())?;
            written.push(path);
        }
        let panel = report::plot::froude_panel(&rep);
        for name in ["speed-froude.svg", "speed-froude.png"] {
            let path = dir.join(name);
            report::plot::draw_panels(&path, std::slice::from_ref(&panel), (1000, 700))?;
            written.push(path);
        }
    } else {
        let stem = format!("{}-vs-{}", spec.y.as_str(), spec.x.as_str());
        for (fmt, ext) in [
            (Format::Md, "md"),
            (Format::Csv, "csv"),
            (Format::Json, "json"),
        ] {
            let path = dir.join(format!("{stem}.{ext}"));
            write_atomic(&path, report::speed::relation(fits, fmt)?.as_bytes())?;
            written.push(path);
        }
    }
    report_written(&written);
    Ok(())
}

#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  survey predict --leg-length 1.0 --class lower-biped --from zippy\n  survey predict --leg-length 1.0 --from design:mugatu --format json\n  survey predict --mass-budget 30 --class lower-biped\n\n\
Predictions use the class OLS fit of log10 y on log10 L (MA/SMA lines are not for \
predicting). The centre is the bias-corrected mean (Duan smearing); the median and the \
back-transformed confidence and prediction intervals are shown beside it."
)]
pub struct PredictArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Target leg length [m] (hip height standing).
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Mass budget [kg]: the inverse query, which leg length the class fit gives for it.
    #[arg(long, value_name = "KG")]
    pub mass_budget: Option<f64>,
    /// Class whose fit predicts (lower-biped, full-biped, quadruped, hexapod, all).
    #[arg(long, default_value = "lower-biped")]
    pub class: String,
    /// Reference to scale isometrically beside the fit: a record id (`zippy`) or a walker
    /// design (`design:mugatu`).
    #[arg(long, value_name = "REF")]
    pub from: Option<String>,
    /// Confidence level of the intervals.
    #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
    pub confidence: f64,
    /// Output: md (text) or json.
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Which speed is predicted at the target leg length: top (the highest reported),
    /// typical, walking or running; fitted on the class's robots with a speed of that kind.
    #[arg(long, value_enum, default_value_t)]
    pub speed_kind: robot_survey::dataset::SpeedKind,
    /// Also draw mass vs leg length with each class's prediction band (SVG or PNG by extension).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// With --from design:NAME: the Table III contact rule the required torque comes from.
    #[arg(long, value_enum, default_value_t = robot_survey::sim::ContactScaling::FixedMaterial)]
    pub torque_contact: robot_survey::sim::ContactScaling,
    /// With --from design:NAME: actuators must deliver this multiple of the required torque
    /// at stall.
    #[arg(long, default_value_t = 2.0)]
    pub torque_margin: f64,
    /// Table III points for the torque (default: the bundled reports/table3.points.csv).
    #[arg(long, value_name = "FILE")]
    pub table3: Option<PathBuf>,
}

/// The design's required hip torque at the target leg length (none without one).
fn torque_need(
    a: &PredictArgs,
    design: &str,
    pred: &robot_survey::analysis::prediction::Prediction,
) -> anyhow::Result<Option<robot_survey::study::torque_need::TorqueNeed>> {
    let Some(l) = a.leg_length else {
        return Ok(None);
    };
    Ok(Some(robot_survey::study::torque_need::for_prediction(
        design,
        a.torque_contact,
        l,
        &pred.reference_masses(),
        a.torque_margin,
        a.table3.as_deref(),
    )?))
}

pub fn predict(a: &PredictArgs) -> anyhow::Result<ExitCode> {
    use robot_survey::analysis::prediction as p;
    let ds = Dataset::locate(a.data.dataset.as_deref())?;
    let table = ds.table(a.data.release.as_deref())?;
    let class = parse_group(&a.class)?;
    let reference = match a.from.as_deref() {
        None => None,
        Some(r) => Some(match r.strip_prefix("design:") {
            Some(name) => p::reference_from_design(&ds.files, name)?,
            None => p::reference_from_record(&table, r).with_context(|| {
                format!("--from {r}: no record `{r}` with leg length and mass in dataset {} (or use design:NAME)", table.version)
            })?,
        }),
    };
    let req = p::PredictRequest {
        leg_length_m: a.leg_length,
        mass_budget_kg: a.mass_budget,
        reference,
        confidence: a.confidence,
        speed_kind: a.speed_kind,
    };
    let pred = p::predict(&table, class, &req)?;
    let torque = match a.from.as_deref().and_then(|r| r.strip_prefix("design:")) {
        Some(name) => torque_need(a, name, &pred)?,
        None => None,
    };
    if let Some(path) = &a.plot {
        let panel = report::plot::prediction_panel(&table, &pred)?;
        report::plot::draw_panels(path, &[panel], (900, 650))?;
        eprintln!("wrote {}", path.display());
    }
    print(&match (a.format, &torque) {
        (Format::Json, t) => report::prediction_json(&pred, t.as_ref())?,
        (Format::Md, t) => {
            let mut s = report::prediction_text(&pred);
            if let Some(t) = t {
                s.push_str(&report::study::torque_need_text(t));
            }
            s
        }
        (f, _) => anyhow::bail!("--format {f:?} is not available for predict (use md or json)"),
    });
    Ok(ExitCode::SUCCESS)
}

#[derive(Args, Debug)]
pub struct TestArgs {
    #[command(subcommand)]
    pub test: TestCommand,
}

/// Variables and output shared by the tests.
#[derive(Args, Debug)]
pub struct TestCommon {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Explanatory variable: leg_length, body_length or mass.
    #[arg(long, default_value = "leg_length")]
    pub x: String,
    /// Response variable: leg_length, body_length, mass or speed (of --speed-kind).
    #[arg(long, default_value = "mass")]
    pub y: String,
    /// Which speeds `--y speed` uses: top, typical, walking, running or unstated.
    #[arg(long, value_enum, default_value_t)]
    pub speed_kind: robot_survey::dataset::SpeedKind,
    /// Line-fitting method.
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// Confidence level (the test's significance level is 1 − confidence).
    #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
    pub confidence: f64,
    /// Output: md (text) or json.
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
}

#[derive(clap::Subcommand, Debug)]
pub enum TestCommand {
    /// Is the exponent of one class equal to VALUE? By default each exponent of the scaling
    /// laws of y against leg length (dataset/laws/table1.toml; speed: 0.5, dynamic
    /// similarity, and 0.25, the biological trend below the speed hump) and 0, no trend.
    Slope {
        #[command(flatten)]
        common: TestCommon,
        /// Class tested.
        #[arg(long, default_value = "lower-biped")]
        class: String,
        /// Hypothesised exponents, comma separated (default: the scaling laws' and 0).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
        value: Vec<f64>,
    },
    /// Do the classes share one exponent? Then: do they differ in elevation (a shift)?
    #[command(alias = "elevation")]
    CommonSlope {
        #[command(flatten)]
        common: TestCommon,
        /// Classes compared, comma separated (default: the four classes).
        #[arg(long, value_delimiter = ',')]
        classes: Vec<String>,
    },
}

pub fn test(a: &TestArgs) -> anyhow::Result<ExitCode> {
    use robot_survey::analysis::inference;
    let common = match &a.test {
        TestCommand::Slope { common, .. } | TestCommand::CommonSlope { common, .. } => common,
    };
    let ds = Dataset::locate(common.data.dataset.as_deref())?;
    let table = ds.table(common.data.release.as_deref())?;
    let (x, y) = (
        parse_var(&common.x, common.speed_kind)?,
        parse_var(&common.y, common.speed_kind)?,
    );
    let text = match &a.test {
        TestCommand::Slope { class, value, .. } => {
            use robot_survey::analysis::relation::{Hypothesis, default_hypotheses};
            let hypotheses = match value.as_slice() {
                [] => default_hypotheses(&ds, x, y)?,
                given => given
                    .iter()
                    .map(|&b| Hypothesis {
                        b,
                        label: format!("b = {b}"),
                        rationale: None,
                    })
                    .collect(),
            };
            let r = inference::slope(
                &table,
                parse_group(class)?,
                x,
                y,
                common.method.into(),
                &hypotheses,
                common.confidence,
            )?;
            match common.format {
                Format::Json => report::json(&r)?,
                _ => report::slope_test_text(&r),
            }
        }
        TestCommand::CommonSlope { classes, .. } => {
            let groups = classes
                .iter()
                .map(|c| parse_group(c))
                .collect::<anyhow::Result<Vec<_>>>()?;
            let r = inference::common_slope(
                &table,
                &groups,
                x,
                y,
                common.method.into(),
                common.confidence,
            )?;
            match common.format {
                Format::Json => report::json(&r)?,
                _ => report::comparison_text(&r),
            }
        }
    };
    print(&text);
    Ok(ExitCode::SUCCESS)
}

#[derive(Args, Debug)]
pub struct LawsArgs {
    #[command(flatten)]
    pub data: DatasetArgs,
    /// Confidence level of the intervals of the exponents from data.
    #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
    pub confidence: f64,
    /// Output: md or json.
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
}

pub fn laws(a: &LawsArgs) -> anyhow::Result<ExitCode> {
    let ds = Dataset::locate(a.data.dataset.as_deref())?;
    let table = ds.table(a.data.release.as_deref())?;
    let t = robot_survey::analysis::laws::law_table(&ds, &table, a.confidence)?;
    print(&match a.format {
        Format::Json => report::json(&t)?,
        _ => report::laws_md(&t),
    });
    Ok(ExitCode::SUCCESS)
}
