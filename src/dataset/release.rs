//! The compiled survey table and frozen, versioned releases of it.
//!
//! Live records compile into one flat table (one row per robot, point values only: ranges
//! stay in the records). A release freezes that table as `releases/X.Y.Z/robots.csv` and
//! `robots.parquet`, with their sha256 in `releases/manifest.toml` (cutting one is
//! `publish.rs`); `survey validate` fails if a frozen file's bytes change.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::record::{Datum, Robot, RobotClass, Source, Value};
use super::vocabulary::{FieldType, Vocabulary};
use super::{Dataset, DatasetError};

pub const MANIFEST: &str = "releases/manifest.toml";
pub const TABLE_CSV: &str = "robots.csv";
pub const TABLE_PARQUET: &str = "robots.parquet";
/// Columns before the vocabulary fields, and after them.
const ID_COLUMNS: [&str; 5] = ["id", "name", "class", "fit", "exclusion"];
const SOURCES_COLUMN: &str = "sources";

/// One robot of the compiled table. Cells keep the table's text form, so a table loaded
/// from a release writes back to the very same bytes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurveyRow {
    pub id: String,
    pub name: String,
    pub class: RobotClass,
    pub fit: bool,
    pub exclusion: Option<String>,
    pub cells: BTreeMap<String, String>,
}

impl SurveyRow {
    /// The record this row describes, with these sources and values (a release keeps no
    /// note).
    pub fn robot(&self, sources: Vec<Source>, values: BTreeMap<String, Datum>) -> Robot {
        Robot {
            id: self.id.clone(),
            name: self.name.clone(),
            class: self.class,
            fit: self.fit,
            exclusion: self.exclusion.clone(),
            note: None,
            sources,
            values,
        }
    }

    /// A numeric cell (empty or non-numeric → None).
    pub fn number(&self, column: &str) -> Option<f64> {
        self.cells
            .get(column)
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|x| x.is_finite())
    }
}

/// The compiled table: live records, or a frozen release.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurveyTable {
    /// Semantic version (the release's, or the live records' `dataset.toml` version).
    pub version: String,
    /// Whether this is a frozen release (false: compiled from live records).
    pub frozen: bool,
    /// sha256 of the table's CSV bytes: the same data always has the same hash.
    pub sha256: String,
    pub columns: Vec<String>,
    pub rows: Vec<SurveyRow>,
}

impl SurveyTable {
    /// The table as CSV (RFC 4180, `\n` line ends, header first).
    pub fn to_csv(&self) -> Vec<u8> {
        table_csv(&self.columns, &self.rows)
    }

    /// The table as Parquet, typed by the vocabulary (numbers f64, integers i64, flags bool).
    pub fn to_parquet(&self, vocab: &Vocabulary) -> Result<Vec<u8>, DatasetError> {
        use polars::prelude::*;
        let mut columns: Vec<Column> = Vec::with_capacity(self.columns.len());
        for name in &self.columns {
            let cells = self.rows.iter().map(|r| match name.as_str() {
                "id" => Some(r.id.clone()),
                "name" => Some(r.name.clone()),
                "class" => Some(r.class.as_str().to_string()),
                "fit" => Some(r.fit.to_string()),
                "exclusion" => r.exclusion.clone(),
                _ => r.cells.get(name).filter(|s| !s.is_empty()).cloned(),
            });
            let ty = if name == "fit" {
                Some(FieldType::Bool)
            } else {
                vocab.get(name).map(|f| f.field_type)
            };
            let col = match ty {
                Some(FieldType::Number) => Column::new(
                    name.into(),
                    cells
                        .map(|c| c.and_then(|s| s.parse::<f64>().ok()))
                        .collect::<Vec<_>>(),
                ),
                Some(FieldType::Integer) => Column::new(
                    name.into(),
                    cells
                        .map(|c| c.and_then(|s| s.parse::<i64>().ok()))
                        .collect::<Vec<_>>(),
                ),
                Some(FieldType::Bool) => Column::new(
                    name.into(),
                    cells.map(|c| c.map(|s| s == "true")).collect::<Vec<_>>(),
                ),
                _ => Column::new(name.into(), cells.collect::<Vec<Option<String>>>()),
            };
            columns.push(col);
        }
        let height = self.rows.len();
        let mut df = DataFrame::new(height, columns)
            .map_err(|e| DatasetError::Other(format!("building the Parquet table: {e}")))?;
        let mut buf = Vec::new();
        ParquetWriter::new(&mut buf)
            .with_compression(ParquetCompression::Uncompressed)
            .with_statistics(StatisticsOptions::empty())
            .finish(&mut df)
            .map_err(|e| DatasetError::Other(format!("writing Parquet: {e}")))?;
        Ok(buf)
    }

