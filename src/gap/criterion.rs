//! The criterion's settings, as data (`dataset/gap/criterion.toml`): the prior mass of each
//! class of explanation, the reach of "something outside these", and the decision's two
//! numbers (the posterior a name needs, the posterior-predictive level below which nothing
//! fits), which the benchmark chooses on half of its cases.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::{GapError, read_text};

/// The bundled criterion file's text (`dataset/gap/criterion.toml`).
pub const BUNDLED: &str = include_str!("../../dataset/gap/criterion.toml");

/// Prior mass per class of explanation (they sum to 1).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ClassPriors {
    pub nominal: f64,
    pub one: f64,
    pub two: f64,
    pub undeclared: f64,
    pub none_of_these: f64,
}

/// "Something outside these": the reach of its discrepancy.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NoneOfThese {
    /// Largest relative discrepancy (1 = 100 % of each value).
    pub max_relative: f64,
}

/// How the posterior becomes an answer.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Decision {
    /// Posterior probability the top explanation needs to be named.
    pub threshold: f64,
    /// Posterior-predictive p-value below which even the best explanation does not fit.
    pub fit_level: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Criterion {
    pub prior: ClassPriors,
    pub none_of_these: NoneOfThese,
    pub decision: Decision,
}

impl Criterion {
    /// The bundled criterion (`dataset/gap/criterion.toml`).
    pub fn bundled() -> Result<Criterion, GapError> {
        Self::parse(BUNDLED, "dataset/gap/criterion.toml (bundled)")
    }

    /// A criterion file.
    pub fn read(path: &Path) -> Result<Criterion, GapError> {
        let text = read_text(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    pub fn parse(text: &str, origin: &str) -> Result<Criterion, GapError> {
        let c: Criterion =
            toml::from_str(text).map_err(|e| GapError::file(origin, e.to_string()))?;
        c.check(origin)?;
        Ok(c)
    }

    fn check(&self, origin: &str) -> Result<(), GapError> {
        let bad = |message: String| Err(GapError::file(origin, message));
        let p = &self.prior;
        let masses = [p.nominal, p.one, p.two, p.undeclared, p.none_of_these];
        if masses.iter().any(|m| !(m.is_finite() && *m >= 0.0)) {
            return bad("prior: every class mass must be a number ≥ 0".into());
        }
        let sum: f64 = masses.iter().sum();
        if (sum - 1.0).abs() > 1e-9 {
            return bad(format!("prior: the class masses sum to {sum}, not 1"));
        }
        if p.nominal <= 0.0 {
            return bad("prior.nominal must be > 0: the nominal model is always weighed".into());
        }
        let d = &self.decision;
        if !(d.threshold > 0.5 && d.threshold < 1.0) {
            return bad(format!(
                "decision.threshold = {}: must be in (0.5, 1), so that at most one \
                 explanation can reach it",
                d.threshold
            ));
        }
        if !(d.fit_level > 0.0 && d.fit_level < 1.0) {
            return bad(format!(
                "decision.fit_level = {}: must be in (0, 1)",
                d.fit_level
            ));
        }
        if !(self.none_of_these.max_relative > 0.0 && self.none_of_these.max_relative.is_finite()) {
            return bad("none_of_these.max_relative must be a number > 0".into());
        }
        Ok(())
    }
}
