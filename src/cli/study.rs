//! `survey sim table3`, `survey sim merge` (and the foot study): sweeps over the simulator.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use robot_survey::report::{self, plot};
use robot_survey::sim::{ContactScaling, Design, MassLaw};
use robot_survey::study::paper::PaperTable3;
use robot_survey::study::sweep::{self, Shard};
use robot_survey::study::table3::{self, TABLE3_KIND, Table3Point};
use robot_survey::study::{Table3Spec, run_table3};

use super::common::{SimFormat, print, templated_bar};

/// Which contact rules a study runs.
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ContactChoice {
    /// Both rules, reported side by side.
    #[default]
    Both,
    Similar,
    FixedMaterial,
}

impl ContactChoice {
    fn rules(self) -> Vec<ContactScaling> {
        match self {
            ContactChoice::Both => vec![ContactScaling::Similar, ContactScaling::FixedMaterial],
            ContactChoice::Similar => vec![ContactScaling::Similar],
            ContactChoice::FixedMaterial => vec![ContactScaling::FixedMaterial],
        }
    }
}

#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum TableFormat {
    #[default]
    Md,
    Tex,
    Csv,
    Json,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:
  survey sim table3 --contact similar --format json
  survey sim table3 --out reports/            # md, tex, csv, json and figures; resumable
  survey sim table3 --points t3.csv --shard 2/6  # one slice (a Slurm array task)
  survey sim merge t3-*.csv --out t3.csv && survey sim table3 --points t3.csv

Each design × mass law × contact rule is a chain over the sizes, run smallest first, each size \
warm-started from its neighbour's torque bracket (rescaled by m·g·L). Chains run in parallel \
on every core and are the unit of --shard. With --points (default DIR/table3.points.csv under \
--out) every finished size is appended at once: run the same command again to resume.

Walks consistently = no fall and steady forward speed above the design's threshold from the \
unperturbed start and --seeds perturbed starts. Velocity and attitudes are of the walk at the \
design's own torque (scaled ∝ m·g·L) when it walks there, else at the minimum torque.")]
pub struct Table3Args {
    /// Designs (built-in names or TOML paths), comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "zippy,zippy-spherical,mugatu"
    )]
    pub designs: Vec<String>,
    /// Mass laws, comma separated.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "l2,l3")]
    pub mass_laws: Vec<MassLaw>,
    /// Contact rule(s): similar scales every contact parameter by dynamic similarity (the
    /// exponents are then 0.5 and m·L by construction); fixed-material keeps the foot
    /// material (modulus, dissipation) of the 1× design at every size.
    #[arg(long, value_enum, default_value_t)]
    pub contact: ContactChoice,
    /// Number of log-spaced sizes from 0.02 to 1.2 m (0.025, 0.15 and 1.0 m included).
    #[arg(long, default_value_t = 36, value_parser = clap::value_parser!(u64).range(4..=1000))]
    pub sizes: u64,
    /// Explicit leg lengths [m] instead of --sizes.
    #[arg(long, value_delimiter = ',', value_name = "M,M,...")]
    pub leg_lengths: Option<Vec<f64>>,
    /// Simulated time at the design's own size [s]; ∝ √L at other sizes (the same number
    /// of drive cycles everywhere).
    #[arg(long, default_value_t = 25.0)]
    pub duration: f64,
    /// Perturbed starts that must walk too (besides the unperturbed one).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(0..=20))]
    pub seeds: u64,
    /// Relative tolerance of the minimum torque.
    #[arg(long, default_value_t = 0.02)]
    pub tolerance: f64,
    /// Largest torque tried, in units of m·g·L.
    #[arg(long, default_value_t = 2.0)]
    pub cap: f64,
    #[command(flatten)]
    pub sweep: SweepArgs,
}

/// Where a sweep keeps its points and writes its outputs.
#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Points file: finished points are appended as they finish and skipped on a re-run
    /// (default: DIR/<study>.points.csv under --out).
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// Run only slice i of n (table3: chains, feet: single feet, k mod n = i − 1); needs
    /// --points.
    #[arg(long, value_name = "i/n")]
    pub shard: Option<Shard>,
    /// Write the tables (md, tex/json, csv) and figures here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// md, tex, csv or json (feet: tex prints md; csv is the points).
    #[arg(long, value_enum, default_value_t)]
    pub format: TableFormat,
}

#[derive(Args, Debug)]
#[command(after_help = "Example:
  survey sim merge shard-1.csv shard-2.csv shard-3.csv --out table3.points.csv

