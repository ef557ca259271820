//! The knobs a diagnosis can turn: the uncertain parameters a design declares
//! (`[[uncertain]]`: model error) and the magnitudes of the library's effects (physics the
//! nominal model lacks). A *model* is a set of knobs set free; the others stay at the
//! nominal value (parameters) or off (effects). A *point* gives every free knob a value.
//!
//! Each knob has a coordinate: its value, or ln(value) for effect magnitudes and log-scale
//! parameters, bounded by its plausible range. A knob's prior over that range is uniform in
//! its coordinate (log-uniform for effects and `log = true` parameters), or the design's
//! Gaussian (`sd` or `relative_sd`) truncated to the range. The design's other numbers
//! (undeclared: not in its `[[uncertain]]`) are knobs too, over ×/÷ 2 around their value
//! ([`crate::sim::Design::undeclared_params`]).

use serde::Serialize;

use super::library::{EffectDef, EffectLibrary, EffectSetting};
use crate::sim::Design;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum KnobKind {
    /// An uncertain parameter of a design (model error).
    Parameter,
    /// An effect of the library (unmodelled physics).
    Effect,
    /// A number of a design that its file does not declare uncertain.
    Undeclared,
}

#[derive(Clone, Debug, Serialize)]
pub struct Knob {
    pub kind: KnobKind,
    /// Parameter: the design it belongs to. Effect: empty (effects act on every design,
    /// scaled by their rule).
    pub design: String,
    /// Parameter path (`mass.leg_com_height_over_l`) or effect name.
    pub name: String,
    /// The coordinate is ln(value).
    pub log: bool,
    /// Bounds of the coordinate.
    pub lo: f64,
    pub hi: f64,
    /// The nominal model's coordinate; None for an effect whose off value lies outside its
    /// range (off = absent).
    pub nominal: Option<f64>,
    /// Effects: the value at which the effect is absent (0, ∞, or inside the range such as
    /// the design's own μ); parameters: None.
    pub off_value: Option<f64>,
    /// Gaussian prior (mean, sd) in value units.
    pub prior: Option<(f64, f64)>,
    /// Value → SI at the design's 1× size (effects: the scale unit; parameters: 1).
    pub si_per_value: f64,
    /// SI unit.
    pub unit: String,
    /// Why the knob is there (the design's reason, or the effect's description).
    pub why: String,
}

impl Knob {
    /// The knob of a design's parameter (declared `[[uncertain]]`, or an undeclared number
    /// the audit weighs): its range and prior in the coordinate its scale asks for.
    pub fn parameter(design: &str, u: &crate::sim::design::UncertainParam) -> Knob {
        let coord = |v: f64| if u.log { v.ln() } else { v };
        Knob {
            kind: KnobKind::Parameter,
            design: design.to_string(),
            name: u.path.clone(),
            log: u.log,
            lo: coord(u.lo),
            hi: coord(u.hi),
            nominal: Some(coord(u.nominal)),
            off_value: None,
            prior: u.prior_sd.map(|sd| (u.nominal, sd)),
            si_per_value: 1.0,
            unit: String::new(),
            why: u.why.clone(),
        }
    }

    /// An undeclared number of a design, weighed over the range the audit gives it.
    pub fn undeclared(design: &str, u: &crate::sim::design::UncertainParam) -> Knob {
        Knob {
            kind: KnobKind::Undeclared,
            ..Knob::parameter(design, u)
        }
    }

    /// A readable name: the effect's, or `design:path` for a parameter.
    pub fn label(&self) -> String {
        match self.kind {
            KnobKind::Effect => self.name.clone(),
            KnobKind::Parameter | KnobKind::Undeclared => format!("{}:{}", self.design, self.name),
        }
    }

    /// A design's number (declared or not), as opposed to an effect.
    pub fn is_parameter(&self) -> bool {
        self.kind != KnobKind::Effect
    }

    /// The log density of the knob's prior at unit coordinate `s` ∈ [0, 1] (uniform: 0; a
    /// Gaussian prior in value units, truncated to the range, carried into unit
    /// coordinates: N(v; mean, sd) · |dv/ds| / its mass over the range).
    pub fn log_prior_unit(&self, s: f64) -> f64 {
        let Some((mean, sd)) = self.prior else {
            return 0.0;
        };
        let x = self.from_unit(s);
        let v = self.value(x);
        let dv_dx = if self.log { v } else { 1.0 };
        let cdf = |v: f64| crate::regression::dist::normal_cdf((v - mean) / sd).unwrap_or(0.5);
        let mass = cdf(self.value(self.hi)) - cdf(self.value(self.lo));
        let z = (v - mean) / sd;
        -0.5 * z * z - (sd * (2.0 * std::f64::consts::PI).sqrt()).ln()
            + (dv_dx * (self.hi - self.lo)).abs().ln()
            - mass.max(f64::MIN_POSITIVE).ln()
    }

