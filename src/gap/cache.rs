//! Walks shared between fits, refits and diagnoses of trials over the same conditions (the
//! benchmark runs thousands of diagnoses on one set): key = (condition, the setting's
//! canonical key for that condition's design). A condition is keyed by its content (its
//! full `Debug` text, interned), not by its place in a list, so diagnoses of two trial sets
//! over the same conditions share their walks whatever order or subset each lists.

use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::error::GapError;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::simulate::{Condition, Walked, simulate_jobs};
use crate::progress::Observer;

/// Walks by (condition id, setting key).
type WalkMap = HashMap<(usize, String), Walked>;

#[derive(Default)]
pub struct SimCache {
    map: Mutex<WalkMap>,
    /// Condition ids by the condition's `Debug` text (every field, f64s round-trip exact).
    condition_ids: Mutex<HashMap<String, usize>>,
    walks: AtomicUsize,
}

impl SimCache {
    /// Walks simulated through this cache so far.
    pub fn walks(&self) -> usize {
        self.walks.load(Ordering::Relaxed)
    }

    /// Walks of `setting` on every condition, walking only what the cache lacks.
    pub fn get(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        setting: &ModelSetting,
        progress: &dyn Observer,
    ) -> Result<Vec<Walked>, GapError> {
        self.get_many(conditions, lib, std::slice::from_ref(setting), progress)
            .map(|mut v| v.remove(0))
    }

    /// Walks of `setting` on every condition from the start perturbed by `seed` (the design's
    /// `initial.seed_*` table), walking only what the cache lacks.
    pub fn get_from(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        setting: &ModelSetting,
        seed: u64,
    ) -> Result<Vec<Walked>, GapError> {
        use rayon::prelude::*;
        let ids = self.condition_ids(conditions)?;
        let keys: Vec<(usize, String)> = conditions
            .iter()
            .zip(&ids)
            .map(|(c, id)| {
                (
                    *id,
                    format!("{}#start{seed}", setting.key_for(&c.design.name)),
                )
            })
            .collect();
        let missing: Vec<usize> = {
            let map = self.lock()?;
            (0..conditions.len())
                .filter(|i| !map.contains_key(&keys[*i]))
                .collect()
        };
        let done: Vec<Walked> = missing
            .par_iter()
            .map(|&i| conditions[i].simulate_from(lib, setting, Some(seed)))
            .collect::<Result<_, _>>()?;
        self.walks.fetch_add(missing.len(), Ordering::Relaxed);
        let mut map = self.lock()?;
        for (i, w) in missing.into_iter().zip(done) {
            map.insert(keys[i].clone(), w);
        }
        keys.iter().map(|k| cached(&map, k)).collect()
    }

    /// Walks of several settings on every condition ([setting][condition]), the missing
    /// walks in one parallel batch.
    pub fn get_many(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        settings: &[ModelSetting],
        progress: &dyn Observer,
    ) -> Result<Vec<Vec<Walked>>, GapError> {
        let ids = self.condition_ids(conditions)?;
        let keys: Vec<Vec<(usize, String)>> = settings
            .iter()
            .map(|s| {
                conditions
                    .iter()
                    .zip(&ids)
                    .map(|(c, id)| (*id, s.key_for(&c.design.name)))
                    .collect()
            })
            .collect();
        let mut jobs: Vec<(usize, ModelSetting)> = Vec::new();
        let mut job_keys: Vec<(usize, String)> = Vec::new();
        {
            let map = self.lock()?;
            let mut queued = std::collections::HashSet::new();
            for (ks, s) in keys.iter().zip(settings) {
                for (i, k) in ks.iter().enumerate() {
                    if !map.contains_key(k) && queued.insert(k.clone()) {
                        jobs.push((i, s.clone()));
                        job_keys.push(k.clone());
                    }
                }
            }
        }
        let done = simulate_jobs(&jobs, conditions, lib, progress)?;
        self.walks.fetch_add(jobs.len(), Ordering::Relaxed);
        let mut map = self.lock()?;
        for (k, m) in job_keys.into_iter().zip(done) {
            map.insert(k, m);
        }
        keys.iter()
            .map(|ks| ks.iter().map(|k| cached(&map, k)).collect())
            .collect()
    }

    /// The id of each condition (a new one for content not seen before).
    fn condition_ids(&self, conditions: &[Condition]) -> Result<Vec<usize>, GapError> {
        let mut ids = locked(&self.condition_ids)?;
        Ok(conditions
            .iter()
            .map(|c| {
                let next = ids.len();
                *ids.entry(format!("{c:?}")).or_insert(next)
            })
            .collect())
    }

    fn lock(&self) -> Result<std::sync::MutexGuard<'_, WalkMap>, GapError> {
        locked(&self.map)
    }
}

/// The walk the cache holds under `key` (just simulated, if it was missing).
fn cached(map: &WalkMap, key: &(usize, String)) -> Result<Walked, GapError> {
    map.get(key)
        .cloned()
        .ok_or_else(|| GapError::Invalid("cache miss after simulation".into()))
}

/// A lock of the cache's, or the error a panicked worker leaves.
fn locked<T>(m: &Mutex<T>) -> Result<std::sync::MutexGuard<'_, T>, GapError> {
    m.lock()
        .map_err(|_| GapError::Invalid("a worker panicked while holding the walk cache".into()))
}
