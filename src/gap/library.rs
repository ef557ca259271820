//! The library of candidate unmodelled effects, as data: one TOML file per effect in
//! `dataset/effects/` (bundled into the binary). A file names the effect (the `effect` tag of
//! [`EffectSpec`]), says what it models and how it scales, and lists its parameters with
//! unit, default and plausible range. Defaults and ranges are written in the units of the
//! parameter's `scale` (m·g·L, √(g/L), L, the foot's modulus, …), so one file serves every
//! design: `--effect NAME=VALUE` and the reported parameters are in SI at the design's 1× size.
//! The first parameter is the effect's magnitude, the one the diagnosis fits; the others stay
//! at their defaults.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::{GapError, read_text};
use crate::sim::{Design, EffectSpec, GRAVITY_MPS2};

/// The natural unit a parameter is written in (its value for a design at 1×).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParamScale {
    None,
    /// m·g·L [N·m].
    Mgl,
    /// m·g·L·√(L/g) [N·m·s/rad].
    MglSqrtLOverG,
    /// √(g/L) [rad/s].
    SqrtGOverL,
    /// √(L/g) [s].
    SqrtLOverG,
    /// L [m].
    LegLength,
    /// The foot's hydroelastic modulus [Pa].
    FootModulus,
}

impl ParamScale {
    /// The unit's value for `d` (at its own size).
    pub fn value(self, d: &Design) -> f64 {
        let l = d.geometry.leg_length_m;
        let tl = (l / GRAVITY_MPS2).sqrt();
        match self {
            ParamScale::None => 1.0,
            ParamScale::Mgl => d.mgl_nm(),
            ParamScale::MglSqrtLOverG => d.mgl_nm() * tl,
            ParamScale::SqrtGOverL => 1.0 / tl,
            ParamScale::SqrtLOverG => tl,
            ParamScale::LegLength => l,
            ParamScale::FootModulus => d.contact.hydroelastic_modulus_pa,
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            ParamScale::None => "",
            ParamScale::Mgl => "m·g·L",
            ParamScale::MglSqrtLOverG => "m·g·L·√(L/g)",
            ParamScale::SqrtGOverL => "√(g/L)",
            ParamScale::SqrtLOverG => "√(L/g)",
            ParamScale::LegLength => "L",
            ParamScale::FootModulus => "E_foot",
        }
    }
}

/// The value of a parameter at which the effect is absent (the nominal model).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum OffValue {
    /// In the parameter's scale units (0 or inf for most effects).
    Value(f64),
    /// "design": the design's own value of the quantity (e.g. its friction coefficient).
    Design(DesignValue),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DesignValue {
    Design,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamDef {
    pub name: String,
    pub unit: String,
    pub scale: ParamScale,
    pub off: OffValue,
    /// Default and plausible range, in `scale` units.
    pub default: f64,
    pub range: [f64; 2],
    #[serde(default)]
    pub note: String,
}

/// One effect file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EffectDef {
    pub name: String,
    pub description: String,
    pub models: String,
    pub scaling: String,
    /// The design field this effect replaces, when the effect *is* a design value being
    /// different (friction_coefficient: `contact.friction_mu`). A design that declares that
    /// field uncertain calibrates it instead of testing the effect (the same physics).
    #[serde(default)]
    pub replaces: Option<String>,
    pub parameters: Vec<ParamDef>,
}

/// An effect with values for its parameters, in scale units (nondimensional), so that one
/// setting applies to trials of different designs and sizes alike.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectSetting {
    pub effect: String,
    pub nondimensional: Vec<f64>,
}

/// A parameter's documentation for one design, in SI (what `survey gap effects` lists).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamSummary {
    pub name: String,
    pub unit: String,
    pub default: f64,
    pub min: f64,
    pub max: f64,
    /// The value at which the effect is absent.
    pub off: f64,
    /// The natural unit the range was written in, and its value for the design.
    pub scale: String,
    pub scale_value: f64,
    pub note: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectSummary {
    pub name: String,
    pub description: String,
    pub models: String,
    pub scaling: String,
    pub params: Vec<ParamSummary>,
}

/// The loaded library, in file-name order.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectLibrary {
    pub effects: Vec<EffectDef>,
}