    /// Rows used in fits.
    pub fn fitted(&self) -> impl Iterator<Item = &SurveyRow> {
        self.rows.iter().filter(|r| r.fit)
    }

    /// The same rows in another table's columns (cells of other columns dropped), with its
    /// hash recomputed: a table compiled with today's vocabulary compared with a release
    /// frozen under an older one, in the release's own columns.
    pub fn in_columns(&self, columns: &[String]) -> SurveyTable {
        let rows: Vec<SurveyRow> = self
            .rows
            .iter()
            .map(|r| SurveyRow {
                cells: r
                    .cells
                    .iter()
                    .filter(|(c, _)| columns.contains(c))
                    .map(|(c, v)| (c.clone(), v.clone()))
                    .collect(),
                ..r.clone()
            })
            .collect();
        SurveyTable {
            version: self.version.clone(),
            frozen: self.frozen,
            sha256: sha256_hex(&table_csv(columns, &rows)),
            columns: columns.to_vec(),
            rows,
        }
    }
}

fn table_csv(columns: &[String], rows: &[SurveyRow]) -> Vec<u8> {
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    // Writing to a Vec cannot fail except on invariant breaks, which `write_record` reports
    // as errors we fold into an empty row count; the buffer is returned either way.
    let _ = w.write_record(columns);
    for r in rows {
        let rec: Vec<String> = columns
            .iter()
            .map(|c| match c.as_str() {
                "id" => r.id.clone(),
                "name" => r.name.clone(),
                "class" => r.class.as_str().to_string(),
                "fit" => r.fit.to_string(),
                "exclusion" => r.exclusion.clone().unwrap_or_default(),
                _ => r.cells.get(c).cloned().unwrap_or_default(),
            })
            .collect();
        let _ = w.write_record(&rec);
    }
    w.into_inner().unwrap_or_default()
}

pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Text form of a value in the compiled table. Floats use Rust's shortest round-trip
/// representation, so parsing the cell gives back the identical f64.
fn cell(value: &Value) -> String {
    match value {
        Value::Number(x) => format!("{x}"),
        Value::Integer(i) => i.to_string(),
        Value::Text(s) => s.clone(),
        Value::Bool(b) => b.to_string(),
        Value::Range { .. } => String::new(),
    }
}

/// Compiles the live records into the survey table.
pub fn compile(ds: &Dataset) -> SurveyTable {
    let robots: Vec<&Robot> = ds.robots.iter().map(|(_, r)| r).collect();
    compile_robots(&ds.vocab, &robots, &ds.meta.version)
}

/// Compiles robots into the survey table (rows sorted by id).
pub fn compile_robots(vocab: &Vocabulary, robots: &[&Robot], version: &str) -> SurveyTable {
    let ds_vocab = vocab;
    let mut columns: Vec<String> = ID_COLUMNS.iter().map(|s| s.to_string()).collect();
    columns.extend(ds_vocab.compiled_fields().map(|f| f.name.clone()));
    columns.push(SOURCES_COLUMN.into());
    let mut robots: Vec<&Robot> = robots.to_vec();
    robots.sort_by(|a, b| a.id.cmp(&b.id));
    let rows: Vec<SurveyRow> = robots
        .into_iter()
        .map(|r| {
            let mut cells: BTreeMap<String, String> = ds_vocab
                .compiled_fields()
                .filter_map(|f| {
                    r.values
                        .get(&f.name)
                        .map(|d| (f.name.clone(), cell(&d.value)))
                })
                .collect();
            let urls: Vec<String> = r
                .sources
                .iter()
                .map(|s| {
                    s.url
                        .clone()
                        .or_else(|| s.title.clone())
                        .unwrap_or_default()
                })
                .collect();
            cells.insert(SOURCES_COLUMN.into(), urls.join(" ; "));
            SurveyRow {
                id: r.id.clone(),
                name: r.name.clone(),
                class: r.class,
                fit: r.fit,
                exclusion: r.exclusion.clone(),
                cells,
            }
        })
        .collect();
    let csv = table_csv(&columns, &rows);
    SurveyTable {
        version: version.to_string(),
        frozen: false,
        sha256: sha256_hex(&csv),
        columns,
        rows,
    }
}

