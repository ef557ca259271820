//! The curated robot dataset: records, vocabulary, validation, frozen releases, and the
//! import of the upstream survey table.
//!
//! A dataset is a directory (by default `./dataset`, or the copy bundled into the binary):
//! ```text
//! dataset.toml            name and semantic version of the live records
//! vocabulary.toml         fields, units, types, plausible ranges
//! robots/ID.toml          one record per robot
//! releases/manifest.toml  frozen releases and the sha256 of each file
//! releases/X.Y.Z/         robots.csv, robots.parquet
//! datapackage.json        Frictionless description of the compiled table
//! ```
//! Everything is read into memory first ([`DatasetFiles`]) so that the directory and the
//! bundled copy go through the same code.

pub mod canonical;
pub mod datapackage;
pub mod problem;
pub mod publish;
pub mod record;
pub mod release;
pub mod selection;
pub mod upstream;
pub mod validate;
pub mod vocabulary;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use include_dir::{Dir, include_dir};
use serde::{Deserialize, Serialize};

pub use problem::{Problem, Rule, Severity};
pub use record::{Datum, Robot, RobotClass, Source, SourceKind, Value};
pub use release::{Manifest, SurveyRow, SurveyTable};
pub use vocabulary::{FieldSpec, FieldType, GaitSpec, SpeedKind, Vocabulary};

/// The dataset directory compiled into the binary, so that `survey fit` works on a fresh
/// machine from any working directory.
static BUNDLED: Dir<'_> = include_dir!("$CARGO_MANIFEST_DIR/dataset");

/// A folder of the bundled dataset (e.g. `effects`, `trials`), for readers that want the
/// compiled-in copy of their data.
pub fn bundled_dir(sub: &str) -> Option<&'static Dir<'static>> {
    BUNDLED.get_dir(sub)
}

/// Errors that stop a dataset from being read at all (as opposed to [`Problem`]s, which
/// are findings about its content).
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        file: String,
        line: Option<usize>,
        message: String,
    },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("{0}")]
    Other(String),
}

impl DatasetError {
    /// A TOML syntax or shape error in `file`, with the line of the offending span.
    pub fn toml(file: impl Into<String>, text: &str, e: &toml::de::Error) -> Self {
        DatasetError::Parse {
            file: file.into(),
            line: e.span().map(|s| vocabulary::line_of_offset(text, s.start)),
            message: e.message().to_string(),
        }
    }
}

/// All files of a dataset, in memory, keyed by `/`-separated path relative to its root.
#[derive(Debug, Clone)]
pub struct DatasetFiles {
    /// Where the files came from, for messages (`dataset` or `<bundled dataset>`).
    pub origin: String,
    /// The directory on disk, when there is one (commands that write need it).
    pub dir: Option<PathBuf>,
    pub files: BTreeMap<String, Vec<u8>>,
}

impl DatasetFiles {
    /// Reads every file below `dir`.
    pub fn from_dir(dir: &Path) -> Result<Self, DatasetError> {
        let io = |p: &Path, e| DatasetError::Io {
            path: p.display().to_string(),
            source: e,
        };
        if !dir.is_dir() {
            return Err(DatasetError::Other(format!(
                "{}: not a dataset directory (expected dataset.toml, vocabulary.toml, robots/)",
                dir.display()
            )));
        }
        let mut files = BTreeMap::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            for entry in std::fs::read_dir(&d).map_err(|e| io(&d, e))? {
                let entry = entry.map_err(|e| io(&d, e))?;
                let path = entry.path();
                if path.is_dir() {
                    stack.push(path);
                } else {
                    let rel = path
                        .strip_prefix(dir)
                        .map_err(|_| {
                            DatasetError::Other(format!("{}: outside dataset", path.display()))
                        })?
                        .components()
                        .map(|c| c.as_os_str().to_string_lossy().into_owned())
                        .collect::<Vec<_>>()
                        .join("/");
                    let bytes = std::fs::read(&path).map_err(|e| io(&path, e))?;
                    files.insert(rel, bytes);
                }
            }
        }
        Ok(DatasetFiles {
            origin: dir.display().to_string(),
            dir: Some(dir.to_path_buf()),
            files,
        })
    }

    /// The dataset bundled into the binary at build time.
    pub fn bundled() -> Self {
        let mut files = BTreeMap::new();
        let mut stack = vec![&BUNDLED];
        while let Some(d) = stack.pop() {
            for f in d.files() {
                files.insert(
                    f.path().to_string_lossy().replace('\\', "/"),
                    f.contents().to_vec(),
                );
            }
            stack.extend(d.dirs());
        }
        DatasetFiles {
            origin: "<bundled dataset>".into(),
            dir: None,
            files,
        }
    }

    /// `--dataset DIR` if given, else `./dataset` when present, else the bundled copy.
    pub fn locate(dir: Option<&Path>) -> Result<Self, DatasetError> {
        match dir {
            Some(d) => Self::from_dir(d),
            None => {
                let local = Path::new("dataset");
                if local.join("dataset.toml").is_file() {
                    Self::from_dir(local)
                } else {
                    Ok(Self::bundled())
                }
            }
        }
    }

    /// Display path of a file, for messages.
    pub fn display(&self, rel: &str) -> String {
        match &self.dir {
            Some(d) => d.join(rel).display().to_string(),
            None => format!("{}/{rel}", self.origin),
        }
    }

    pub fn bytes(&self, rel: &str) -> Option<&[u8]> {
        self.files.get(rel).map(Vec::as_slice)
    }

    /// A file as UTF-8 text; a missing or non-UTF-8 file is an error naming it.
    pub fn text(&self, rel: &str) -> Result<&str, DatasetError> {
        let bytes = self.bytes(rel).ok_or_else(|| DatasetError::Invalid {
            file: self.display(rel),
            message: "file is missing".into(),
        })?;
        std::str::from_utf8(bytes).map_err(|e| DatasetError::Parse {
            file: self.display(rel),
            line: Some(vocabulary::line_of_offset(
                &String::from_utf8_lossy(bytes),
                e.valid_up_to(),
            )),
            message: "not valid UTF-8".into(),
        })
    }
}