    /// Value (the field's unit; nondimensional magnitude for effects) of a coordinate.
    pub fn value(&self, x: f64) -> f64 {
        if self.log { x.exp() } else { x }
    }

    /// SI value of a coordinate (the design at 1×).
    pub fn si(&self, x: f64) -> f64 {
        self.value(x) * self.si_per_value
    }

    /// The coordinate of a value.
    pub fn coordinate(&self, value: f64) -> f64 {
        if self.log { value.ln() } else { value }
    }

    /// Coordinate ↔ the unit interval the solvers work in.
    pub fn to_unit(&self, x: f64) -> f64 {
        (x - self.lo) / (self.hi - self.lo)
    }
    pub fn from_unit(&self, s: f64) -> f64 {
        self.lo + s.clamp(0.0, 1.0) * (self.hi - self.lo)
    }

    /// Where the knob rests when the model does not fit it: its nominal coordinate, or for
    /// an effect without one its weakest setting.
    pub fn resting(&self) -> f64 {
        self.nominal.unwrap_or_else(|| {
            self.strengthening_path(1)
                .first()
                .copied()
                .unwrap_or(self.lo)
        })
    }

    /// Coordinates from the nominal (or off) toward the strongest setting: up from an off
    /// value of 0 (or below the range), down from ∞ (or above), and from an off value inside
    /// the range toward the lower end (for μ: slipperier). Parameters: toward the farther end.
    pub fn strengthening_path(&self, steps: usize) -> Vec<f64> {
        let (from, to) = match (self.kind, self.off_value, self.nominal) {
            (KnobKind::Effect, Some(off), None) if off.is_infinite() || off.ln() > self.hi => {
                (self.hi, self.lo)
            }
            (KnobKind::Effect, _, None) => (self.lo, self.hi),
            (KnobKind::Effect, _, Some(x)) => (x, self.lo),
            (KnobKind::Parameter | KnobKind::Undeclared, _, x) => {
                let x = x.unwrap_or(self.lo);
                if self.hi - x >= x - self.lo {
                    (x, self.hi)
                } else {
                    (x, self.lo)
                }
            }
        };
        (0..=steps)
            .map(|k| from + (to - from) * k as f64 / steps.max(1) as f64)
            .collect()
    }

    /// Nodes of the knob's curve: `n` evenly spaced coordinates over its range, plus the
    /// nominal if it lies inside (that walk is the nominal one).
    pub fn nodes(&self, n: usize) -> Vec<f64> {
        let n = n.max(2);
        (0..n)
            .map(|k| self.lo + (self.hi - self.lo) * k as f64 / (n - 1) as f64)
            .collect()
    }
}

/// The parameter values and effects of a model point, as the simulator takes them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelSetting {
    /// (design name, path, value): applied to the trials of that design, on its 1× values.
    pub params: Vec<(String, String, f64)>,
    pub effects: Vec<EffectSetting>,
}

impl ModelSetting {
    pub fn nominal() -> ModelSetting {
        ModelSetting::default()
    }

    /// The overrides that apply to design `design`.
    pub fn params_of<'a>(&'a self, design: &'a str) -> impl Iterator<Item = (&'a str, f64)> {
        self.params
            .iter()
            .filter(move |(d, _, _)| d == design)
            .map(|(_, p, v)| (p.as_str(), *v))
    }

    /// A canonical key of what changes the walks of design `design` (the cache key).
    pub fn key_for(&self, design: &str) -> String {
        let mut parts: Vec<String> = self
            .params_of(design)
            .map(|(p, v)| format!("{p}={:016x}", v.to_bits()))
            .collect();
        parts.sort();
        let mut effects: Vec<String> = self
            .effects
            .iter()
            .map(|e| {
                let mut k = e.effect.clone();
                for v in &e.nondimensional {
                    k.push_str(&format!(":{:016x}", v.to_bits()));
                }
                k
            })
            .collect();
        effects.sort();
        parts.extend(effects);
        if parts.is_empty() {
            "nominal".into()
        } else {
            parts.join(";")
        }
    }
}

/// The knobs of a diagnosis, parameters first, then effects.
#[derive(Clone, Debug, Serialize)]
pub struct Knobs {
    pub list: Vec<Knob>,
    /// Effects left out because a design declares their quantity uncertain (the parameter
    /// is calibrated instead): (effect, the parameter that stands for it).
    pub aliased: Vec<(String, String)>,
}

/// A point: a coordinate for every free knob, None for the others (nominal or off).
pub type Point = Vec<Option<f64>>;

