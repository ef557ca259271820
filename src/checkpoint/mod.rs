//! Long runs that survive interruption and split across machines (the sweeps of `survey
//! sim` and the gap benchmark), a checkpointing add-on kept out of the loops it serves: every finished point is
//! appended to a points file (CSV) at once, so a re-run skips what is done; `--shard i/n`
//! runs one slice of a study's independent units; [`merge`] joins the slices' files into
//! exactly what one run writes.
//!
//! A points file starts with one comment line naming the study and its full specification
//! (`# robot-survey sweep <kind> <json>`): resuming or merging files of a different
//! specification is refused instead of mixing results. Numbers are written in the
//! shortest form that reads back to the same `f64`, so a resumed study continues from
//! exactly the values it would have held in memory.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::Serialize;
use serde::de::DeserializeOwned;

/// What can go wrong with a points file.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("cannot read or write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A points file (checkpoint or shard) that cannot be used.
    #[error("{path}: {message}")]
    Points { path: PathBuf, message: String },
    #[error("invalid option `{option}`: {reason}")]
    Invalid { option: String, reason: String },
}

impl CheckpointError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        CheckpointError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
    pub(crate) fn points(path: &Path, message: impl Into<String>) -> Self {
        CheckpointError::Points {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// A row of a sweep: serialisable, with a key unique within its study.
pub trait SweepPoint: Serialize + DeserializeOwned + Clone + Send + Sync {
    fn key(&self) -> String;
}

/// One slice of a study: units k with k mod count = index − 1 (written `index/count`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Does this shard run unit `k` (0-based)?
    pub fn takes(&self, k: usize) -> bool {
        k % self.count == self.index - 1
    }
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}`: expected i/n, e.g. 2/4"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: shard index `{i}` is not a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: shard count `{n}` is not a whole number"))?;
        if count == 0 || index == 0 || index > count {
            return Err(format!("`{s}`: need 1 ≤ i ≤ n"));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

const MAGIC: &str = "# robot-survey sweep ";

/// The first line of a points file of study `kind` with specification `spec` (JSON).
pub fn spec_line(kind: &str, spec: &str) -> String {
    format!("{MAGIC}{kind} {spec}")
}

/// A points file open for appending.
pub struct PointLog {
    path: PathBuf,
    writer: csv::Writer<File>,
}

impl PointLog {
    /// Opens (or creates) the points file at `path` for a study whose first line is
    /// `header`, returning the log and the points already in it. A last line cut short by
    /// an interruption is dropped.
    pub fn open<R: SweepPoint>(
        path: &Path,
        header: &str,
    ) -> Result<(PointLog, Vec<R>), CheckpointError> {
        let existing = match std::fs::read(path) {
            Ok(bytes) => Some(bytes),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(CheckpointError::io(path, e)),
        };
        let (points, has_rows_header) = match &existing {
            Some(bytes) if !bytes.is_empty() => {
                let complete = match bytes.iter().rposition(|&b| b == b'\n') {
                    Some(i) => i + 1,
                    None => 0,
                };
                if complete < bytes.len() {
                    // An interrupted write: keep whole lines only.
                    let f = OpenOptions::new()
                        .write(true)
                        .open(path)
                        .map_err(|e| CheckpointError::io(path, e))?;
                    f.set_len(complete as u64)
                        .map_err(|e| CheckpointError::io(path, e))?;
                }
                let text = std::str::from_utf8(&bytes[..complete])
                    .map_err(|_| CheckpointError::points(path, "not UTF-8 text"))?;
                let first = text.lines().next().unwrap_or("");
                if first != header {
                    return Err(other_study(path, first, header));
                }
                let has_header = text.lines().nth(1).is_some();
                (parse_rows::<R>(path, text)?, has_header)
            }
            _ => (Vec::new(), false),
        };
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| CheckpointError::io(path, e))?;
        if existing.as_ref().is_none_or(|b| b.is_empty()) {
            writeln!(file, "{header}").map_err(|e| CheckpointError::io(path, e))?;
        }
        let writer = csv::WriterBuilder::new()
            .has_headers(!has_rows_header)
            .from_writer(file);
        Ok((
            PointLog {
                path: path.to_path_buf(),
                writer,
            },
            points,
        ))
    }

    /// Appends one point and flushes it to disk.
    pub fn append<R: SweepPoint>(&mut self, point: &R) -> Result<(), CheckpointError> {
        self.writer
            .serialize(point)
            .map_err(|e| CheckpointError::points(&self.path, e.to_string()))?;
        self.writer
            .flush()
            .map_err(|e| CheckpointError::io(&self.path, e))
    }
}

/// Opens the points file of a sweep when one is given: the log to append to (shared by the
/// workers) and the points already done, by key.
pub type OpenedLog<R> = (
    Option<std::sync::Mutex<PointLog>>,
    std::collections::HashMap<String, R>,
);

pub fn open_log<R: SweepPoint>(
    path: Option<&Path>,
    header: &str,
) -> Result<OpenedLog<R>, CheckpointError> {
    match path {
        Some(p) => {
            let (log, done) = PointLog::open::<R>(p, header)?;
            Ok((
                Some(std::sync::Mutex::new(log)),
                done.into_iter().map(|r| (r.key(), r)).collect(),
            ))
        }
        None => Ok((None, Default::default())),
    }
}

/// Appends a finished point to the shared log, if any.
pub fn append_to<R: SweepPoint>(
    log: Option<&std::sync::Mutex<PointLog>>,
    point: &R,
) -> Result<(), CheckpointError> {
    match log {
        Some(log) => log
            .lock()
            .map_err(|_| CheckpointError::Invalid {
                option: "points".into(),
                reason: "a worker panicked while writing the points file".into(),
            })?
            .append(point),
        None => Ok(()),
    }
}

/// The refusal of a points file whose first line is not `header`.
fn other_study(path: &Path, first: &str, header: &str) -> CheckpointError {
    CheckpointError::points(
        path,
        format!(
            "was written for a different study (first line differs); resume only with the same \
             options, or use another file.\n  file:     {}\n  expected: {}",
            truncate(first, 300),
            truncate(header, 300)
        ),
    )
}

/// Whether the points file at `path` can be resumed by a study whose first line is
/// `header` (no file, an empty one, or one of the same study): the check [`PointLog::open`]
/// makes, for a caller to refuse early, before minutes of planning, rather than after.
pub fn check_resumable(path: &Path, header: &str) -> Result<(), CheckpointError> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(CheckpointError::io(path, e)),
    };
    let mut first = String::new();
    std::io::BufRead::read_line(&mut std::io::BufReader::new(file), &mut first)
        .map_err(|e| CheckpointError::io(path, e))?;
    let first = first.trim_end_matches(['\n', '\r']);
    if first.is_empty() || first == header {
        Ok(())
    } else {
        Err(other_study(path, first, header))
    }
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(n).collect::<String>())
    }
}

fn parse_rows<R: SweepPoint>(path: &Path, text: &str) -> Result<Vec<R>, CheckpointError> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let mut rows = Vec::new();
    for (i, rec) in reader.deserialize::<R>().enumerate() {
        // Line 1 is the specification, line 2 the column names.
        let row = rec.map_err(|e| CheckpointError::points(path, format!("line {}: {e}", i + 3)))?;
        rows.push(row);
    }
    Ok(rows)
}

/// Reads a points file: its first line (the specification) and its rows.
pub fn read_points<R: SweepPoint>(path: &Path) -> Result<(String, Vec<R>), CheckpointError> {
    let mut text = String::new();
    File::open(path)
        .and_then(|mut f| f.read_to_string(&mut text))
        .map_err(|e| CheckpointError::io(path, e))?;
    let first = text.lines().next().unwrap_or("").to_string();
    if !first.starts_with(MAGIC) {
        return Err(CheckpointError::points(
            path,
            "not a points file of `survey` (its first line must start with `# robot-survey sweep`)",
        ));
    }
    // Ignore a last line cut short by an interruption, as a resume would.
    let complete = text.rfind('\n').map_or(0, |i| i + 1);
    Ok((first, parse_rows(path, &text[..complete])?))
}

