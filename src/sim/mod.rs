//! 3D simulation of quasi-passive hip-actuated bipeds (Mugatu, Zippy) for the scaling study
//! of Sections IV–V of "Allometric Scaling Laws for Bipedal Robots".
//!
//! * [`model`]: two rigid legs, one lateral hip joint, floating base (7 DOF, reduced
//!   coordinates), full 3D rigid-body dynamics, linearly implicit Euler integrator.
//! * [`contact`]: pressure-field (hydroelastic) contact of ellipsoidal feet on a rigid plane,
//!   closed-form normal force / centre of pressure / rolling resistance, patch-integrated
//!   regularised Coulomb friction with torsional moment.
//! * [`control`]: position servo (Mugatu) and bang-bang torque with hardstops (Zippy).
//! * [`state`]: the generalized state and the kinematics of a configuration.
//! * [`design`]: designs as TOML data and their validation.
//! * [`similarity`]: scaling a design and its effects with leg length (mass law, contact
//!   scaling; gravity fixed).
//! * [`effects`]: optional unmodelled physics as data, switched on per design: hip effects
//!   (viscous and Coulomb friction, motor torque–speed line, actuation latency, backlash) as
//!   plug-ins, contact effects (friction coefficient, soft ground, rolling resistance) through
//!   the contact parameters.
//! * [`walk`]: running a walk and its gait metrics ([`WalkReport`]).
//!
//! Self-contained: depends only on external crates and std.

pub mod contact;
pub mod control;
pub mod design;
pub mod effects;
pub mod error;
pub mod model;
pub mod similarity;
pub mod state;
pub mod walk;

pub use contact::{
    ContactParams, Cut, Patch, PatchWrench, patch, patch_forces, patch_into, patch_wrench,
    upright_sinkage_m, upright_stiffness_n_per_m,
};
pub use control::{Command, Controller};
pub use design::{
    BUILTIN_DESIGNS, Design, DesignOrigin, FrictionCone, MIRROR_ODD_PATHS, WalkingDirection,
};
pub use effects::{Effect, EffectContext, EffectSpec, GeneralizedForce};
pub use error::SimError;
pub use model::{Energy, FootSection, GRAVITY_MPS2, Hardstop, Leg, Model, Simulator, StepInfo};
pub use similarity::{ContactScaling, MassLaw};
pub use state::{Kinematics, Matrix7, State, Vector7};
pub use walk::{
    TrajectorySample, WalkOptions, WalkReport, WalkResult, WalkSetup, hip_frame_attitude,
    prepare_walk, read_trajectory_csv, report_from_trajectory, run_setup, simulate_walk,
    walks_with_torque_limit, write_trajectory_csv,
};
