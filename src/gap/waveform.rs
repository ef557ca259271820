//! Waveform evidence: the cycle of each logged signal over the drive period, reduced to a
//! few Fourier coefficients per cycle, and the χ² between a measured and a simulated cycle.
//!
//! Why Fourier coefficients per cycle: neighbouring samples of a log are strongly
//! correlated (≈ 200 per cycle, and the gait is smooth), so a χ² over samples would count
//! the same deviation hundreds of times. A cycle's mean and its first few harmonics carry
//! the shape (when in the cycle a torque or a loss acts) with nearly uncorrelated errors,
//! and their spread from cycle to cycle is the measurement's own noise.
//!
//! Time alignment is by the drive phase, which the robot's controller knows: a log may carry
//! it (`drive_phase_cycles`), otherwise it is f·t with t = 0 at the start of the drive (the
//! simulator's convention: q_d = A·sin(2πft), bang-bang torque positive for phase < ½).

use std::path::Path;

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::error::{GapError, read_text};
use crate::sim::TrajectorySample;

/// Harmonics kept per signal (the cycle's mean plus cos/sin of 1..=H times the drive
/// frequency). The gaits' signals are mostly smooth at the drive period (pitch's main
/// component is the second harmonic, the hip torque's shape the third and fourth), but
/// look-alikes act in short windows: backlash delivers no torque while the lash closes after
/// each reversal, latency shifts every edge; more harmonics tell them apart better. A log
/// needs 2H + 8 samples per cycle (Nyquist for the 12th harmonic, with room for the least
/// squares).
pub const HARMONICS: usize = 12;
/// Coefficients per signal and cycle: the mean, then a cosine and a sine per harmonic.
pub const COEFFICIENTS: usize = 1 + 2 * HARMONICS;
/// Channels of a cycle in a walk's outputs: every signal's coefficients, in
/// [`Signal::ALL`] order ([`flat`]).
pub const CHANNELS: usize = Signal::ALL.len() * COEFFICIENTS;
/// Bins of the phase-averaged cycle drawn in the figure.
pub const FIGURE_BINS: usize = 48;
/// Fewest samples per cycle for a cycle to count (the fit has 2H + 2 unknowns).
pub const MIN_SAMPLES_PER_CYCLE: usize = 2 * HARMONICS + 8;
/// Fewest steady cycles a signature needs (the spread needs several).
pub const MIN_CYCLES: usize = 3;

/// A logged signal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    HipAngle,
    Roll,
    Pitch,
    Yaw,
    HipTorque,
}

impl Signal {
    pub const ALL: [Signal; 5] = [
        Signal::HipAngle,
        Signal::Roll,
        Signal::Pitch,
        Signal::Yaw,
        Signal::HipTorque,
    ];

    /// The log's column.
    pub fn column(self) -> &'static str {
        match self {
            Signal::HipAngle => "hip_angle_deg",
            Signal::Roll => "roll_deg",
            Signal::Pitch => "pitch_deg",
            Signal::Yaw => "yaw_deg",
            Signal::HipTorque => "hip_torque_nm",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Signal::HipTorque => "N·m",
            _ => "deg",
        }
    }

    /// The cycle channel of this signal's coefficient `c`.
    pub fn channel(self, c: usize) -> usize {
        let k = Signal::ALL.iter().position(|s| *s == self).unwrap_or(0);
        k * COEFFICIENTS + c
    }

    /// Yaw's mean is the heading (arbitrary) and it drifts when the walker turns: its cycle
    /// is fitted with a trend and without its mean.
    fn has_trend(self) -> bool {
        self == Signal::Yaw
    }

    /// Sensor resolution of a coefficient, in the signal's unit (an IMU or encoder does not
    /// resolve a cycle's harmonic below ≈ 0.05°); torque has none (its scale depends on the
    /// robot's size): its cycle-to-cycle spread stands for it.
    pub fn absolute_floor(self) -> f64 {
        match self {
            Signal::HipTorque => 0.0,
            _ => 0.05,
        }
    }
}

