//! The posterior over explanations, and the search that makes it trustworthy.
//!
//! The criterion is fixed: P(H | trials) ∝ P(H) · Z_H ([`super::hypothesis`],
//! [`super::evidence`]). The search only decides how well each Z_H is computed: it integrates
//! every explanation on the additive surrogate, refines the leading singles and confirms the
//! leading pairs by walks (pairs about the best single, [`super::surrogate::Anchored`]),
//! repeats while the top of either size is unwalked or nothing walked fits, and walks the
//! top last: the answer rests on walks (why: docs/gap-criterion.md, "The search").
//! [`Search::exhaustive`] refines and confirms every explanation: how misses are measured.

use rayon::prelude::*;

use super::cache::SimCache;
use super::criterion::{Criterion, Decision};
use super::error::GapError;
use super::evidence::{Discrepancy, Evidence, Slab, Target, evidence};
use super::hypothesis::{Class, Hypothesis};
use super::knob::Knobs;
use super::library::EffectLibrary;
use super::likelihood::{Observation, chi2_of, log_normaliser};
use super::simulate::{Condition, Walked};
use super::surrogate::{Anchored, Correction, Surrogate};
use crate::progress::Observer;

/// How hard the search works (none of it changes the criterion).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// Single explanations refined, and pairs confirmed, at most (the most probable first).
    pub confirm: usize,
    /// An explanation is refined or confirmed only while its probability is at least this
    /// share of the most probable one's.
    pub share: f64,
    /// Walk-and-refit rounds per explanation.
    pub rounds: usize,
    /// Refine and confirm every explanation (to measure what the search misses).
    pub exhaustive: bool,
}

impl Default for Search {
    fn default() -> Self {
        Search {
            confirm: 6,
            share: 0.01,
            rounds: 5,
            exhaustive: false,
        }
    }
}

/// What the posterior needs besides the surrogate it refines.
pub struct Inputs<'a> {
    pub conditions: &'a [Condition],
    pub lib: &'a EffectLibrary,
    pub cache: &'a SimCache,
    pub knobs: &'a Knobs,
    pub obs: &'a [Observation],
    pub progress: &'a dyn Observer,
}

/// One explanation, weighed.
#[derive(Clone, Debug)]
pub struct Weighed {
    pub hypothesis: Hypothesis,
    pub evidence: Evidence,
    /// The walks' first-order correction of the surrogate at the mode (pairs).
    pub correction: Option<Correction>,
    /// Real walks at the mode, and their χ² (None: not walked).
    pub walks: Option<Vec<Walked>>,
    pub walked_chi2: Option<f64>,
    /// The observations with the model's own spread at the mode (None: the nominal's).
    pub obs: Option<Vec<Observation>>,
    /// The surrogate's error per observation near the mode, from walks it had not seen.
    pub surrogate_sd: Option<Vec<f64>>,
    /// ln of the Bayes factor of this explanation with "something outside these" beside it
    /// over it alone, at its most probable point.
    pub log_bf: f64,
    pub probability: f64,
    /// Its probability given that one of the library's explanations holds: what the search
    /// ranks by (`probability` underflows to 0 when "something outside these" takes all).
    pub share: f64,
}

/// The posterior: every explanation weighed, most probable first, and "something outside
/// these".
#[derive(Clone, Debug)]
pub struct Posterior {
    pub weighed: Vec<Weighed>,
    /// "Something outside these": its evidence, prior and probability (None: the trials
    /// leave it no range).
    pub outside: Option<(Evidence, f64, f64)>,
    /// The knob the other suspects' curves were walked again about, and its value.
    pub anchor: Option<(usize, f64)>,
}

impl Posterior {
    /// The most probable explanation that is not "something outside these".
    pub fn best(&self) -> Option<&Weighed> {
        self.weighed.first()
    }
}

