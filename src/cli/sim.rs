//! `survey sim …`: the 3D walker simulation.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use robot_survey::report;
use robot_survey::sim::{self, ContactScaling, Design, MassLaw, WalkOptions};

use super::common::{Progress, SimFormat, print, templated_bar};

/// Largest number of sizes in one `sim scale` sweep (each is a full walk).
const MAX_SWEEP_SIZES: usize = 1000;

#[derive(Args, Debug)]
pub struct SimArgs {
    #[command(subcommand)]
    pub command: SimCommand,
}

#[derive(Subcommand, Debug)]
pub enum SimCommand {
    /// Simulate one walk of a design and report its gait (velocity, Froude number,
    /// attitude amplitudes, cost of transport, peak hip torque).
    Walk(WalkArgs),
    /// The scaling study: simulate a design at several leg lengths and fit velocity and
    /// peak hip torque power laws (dynamic similarity predicts v ∝ L^0.5).
    Scale(ScaleArgs),
    /// Measure the gait of a trajectory recorded elsewhere (Drake through tools/drake/, or
    /// a measurement exported in the trajectory CSV format) with the same metric code as
    /// `sim walk`.
    Analyze(AnalyzeArgs),
    /// The minimum hip torque (servo torque limit, or bang-bang torque magnitude) at which
    /// the design walks consistently at a size, by bracketing and bisection.
    MinTorque(MinTorqueArgs),
    /// The paper's Table III: minimum hip torque and gait of each design over leg lengths
    /// 0.02–1.2 m under m ∝ L² and m ∝ L³, with fitted power laws (v ∝ L^a, τ_min ∝ L^b,
    /// τ_min ∝ (m·L)^c); parallel, resumable (--points) and shardable (--shard i/n).
    Table3(super::study::Table3Args),
    /// The foot study: each foot semi-axis scaled 0.5–2.0× at three sizes; which feet walk,
    /// feasible semi-axis vs L as power laws, the fastest foot against the Froude prediction.
    Feet(super::study::FeetArgs),
    /// Join the points files of sharded runs into the file one run writes.
    Merge(super::study::MergeArgs),
    /// The Drake cross-check: run every elementary case of the goldens' cases.toml in this
    /// engine and compare with Drake's and the analytic values; compare every Drake walk
    /// golden with this engine's walk of the same design (both measured by this code).
    Crosscheck(CrosscheckArgs),
    /// Write a design (scaled or not) as MJCF (MuJoCo), URDF or SDF (Drake): legs, hip,
    /// feet, servo and start; what the format cannot carry goes to a sidecar TOML.
    Export(ExportArgs),
    /// Read a two-body hip walker from MJCF, URDF or SDF as a design TOML, every value tagged
    /// with its source (the file and its sha256, --set, or the command's defaults).
    Import(ImportArgs),
    /// How fast this simulator walks a design: steps per second on one thread and on every
    /// core, with the gait (tools/mujoco/bench.py runs it beside MuJoCo and Drake).
    Bench(BenchArgs),
}