/// One sample of a log: what a small walker records (time, hip encoder, IMU attitude, and
/// optionally the hip torque or current × torque constant, and the drive phase).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogSample {
    pub t_s: f64,
    pub hip_angle_deg: f64,
    pub roll_deg: f64,
    pub pitch_deg: f64,
    pub yaw_deg: f64,
    pub hip_torque_nm: Option<f64>,
    /// Drive phase in cycles since the drive started (None: f·t).
    pub drive_phase_cycles: Option<f64>,
}

impl LogSample {
    pub fn get(&self, s: Signal) -> Option<f64> {
        match s {
            Signal::HipAngle => Some(self.hip_angle_deg),
            Signal::Roll => Some(self.roll_deg),
            Signal::Pitch => Some(self.pitch_deg),
            Signal::Yaw => Some(self.yaw_deg),
            Signal::HipTorque => self.hip_torque_nm,
        }
    }
}

/// A simulated trajectory as a log (the simulator's drive phase is f·t).
pub fn log_of(samples: &[TrajectorySample]) -> Vec<LogSample> {
    samples
        .iter()
        .map(|s| LogSample {
            t_s: s.t_s,
            hip_angle_deg: s.hip_angle_deg,
            roll_deg: s.roll_deg,
            pitch_deg: s.pitch_deg,
            yaw_deg: s.yaw_deg,
            hip_torque_nm: Some(s.hip_torque_nm),
            drive_phase_cycles: None,
        })
        .collect()
}

/// Columns a log must have.
pub const REQUIRED_COLUMNS: [&str; 5] =
    ["t_s", "hip_angle_deg", "roll_deg", "pitch_deg", "yaw_deg"];
/// Columns a log may have.
pub const OPTIONAL_COLUMNS: [&str; 2] = ["hip_torque_nm", "drive_phase_cycles"];

/// True when the CSV file's header has every column of the simulator's full trajectory
/// format (then the summary metrics can be measured from it too); false for a log with
/// only the columns a robot records. Errors when the file cannot be read.
pub fn is_full_trajectory(path: &Path) -> Result<bool, GapError> {
    use std::io::BufRead;
    let read = GapError::read(path);
    // The header only: the log itself is read once, by the caller that needs its samples.
    let file = std::fs::File::open(path).map_err(&read)?;
    let mut header = String::new();
    for line in std::io::BufReader::new(file).lines() {
        let line = line.map_err(&read)?;
        if !line.trim_start().starts_with('#') {
            header = line;
            break;
        }
    }
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    Ok([
        "x_m",
        "y_m",
        "z_m",
        "feet_in_contact",
        "left_normal_force_n",
    ]
    .iter()
    .all(|c| cols.contains(c)))
}

/// Reads a log CSV: a header naming at least [`REQUIRED_COLUMNS`] (any order; extra columns
/// such as the simulator's full trajectory format are ignored), then one sample per line.
/// Errors name the file, line and column.
pub fn read_log_csv(path: &Path) -> Result<Vec<LogSample>, GapError> {
    let text = read_text(path)?;
    parse_log(&text, &path.display().to_string())
}