The inputs must come from one specification (their first lines agree); a point present in two \
files must be identical in both. The merged file is what one unsharded run writes, byte for \
byte; pass it to the study with --points to get the table without simulating again.")]
pub struct MergeArgs {
    /// Points files written by `--shard` runs.
    #[arg(required = true, value_name = "FILE")]
    pub inputs: Vec<PathBuf>,
    /// The merged points file.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:
  survey sim feet                                   # Mugatu and Zippy at 0.025, 0.15, 1.0 m
  survey sim feet --contact similar --out reports/   # feet.{md,json,csv}, feet.svg
  survey sim feet --points feet.csv --shard 1/4

Each semi-axis of the foot (R_X fore-aft, R_Y lateral, R_Z vertical) is scaled alone by \
--factors (the others at 1×) and the walker runs once with its own scaled control; a foot \
walks when it does not fall and its steady speed exceeds the design's threshold.")]
pub struct FeetArgs {
    /// Designs (built-in names or TOML paths), comma separated.
    #[arg(long, value_delimiter = ',', default_value = "mugatu,zippy")]
    pub designs: Vec<String>,
    /// Leg lengths [m].
    #[arg(long, value_delimiter = ',', default_value = "0.025,0.15,1.0")]
    pub leg_lengths: Vec<f64>,
    /// Multipliers of one semi-axis (default 0.5 to 2.0 in steps of 0.1).
    #[arg(long, value_delimiter = ',')]
    pub factors: Option<Vec<f64>>,
    #[arg(long, value_enum, default_value_t)]
    pub contact: ContactChoice,
    #[arg(long, value_enum, default_value_t)]
    pub mass_law: MassLaw,
    /// Simulated time at the design's own size [s]; ∝ √L elsewhere.
    #[arg(long, default_value_t = 25.0)]
    pub duration: f64,
    #[command(flatten)]
    pub sweep: SweepArgs,
}

pub fn feet(a: &FeetArgs) -> anyhow::Result<ExitCode> {
    use robot_survey::study::feet::{FeetSpec, run_feet};
    let designs = a
        .designs
        .iter()
        .map(|d| Design::resolve(d))
        .collect::<Result<Vec<_>, _>>()?;
    let mut spec = FeetSpec::paper(designs, a.contact.rules());
    spec.leg_lengths_m = a.leg_lengths.clone();
    if let Some(f) = &a.factors {
        spec.factors = f.clone();
    }
    spec.mass_law = a.mass_law;
    spec.duration_at_design_size_s = a.duration;
    let shard = a.sweep.shard.unwrap_or(Shard::WHOLE);
    let points = sweep_points(&a.sweep, "feet.points.csv", shard)?;
    let total = spec
        .units()
        .iter()
        .enumerate()
        .filter(|(k, _)| shard.takes(*k))
        .count();
    let bar = templated_bar(
        total as u64,
        "feet [{bar:30}] {pos}/{len} feet, {elapsed} (eta {eta})",
    );
    let run = run_feet(&spec, shard, points.as_deref(), &|_, _| bar.inc(1))?;
    bar.finish_and_clear();
    let Some(study) = run.study else {
        eprintln!(
            "shard {shard}: {} feet ({} simulated now); join the shards with `survey sim merge`",
            run.points.len(),
            run.simulated
        );
        return Ok(ExitCode::SUCCESS);
    };
    let render = |f: TableFormat| -> anyhow::Result<String> {
        Ok(match f {
            TableFormat::Md | TableFormat::Tex => report::study::feet_md(&study),
            TableFormat::Json => report::json(&study)?,
            TableFormat::Csv => {
                let mut w = csv::Writer::from_writer(Vec::new());
                for p in &study.points {
                    w.serialize(p)?;
                }
                String::from_utf8_lossy(&w.into_inner().map_err(|e| e.into_error())?).into_owned()
            }
        })
    };
    if let Some(dir) = &a.sweep.out {
        for (f, ext) in [
            (TableFormat::Md, "md"),
            (TableFormat::Json, "json"),
            (TableFormat::Csv, "csv"),
        ] {
            write(&dir.join(format!("feet.{ext}")), &render(f)?)?;
        }
        let panels = report::study::feet_panels(&study);
        let n = panels.len().max(1) as u32;
        let path = dir.join("feet.svg");
        plot::draw_panels(&path, &panels, (520 * n, 520))?;
        eprintln!("wrote {}", path.display());
    }
    print(&render(a.sweep.format)?);
    Ok(ExitCode::SUCCESS)
}

/// The points file of a sweep (--points, else DIR/NAME under --out), checked against the
/// shard, and the output folder created.
fn sweep_points(a: &SweepArgs, name: &str, shard: Shard) -> anyhow::Result<Option<PathBuf>> {
    let (points, out) = (&a.points, &a.out);
    let points = points
        .clone()
        .or_else(|| out.as_ref().map(|d| d.join(name)));
    if shard != Shard::WHOLE && points.is_none() {
        anyhow::bail!("--shard {shard} writes its points to a file: give --points FILE");
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
    }
    Ok(points)
}

struct Bar(indicatif::ProgressBar);

impl table3::Observer for Bar {
    fn point_done(&self, p: &Table3Point, resumed: bool) {
        self.0.set_message(p.progress_label(resumed));
        self.0.inc(1);
    }
}

pub fn table3_spec(a: &Table3Args) -> anyhow::Result<Table3Spec> {
    let designs = a
        .designs
        .iter()
        .map(|d| Design::resolve(d))
        .collect::<Result<Vec<_>, _>>()?;
    let mut spec = Table3Spec::paper(designs, a.contact.rules());
    spec.mass_laws = a.mass_laws.clone();
    if let Some(ls) = &a.leg_lengths {
        if let Some(bad) = ls.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
            anyhow::bail!("--leg-lengths: {bad} is not a positive length in metres");
        }
        spec.leg_lengths_m = ls.clone();
    } else {
        spec.leg_lengths_m = table3::table3_leg_lengths(a.sizes as usize);
    }
    spec.duration_at_design_size_s = a.duration;
    spec.seeds = a.seeds;
    spec.rel_tol = a.tolerance;
    spec.cap_over_mgl = a.cap;
    Ok(spec)
}