/// The study kind named on a points file's first line.
pub fn points_kind(path: &Path) -> Result<String, CheckpointError> {
    let mut text = String::new();
    File::open(path)
        .and_then(|mut f| f.read_to_string(&mut text))
        .map_err(|e| CheckpointError::io(path, e))?;
    let first = text.lines().next().unwrap_or("");
    first
        .strip_prefix(MAGIC)
        .and_then(|rest| rest.split_whitespace().next())
        .map(str::to_string)
        .ok_or_else(|| {
            CheckpointError::points(
                path,
                "not a points file of `survey` (its first line must start with `# robot-survey sweep`)",
            )
        })
}

/// Writes a complete points file (header line, then `rows` in the order given) atomically:
/// to a temporary file beside `path`, renamed over it when complete.
pub fn write_points<R: SweepPoint>(
    path: &Path,
    header: &str,
    rows: &[R],
) -> Result<(), CheckpointError> {
    let tmp = path.with_extension("csv.partial");
    {
        let mut file = File::create(&tmp).map_err(|e| CheckpointError::io(&tmp, e))?;
        writeln!(file, "{header}").map_err(|e| CheckpointError::io(&tmp, e))?;
        let mut w = csv::Writer::from_writer(file);
        for r in rows {
            w.serialize(r)
                .map_err(|e| CheckpointError::points(&tmp, e.to_string()))?;
        }
        w.flush().map_err(|e| CheckpointError::io(&tmp, e))?;
    }
    std::fs::rename(&tmp, path).map_err(|e| CheckpointError::io(path, e))
}