#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  survey sim export --design mugatu --format mjcf --out mugatu.xml\n  \
survey sim export --design mugatu --leg-length 1.0 --mass-law l2 --format urdf --out mugatu-1m.urdf\n\n\
Writes FILE, FILE.sidecar.toml (the design values the format lacks: drive, start, the pressure-field \
contact) and, for URDF/SDF of a design with section-cut feet, the feet as OBJ meshes beside it. \
MuJoCo's contact is the closest soft contact to the pressure field (same bounce frequency and damping \
ratio of the weight on one foot), not the same law; the command prints what differs."
)]
pub struct ExportArgs {
    /// Design: a built-in name or a path to a design TOML.
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// Scale the design to this leg length [m] first.
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Mass law used when scaling.
    #[arg(long, value_enum, default_value_t)]
    pub mass_law: MassLaw,
    /// Contact scaling rule.
    #[arg(long, value_enum, default_value_t)]
    pub contact: ContactScaling,
    /// The format (default: from the extension of --out: .xml MJCF, .urdf, .sdf).
    #[arg(long, value_enum)]
    pub format: Option<robot_survey::interop::Format>,
    /// The model file to write.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  survey sim import walker.urdf --out walker.toml\n  \
survey sim import lab/mugatu.xml --set control.amplitude_deg=35 --set control.frequency_hz=1.4 --out mugatu-lab.toml\n  \
survey sim import mugatu.sdf --sidecar mugatu.sdf.sidecar.toml --out mugatu.toml\n\n\
The file must be two legs joined by one revolute hip, the first leg free (links fixed to a leg are \
merged into it); anything else is refused, saying what is missing. Each leg's foot is its lowest \
collision geometry: a sphere or ellipsoid as it is, an upright capsule as the sphere of its lower \
end, a mesh, box, cylinder or tilted capsule replaced by the best-fitting ellipsoid of its hull. \
Values the file lacks (the drive, for instance) come from --set or the defaults, tagged as such. \
SDF: one <model> (or the one model of a <world>); poses relative_to a link or __model__ only; meshes \
by a path relative to the file (model:// and package:// are refused)."
)]
pub struct ImportArgs {
    /// The robot file: MJCF (.xml), URDF (.urdf) or SDFormat 1.5–1.11 (.sdf).
    pub file: PathBuf,
    /// Write the design TOML here (default: print it).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// A design value: dotted path = number (or text for control.kind, contact.friction_cone).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// The sidecar TOML of an export (its [design] values).
    #[arg(long, value_name = "FILE")]
    pub sidecar: Option<PathBuf>,
    /// The design's name (default: the file's stem).
    #[arg(long)]
    pub name: Option<String>,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey sim bench --design mugatu-ref --duration 25 --walks 32 --format json\n\n\
Times the unperturbed walk --repeats times on one thread (best and median) and --walks seeded walks \
on --threads threads (default every core); steps counted to a fall. Build with --release to measure."
)]
pub struct BenchArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Scale the design to this leg length [m].
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Single-thread repeats.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub repeats: u64,
    /// Walks of the batch.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u64).range(1..=100000))]
    pub walks: u64,
    /// Threads of the batch (default: every core).
    #[arg(long)]
    pub threads: Option<usize>,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey sim min-torque --design mugatu --leg-length 0.5 --mass-law l3 --format json\n\n\
Walks consistently = no fall and steady forward speed above the design's threshold from the \
unperturbed start and from each of --seeds perturbed starts. The search starts at the design's \
own torque (scaled ∝ m·g·L), halves or doubles it to bracket, then bisects to --tolerance. \
`walks: false` means no torque up to --cap m·g·L works: the design does not walk at that size \
with its 1× control."
)]
pub struct MinTorqueArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Scale the design to this leg length [m].
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Perturbed starts that must walk too (besides the unperturbed one).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(0..=20))]
    pub seeds: u64,
    /// Relative tolerance of the bisection, (hi − lo)/hi.
    #[arg(long, default_value_t = 0.02)]
    pub tolerance: f64,
    /// Largest torque tried, in units of m·g·L.
    #[arg(long, default_value_t = 2.0)]
    pub cap: f64,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey sim crosscheck --golden tests/golden/drake --format md\n\n\