/// A deterministic seed of an explanation's importance samples.
fn seed_of(free: &[usize]) -> u64 {
    free.iter().fold(0x9e37_79b9_7f4a_7c15_u64, |h, k| {
        (h ^ (*k as u64)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The search's state: the surrogate it refines, the slabs on it, the explanations.
struct State {
    surrogate: Surrogate,
    slabs: Vec<Slab>,
    weighed: Vec<Weighed>,
    outside: Option<(Evidence, f64, f64)>,
    /// "Something outside these" beside an explanation, and its prior.
    discrepancy: Option<Discrepancy>,
    outside_prior: f64,
    log_norm: f64,
}

impl State {
    /// Every explanation's Bayes factor with "something outside these" beside it, at its
    /// most probable point (with its observations with the model's spread there, where
    /// counted).
    fn bayes_factors(&mut self, inp: &Inputs<'_>) {
        let Some(d) = &self.discrepancy else { return };
        let bfs: Vec<f64> = self
            .weighed
            .par_iter()
            .map(|w| {
                let obs = w.obs.as_deref().unwrap_or(inp.obs);
                let pred = self.predictions(inp, w);
                d.log_bayes_factor(obs, &pred)
            })
            .collect();
        for (w, bf) in self.weighed.iter_mut().zip(bfs) {
            w.log_bf = bf;
        }
    }

    /// An explanation's predictions at its most probable point on the surrogate (and walks'
    /// correction) its evidence integrates, so that its Bayes factor compares like with like
    /// (the nominal's: the surrogate's nominal walks, non-finite where they fall).
    fn predictions(&self, inp: &Inputs<'_>, w: &Weighed) -> Vec<f64> {
        if w.evidence.mode.iter().any(|v| !v.is_finite()) {
            return vec![f64::NAN; inp.obs.len()];
        }
        let set = inp.knobs.set_of(&w.hypothesis.knobs, &w.evidence.mode);
        inp.obs
            .iter()
            .map(|o| {
                self.surrogate
                    .predict(o.trial, o.channel, &set, w.correction.as_ref())
            })
            .collect()
    }

    /// "Something outside these" beside the most probable explanation, for the report: κ's
    /// posterior there, its prior and its probability (all explanations' share).
    fn outside_of_best(&self, inp: &Inputs<'_>) -> Option<(Evidence, f64, f64)> {
        let d = self.discrepancy.as_ref()?;
        let best = self.weighed.first()?;
        let obs = best.obs.as_deref().unwrap_or(inp.obs);
        let e = d.posterior(obs, &self.predictions(inp, best));
        let lib: f64 = self.weighed.iter().map(|w| w.probability).sum();
        Some((e, self.outside_prior, (1.0 - lib).max(0.0)))
    }

    /// The explanations not yet integrated, "something outside these" (its prior the
    /// hypothesis' of that class, its reach `max_relative`) on the nominal.
    fn new(
        inp: &Inputs<'_>,
        surrogate: Surrogate,
        slabs: Vec<Slab>,
        hypotheses: Vec<Hypothesis>,
        max_relative: f64,
    ) -> State {
        let discrepancy = Discrepancy::new(inp.obs, &surrogate.nominal, max_relative);
        let (outside, hypotheses): (Vec<Hypothesis>, Vec<Hypothesis>) = hypotheses
            .into_iter()
            .partition(|h| h.class == Class::NoneOfThese);
        let weighed = hypotheses
            .into_iter()
            .map(|h| Weighed {
                hypothesis: h,
                evidence: Evidence::empty(0),
                correction: None,
                walks: None,
                walked_chi2: None,
                obs: None,
                surrogate_sd: None,
                log_bf: f64::NEG_INFINITY,
                probability: 0.0,
                share: 0.0,
            })
            .collect();
        State {
            surrogate,
            slabs,
            weighed,
            outside: None,
            discrepancy,
            outside_prior: outside.first().map_or(0.0, |h| h.prior),
            log_norm: log_normaliser(inp.obs),
        }
    }

    fn integrate(&self, inp: &Inputs<'_>, free: &[usize], c: Option<&Correction>) -> Evidence {
        self.integrate_on(inp, inp.obs, self.log_norm, free, c)
    }

    fn integrate_on(
        &self,
        inp: &Inputs<'_>,
        obs: &[Observation],
        log_norm: f64,
        free: &[usize],
        c: Option<&Correction>,
    ) -> Evidence {
        let t = Target {
            surrogate: &self.surrogate,
            knobs: inp.knobs,
            obs,
            free,
            slabs: &self.slabs,
            correction: c,
            log_norm,
        };
        evidence(&t, seed_of(free))
    }

    /// Counts the model's own spread at explanation `i`'s mode (perturbed starts there) in
    /// its likelihood, and integrates it again with it.
    fn spread_at_mode(&mut self, inp: &Inputs<'_>, i: usize) -> Result<(), GapError> {
        let w = &self.weighed[i];
        let free = w.hypothesis.knobs.clone();
        if w.evidence.mode.iter().any(|v| !v.is_finite()) {
            return Ok(());
        }
        let setting = inp
            .knobs
            .setting_at(inp.lib, &inp.knobs.set_of(&free, &w.evidence.mode));
        let spread = super::discrepancy::model_spread(
            inp.conditions,
            inp.lib,
            &setting,
            super::discrepancy::STARTS,
            inp.cache,
        )?;
        let mut obs = inp.obs.to_vec();
        super::discrepancy::apply(&mut obs, &spread);
        if let Some(sd) = &w.surrogate_sd {
            for (o, s) in obs.iter_mut().zip(sd) {
                o.model_sd = o.model_sd.hypot(*s);
            }
        }
        let log_norm = log_normaliser(&obs);
        let e = self.integrate_on(inp, &obs, log_norm, &free, w.correction.as_ref());
        let w = &mut self.weighed[i];
        if let Some(walks) = &w.walks {
            w.walked_chi2 = Some(chi2_of(&obs, walks));
        }
        w.evidence = e;
        w.obs = Some(obs);
        Ok(())
    }

    /// Integrates again every explanation holding one of `knobs` (all when empty) that has
    /// no correction of its own.
    fn reintegrate(&mut self, inp: &Inputs<'_>, knobs: &[usize]) {
        self.reintegrate_where(inp, |h| {
            !h.is_empty() && (knobs.is_empty() || h.iter().any(|k| knobs.contains(k)))
        });
    }

    /// Integrates again every explanation without a correction of its own whose knobs
    /// `pick` takes.
    fn reintegrate_where(&mut self, inp: &Inputs<'_>, pick: impl Fn(&[usize]) -> bool) {
        let todo: Vec<usize> = (0..self.weighed.len())
            .filter(|&i| {
                self.weighed[i].correction.is_none() && pick(&self.weighed[i].hypothesis.knobs)
            })
            .collect();
        let fresh: Vec<Evidence> = todo
            .par_iter()
            .map(|&i| self.integrate_own(inp, i))
            .collect();
        for (i, e) in todo.into_iter().zip(fresh) {
            self.weighed[i].evidence = e;
        }
    }

    /// Explanation `i` integrated on its own observations (the model's spread at its mode,
    /// when counted) and correction.
    fn integrate_own(&self, inp: &Inputs<'_>, i: usize) -> Evidence {
        let w = &self.weighed[i];
        match &w.obs {
            Some(obs) => self.integrate_on(
                inp,
                obs,
                log_normaliser(obs),
                &w.hypothesis.knobs,
                w.correction.as_ref(),
            ),
            None => self.integrate(inp, &w.hypothesis.knobs, w.correction.as_ref()),
        }
    }

    fn normalise(&mut self, inp: &Inputs<'_>) {
        self.bayes_factors(inp);
        normalise(&mut self.weighed, self.outside_prior);
        self.outside = self.outside_of_best(inp);
    }

    /// Runs `step` on each explanation of `indices` (found again by its knobs, as a step
    /// may reorder the list): `step(state, its index now, its knobs)`.
    fn for_each(
        &mut self,
        indices: &[usize],
        mut step: impl FnMut(&mut State, usize, &[usize]) -> Result<(), GapError>,
    ) -> Result<(), GapError> {
        let keys: Vec<Vec<usize>> = indices
            .iter()
            .map(|&i| self.weighed[i].hypothesis.knobs.clone())
            .collect();
        for key in keys {
            if let Some(i) = self.weighed.iter().position(|w| w.hypothesis.knobs == key) {
                step(self, i, &key)?;
            }
        }
        Ok(())
    }

    /// The most probable unwalked explanations of `len` knobs, at most `search.confirm`, with
    /// at least `share` of the top one's probability (of that size, or overall when `settled`)
    /// — no such floor when `wide` (nothing walked fits) or `exhaustive` (all of them).
    fn leading(&self, len: usize, search: &Search, settled: bool, wide: bool) -> Vec<usize> {
        let of_len: Vec<usize> = (0..self.weighed.len())
            .filter(|&i| self.weighed[i].hypothesis.knobs.len() == len)
            .collect();
        let mut top = of_len.first().map_or(0.0, |&i| self.weighed[i].share);
        if settled {
            top = top.max(self.weighed.first().map_or(0.0, |w| w.share));
        }
        of_len
            .into_iter()
            .filter(|&i| self.weighed[i].walks.is_none())
            .filter(|&i| search.exhaustive || wide || self.weighed[i].share >= search.share * top)
            .take(if search.exhaustive {
                usize::MAX
            } else {
                search.confirm
            })
            .collect()
    }
}

impl Inputs<'_> {
    /// Real walks with the knobs of `set` at their coordinates.
    fn walks(&self, set: &[(usize, f64)]) -> Result<Vec<Walked>, GapError> {
        let clamped: Vec<(usize, f64)> = set
            .iter()
            .map(|&(k, x)| (k, x.clamp(self.knobs.list[k].lo, self.knobs.list[k].hi)))
            .collect();
        let setting = self.knobs.setting_at(self.lib, &clamped);
        self.cache
            .get(self.conditions, self.lib, &setting, self.progress)
    }
}

/// One posterior width along each free knob of an evidence (unit coordinates), kept between
/// 1/1024 and 1/32 of the range; a NaN width (no interval) gives 1/32 (clamp would keep NaN).
#[expect(clippy::manual_clamp)]
fn widths(e: &Evidence) -> Vec<f64> {
    e.marginal
        .iter()
        .map(|[a, b]| ((b - a) / 4.0).min(1.0 / 32.0).max(1.0 / 1024.0))
        .collect()
}

/// Refines single explanation `i`: walks at its mode and a posterior width either side
/// become nodes of its knob's curve; integrate again; repeat while the mode moves by more than
/// a quarter of the posterior's width. Each walk between nodes already placed about the mode
/// measures the curve's error there, which the likelihood counts as for a pair.
fn refine_single(
    inp: &Inputs<'_>,
    st: &mut State,
    i: usize,
    rounds: usize,
) -> Result<(), GapError> {
    let k = st.weighed[i].hypothesis.knobs[0];
    let knob = &inp.knobs.list[k];
    let mut misses = Vec::new();
    let mut node = |st: &mut State, x: f64, judge: bool| -> Result<Vec<Walked>, GapError> {
        let (walks, set) = (inp.walks(&[(k, x)])?, [(k, x)]);
        if judge && !st.surrogate.curves[k].has_node(x) {
            misses.push(surrogate_misses(inp, &st.surrogate, &set, None, &walks));
        }
        st.surrogate.curves[k].insert(x, &walks);
        Ok(walks)
    };
    for round in 0..rounds {
        let e = &st.weighed[i].evidence;
        let (u, w) = (e.mode[0], widths(e)[0]);
        if !u.is_finite() {
            break;
        }
        // The mode itself in the first round; each round walks its new mode at its end.
        for side in &[0.0, -1.0, 1.0][(round > 0) as usize..] {
            let x = knob.from_unit((u + side * w).clamp(0.0, 1.0));
            node(st, x, round > 0)?;
        }
        st.slabs[k] = Slab::new(k, knob, &st.surrogate, inp.obs);
        let fresh = st.integrate(inp, &[k], None);
        let moved = (fresh.mode[0] - u).abs();
        let walks = node(st, knob.from_unit(fresh.mode[0]), true)?;
        let w = &mut st.weighed[i];
        w.walked_chi2 = Some(chi2_of(inp.obs, &walks));
        w.walks = Some(walks);
        w.evidence = fresh;
        if moved.is_nan() || moved <= 0.25 * widths(&w.evidence)[0] {
            break;
        }
    }
    st.slabs[k] = Slab::new(k, knob, &st.surrogate, inp.obs);
    st.weighed[i].evidence = st.integrate(inp, &[k], None);
    st.weighed[i].surrogate_sd = surrogate_sd(&misses);
    Ok(())
}

/// Nodes of an anchored curve (the design's value added when inside the range).
const ANCHORED_NODES: usize = 9;

/// Walks every other suspect's curve (declared parameters and effects) with knob `k` at
/// `x`: the surrogate's anchored curves, at evenly spaced nodes.
fn anchor(
    inp: &Inputs<'_>,
    st: &mut State,
    k: usize,
    x: f64,
    suspects: &[usize],
) -> Result<(), GapError> {
    inp.progress.stage(&format!(
        "walking the other suspects' curves with {} held at its most probable value",
        inp.knobs.list[k].label()
    ));
    let mut curves = std::collections::BTreeMap::new();
    let jobs: Vec<(usize, Vec<f64>)> = suspects
        .iter()
        .filter(|&&b| b != k)
        .map(|&b| {
            let knob = &inp.knobs.list[b];
            let mut xs = knob.nodes(ANCHORED_NODES);
            xs.extend(knob.nominal);
            (b, xs)
        })
        .collect();
    let mut settings = Vec::new();
    for (b, xs) in &jobs {
        for xb in xs {
            settings.push(inp.knobs.setting_at(inp.lib, &[(k, x), (*b, *xb)]));
        }
    }
    let walks = inp
        .cache
        .get_many(inp.conditions, inp.lib, &settings, inp.progress)?;
    let mut it = walks.into_iter();
    for (b, xs) in jobs {
        let w: Vec<Vec<Walked>> = (0..xs.len()).filter_map(|_| it.next()).collect();
        curves.insert(b, super::curve::Curve::new(&st.surrogate.channels, xs, w));
    }
    st.surrogate.anchored = Some(Anchored { knob: k, x, curves });
    Ok(())
}

/// Confirms pair `i`: walks at its mode and one posterior width along each knob give a
/// first-order correction; integrate again with it; repeat while the mode moves; walk the
/// last mode. Each walk at a mode a correction had not seen measures its error, which the
/// likelihood counts beside the model's spread (a knife-edge gait defeats local corrections).
fn confirm_pair(inp: &Inputs<'_>, st: &mut State, i: usize, rounds: usize) -> Result<(), GapError> {
    let free = st.weighed[i].hypothesis.knobs.clone();
    let (mut misses, mut settled) = (Vec::new(), false);
    for round in 0..=rounds {
        let e = &st.weighed[i].evidence;
        if e.mode.iter().any(|v| !v.is_finite()) {
            break;
        }
        let (u, w) = (e.mode.clone(), widths(e));
        let set = inp.knobs.set_of(&free, &u);
        let walks = inp.walks(&set)?;
        if let Some(c) = &st.weighed[i].correction {
            misses.push(surrogate_misses(inp, &st.surrogate, &set, Some(c), &walks));
        }
        let wt = &mut st.weighed[i];
        wt.walked_chi2 = Some(chi2_of(inp.obs, &walks));
        if settled || round == rounds {
            wt.walks = Some(walks);
            break;
        }
        let (mut stepped, mut steps) = (Vec::new(), Vec::new());
        for j in 0..free.len() {
            let dir = if u[j] + w[j] <= 1.0 { 1.0 } else { -1.0 };
            let mut moved = u.clone();
            moved[j] += dir * w[j];
            let ms = inp.knobs.set_of(&free, &moved);
            stepped.push(inp.walks(&ms)?);
            steps.push(ms[j].1 - set[j].1);
        }
        let c = st.surrogate.first_order_at(&set, &walks, &stepped, &steps);
        let fresh = st.integrate(inp, &free, Some(&c));
        let moved = fresh
            .mode
            .iter()
            .zip(&u)
            .zip(&w)
            .map(|((a, b), w)| (a - b).abs() / w)
            .fold(0.0, f64::max);
        let wt = &mut st.weighed[i];
        wt.walks = Some(walks);
        wt.evidence = fresh;
        wt.correction = Some(c);
        settled = moved.is_nan() || moved <= 0.25;
    }
    st.weighed[i].surrogate_sd = surrogate_sd(&misses);
    Ok(())
}

/// Walked minus predicted (the surrogate with correction `c`) at `set`, per observation.
fn surrogate_misses(
    inp: &Inputs<'_>,
    s: &Surrogate,
    set: &[(usize, f64)],
    c: Option<&Correction>,
    walks: &[Walked],
) -> Vec<f64> {
    let miss =
        |o: &Observation| walks[o.trial].channel(o.channel) - s.predict(o.trial, o.channel, set, c);
    inp.obs.iter().map(miss).collect()
}

/// Each observation's root-mean-square miss over the walks where it is one (None: no walk).
pub fn surrogate_sd(misses: &[Vec<f64>]) -> Option<Vec<f64>> {
    let rms = |o: usize| {
        let (mut sum, mut n) = (0.0, 0);
        for x in misses.iter().map(|v| v[o]).filter(|x| x.is_finite()) {
            (sum, n) = (sum + x * x, n + 1);
        }
        (sum / n.max(1) as f64).sqrt()
    };
    Some((0..misses.first()?.len()).map(rms).collect())
}

/// Weighs `hypotheses` (the nominal and "something outside these" among them) on
/// `surrogate`, which the search refines, under the criterion `c`.
pub fn weigh(
    inp: &Inputs<'_>,
    surrogate: Surrogate,
    slabs: Vec<Slab>,
    hypotheses: Vec<Hypothesis>,
    c: &Criterion,
    search: Search,
) -> Result<(Posterior, Vec<Slab>), GapError> {
    let decision = &c.decision;
    let max_relative = c.none_of_these.max_relative;
    let mut st = State::new(inp, surrogate, slabs, hypotheses, max_relative);
    inp.progress.stage(&format!(
        "integrating {} explanations",
        st.weighed.len() + 1
    ));
    // The nominal's walks are the surrogate's own.
    for i in 0..st.weighed.len() {
        if st.weighed[i].hypothesis.knobs.is_empty() {
            let e = st.integrate(inp, &[], None);
            let w = &mut st.weighed[i];
            w.walks = Some(st.surrogate.nominal.clone());
            w.walked_chi2 = Some(e.chi2_mode);
            w.evidence = e;
        }
    }
    st.reintegrate(inp, &[]);
    st.normalise(inp);

    inp.progress
        .stage("refining the leading single explanations by walks");
    walk_leaders(inp, &mut st, 1, &search, decision)?;
    if (search.confirm > 0 && needs_pairs(&st, decision)) || search.exhaustive {
        anchor_at_best_single(inp, &mut st)?;
        inp.progress.stage("confirming the leading pairs by walks");
        walk_leaders(inp, &mut st, 2, &search, decision)?;
    }
    spread_at_walked_modes(inp, &mut st)?;
    walk_the_top(inp, &mut st, &search)?;
    let anchor = st.surrogate.anchored.as_ref().map(|a| (a.knob, a.x));
    let posterior = Posterior {
        weighed: st.weighed,
        outside: st.outside,
        anchor,
    };
    Ok((posterior, st.slabs))
}

/// Passes of refinement or confirmation at most, per size of explanation.
const PASSES: usize = 3;

/// Walks the leading explanations of `len` knobs, pass after pass, until the top one of that
/// size is walked and some walked explanation fits: walking the leaders can lift another,
/// seen by the surrogate alone, to the top; while nothing fits the share floor is dropped.
fn walk_leaders(
    inp: &Inputs<'_>,
    st: &mut State,
    len: usize,
    search: &Search,
    decision: &Decision,
) -> Result<(), GapError> {
    for _ in 0..PASSES {
        let wide = !walked_fits(st, decision);
        let settled = len == 1 && !needs_pairs(st, decision);
        let leaders = st.leading(len, search, settled, wide);
        st.for_each(&leaders, |st, i, _| walk_one(inp, st, i, search.rounds))?;
        st.normalise(inp);
        if leaders.is_empty() || (top_walked(st, len) && walked_fits(st, decision)) {
            break;
        }
    }
    Ok(())
}

/// Walks explanation `i`: refines a single (and integrates again the pairs holding its knob),
/// confirms a pair.
fn walk_one(inp: &Inputs<'_>, st: &mut State, i: usize, rounds: usize) -> Result<(), GapError> {
    let key = st.weighed[i].hypothesis.knobs.clone();
    if key.len() == 1 {
        refine_single(inp, st, i, rounds)?;
        st.reintegrate(inp, &key);
    } else if key.len() == 2 {
        confirm_pair(inp, st, i, rounds)?;
    }
    Ok(())
}

/// Whether the most probable explanation of `len` knobs has been walked.
fn top_walked(st: &State, len: usize) -> bool {
    st.weighed
        .iter()
        .find(|w| w.hypothesis.knobs.len() == len)
        .is_none_or(|w| w.walks.is_some())
}

/// Whether some explanation the search walked passes the posterior-predictive check.
fn walked_fits(st: &State, decision: &Decision) -> bool {
    st.weighed
        .iter()
        .any(|w| w.walks.is_some() && w.evidence.fit_p >= decision.fit_level)
}

/// Counts the model's spread at the mode of every explanation the search walked (perturbed
/// starts there): a knife-edge gait's spread is what lets the explanation that walks it fit.
fn spread_at_walked_modes(inp: &Inputs<'_>, st: &mut State) -> Result<(), GapError> {
    let todo: Vec<usize> = (0..st.weighed.len())
        .filter(|&i| {
            let w = &st.weighed[i];
            w.walks.is_some() && !w.hypothesis.knobs.is_empty() && w.obs.is_none()
        })
        .collect();
    todo.iter().try_for_each(|&i| st.spread_at_mode(inp, i))?;
    if !todo.is_empty() {
        st.normalise(inp);
    }
    Ok(())
}

/// Walks the most probable explanation when only the surrogate has weighed it (counting the
/// model's spread at the leaders' modes can reorder them), until the top is one the walks
/// confirmed: the answer always rests on real walks at its most probable point.
fn walk_the_top(inp: &Inputs<'_>, st: &mut State, search: &Search) -> Result<(), GapError> {
    for _ in 0..PASSES {
        let top = st.weighed.first();
        if !top.is_some_and(|t| t.walks.is_none() && (1..=2).contains(&t.hypothesis.knobs.len())) {
            break;
        }
        walk_one(inp, st, 0, search.rounds)?;
        st.normalise(inp);
        spread_at_walked_modes(inp, st)?;
    }
    Ok(())
}

/// Pairs are worth the walks when no explanation yet reaches the threshold, or the most
/// probable one does not fit.
fn needs_pairs(st: &State, decision: &Decision) -> bool {
    let outside = st.outside.as_ref().map_or(0.0, |o| o.2);
    st.weighed.first().is_some_and(|w| {
        w.evidence.fit_p < decision.fit_level
            || w.probability.max(outside) < decision.threshold
            || outside >= decision.threshold
    })
}

/// Anchors the surrogate at the most probable refined single explanation's mode, and
/// integrates every pair holding its knob again.
fn anchor_at_best_single(inp: &Inputs<'_>, st: &mut State) -> Result<(), GapError> {
    let Some(best) = st.weighed.iter().find(|w| {
        w.hypothesis.knobs.len() == 1 && w.walks.is_some() && w.hypothesis.class == Class::One
    }) else {
        return Ok(());
    };
    let k = best.hypothesis.knobs[0];
    let x = inp.knobs.list[k].from_unit(best.evidence.mode[0]);
    let suspects: Vec<usize> = st
        .weighed
        .iter()
        .filter(|w| w.hypothesis.class == Class::One)
        .map(|w| w.hypothesis.knobs[0])
        .collect();
    anchor(inp, st, k, x, &suspects)?;
    st.reintegrate_where(inp, |h| h.len() == 2 && h.contains(&k));
    st.normalise(inp);
    Ok(())
}

/// Posterior probabilities from priors, evidences and Bayes factors; most probable first by
/// their share of the library's mass (ties in list order). Every explanation H is weighed
/// alone (prior ∝ its own, evidence Z_H) and with "something outside these" beside it (prior
/// `outside_prior` spread in proportion to H's, evidence Z_H·BF_H): P(outside) =
/// q·E / ((1 − q) + q·E), E the posterior mean of BF; each keeps its share of the rest.
pub fn normalise(weighed: &mut [Weighed], outside_prior: f64) -> f64 {
    // An evidence that is not a finite number carries no mass (never all of it).
    let logs: Vec<f64> = weighed
        .iter()
        .map(|w| w.hypothesis.prior.ln() + w.evidence.log_z)
        .map(|l| if l.is_finite() { l } else { f64::NEG_INFINITY })
        .collect();
    let max = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !max.is_finite() {
        return 0.0;
    }
    let total: f64 = logs.iter().map(|l| (l - max).exp()).sum();
    let lib: Vec<f64> = logs.iter().map(|l| (l - max).exp() / total).collect();
    let terms: Vec<f64> = lib
        .iter()
        .zip(weighed.iter())
        .filter(|(p, w)| **p > 0.0 && w.log_bf.is_finite())
        .map(|(p, w)| p.ln() + w.log_bf)
        .collect();
    let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let log_e = top + terms.iter().map(|t| (t - top).exp()).sum::<f64>().ln();
    let q = outside_prior;
    let outside = if q > 0.0 && log_e.is_finite() {
        1.0 / (1.0 + (((1.0 - q) / q).ln() - log_e).exp())
    } else {
        0.0
    };
    for (w, p) in weighed.iter_mut().zip(&lib) {
        w.share = *p;
        w.probability = p * (1.0 - outside);
    }
    weighed.sort_by(|a, b| b.share.total_cmp(&a.share));
    outside
}
