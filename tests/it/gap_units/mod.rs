//! The unit tests of `src/gap/`, one file per module, through the library's public items.

mod criterion;
mod curve;
mod discrepancy;
mod evidence;
mod explore;
mod hypothesis;
mod knob;
mod likelihood;
mod plan;
mod posterior;
mod reference;
mod scoring;
mod suggest;
mod surrogate;
mod waveform;
