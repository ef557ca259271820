//! Sim-to-real gap diagnosis: where the simulator and measurements disagree, which
//! unmodelled effect explains it, and how far the gap shrinks once that effect is added.
//!
//! * [`trials`]: the measurement format (`dataset/trials/`), validated with file:line:column.
//! * [`library`]: the candidate effects, as data (`dataset/effects/`): parameters, units,
//!   plausible ranges, and how each becomes a term of the simulator ([`crate::sim::EffectSpec`]).
//! * [`simulate`]: a trial condition run through the simulator, with or without an effect.
//! * [`diagnose`]: standardised residuals ("where"), effect fitting over cached simulation
//!   grids, leave-one-condition-out ranking, significance and intervals ("which", "how far").
//! * [`synth`]: "real" trials simulated with a withheld effect plus measurement noise.
//! * [`benchmark`]: identification, false alarms, parameter recovery over many synth cases.
//!
//! Depends on [`crate::sim`] (the simulator) and [`crate::regression`] (distributions) only.

pub mod benchmark;
pub mod diagnose;
pub mod error;
pub mod library;
pub mod simulate;
pub mod synth;
pub mod trials;

pub use diagnose::{DiagnoseOptions, Diagnosis, diagnose};
pub use error::GapError;
pub use library::{EffectDef, EffectLibrary, EffectSetting};
pub use trials::{Metric, Trial, TrialSet};