pub fn table3(a: &Table3Args) -> anyhow::Result<ExitCode> {
    let spec = table3_spec(a)?;
    let shard = a.sweep.shard.unwrap_or(Shard::WHOLE);
    let points = sweep_points(&a.sweep, "table3.points.csv", shard)?;
    let total = spec
        .chains()
        .iter()
        .enumerate()
        .filter(|(k, _)| shard.takes(*k))
        .count()
        * spec.leg_lengths_m.len();
    let bar = templated_bar(
        total as u64,
        "table3 [{bar:30}] {pos}/{len} sizes, {elapsed} (eta {eta}) {msg}",
    );
    let run = run_table3(&spec, shard, points.as_deref(), &Bar(bar.clone()))?;
    bar.finish_and_clear();
    let Some(table) = run.table else {
        eprintln!(
            "shard {shard}: {} sizes ({} simulated now) in {}; join the shards with `survey sim merge`",
            run.points.len(),
            run.simulated,
            points
                .as_deref()
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        );
        return Ok(ExitCode::SUCCESS);
    };
    let paper = PaperTable3::bundled().ok();
    let render = |f: TableFormat| -> anyhow::Result<String> {
        Ok(match f {
            TableFormat::Md => report::study::table3_md(&table, paper.as_ref()),
            TableFormat::Tex => report::study::table3_tex(&table),
            TableFormat::Csv => report::study::table3_csv(&table)?,
            TableFormat::Json => report::json(&table)?,
        })
    };
    if let Some(dir) = &a.sweep.out {
        for (f, ext) in [
            (TableFormat::Md, "md"),
            (TableFormat::Tex, "tex"),
            (TableFormat::Csv, "csv"),
            (TableFormat::Json, "json"),
        ] {
            write(&dir.join(format!("table3.{ext}")), &render(f)?)?;
        }
        let n = report::study::table3_velocity_panels(&table).len().max(1) as u32;
        for (name, panels) in [
            (
                "table3-velocity.svg",
                report::study::table3_velocity_panels(&table),
            ),
            (
                "table3-torque.svg",
                report::study::table3_torque_panels(&table),
            ),
        ] {
            let path = dir.join(name);
            plot::draw_panels(&path, &panels, (560 * n, 520))?;
            eprintln!("wrote {}", path.display());
        }
    }
    print(&render(a.sweep.format)?);
    Ok(ExitCode::SUCCESS)
}

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