impl ParamDef {
    /// The off value in scale units for design `d`.
    pub fn off_nondimensional(&self, d: &Design, effect: &str) -> f64 {
        match self.off {
            OffValue::Value(v) => v,
            OffValue::Design(_) => design_value(effect, &self.name, d) / self.scale.value(d),
        }
    }
}

/// The design's own value of a quantity an effect replaces (off = "design").
fn design_value(effect: &str, param: &str, d: &Design) -> f64 {
    match (effect, param) {
        (_, "friction_mu") => d.contact.friction_mu,
        _ => f64::NAN,
    }
}

/// `dataset/effects/` compiled into the binary. Embedded here (as `study::paper` embeds its
/// table) rather than taken from `dataset`'s copy, so that gap depends on sim and
/// regression only; the files are a few kB.
static BUNDLED_EFFECTS: include_dir::Dir<'_> =
    include_dir::include_dir!("$CARGO_MANIFEST_DIR/dataset/effects");

impl EffectLibrary {
    /// The bundled library (dataset/effects/ as compiled in).
    pub fn bundled() -> Result<EffectLibrary, GapError> {
        let mut files: Vec<(String, String)> = BUNDLED_EFFECTS
            .files()
            .filter(|f| f.path().extension().is_some_and(|e| e == "toml"))
            .map(|f| {
                (
                    format!("dataset/effects/{} (bundled)", f.path().display()),
                    f.contents_utf8().unwrap_or("").to_string(),
                )
            })
            .collect();
        files.sort();
        Self::from_texts(&files)
    }

    /// A library read from a folder of effect files.
    pub fn from_dir(dir: &Path) -> Result<EffectLibrary, GapError> {
        let rd = std::fs::read_dir(dir).map_err(GapError::read(dir))?;
        let mut files = Vec::new();
        for e in rd {
            let e = e.map_err(GapError::read(dir))?;
            let p = e.path();
            if p.extension().is_some_and(|x| x == "toml") {
                let text = read_text(&p)?;
                files.push((p.display().to_string(), text));
            }
        }
        files.sort();
        Self::from_texts(&files)
    }

    fn from_texts(files: &[(String, String)]) -> Result<EffectLibrary, GapError> {
        let mut effects = Vec::new();
        for (origin, text) in files {
            let def: EffectDef =
                toml::from_str(text).map_err(|e| GapError::file(origin, e.to_string()))?;
            def.check(origin)?;
            effects.push(def);
        }
        if effects.is_empty() {
            return Err(GapError::Library("no effect files found".into()));
        }
        Ok(EffectLibrary { effects })
    }

    pub fn get(&self, name: &str) -> Result<&EffectDef, GapError> {
        self.effects.iter().find(|e| e.name == name).ok_or_else(|| {
            GapError::Library(format!(
                "unknown effect {name:?}; the library has {}",
                self.names().join(", ")
            ))
        })
    }

    pub fn names(&self) -> Vec<String> {
        self.effects.iter().map(|e| e.name.clone()).collect()
    }

    /// The subset named in `names` (all when empty), in library order.
    pub fn subset(&self, names: &[String]) -> Result<Vec<&EffectDef>, GapError> {
        if names.is_empty() {
            return Ok(self.effects.iter().collect());
        }
        for n in names {
            self.get(n)?;
        }
        Ok(self
            .effects
            .iter()
            .filter(|e| names.iter().any(|n| n == &e.name))
            .collect())
    }
}

impl EffectDef {
    fn check(&self, origin: &str) -> Result<(), GapError> {
        let bad = |m: String| GapError::file(origin, m);
        if self.parameters.is_empty() {
            return Err(bad("an effect needs at least one parameter".into()));
        }
        for p in &self.parameters {
            let [lo, hi] = p.range;
            if !(lo > 0.0 && hi > lo && hi.is_finite()) {
                return Err(bad(format!(
                    "parameters.{}: range must satisfy 0 < min < max < inf, got [{lo}, {hi}]",
                    p.name
                )));
            }
            if !(p.default.is_finite() && p.default > 0.0) {
                return Err(bad(format!(
                    "parameters.{}: default must be finite and > 0",
                    p.name
                )));
            }
        }
        // Every default must build a valid simulator term: the names match EffectSpec's.
        let probe = Design::builtin("mugatu").map_err(|e| bad(e.to_string()))?;
        if let Some(field) = &self.replaces {
            probe
                .value_at(field)
                .map_err(|e| bad(format!("replaces: {e}")))?;
        }
        let defaults: Vec<f64> = self.parameters.iter().map(|p| p.default).collect();
        self.spec(&probe, &defaults)
            .map_err(|e| bad(format!("does not build a simulator effect: {e}")))?;
        Ok(())
    }