/// [`read_log_csv`] on text (`origin` names it in errors).
pub fn parse_log(text: &str, origin: &str) -> Result<Vec<LogSample>, GapError> {
    let bad = |line: usize, column: usize, message: String| {
        GapError::at(origin, line as u64, column, message)
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#'));
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => return Err(bad(1, 0, "empty log: expected a header line".into())),
    };
    let find = |name: &str| header.iter().position(|h| *h == name);
    let mut required = [0usize; 5];
    for (k, name) in REQUIRED_COLUMNS.iter().enumerate() {
        required[k] = find(name).ok_or_else(|| {
            bad(
                1,
                0,
                format!(
                    "missing column `{name}` (a log needs {}; optional: {})",
                    REQUIRED_COLUMNS.join(", "),
                    OPTIONAL_COLUMNS.join(", ")
                ),
            )
        })?;
    }
    let torque = find("hip_torque_nm");
    let phase = find("drive_phase_cycles");
    let mut out: Vec<LogSample> = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let number = |col: usize, name: &str| -> Result<f64, GapError> {
            let bad_cell = |what: String| bad(i + 1, col + 1, format!("column `{name}`: {what}"));
            let cell = cells
                .get(col)
                .ok_or_else(|| bad_cell("missing cell".into()))?;
            let v = cell
                .parse::<f64>()
                .map_err(|_| bad_cell(format!("`{cell}` is not a number")))?;
            if !v.is_finite() {
                return Err(bad_cell(format!("{v} is not finite")));
            }
            Ok(v)
        };
        let optional = |col: Option<usize>, name: &str| -> Result<Option<f64>, GapError> {
            match col {
                Some(c) if cells.get(c).is_some_and(|s| !s.is_empty()) => {
                    Ok(Some(number(c, name)?))
                }
                _ => Ok(None),
            }
        };
        let s = LogSample {
            t_s: number(required[0], "t_s")?,
            hip_angle_deg: number(required[1], "hip_angle_deg")?,
            roll_deg: number(required[2], "roll_deg")?,
            pitch_deg: number(required[3], "pitch_deg")?,
            yaw_deg: number(required[4], "yaw_deg")?,
            hip_torque_nm: optional(torque, "hip_torque_nm")?,
            drive_phase_cycles: optional(phase, "drive_phase_cycles")?,
        };
        if let Some(p) = out.last() {
            if s.t_s <= p.t_s {
                return Err(bad(
                    i + 1,
                    required[0] + 1,
                    format!("column `t_s`: time {} does not increase", s.t_s),
                ));
            }
            if let (Some(a), Some(b)) = (p.drive_phase_cycles, s.drive_phase_cycles)
                && b < a
            {
                return Err(bad(
                    i + 1,
                    phase.map_or(0, |c| c + 1),
                    format!(
                        "column `drive_phase_cycles`: {b} decreases (the phase counts cycles \
                         since the drive started, it does not wrap)"
                    ),
                ));
            }
        }
        out.push(s);
    }
    Ok(out)
}

/// A log as CSV text with the columns a real robot's log provides (time, hip angle,
/// attitude, hip torque when known); the caller writes it (atomically, in the CLI).
pub fn log_csv_text(log: &[LogSample]) -> String {
    use std::fmt::Write as _;
    let mut text = String::from("t_s,hip_angle_deg,roll_deg,pitch_deg,yaw_deg,hip_torque_nm\n");
    for s in log {
        let torque = s.hip_torque_nm.map(|v| v.to_string()).unwrap_or_default();
        // Writing to a String cannot fail.
        let _ = writeln!(
            text,
            "{},{},{},{},{},{}",
            s.t_s, s.hip_angle_deg, s.roll_deg, s.pitch_deg, s.yaw_deg, torque
        );
    }
    text
}

/// The steady cycle of one signal.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SignalCycle {
    pub signal: Signal,
    /// Mean over cycles of [a₀, a₁, b₁, …, a_H, b_H]: y(φ) ≈ a₀ + Σ a_k cos 2πkφ + b_k sin 2πkφ
    /// (a₀ is NaN for yaw, whose mean is the arbitrary heading).
    pub coefficients: Vec<f64>,
    /// Cycle-to-cycle sd of each coefficient (the sd of one cycle's value).
    pub spread: Vec<f64>,
    /// RMS of the mean cycle about its mean (its size: the relative floor's unit).
    pub rms: f64,
    /// The mean cycle rebuilt from the coefficients at [`FIGURE_BINS`] phases.
    pub cycle: Vec<f64>,
}

impl SignalCycle {
    /// A signal's cycle from its mean coefficients and their spread: its RMS about its mean
    /// and the cycle rebuilt at [`FIGURE_BINS`] phases follow from them.
    pub fn from_coefficients(signal: Signal, coefficients: Vec<f64>, spread: Vec<f64>) -> Self {
        // Skip, not slice: an empty coefficient list has an RMS of 0, not a panic.
        let rms = (coefficients.iter().skip(1).map(|a| a * a).sum::<f64>() / 2.0).sqrt();
        let cycle = (0..FIGURE_BINS)
            .map(|b| evaluate(&coefficients, (b as f64 + 0.5) / FIGURE_BINS as f64))
            .collect();
        SignalCycle {
            signal,
            coefficients,
            spread,
            rms,
            cycle,
        }
    }
}

