//! Walker designs in the formats roboticists use. A design (scaled or not) is exported as
//! MJCF (MuJoCo), URDF or SDF (Drake's extensions); a two-body hip walker is imported from
//! MJCF, URDF or SDF as a design TOML whose every value names its source.
//!
//! * [`export`]: the legs, hip, feet, servo and start of a design in each format, and what a
//!   format cannot carry (MJCF `<custom>` data, a sidecar TOML).
//! * [`import`]: a robot file's two legs, hip and feet as the design's symmetric model.
//! * [`robot_file`]: MJCF, URDF and SDFormat read into one neutral form.
//! * [`soft_contact`]: the closest MuJoCo soft contact to the pressure field, and back.
//! * [`mesh`]: STL meshes, their mass properties, the best-fitting ellipsoid of a foot.
//!
//! Depends on `sim` only (a design and its model).

pub mod export;
pub mod import;
mod legs;
pub mod mesh;
mod mjcf;
pub mod robot_file;
mod sdf;
pub mod soft_contact;
mod urdf;
mod xml;

pub use export::{Export, Format, export};
pub use import::{ImportOptions, Imported, import};
pub use soft_contact::{SoftContact, soft_contact};

use std::path::PathBuf;

/// Names of MJCF `<custom>` data an export writes: this prefix and a design path.
pub const CUSTOM_PREFIX: &str = "robot_survey:";

/// What can go wrong reading or writing a robot file.
#[derive(Debug, thiserror::Error)]
pub enum InteropError {
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    /// A malformed file or value: the file (and line) and what is wrong.
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    /// A robot that is not a two-body hip walker: what is missing.
    #[error("{file}: not a two-body hip walker: {message}")]
    Topology { file: String, message: String },
    #[error(transparent)]
    Sim(#[from] crate::sim::SimError),
}