pub fn merge(a: &MergeArgs) -> anyhow::Result<ExitCode> {
    let first = a
        .inputs
        .first()
        .ok_or_else(|| anyhow::anyhow!("no points files given"))?;
    let kind = sweep::points_kind(first)?;
    let n = match kind.as_str() {
        TABLE3_KIND => merge_kind::<Table3Point>(&a.inputs, &a.out)?,
        robot_survey::study::feet::FEET_KIND => {
            merge_kind::<robot_survey::study::feet::FootPoint>(&a.inputs, &a.out)?
        }
        other => anyhow::bail!(
            "{}: a points file of study `{other}`, which `survey sim merge` does not know",
            first.display()
        ),
    };
    eprintln!(
        "merged {} files: {n} points → {}",
        a.inputs.len(),
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn merge_kind<R: sweep::SweepPoint + PartialEq>(
    inputs: &[PathBuf],
    out: &Path,
) -> anyhow::Result<usize> {
    let (header, rows) = sweep::merge::<R>(inputs)?;
    sweep::finish_points(out, &header, &rows)?;
    Ok(rows.len())
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:
  survey torque-check --design mugatu
  survey torque-check --design mugatu --mass-law l3 --format json --plot torque-check.svg
  survey torque-check --design zippy --actuator pololu-micro-metal-lp-6v-298 --voltage 6

The required torque is Table III's minimum torque (the bundled reports/table3.points.csv, or \\
--points FILE from `survey sim table3`). The motor laws (dataset/motors/laws.toml) have no \\
published coefficients: each is pinned to the design's own hip actuator at the design's own \\
size (dataset/motors/anchors.toml), and carried across sizes by two bridges: an isometric \\
actuator (length ∝ L) or a fixed actuator mass fraction (mass ∝ robot mass).")]
pub struct TorqueCheckArgs {
    /// Design (built-in name or TOML path).
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// Mass law of the Table III chain.
    #[arg(long, value_enum, default_value_t)]
    pub mass_law: MassLaw,
    /// Contact rule of the Table III chain.
    #[arg(long, value_enum, default_value_t = ContactScaling::FixedMaterial)]
    pub contact: ContactScaling,
    /// Table III points file (default: the bundled reports/table3.points.csv).
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// Pin the laws to this actuator (id in dataset/motors/actuators.toml) instead of the
    /// design's anchor; it drives the design at its own leg length.
    #[arg(long, value_name = "ID")]
    pub actuator: Option<String>,
    /// Rating voltage of --actuator (default: its recommended voltage).
    #[arg(long, value_name = "V")]
    pub voltage: Option<f64>,
    /// Draw the required torque and every law under both bridges (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Motor catalogue folder (default: dataset/motors when present, else the bundled one).
    #[arg(long, value_name = "DIR")]
    pub motors: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = SimFormat::Text)]
    pub format: SimFormat,
}

/// Table III points: a file, or the bundled copy.
pub fn torque_check(a: &TorqueCheckArgs) -> anyhow::Result<ExitCode> {
    let design = Design::resolve(&a.design)?;
    let points = table3::points(a.points.as_deref())?;
    let rows = table3::rows_from_points(&points);
    let row = rows
        .iter()
        .find(|r| r.design == design.name && r.mass_law == a.mass_law && r.contact == a.contact)
        .ok_or_else(|| {
            anyhow::anyhow!(
                "Table III has no chain for design `{}` with {:?} and {:?} contact; run `survey sim table3 --designs {} --points FILE` and pass --points FILE",
                design.name,
                a.mass_law,
                a.contact,
                a.design
            )
        })?;
    let catalogue = robot_survey::motors::MotorCatalogue::locate(a.motors.as_deref())?;
    let mass_at = |l: f64| {
        design
            .scaled(l, a.mass_law, a.contact)
            .map(|d| d.mass.total_mass_kg)
            .unwrap_or(f64::NAN)
    };
    let check = robot_survey::study::torque_check::torque_check(
        row,
        &catalogue,
        a.actuator.as_deref().map(|id| (id, a.voltage)),
        Some(design.geometry.leg_length_m),
        &mass_at,
    )?;
    if let Some(path) = &a.plot {
        let panels = report::study::torque_check_panels(&check);
        plot::draw_panels(path, &panels, (760 * panels.len().max(1) as u32, 620))?;
        eprintln!("wrote {}", path.display());
    }
    print(&match a.format {
        SimFormat::Json => report::json(&check)?,
        SimFormat::Text => report::study::torque_check_text(&check),
    });
    Ok(ExitCode::SUCCESS)
}