    /// The magnitude parameter.
    pub fn magnitude(&self) -> &ParamDef {
        &self.parameters[0]
    }

    /// The simulator term for design `d` (at its own size) with `nondimensional` values.
    pub fn spec(&self, d: &Design, nondimensional: &[f64]) -> Result<EffectSpec, GapError> {
        let mut t = toml::Table::new();
        t.insert("effect".into(), toml::Value::String(self.name.clone()));
        for (p, v) in self.parameters.iter().zip(nondimensional) {
            t.insert(p.name.clone(), toml::Value::Float(v * p.scale.value(d)));
        }
        let spec: EffectSpec = t.try_into().map_err(|e: toml::de::Error| {
            GapError::Library(format!("effect {}: {}", self.name, e.message()))
        })?;
        spec.validate(&format!("effect {}", self.name), "spec")
            .map_err(|e| GapError::Library(e.to_string()))?;
        Ok(spec)
    }

    /// Default nondimensional values with the magnitude set to `magnitude`.
    pub fn setting(&self, magnitude: f64) -> EffectSetting {
        let mut v: Vec<f64> = self.parameters.iter().map(|p| p.default).collect();
        v[0] = magnitude;
        EffectSetting {
            effect: self.name.clone(),
            nondimensional: v,
        }
    }

    /// The documentation in SI for design `d` at its own size.
    pub fn summary(&self, d: &Design) -> EffectSummary {
        EffectSummary {
            name: self.name.clone(),
            description: self.description.clone(),
            models: self.models.clone(),
            scaling: self.scaling.clone(),
            params: self
                .parameters
                .iter()
                .map(|p| {
                    let s = p.scale.value(d);
                    ParamSummary {
                        name: p.name.clone(),
                        unit: p.unit.clone(),
                        default: p.default * s,
                        min: p.range[0] * s,
                        max: p.range[1] * s,
                        off: p.off_nondimensional(d, &self.name) * s,
                        scale: p.scale.label().to_string(),
                        scale_value: s,
                        note: p.note.clone(),
                    }
                })
                .collect(),
        }
    }
}

/// Parses the `--effect` arguments (`NAME=VALUE` sets the magnitude, `NAME.PARAM=VALUE` one
/// parameter; values in SI at `d`'s 1× size) into settings, one per effect named.
pub fn parse_effect_args(
    lib: &EffectLibrary,
    d: &Design,
    args: &[String],
) -> Result<Vec<EffectSetting>, GapError> {
    let mut out: Vec<EffectSetting> = Vec::new();
    for a in args {
        let err = |reason: String| GapError::EffectArg {
            spec: a.clone(),
            reason,
        };
        let (key, value) = a
            .split_once('=')
            .ok_or_else(|| err("expected NAME=VALUE or NAME.PARAM=VALUE".into()))?;
        let value: f64 = value
            .trim()
            .parse()
            .map_err(|_| err(format!("{value:?} is not a number")))?;
        if !value.is_finite() {
            return Err(err("the value must be finite".into()));
        }
        let (name, param) = match key.split_once('.') {
            Some((n, p)) => (n.trim(), Some(p.trim())),
            None => (key.trim(), None),
        };
        let def = lib.get(name).map_err(|e| err(e.to_string()))?;
        let idx = match param {
            None => 0,
            Some(p) => def
                .parameters
                .iter()
                .position(|x| x.name == p)
                .ok_or_else(|| {
                    err(format!(
                        "effect {name} has no parameter {p:?}; it has {}",
                        def.parameters
                            .iter()
                            .map(|x| x.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })?,
        };
        let pos = match out.iter().position(|s| s.effect == def.name) {
            Some(i) => i,
            None => {
                out.push(def.setting(def.magnitude().default));
                out.len() - 1
            }
        };
        out[pos].nondimensional[idx] = value / def.parameters[idx].scale.value(d);
        // The simulator must accept it (signs, ranges): fail here, naming the argument.
        def.spec(d, &out[pos].nondimensional)
            .map_err(|e| err(e.to_string()))?;
    }
    Ok(out)
}