/// At the end of a complete (unsharded) run: rewrites its points file in canonical order
/// (by key), the order [`merge`]'s callers write, so one run's file and merged shards'
/// file are the same bytes.
pub fn finish_points<R: SweepPoint>(
    path: &Path,
    header: &str,
    points: &[R],
) -> Result<(), CheckpointError> {
    let mut sorted = points.to_vec();
    sorted.sort_by_key(|p| p.key());
    write_points(path, header, &sorted)
}

/// Joins points files of one study (same first line): rows keyed alike must agree
/// exactly. Returns the specification line and the union of the rows (unordered: the
/// study sorts them).
pub fn merge<R: SweepPoint + PartialEq>(
    inputs: &[PathBuf],
) -> Result<(String, Vec<R>), CheckpointError> {
    let mut header: Option<(String, &PathBuf)> = None;
    let mut rows: std::collections::BTreeMap<String, (R, &PathBuf)> = Default::default();
    for path in inputs {
        let (h, pts) = read_points::<R>(path)?;
        match &header {
            None => header = Some((h, path)),
            Some((first, from)) if *first != h => {
                return Err(CheckpointError::points(
                    path,
                    format!(
                        "is from a different study than {} (their first lines differ); \
                         only shards of one specification can be merged",
                        from.display()
                    ),
                ));
            }
            _ => {}
        }
        for p in pts {
            let k = p.key();
            match rows.get(&k) {
                Some((q, other)) if *q != p => {
                    return Err(CheckpointError::points(
                        path,
                        format!(
                            "point {k} differs from the same point in {}; \
                             the files were not made by the same code and options",
                            other.display()
                        ),
                    ));
                }
                Some(_) => {}
                None => {
                    rows.insert(k, (p, path));
                }
            }
        }
    }
    let (h, _) = header.ok_or_else(|| CheckpointError::Invalid {
        option: "inputs".into(),
        reason: "no points files given".into(),
    })?;
    Ok((h, rows.into_values().map(|(r, _)| r).collect()))
}