impl Knobs {
    /// The knobs for trials of `designs` (each scaled to 1× for the SI units): the designs'
    /// uncertain parameters when `calibrate`, and the candidate `effects`. An effect that
    /// replaces a design field (`replaces = "contact.friction_mu"`) which every design
    /// declares uncertain is left out: calibrating the parameter is the same physics.
    pub fn build(
        designs: &[&Design],
        effects: &[&EffectDef],
        calibrate: bool,
    ) -> Result<Knobs, crate::sim::SimError> {
        let mut list = Vec::new();
        if calibrate {
            for d in designs {
                for u in d.uncertain_params()? {
                    list.push(Knob::parameter(&d.name, &u));
                }
            }
        }
        let mut aliased = Vec::new();
        let first = designs.first().copied();
        for def in effects {
            if let Some(field) = &def.replaces
                && !designs.is_empty()
                && list
                    .iter()
                    .filter(|k| k.kind == KnobKind::Parameter && &k.name == field)
                    .count()
                    == designs.len()
            {
                aliased.push((def.name.clone(), field.clone()));
                continue;
            }
            let p = def.magnitude();
            let (nominal, si, off) = match first {
                Some(d) => {
                    let off = p.off_nondimensional(d, &def.name);
                    let inside =
                        off > 0.0 && off.is_finite() && (p.range[0]..=p.range[1]).contains(&off);
                    (inside.then(|| off.ln()), p.scale.value(d), Some(off))
                }
                None => (None, 1.0, None),
            };
            list.push(Knob {
                kind: KnobKind::Effect,
                design: String::new(),
                name: def.name.clone(),
                log: true,
                lo: p.range[0].ln(),
                hi: p.range[1].ln(),
                nominal,
                off_value: off,
                prior: None,
                si_per_value: si,
                unit: p.unit.clone(),
                why: def.description.clone(),
            });
        }
        Ok(Knobs { list, aliased })
    }

    /// These knobs and, after them, every undeclared number of `designs` that no knob
    /// already frees and no candidate effect stands for (`soft_ground` replaces the contact
    /// modulus: the same physics, already weighed).
    pub fn with_undeclared(
        mut self,
        designs: &[&Design],
        lib: &EffectLibrary,
    ) -> Result<Knobs, crate::sim::SimError> {
        let replaced: Vec<String> = self
            .list
            .iter()
            .filter(|k| k.kind == KnobKind::Effect)
            .filter_map(|k| lib.get(&k.name).ok().and_then(|d| d.replaces.clone()))
            .collect();
        for d in designs {
            for u in d.undeclared_params()? {
                let freed = self
                    .list
                    .iter()
                    .any(|k| k.is_parameter() && k.design == d.name && k.name == u.path);
                if !freed && !replaced.contains(&u.path) {
                    self.list.push(Knob::undeclared(&d.name, &u));
                }
            }
        }
        Ok(self)
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The all-nominal point.
    pub fn nominal_point(&self) -> Point {
        vec![None; self.list.len()]
    }

    pub fn index_of(&self, label: &str) -> Option<usize> {
        self.list.iter().position(|k| k.label() == label)
    }

    /// The simulator's setting of a point. A knob at exactly its nominal coordinate is the
    /// nominal model (same walks, same cache key).
    pub fn setting(&self, lib: &EffectLibrary, point: &[Option<f64>]) -> ModelSetting {
        let mut s = ModelSetting::default();
        for (k, x) in self.list.iter().zip(point) {
            let Some(x) = *x else { continue };
            if k.nominal == Some(x) {
                continue;
            }
            match k.kind {
                KnobKind::Parameter | KnobKind::Undeclared => {
                    s.params
                        .push((k.design.clone(), k.name.clone(), k.value(x)));
                }
                KnobKind::Effect => {
                    if let Ok(def) = lib.get(&k.name) {
                        s.effects.push(def.setting(k.value(x)));
                    }
                }
            }
        }
        s
    }

    /// The setting with the knobs of `set` at their coordinates and the others nominal.
    pub fn setting_at(&self, lib: &EffectLibrary, set: &[(usize, f64)]) -> ModelSetting {
        let mut p = self.nominal_point();
        for &(k, x) in set {
            p[k] = Some(x);
        }
        self.setting(lib, &p)
    }

    /// The (knob, coordinate) pairs of the knobs `free` at unit coordinates `unit`.
    pub fn set_of(&self, free: &[usize], unit: &[f64]) -> Vec<(usize, f64)> {
        let at = |(&k, &s): (&usize, &f64)| (k, self.list[k].from_unit(s));
        free.iter().zip(unit).map(at).collect()
    }

    /// `base` with the knobs `active` set from unit coordinates `unit` (what the solvers
    /// see) to values.
    pub fn point_at(&self, base: &[Option<f64>], active: &[usize], unit: &[f64]) -> Point {
        let mut p = base.to_vec();
        for (&k, &s) in active.iter().zip(unit) {
            p[k] = Some(self.list[k].from_unit(s));
        }
        p
    }
}
