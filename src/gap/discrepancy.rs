//! The model's own spread: how much the simulator's answer at a condition moves when only
//! its start is perturbed (the design's `initial.seed_*` table). A stable limit cycle
//! forgets its start and its spread is ~0; an irregular or knife-edge gait does not, and a
//! trial of a few cycles samples that variability, which no explanation can remove. It
//! enters the likelihood beside each measurement's sd ([`super::likelihood`]), per condition
//! and channel, estimated by walks rather than set by hand.

use serde::Serialize;

use super::cache::SimCache;
use super::error::GapError;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::likelihood::{Block, Observation};
use super::simulate::{Condition, Walked};

/// Perturbed starts walked per condition beside the unperturbed one.
pub const STARTS: u64 = 4;

/// The sd of every channel of every condition over the unperturbed walk and `starts`
/// perturbed ones ([condition][channel]; [`channel_spread`]).
pub fn model_spread(
    conditions: &[Condition],
    lib: &EffectLibrary,
    setting: &ModelSetting,
    starts: u64,
    cache: &SimCache,
) -> Result<Vec<Vec<f64>>, GapError> {
    let mut runs = vec![cache.get(conditions, lib, setting, &crate::progress::Silent)?];
    for seed in 1..=starts {
        runs.push(cache.get_from(conditions, lib, setting, seed)?);
    }
    Ok((0..conditions.len())
        .map(|c| {
            let walks: Vec<&Walked> = runs.iter().map(|r| &r[c]).collect();
            let n = Walked::channels_of(&conditions[c]);
            (0..n).map(|ch| channel_spread(&walks, ch)).collect()
        })
        .collect())
}

/// One channel's spread over several walks of a condition: the sample sd (n − 1); where
/// some walks give a value and others do not (a fall), the largest |value| (a fall is as far
/// off as the channel can be); 0 where none does.
pub fn channel_spread(walks: &[&Walked], ch: usize) -> f64 {
    let finite: Vec<f64> = walks
        .iter()
        .map(|w| w.channel(ch))
        .filter(|x| x.is_finite())
        .collect();
    if finite.is_empty() {
        0.0
    } else if finite.len() < walks.len() {
        finite.iter().map(|x| x.abs()).fold(0.0, f64::max)
    } else if finite.len() > 1 {
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        (finite.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (finite.len() - 1) as f64).sqrt()
    } else {
        0.0
    }
}

/// Sets every observation's model sd from `spread`.
pub fn apply(obs: &mut [Observation], spread: &[Vec<f64>]) {
    for o in obs.iter_mut() {
        o.model_sd = spread
            .get(o.trial)
            .and_then(|s| s.get(o.channel))
            .copied()
            .unwrap_or(0.0);
    }
}

/// A block's spread against its measurements: how many observations, and the RMS and largest
/// ratio of the model's sd to the measurement's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlockSpread {
    pub block: Block,
    pub observations: usize,
    pub rms_ratio: f64,
    pub max_ratio: f64,
}

/// Per block, the model's spread against the measurements'.
pub fn by_block(obs: &[Observation]) -> Vec<BlockSpread> {
    let mut blocks: Vec<Block> = obs.iter().map(|o| o.block).collect();
    blocks.sort();
    blocks.dedup();
    blocks
        .into_iter()
        .map(|b| {
            let ratios: Vec<f64> = obs
                .iter()
                .filter(|o| o.block == b)
                .map(|o| o.model_sd / o.sd)
                .collect();
            BlockSpread {
                block: b,
                observations: ratios.len(),
                rms_ratio: (ratios.iter().map(|r| r * r).sum::<f64>() / ratios.len() as f64).sqrt(),
                max_ratio: ratios.iter().copied().fold(0.0, f64::max),
            }
        })
        .collect()
}