/// The steady cycles of a log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleSignature {
    pub drive_frequency_hz: f64,
    /// Whole drive cycles used.
    pub cycles: usize,
    pub signals: Vec<SignalCycle>,
}

impl CycleSignature {
    pub fn signal(&self, s: Signal) -> Option<&SignalCycle> {
        self.signals.iter().find(|c| c.signal == s)
    }
}

/// A signature's mean coefficients as channels: [`COEFFICIENTS`] per signal in
/// [`Signal::ALL`] order, NaN for a signal the log lacks.
pub fn flat(sig: &CycleSignature) -> Vec<f64> {
    let mut out = vec![f64::NAN; CHANNELS];
    for c in &sig.signals {
        for (i, v) in c.coefficients.iter().enumerate().take(COEFFICIENTS) {
            out[c.signal.channel(i)] = *v;
        }
    }
    out
}

/// The steady cycle of every signal the log has: cycles `settle_cycles` and later (whole
/// cycles only), each fitted by least squares with the mean and [`HARMONICS`] harmonics
/// (plus a trend for yaw); their mean and spread. Errors when fewer than [`MIN_CYCLES`]
/// steady cycles have enough samples.
pub fn signature(
    log: &[LogSample],
    drive_frequency_hz: f64,
    settle_cycles: usize,
) -> Result<CycleSignature, String> {
    if !(drive_frequency_hz > 0.0 && drive_frequency_hz.is_finite()) {
        return Err(format!(
            "drive frequency {drive_frequency_hz} Hz: must be a positive number"
        ));
    }
    let phase = |s: &LogSample| s.drive_phase_cycles.unwrap_or(s.t_s * drive_frequency_hz);
    // Group samples by whole cycle.
    let mut by_cycle: std::collections::BTreeMap<i64, Vec<&LogSample>> = Default::default();
    for s in log {
        let p = phase(s);
        if p.is_finite() && p >= settle_cycles as f64 {
            by_cycle.entry(p.floor() as i64).or_default().push(s);
        }
    }
    // The last cycle may be cut short: keep cycles whose samples span most of the period.
    let cycles: Vec<(i64, Vec<&LogSample>)> = by_cycle
        .into_iter()
        .filter(|(j, v)| {
            v.len() >= MIN_SAMPLES_PER_CYCLE && {
                let first = phase(v[0]) - *j as f64;
                let last = phase(v[v.len() - 1]) - *j as f64;
                first < 0.1 && last > 0.9
            }
        })
        .collect();
    if cycles.len() < MIN_CYCLES {
        return Err(format!(
            "{} steady drive cycle(s) after the first {settle_cycles} with at least \
             {MIN_SAMPLES_PER_CYCLE} samples each; at least {MIN_CYCLES} are needed",
            cycles.len()
        ));
    }
    // One basis per cycle, shared by its signals (they are sampled together).
    let bases: Vec<CycleBasis> = cycles
        .iter()
        .map(|(j, v)| CycleBasis::new(v.iter().map(|s| phase(s) - *j as f64)))
        .collect();
    let mut signals = Vec::new();
    for signal in Signal::ALL {
        if log.iter().any(|s| s.get(signal).is_none()) {
            continue;
        }
        let per_cycle: Vec<Vec<f64>> = cycles
            .iter()
            .zip(&bases)
            .map(|((_, v), basis)| {
                let y: Vec<f64> = v.iter().filter_map(|s| s.get(signal)).collect();
                basis.fit(&y, signal.has_trend())
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| format!("{}: a cycle's harmonic fit is singular", signal.column()))?;
        let n = per_cycle.len() as f64;
        let k = per_cycle[0].len();
        let mean: Vec<f64> = (0..k)
            .map(|c| per_cycle.iter().map(|v| v[c]).sum::<f64>() / n)
            .collect();
        let spread: Vec<f64> = (0..k)
            .map(|c| {
                let ss: f64 = per_cycle.iter().map(|v| (v[c] - mean[c]).powi(2)).sum();
                (ss / (n - 1.0)).sqrt()
            })
            .collect();
        // The figure's cycle keeps the mean heading; the compared coefficients do not.
        let mut cycle = SignalCycle::from_coefficients(signal, mean, spread);
        if signal.has_trend() {
            cycle.coefficients[0] = f64::NAN;
            cycle.spread[0] = f64::NAN;
        }
        signals.push(cycle);
    }
    Ok(CycleSignature {
        drive_frequency_hz,
        cycles: cycles.len(),
        signals,
    })
}

/// The least-squares basis of one cycle's sample phases: [1, cos 2πφ, sin 2πφ, …,
/// cos 2πHφ, sin 2πHφ, φ − ½] per sample (the last, a trend, for yaw only), with the
/// normal equations factored once for every signal of the cycle: far cheaper than an SVD per
/// signal, and as exact, since the Fourier columns are near-orthogonal over a whole cycle. A
/// cycle whose Gram matrix is not positive definite falls back to the SVD.
pub struct CycleBasis {
    /// Samples × (1 + 2H + 1).
    a: DMatrix<f64>,
    plain: Option<nalgebra::linalg::Cholesky<f64, nalgebra::Dyn>>,
    trend: Option<nalgebra::linalg::Cholesky<f64, nalgebra::Dyn>>,
}

impl CycleBasis {
    /// The basis of the sample phases `phases` (in cycles).
    pub fn new(phases: impl Iterator<Item = f64>) -> CycleBasis {
        let phases: Vec<f64> = phases.collect();
        let k = COEFFICIENTS;
        let mut a = DMatrix::zeros(phases.len(), k + 1);
        for (r, &phi) in phases.iter().enumerate() {
            let (s1, c1) = (std::f64::consts::TAU * phi).sin_cos();
            a[(r, 0)] = 1.0;
            // cos hx, sin hx by the angle-addition recurrence (2 trig calls per sample).
            let (mut c, mut s) = (c1, s1);
            for h in 1..=HARMONICS {
                a[(r, 2 * h - 1)] = c;
                a[(r, 2 * h)] = s;
                (c, s) = (c * c1 - s * s1, s * c1 + c * s1);
            }
            a[(r, k)] = phi - 0.5;
        }
        let gram = a.tr_mul(&a);
        let plain = gram.view((0, 0), (k, k)).clone_owned().cholesky();
        let trend = gram.cholesky();
        CycleBasis { a, plain, trend }
    }

    /// [a₀, a₁, b₁, …, a_H, b_H] of the samples `y` (with the trend column fitted and
    /// dropped when `trend`).
    pub fn fit(&self, y: &[f64], trend: bool) -> Option<Vec<f64>> {
        let k = COEFFICIENTS;
        let cols = k + usize::from(trend);
        let a = self.a.columns(0, cols);
        // The caller passes one value per sample the basis was built from.
        debug_assert_eq!(y.len(), a.nrows());
        let y = DVector::from_column_slice(y);
        let chol = if trend { &self.trend } else { &self.plain };
        let x = match chol {
            Some(c) => c.solve(&a.tr_mul(&y)),
            None => a.clone_owned().svd(true, true).solve(&y, 1e-12).ok()?,
        };
        x.iter()
            .all(|v| v.is_finite())
            .then(|| x.iter().take(k).copied().collect())
    }
}

/// The cycle of coefficients at phase `phi` (a NaN mean counts as 0).
pub fn evaluate(coef: &[f64], phi: f64) -> f64 {
    let mut y = if coef[0].is_finite() { coef[0] } else { 0.0 };
    for h in 1..=HARMONICS {
        let x = std::f64::consts::TAU * h as f64 * phi;
        y += coef[2 * h - 1] * x.cos() + coef[2 * h] * x.sin();
    }
    y
}