/// Parses a compiled table from CSV bytes; `file` names it in errors.
pub fn parse_table_csv(
    bytes: &[u8],
    file: &str,
    version: &str,
) -> Result<SurveyTable, DatasetError> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(bytes);
    let bad = |line: Option<u64>, message: String| DatasetError::Parse {
        file: file.to_string(),
        line: line.map(|l| l as usize),
        message,
    };
    let columns: Vec<String> = rdr
        .headers()
        .map_err(|e| bad(Some(1), e.to_string()))?
        .iter()
        .map(str::to_string)
        .collect();
    for needed in ID_COLUMNS {
        if !columns.iter().any(|c| c == needed) {
            return Err(bad(Some(1), format!("missing column `{needed}`")));
        }
    }
    let mut rows = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| bad(e.position().map(|p| p.line()), e.to_string()))?;
        let line = rec.position().map(|p| p.line());
        let get = |c: &str| -> String {
            columns
                .iter()
                .position(|x| x == c)
                .and_then(|i| rec.get(i))
                .unwrap_or_default()
                .to_string()
        };
        let class_text = get("class");
        let class = RobotClass::parse(&class_text)
            .ok_or_else(|| bad(line, format!("unknown class `{class_text}`")))?;
        let fit = match get("fit").as_str() {
            "true" => true,
            "false" => false,
            other => {
                return Err(bad(
                    line,
                    format!("`fit` must be true or false, found `{other}`"),
                ));
            }
        };
        let exclusion = Some(get("exclusion")).filter(|s| !s.is_empty());
        let cells = columns
            .iter()
            .enumerate()
            .filter(|(_, c)| !ID_COLUMNS.contains(&c.as_str()))
            .filter_map(|(i, c)| {
                rec.get(i)
                    .filter(|s| !s.is_empty())
                    .map(|s| (c.clone(), s.to_string()))
            })
            .collect();
        rows.push(SurveyRow {
            id: get("id"),
            name: get("name"),
            class,
            fit,
            exclusion,
            cells,
        });
    }
    Ok(SurveyTable {
        version: version.to_string(),
        frozen: true,
        sha256: sha256_hex(bytes),
        columns,
        rows,
    })
}

/// A file of a frozen release and the hash it must keep.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ReleaseFile {
    pub path: String,
    pub sha256: String,
}

/// One frozen release.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Release {
    pub version: String,
    pub date: String,
    pub note: String,
    #[serde(rename = "file")]
    pub files: Vec<ReleaseFile>,
}

/// `releases/manifest.toml`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    #[serde(default, rename = "release")]
    pub releases: Vec<Release>,
}

impl Manifest {
    pub fn parse(text: &str, file: &str) -> Result<Self, DatasetError> {
        toml::from_str(text).map_err(|e| DatasetError::toml(file, text, &e))
    }

    pub fn get(&self, version: &str) -> Option<&Release> {
        self.releases.iter().find(|r| r.version == version)
    }

    pub fn to_toml(&self) -> Result<String, DatasetError> {
        let body = toml::to_string(self).map_err(|e| DatasetError::Other(e.to_string()))?;
        Ok(format!(
            "# Frozen releases of the compiled robot table. A released file never changes:\n\
             # `survey validate` checks every sha256 below. Corrections go into the live\n\
             # records and a new release (see CONTRIBUTING.md).\n\n{body}"
        ))
    }
}

/// Parses `X.Y.Z` into a comparable triple.
pub fn parse_semver(v: &str) -> Option<(u64, u64, u64)> {
    let mut it = v.split('.');
    let t = (
        it.next()?.parse().ok()?,
        it.next()?.parse().ok()?,
        it.next()?.parse().ok()?,
    );
    it.next().is_none().then_some(t)
}

/// Checks a release's files against the manifest; returns one message per mismatch.
pub fn verify_release(ds: &Dataset, release: &Release) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for f in &release.files {
        let rel = format!("releases/{}", f.path);
        match ds.files.bytes(&rel) {
            None => out.push((rel, "frozen release file is missing".to_string())),
            Some(bytes) => {
                let got = sha256_hex(bytes);
                if got != f.sha256 {
                    out.push((
                        rel,
                        format!(
                            "frozen release {} changed: sha256 is {got}, manifest says {} (never edit a release; put corrections in the live records and cut a new version)",
                            release.version, f.sha256
                        ),
                    ));
                }
            }
        }
    }
    out
}

/// Loads a frozen release's table after checking its bytes.
pub fn load_release(ds: &Dataset, version: &str) -> Result<SurveyTable, DatasetError> {
    let manifest = ds.manifest()?;
    let release = manifest.get(version).ok_or_else(|| {
        let known: Vec<_> = manifest
            .releases
            .iter()
            .map(|r| r.version.as_str())
            .collect();
        DatasetError::Other(format!(
            "no release {version} in {} (releases: {})",
            ds.files.display(MANIFEST),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        ))
    })?;
    if let Some((file, msg)) = verify_release(ds, release).into_iter().next() {
        return Err(DatasetError::Invalid {
            file: ds.files.display(&file),
            message: msg,
        });
    }
    let rel = format!("releases/{version}/{TABLE_CSV}");
    let bytes = ds.files.bytes(&rel).ok_or_else(|| DatasetError::Invalid {
        file: ds.files.display(&rel),
        message: "release has no robots.csv".into(),
    })?;
    parse_table_csv(bytes, &ds.files.display(&rel), version)
}
