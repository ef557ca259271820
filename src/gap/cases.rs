//! The benchmark's out-of-library cases of a design — nominal-parameter errors and the
//! compound errors paired with every effect — as data.
//!
//! A design's cases live in `dataset/benchmarks/<design>.toml` (bundled into the binary),
//! or in a file given with `--cases`. A design without such a file gets cases derived from
//! its own declarations, so `survey gap benchmark --design D` runs on any design:
//! * each declared `[[uncertain]]` value moved half-way from the file's value toward the
//!   farther end of its range (on a log scale when the range is logarithmic; the upper end
//!   on a tie): an error the
//!   calibration should name;
//! * each number the design does not declare (the audit's list, [`Design::undeclared_params`],
//!   which leaves out the `[audit]` table's known values) ×1.3, or + 0.015 L when it is a
//!   zero offset in leg lengths: an error nothing may be blamed for — the answer should be
//!   "unexplained", "partly explained" or the audit's "not told apart".
//!
//! The derived list is a default for a design nobody has curated cases for: it tests the
//! call rules where their premise fails, not the designer's likeliest errors.

use std::path::Path;

use serde::Deserialize;

use super::error::{GapError, read_text};
use crate::sim::design::Design;

/// Fraction of the way from the file's value to the farther range end of a declared error.
pub const DECLARED_SHIFT: f64 = 0.5;
/// Factor of a derived undeclared error (inside the audit's default ×/÷ 2).
pub const UNDECLARED_FACTOR: f64 = 1.3;
/// Offset of a derived undeclared error whose file value is a zero offset in leg lengths.
pub const UNDECLARED_OFFSET_OVER_L: f64 = 0.015;

/// One error: the robot differs from its design file at these paths (values at 1×).
pub type ParameterError = Vec<(String, f64)>;

/// The out-of-library cases of one design.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchmarkCases {
    /// Where they come from: the file, or "derived from <design>".
    pub origin: String,
    pub parameter_errors: Vec<ParameterError>,
    /// Each run once with every effect of the library (the answer "both", or the effect
    /// alone when the error is undeclared).
    pub compound_errors: Vec<ParameterError>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CasesFile {
    #[serde(default)]
    parameter_error: Vec<ErrorSpec>,
    #[serde(default)]
    compound_error: Vec<ErrorSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ErrorSpec {
    set: Vec<SetSpec>,
    why: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetSpec {
    path: String,
    value: f64,
}

impl BenchmarkCases {
    /// The cases of a design: its bundled file if there is one, else derived.
    pub fn for_design(design_name: &str) -> Result<BenchmarkCases, GapError> {
        let file = format!("{design_name}.toml");
        let bundled = crate::dataset::bundled_dir("benchmarks")
            .and_then(|d| d.get_file(format!("benchmarks/{file}")))
            .and_then(|f| f.contents_utf8());
        let design = resolve_design(design_name)?;
        match bundled {
            Some(text) => Self::parse(text, &format!("dataset/benchmarks/{file}"), &design),
            None => Self::derived(&design),
        }
    }

    /// A cases file given by the user, checked against the design.
    pub fn read(path: &Path, design_name: &str) -> Result<BenchmarkCases, GapError> {
        let text = read_text(path)?;
        Self::parse(
            &text,
            &path.display().to_string(),
            &resolve_design(design_name)?,
        )
    }

    /// Parses a cases file; every path must name a number of the design, and the design
    /// with each error's values set must be valid. Errors name the file and the entry.
    pub fn parse(text: &str, origin: &str, design: &Design) -> Result<BenchmarkCases, GapError> {
        let bad = |message: String| GapError::file(origin, message);
        let file: CasesFile = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        let check = |table: &str, specs: Vec<ErrorSpec>| -> Result<Vec<ParameterError>, GapError> {
            specs
                .into_iter()
                .enumerate()
                .map(|(i, spec)| {
                    let entry = format!("[[{table}]] #{}", i + 1);
                    if spec.why.trim().is_empty() {
                        return Err(bad(format!(
                            "{entry}: `why` is empty (say what the error stands for)"
                        )));
                    }
                    if spec.set.is_empty() {
                        return Err(bad(format!("{entry}: `set` is empty")));
                    }
                    let values: Vec<(&str, f64)> = spec
                        .set
                        .iter()
                        .map(|s| (s.path.as_str(), s.value))
                        .collect();
                    design
                        .with_values(&values)
                        .map_err(|e| bad(format!("{entry}: {e}")))?;
                    Ok(spec.set.into_iter().map(|s| (s.path, s.value)).collect())
                })
                .collect()
        };
        Ok(BenchmarkCases {
            origin: origin.to_string(),
            parameter_errors: check("parameter_error", file.parameter_error)?,
            compound_errors: check("compound_error", file.compound_error)?,
        })
    }

    /// Cases derived from a design's declarations (module docs). The compound error is the
    /// first undeclared one (an undeclared error beside every effect), if the design has any.
    pub fn derived(design: &Design) -> Result<BenchmarkCases, GapError> {
        let sim = GapError::sim(&design.name);
        let mut parameter_errors = Vec::new();
        for u in design.uncertain_params().map_err(&sim)? {
            let toward = |end: f64| {
                if u.log && u.nominal > 0.0 && end > 0.0 {
                    u.nominal * (end / u.nominal).powf(DECLARED_SHIFT)
                } else {
                    u.nominal + DECLARED_SHIFT * (end - u.nominal)
                }
            };
            // The farther end (in the range's own scale) gives the larger, surer error; a tie
            // within rounding (0.3 − 0.2 < 0.2 − 0.1 in binary) takes the upper end.
            let span = |end: f64| {
                if u.log && u.nominal > 0.0 && end > 0.0 {
                    (end / u.nominal).ln().abs()
                } else {
                    (end - u.nominal).abs()
                }
            };
            let end = if span(u.hi) >= span(u.lo) * (1.0 - 1e-9) {
                u.hi
            } else {
                u.lo
            };
            let value = six_digits(toward(end));
            if value != u.nominal && design.with_value(&u.path, value).is_ok() {
                parameter_errors.push(vec![(u.path.clone(), value)]);
            }
        }
        let mut undeclared = Vec::new();
        for u in design.undeclared_params().map_err(&sim)? {
            let value = if u.nominal != 0.0 {
                six_digits(u.nominal * UNDECLARED_FACTOR)
            } else {
                UNDECLARED_OFFSET_OVER_L
            };
            if design.with_value(&u.path, value).is_ok() {
                undeclared.push(vec![(u.path.clone(), value)]);
            }
        }
        let compound_errors = undeclared.first().cloned().into_iter().collect();
        parameter_errors.extend(undeclared);
        Ok(BenchmarkCases {
            origin: format!(
                "derived from {}'s [[uncertain]] and undeclared numbers",
                design.name
            ),
            parameter_errors,
            compound_errors,
        })
    }
}

/// Six significant digits: a derived value is a case's name in the points file and the
/// report (0.00052, not 0.0005200000000000001).
fn six_digits(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

/// A bundled design by name, or a design file.
pub fn resolve_design(design_name: &str) -> Result<Design, GapError> {
    Design::resolve(design_name).map_err(GapError::sim(design_name))
}
