//! Sim-to-real gap diagnosis: where the simulator and measurements disagree, and whether
//! the design's uncertain parameters are off, an unmodelled effect is missing, both, or
//! neither explains it — with how far the gap shrinks on held-out conditions.
//!
//! * [`trials`]: the measurement format (`dataset/trials/`), validated with file:line:column.
//! * [`library`]: the candidate effects, as data (`dataset/effects/`): parameters, units,
//!   plausible ranges, and how each becomes a term of the simulator ([`crate::sim::EffectSpec`]).
//! * [`knob`]: what a diagnosis can turn: the designs' `[[uncertain]]` parameters and the
//!   effects' magnitudes; a model is a set of free knobs.
//! * [`simulate`], [`cache`]: a trial condition through the simulator under a setting, and
//!   the walks shared between fits.
//! * [`curve`], [`surrogate`]: every knob walked over its range; the additive surrogate
//!   with a per-model correction from real walks.
//! * [`problem`] (the χ² cost), [`solver`] (Nelder–Mead, scans), [`fit`] (surrogate fit,
//!   refinement with walks, held-out χ², profiles, consistency across groups).
//! * [`select`]: forward selection with the call rules, the backward pass, and five rules
//!   that judge the chain again with every cause of it in (on by default: an exchange
//!   round, the look-ahead check, the deferred recalibration test, look-alikes compared at
//!   the end, the within-noise subset of the look-ahead's larger model); [`audit`]: the
//!   answer's named knobs against every number the designs do not declare
//!   (`--audit-undeclared`: one that fits as well in a knob's place unnames it);
//!   [`diagnose`]: the answer;
//!   [`locate`]: where the gap lies; [`identify`]: detection and identification thresholds;
//!   [`reference`]: trials carried onto the model through a reference set of the same
//!   robot (`--reference`: the diagnosis of what changed between them), their logged cycles
//!   too, where the model walks the reference's gait.
//! * [`waveform`]: a robot's log (time, hip angle, attitude, torque) reduced to the Fourier
//!   coefficients of its steady cycle, and their χ² against a simulated cycle;
//!   [`separate`]: look-alike candidates ranked on summaries and on summaries + cycles, and
//!   a diagnosis's answer followed by the cycles (`follow_up`);
//!   [`suggest`]: the next trials that best separate the two leading candidates.
//! * [`synth`]: "real" trials simulated with withheld effects or wrong parameters plus noise
//!   (and robot logs).
//! * [`benchmark`]: the diagnosis on cases of known cause, inside and outside its library
//!   ([`cases`]: its out-of-library errors of a design, as data in `dataset/benchmarks/` or
//!   derived from the design's declarations);
//!   [`waveform_bench`]: what the logged cycles buy on the look-alike pairs.
//!
//! Depends on [`crate::sim`] (the simulator), [`crate::regression`] (distributions),
//! [`crate::checkpoint`] (the benchmark's resumable points file) and [`crate::progress`]
//! (the observer its long runs report to) only.

pub mod audit;
pub mod benchmark;
pub mod cache;
pub mod cases;
pub mod curve;
pub mod diagnose;
pub mod error;
pub mod explore;
pub mod fit;
pub mod identify;
pub mod knob;
pub mod library;
pub mod locate;
pub mod problem;
pub mod reference;
pub mod select;
pub mod separate;
pub mod simulate;
pub mod solver;
pub mod suggest;
pub mod surrogate;
pub mod synth;
pub mod trials;
pub mod waveform;
pub mod waveform_bench;

pub use diagnose::{DiagnoseOptions, Diagnosis, diagnose};
pub use error::GapError;
pub use library::{EffectDef, EffectLibrary, EffectSetting};
pub use trials::{Metric, Trial, TrialSet};
