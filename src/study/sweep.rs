//! The points files of the sweeps: the shared checkpointing of [`crate::checkpoint`].

pub use crate::checkpoint::*;