The goldens are made by tools/drake/harness.py (Drake, Python); this command needs neither."
)]
pub struct CrosscheckArgs {
    /// Folder with cases.toml, elementary.json and walks/ (from tools/drake/).
    #[arg(long, value_name = "DIR", default_value = "tests/golden/drake")]
    pub golden: PathBuf,
    /// Folder with MuJoCo's walks/ (from tools/mujoco/; skipped when absent).
    #[arg(long, value_name = "DIR", default_value = "tests/golden/mujoco")]
    pub mujoco_golden: PathBuf,
    /// Repository root the case and walk design paths are relative to.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub root: PathBuf,
    /// md (tables for reports/drake-crosscheck.md) or json.
    #[arg(long, value_enum, default_value_t = CrosscheckFormat::Md)]
    pub format: CrosscheckFormat,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum CrosscheckFormat {
    Md,
    Json,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey sim analyze --design mugatu-ref --trajectory tests/golden/drake/walks/mugatu-ref-1.4hz.csv\n\n\
The design (scaled by --leg-length/--mass-law, drive by --frequency) supplies the size, mass, \
drive period and walking thresholds; the CSV needs the columns `sim walk --trajectory` writes."
)]
pub struct AnalyzeArgs {
    /// Design the trajectory belongs to: a built-in name or a path to a design TOML.
    #[arg(long)]
    pub design: String,
    /// The trajectory CSV.
    #[arg(long, value_name = "FILE")]
    pub trajectory: PathBuf,
    /// Leg length the design was scaled to [m].
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Mass law used when scaling.
    #[arg(long, value_enum, default_value_t)]
    pub mass_law: MassLaw,
    /// Drive frequency of the run [Hz] (default: the design's, scaled).
    #[arg(long, value_name = "HZ")]
    pub frequency: Option<f64>,
    #[arg(long, value_enum, default_value_t)]
    pub format: SimFormat,
}

/// What every simulation command needs: the design, how it is scaled, how long it runs.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Design: a built-in name or a path to a design TOML.
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// Mass law used when scaling.
    #[arg(long, value_enum, default_value_t)]
    pub mass_law: MassLaw,
    /// Contact scaling rule.
    #[arg(long, value_enum, default_value_t)]
    pub contact: ContactScaling,
    /// Simulated time [s] (per size for `scale`).
    #[arg(long, default_value_t = 25.0)]
    pub duration: f64,
    /// Seed of a deterministic perturbation of the initial state.
    #[arg(long)]
    pub seed: Option<u64>,
    #[arg(long, value_enum, default_value_t)]
    pub format: SimFormat,
}

impl RunArgs {
    fn options(&self) -> WalkOptions {
        WalkOptions {
            mass_law: self.mass_law,
            contact_scaling: self.contact,
            duration_s: self.duration,
            seed: self.seed,
            ..WalkOptions::default()
        }
    }
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey sim scale --design mugatu --leg-lengths 0.05,0.153,0.5,1.0 --mass-law l3\n\n\
Sizes run in parallel; the result is the same bit for bit whatever the thread count."
)]
pub struct ScaleArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Leg lengths [m], comma separated (at least 3 for the fits).
    #[arg(long, value_delimiter = ',', required = true, value_name = "M,M,...")]
    pub leg_lengths: Vec<f64>,
    /// Draw velocity and peak torque against leg length (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  survey sim walk --design mugatu\n  survey sim walk --design zippy --leg-length 0.5 --mass-law l3 --format json\n  survey sim walk --design my-walker.toml --trajectory walk.csv --plot walk.svg\n\n\