/// `dataset.toml`: what the live records are.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetMeta {
    pub name: String,
    /// Semantic version of the live records (the next release they will become).
    pub version: String,
    pub description: String,
    pub license: String,
}

/// A loaded dataset: live records plus everything needed to check and release them.
#[derive(Debug, Clone)]
pub struct Dataset {
    pub files: DatasetFiles,
    pub meta: DatasetMeta,
    pub vocab: Vocabulary,
    /// Parsed robots with the file they came from (`robots/ID.toml`), sorted by file.
    pub robots: Vec<(String, Robot)>,
    /// Problems met while parsing records (the validator adds the rest).
    pub parse_problems: Vec<Problem>,
}

/// The bundled vocabulary, used when a dataset directory has none of its own.
pub const BUNDLED_VOCABULARY: &str = include_str!("../../dataset/vocabulary.toml");

impl Dataset {
    /// Parses metadata, vocabulary and every record. Broken records become problems, not
    /// errors; only an unreadable `dataset.toml` or vocabulary stops loading.
    pub fn load(files: DatasetFiles) -> Result<Self, DatasetError> {
        let meta_text = files.text("dataset.toml")?;
        let meta: DatasetMeta = toml::from_str(meta_text)
            .map_err(|e| DatasetError::toml(files.display("dataset.toml"), meta_text, &e))?;
        let vocab = match files.bytes("vocabulary.toml") {
            Some(_) => Vocabulary::parse(
                files.text("vocabulary.toml")?,
                &files.display("vocabulary.toml"),
            )?,
            None => Vocabulary::parse(BUNDLED_VOCABULARY, "<bundled vocabulary.toml>")?,
        };
        let mut robots = Vec::new();
        let mut parse_problems = Vec::new();
        for (rel, bytes) in files.files.range("robots/".to_string()..) {
            if !rel.starts_with("robots/") {
                break;
            }
            if !rel.ends_with(".toml") {
                continue;
            }
            let display = files.display(rel);
            let text = match std::str::from_utf8(bytes) {
                Ok(t) => t,
                Err(e) => {
                    parse_problems.push(
                        Problem::error(&display, Rule::Parse, "not valid UTF-8").line(Some(
                            vocabulary::line_of_offset(
                                &String::from_utf8_lossy(bytes),
                                e.valid_up_to(),
                            ),
                        )),
                    );
                    continue;
                }
            };
            if let Some(robot) = record::parse_record(text, &display, &vocab, &mut parse_problems) {
                robots.push((rel.clone(), robot));
            }
        }
        Ok(Dataset {
            files,
            meta,
            vocab,
            robots,
            parse_problems,
        })
    }

    /// Loads a dataset from `--dataset DIR`, `./dataset` or the bundled copy.
    pub fn locate(dir: Option<&Path>) -> Result<Self, DatasetError> {
        Self::load(DatasetFiles::locate(dir)?)
    }

    /// The release manifest (an empty one when the dataset has no releases yet).
    pub fn manifest(&self) -> Result<Manifest, DatasetError> {
        match self.files.bytes(release::MANIFEST) {
            None => Ok(Manifest::default()),
            Some(_) => Manifest::parse(
                self.files.text(release::MANIFEST)?,
                &self.files.display(release::MANIFEST),
            ),
        }
    }

    /// The survey table of the live records, or of a frozen release when `release` is given
    /// (its bytes are checked against the manifest first).
    pub fn table(&self, release: Option<&str>) -> Result<SurveyTable, DatasetError> {
        match release {
            None => {
                let blocking: Vec<_> = self
                    .parse_problems
                    .iter()
                    .filter(|p| p.severity == Severity::Error)
                    .collect();
                if let Some(first) = blocking.first() {
                    return Err(DatasetError::Other(format!(
                        "{} record problem(s) stop the live dataset from being used, first: {}\n(run `survey validate` for all of them)",
                        blocking.len(),
                        first.to_line()
                    )));
                }
                Ok(release::compile(self))
            }
            Some(version) => release::load_release(self, version),
        }
    }
}
