//! Studies over the walker simulator: sweeps and searches that call `sim` many times.
//!
//! * [`scaling`]: one design simulated across leg lengths at its own control (`sim scale`).
//! * [`min_torque`]: the minimum hip torque at which a design walks consistently, by
//!   bracketing and bisection (the problem, "walks at τ?", separate from the solver).
//! * [`table3`]: the paper's Table III — minimum torque and gait over 0.02–1.2 m, both mass
//!   laws, fitted power laws.
//! * [`feet`]: the foot study — each semi-axis scaled 0.5–2.0× at three sizes.
//! * [`bench`]: the simulator's speed on one design, one thread and every core (`sim bench`).
//! * [`sweep`]: points files that make sweeps resumable and shardable, and their merge.

pub mod bench;
pub mod error;
pub mod feet;
pub mod min_torque;
pub mod paper;
pub mod scaling;
pub mod sweep;
pub mod table3;
pub mod torque_check;
pub mod torque_need;

pub use error::StudyError;
pub use min_torque::{MinTorqueOptions, MinTorqueResult, min_torque};
pub use sweep::{Shard, SweepPoint};
pub use table3::{Table3, Table3Point, Table3Row, Table3Run, Table3Spec, run_table3};
