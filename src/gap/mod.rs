//! Sim-to-real gap diagnosis: where the simulator and measurements disagree, and the
//! posterior probability of every explanation — nothing off, the design's declared
//! parameters off, a library effect missing, two at once, an undeclared number off, or
//! something outside all of these — with one answer drawn from it.
//!
//! * [`trials`]: the measurement format (`dataset/trials/`), validated with file:line:column.
//! * [`library`]: the candidate effects, as data (`dataset/effects/`).
//! * [`knob`]: what an explanation can turn: the designs' `[[uncertain]]` parameters, their
//!   undeclared numbers and the effects' magnitudes, each with its prior.
//! * [`simulate`], [`cache`]: a trial condition through the simulator under a setting, and
//!   the walks shared between explanations and diagnoses.
//! * [`curve`], [`surrogate`]: every knob walked over its range; the additive surrogate with
//!   a per-explanation correction from real walks.
//! * [`observe`], [`waveform`], [`reference`]: the trials as observations (metrics, and the
//!   Fourier coefficients of logged cycles), carried through a reference set of the same
//!   robot when one is given.
//! * [`likelihood`], [`discrepancy`]: the one Gaussian likelihood, with the model's own
//!   spread beside each measurement's sd.
//! * [`criterion`] (as data: `dataset/gap/criterion.toml`), [`hypothesis`], [`evidence`],
//!   [`posterior`], [`decide`]: the explanations and their priors, each one's evidence, the
//!   search that confirms the leading ones by walks, and the answer.
//! * [`diagnose`]: all of it on a trials file; [`locate`]: where the gap lies.
//! * [`explore`]: which settings of the declared parameters fit at all; [`suggest`]: the
//!   next trials, those that most reduce the posterior's expected entropy.
//! * [`synth`]: "real" trials simulated with withheld effects or wrong parameters plus
//!   noise (and robot logs); [`plan`], [`cases`], [`benchmark`], [`scoring`]: the diagnosis
//!   on cases of known cause, scored and calibrated.
//!
//! Depends on [`crate::sim`] (the simulator), [`crate::regression`] (distributions),
//! [`crate::checkpoint`] (the benchmark's resumable points file) and [`crate::progress`]
//! only. The method: `docs/gap-criterion.md`.

pub mod benchmark;
pub mod cache;
pub mod cases;
pub mod criterion;
pub mod curve;
pub mod decide;
pub mod diagnose;
pub mod discrepancy;
pub mod error;
pub mod evidence;
pub mod explore;
pub mod hypothesis;
pub mod knob;
pub mod library;
pub mod likelihood;
pub mod locate;
pub mod observe;
pub mod plan;
pub mod posterior;
pub mod reference;
pub mod scoring;
pub mod simulate;
pub mod solver;
pub mod suggest;
pub mod surrogate;
pub mod synth;
pub mod trials;
pub mod waveform;

pub use diagnose::{DiagnoseOptions, Diagnosis, diagnose};
pub use error::GapError;
pub use library::{EffectDef, EffectLibrary, EffectSetting};
pub use trials::{Metric, Trial, TrialSet};