Built-in designs: mugatu, zippy, zippy-spherical, mugatu-lab (dataset/walkers/*.toml); a path to a TOML \
file of the same shape defines a new one. Scaling to --leg-length keeps dynamic similarity: \
lengths ∝ L, mass ∝ L² or L³, inertia ∝ m·L², drive frequency ∝ L^(-1/2)."
)]
pub struct WalkArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Scale the design to this leg length [m].
    #[arg(long, value_name = "M")]
    pub leg_length: Option<f64>,
    /// Servo torque limit or bang-bang torque magnitude [N·m] (default: the design's, scaled).
    #[arg(long, value_name = "NM")]
    pub torque_limit: Option<f64>,
    /// Drive frequency [Hz] (default: the design's, scaled ∝ L^(-1/2)).
    #[arg(long, value_name = "HZ")]
    pub frequency: Option<f64>,
    /// Write the trajectory (time, position, roll/pitch/yaw, hip angle and torque) as CSV.
    #[arg(long, value_name = "FILE")]
    pub trajectory: Option<PathBuf>,
    /// Draw roll, pitch, yaw and hip angle over time and the path seen from above (SVG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

pub fn run(a: &SimArgs) -> anyhow::Result<ExitCode> {
    match &a.command {
        SimCommand::Walk(w) => walk(w),
        SimCommand::Scale(s) => scale(s),
        SimCommand::Analyze(a) => analyze(a),
        SimCommand::Crosscheck(c) => crosscheck(c),
        SimCommand::MinTorque(m) => min_torque(m),
        SimCommand::Table3(t) => super::study::table3(t),
        SimCommand::Merge(m) => super::study::merge(m),
        SimCommand::Feet(f) => super::study::feet(f),
        SimCommand::Export(e) => export(e),
        SimCommand::Import(i) => import(i),
        SimCommand::Bench(b) => bench(b),
    }
}

fn export(a: &ExportArgs) -> anyhow::Result<ExitCode> {
    use robot_survey::interop::Format;
    let format = match a.format {
        Some(f) => f,
        None => match a.out.extension().and_then(|e| e.to_str()) {
            Some("xml") | Some("mjcf") => Format::Mjcf,
            Some("urdf") => Format::Urdf,
            Some("sdf") => Format::Sdf,
            _ => anyhow::bail!(
                "--out {}: give --format mjcf|urdf|sdf (the extension says none)",
                a.out.display()
            ),
        },
    };
    let design = Design::resolve(&a.design)?;
    let design = design.scaled(
        a.leg_length.unwrap_or(design.geometry.leg_length_m),
        a.mass_law,
        a.contact,
    )?;
    let stem = a
        .out
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "walker".into());
    let e = robot_survey::interop::export(&design, format, &stem)?;
    let dir = a.out.parent().unwrap_or(std::path::Path::new(""));
    let sidecar = PathBuf::from(format!("{}.sidecar.toml", a.out.display()));
    let mut files = Vec::new();
    for (name, text) in &e.meshes {
        let p = dir.join(name);
        robot_survey::io::write_atomic(&p, text.as_bytes())?;
        files.push(p.display().to_string());
    }
    robot_survey::io::write_atomic(&sidecar, e.sidecar.as_bytes())?;
    robot_survey::io::write_atomic(&a.out, e.model.as_bytes())?;
    files.push(sidecar.display().to_string());
    files.push(a.out.display().to_string());
    eprint!("{}", report::interop::export_text(&e, &files));
    Ok(ExitCode::SUCCESS)
}

fn import(a: &ImportArgs) -> anyhow::Result<ExitCode> {
    let mut set = Vec::new();
    for s in &a.set {
        let Some((k, v)) = s.split_once('=') else {
            anyhow::bail!("--set {s}: expected PATH=VALUE, e.g. control.amplitude_deg=30");
        };
        set.push((k.trim().to_string(), v.trim().to_string()));
    }
    let opts = robot_survey::interop::ImportOptions {
        set,
        sidecar: a.sidecar.clone(),
        name: a.name.clone(),
    };
    let imported = robot_survey::interop::import(&a.file, &opts)?;
    match &a.out {
        Some(p) => {
            robot_survey::io::write_atomic(p, imported.toml.as_bytes())?;
            eprint!("{}", report::interop::import_text(&imported));
            eprintln!("wrote {}", p.display());
        }
        None => {
            print(&imported.toml);
            eprint!("{}", report::interop::import_text(&imported));
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn bench(a: &BenchArgs) -> anyhow::Result<ExitCode> {
    let design = Design::resolve(&a.run.design)?;
    let opts = robot_survey::study::bench::BenchOptions {
        walk: WalkOptions {
            leg_length_m: a.leg_length,
            ..a.run.options()
        },
        repeats: a.repeats as usize,
        batch_walks: a.walks as usize,
        threads: a.threads,
    };
    let r = robot_survey::study::bench::bench(&design, &opts)?;
    print(&match a.run.format {
        SimFormat::Json => report::json(&r)?,
        SimFormat::Text => report::interop::bench_text(&r),
    });
    Ok(ExitCode::SUCCESS)
}

fn min_torque(a: &MinTorqueArgs) -> anyhow::Result<ExitCode> {
    let design = Design::resolve(&a.run.design)?;
    let opts = robot_survey::study::MinTorqueOptions {
        walk: WalkOptions {
            leg_length_m: a.leg_length,
            record_trajectory: false,
            ..a.run.options()
        },
        seeds: a.seeds,
        rel_tol: a.tolerance,
        cap_over_mgl: a.cap,
        start_nm: None,
        start_bracket_nm: None,
    };
    let result = robot_survey::study::min_torque(&design, &opts)?;
    print(&match a.run.format {
        SimFormat::Json => report::json(&result)?,
        SimFormat::Text => report::min_torque_text(&result),
    });
    Ok(ExitCode::SUCCESS)
}

fn crosscheck(a: &CrosscheckArgs) -> anyhow::Result<ExitCode> {
    let spinner = Progress::Spinner(indicatif::ProgressBar::new_spinner());
    let result =
        robot_survey::crosscheck::run(&a.root, &a.golden, Some(&a.mujoco_golden), &spinner)?;
    spinner.clear();
    print(&match a.format {
        CrosscheckFormat::Json => report::json(&result)?,
        CrosscheckFormat::Md => report::crosscheck_md(&result),
    });
    Ok(ExitCode::SUCCESS)
}

fn analyze(a: &AnalyzeArgs) -> anyhow::Result<ExitCode> {
    let design = Design::resolve(&a.design)?;
    let samples = sim::read_trajectory_csv(&a.trajectory)?;
    let opts = WalkOptions {
        leg_length_m: a.leg_length,
        mass_law: a.mass_law,
        frequency_hz: a.frequency,
        ..WalkOptions::default()
    };
    let report = sim::report_from_trajectory(&design, &opts, &samples)?;
    print(&match a.format {
        SimFormat::Json => report::json(&report)?,
        SimFormat::Text => report::walk_text(&report),
    });
    Ok(ExitCode::SUCCESS)
}

fn scale(a: &ScaleArgs) -> anyhow::Result<ExitCode> {
    if let Some(bad) = a.leg_lengths.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        anyhow::bail!("--leg-lengths: {bad} is not a positive length in metres");
    }
    if a.leg_lengths.len() > MAX_SWEEP_SIZES {
        anyhow::bail!(
            "--leg-lengths: {} sizes given, at most {MAX_SWEEP_SIZES} are accepted in one sweep",
            a.leg_lengths.len()
        );
    }
    let design = Design::resolve(&a.run.design)?;
    let base = a.run.options();
    let bar = templated_bar(
        a.leg_lengths.len() as u64,
        "{msg} [{bar:30}] {pos}/{len} sizes, {elapsed}",
    );
    bar.set_message(format!("simulating {}", a.run.design));
    let bar = Progress::Bar(bar);
    let study = robot_survey::study::scaling::scaling_study(&design, &a.leg_lengths, &base, &bar)?;
    bar.clear();
    if let Some(path) = &a.plot {
        report::plot::draw_panels(path, &report::plot::scaling_panels(&study), (1200, 520))?;
        eprintln!("wrote {}", path.display());
    }
    print(&match a.run.format {
        SimFormat::Json => report::json(&study)?,
        SimFormat::Text => report::scaling_text(&study),
    });
    Ok(ExitCode::SUCCESS)
}

fn walk(a: &WalkArgs) -> anyhow::Result<ExitCode> {
    let design = Design::resolve(&a.run.design)?;
    let opts = WalkOptions {
        leg_length_m: a.leg_length,
        torque_limit_nm: a.torque_limit,
        frequency_hz: a.frequency,
        record_trajectory: a.trajectory.is_some() || a.plot.is_some(),
        ..a.run.options()
    };
    let result = sim::simulate_walk(&design, &opts)?;
    if let Some(path) = &a.trajectory {
        sim::write_trajectory_csv(&result.trajectory, path)?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &a.plot {
        let r = &result.report;
        let title = format!(
            "{} at L = {:.3} m ({:?})",
            r.design, r.leg_length_m, r.mass_law
        );
        robot_survey::report::walk_plot::write_plot_svg(&result.trajectory, &title, path)?;
        eprintln!("wrote {}", path.display());
    }
    print(&match a.run.format {
        SimFormat::Json => report::json(&result.report)?,
        SimFormat::Text => report::walk_text(&result.report),
    });
    Ok(ExitCode::SUCCESS)
}
