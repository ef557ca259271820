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
use super::simulate::{Condition, SimMetrics, simulate_jobs};
use crate::progress::Observer;

/// Walk metrics by (condition id, setting key).
type WalkMap = HashMap<(usize, String), SimMetrics>;

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

    /// Metrics of `setting` on every condition, walking only what the cache lacks.
    pub fn get(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        setting: &ModelSetting,
        progress: &dyn Observer,
    ) -> Result<Vec<SimMetrics>, GapError> {
        self.get_many(conditions, lib, std::slice::from_ref(setting), progress)
            .map(|mut v| v.remove(0))
    }

    /// Metrics of several settings on every condition ([setting][condition]), the missing
    /// walks in one parallel batch.
    pub fn get_many(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        settings: &[ModelSetting],
        progress: &dyn Observer,
    ) -> Result<Vec<Vec<SimMetrics>>, GapError> {
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
            .map(|ks| {
                ks.iter()
                    .map(|k| {
                        map.get(k)
                            .copied()
                            .ok_or_else(|| GapError::Invalid("cache miss after simulation".into()))
                    })
                    .collect()
            })
            .collect()
    }

    /// Metrics of `setting` on the conditions `which` (indices into `conditions`), in that
    /// order, walking only what the cache lacks.
    pub fn get_at(
        &self,
        conditions: &[Condition],
        which: &[usize],
        lib: &EffectLibrary,
        setting: &ModelSetting,
        progress: &dyn Observer,
    ) -> Result<Vec<SimMetrics>, GapError> {
        let ids = self.condition_ids(conditions)?;
        let keys: Vec<(usize, String)> = which
            .iter()
            .map(|i| (ids[*i], setting.key_for(&conditions[*i].design.name)))
            .collect();
        let (missing_at, missing): (Vec<usize>, Vec<(usize, String)>) = {
            let map = self.lock()?;
            which
                .iter()
                .zip(&keys)
                .filter(|(_, k)| !map.contains_key(*k))
                .map(|(i, k)| (*i, k.clone()))
                .unzip()
        };
        let jobs: Vec<(usize, ModelSetting)> =
            missing_at.iter().map(|i| (*i, setting.clone())).collect();
        let done = simulate_jobs(&jobs, conditions, lib, progress)?;
        self.walks.fetch_add(jobs.len(), Ordering::Relaxed);
        let mut map = self.lock()?;
        for (k, m) in missing.into_iter().zip(done) {
            map.insert(k, m);
        }
        keys.iter()
            .map(|k| {
                map.get(k)
                    .copied()
                    .ok_or_else(|| GapError::Invalid("cache miss after simulation".into()))
            })
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

/// A lock of the cache's, or the error a panicked worker leaves.
fn locked<T>(m: &Mutex<T>) -> Result<std::sync::MutexGuard<'_, T>, GapError> {
    m.lock()
        .map_err(|_| GapError::Invalid("a worker panicked while holding the walk cache".into()))
}
