//! Cutting a release: the live records validated, compiled and frozen as
//! `releases/X.Y.Z/` with the manifest updated (`survey dataset release`).
//!
//! A file of its own because it needs both [`super::release`] (the table, the manifest,
//! the frozen files) and [`super::validate`] (which reads the releases to check them): from
//! above both, it leaves one arrow between them, validate → release.

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use super::release::{
    MANIFEST, Release, ReleaseFile, TABLE_CSV, TABLE_PARQUET, compile, parse_semver, sha256_hex,
};
use super::validate::{as_release_problems, validate};
use super::{Dataset, DatasetError, Manifest};

/// Today's date (UTC) as YYYY-MM-DD, from the system clock (civil-from-days, H. Hinnant).
pub fn today_utc() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let z = secs.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// What `survey dataset release` did.
#[derive(Debug, Clone, Serialize)]
pub struct ReleaseOutcome {
    pub version: String,
    pub rows: usize,
    pub fitted: usize,
    pub files: Vec<ReleaseFile>,
}

/// Freezes the live records as release `version` into the dataset directory.
///
/// Refuses when the version is not the live version, is not newer than every release,
/// already exists, has no CHANGELOG entry, or the records have validation errors. Files
/// are written to a temporary directory and renamed into place, so nothing is half-written.
/// Validation errors refuse the release unless `allow_errors` (for a release that must
/// preserve a published table with its errors, as 1.0.0 does); the count is then written
/// into the manifest note.
pub fn cut_release(
    ds: &Dataset,
    version: &str,
    date: &str,
    note: &str,
    allow_errors: bool,
) -> Result<ReleaseOutcome, DatasetError> {
    let dir = ds.files.dir.clone().ok_or_else(|| {
        DatasetError::Other(
            "cannot cut a release into the bundled dataset: pass --dataset DIR".into(),
        )
    })?;
    let mut manifest = check_version(ds, version)?;
    check_changelog(ds, version)?;
    let note = release_note(ds, note, allow_errors)?;
    let table = compile(ds);
    let csv = table.to_csv();
    let parquet = table.to_parquet(&ds.vocab)?;
    let files = vec![
        ReleaseFile {
            path: format!("{version}/{TABLE_CSV}"),
            sha256: sha256_hex(&csv),
        },
        ReleaseFile {
            path: format!("{version}/{TABLE_PARQUET}"),
            sha256: sha256_hex(&parquet),
        },
    ];
    manifest.releases.push(Release {
        version: version.to_string(),
        date: date.to_string(),
        note,
        files: files.clone(),
    });
    let manifest_text = manifest.to_toml()?;

    write_release(&dir, version, &csv, &parquet, &manifest_text)?;
    Ok(ReleaseOutcome {
        version: version.to_string(),
        rows: table.rows.len(),
        fitted: table.fitted().count(),
        files,
    })
}

/// Checks that `version` is a semantic version, is the live version, is not yet released
/// and is newer than every release; returns the current manifest.
fn check_version(ds: &Dataset, version: &str) -> Result<Manifest, DatasetError> {
    let parsed = parse_semver(version).ok_or_else(|| {
        DatasetError::Other(format!("`{version}` is not a semantic version X.Y.Z"))
    })?;
    if version != ds.meta.version {
        return Err(DatasetError::Other(format!(
            "the live records are version {} (dataset.toml); set it to {version} first",
            ds.meta.version
        )));
    }
    let manifest = ds.manifest()?;
    if manifest.get(version).is_some() {
        return Err(DatasetError::Other(format!(
            "release {version} already exists and is frozen"
        )));
    }
    if let Some(newest) = manifest
        .releases
        .iter()
        .filter_map(|r| parse_semver(&r.version))
        .max()
        && parsed <= newest
    {
        return Err(DatasetError::Other(format!(
            "{version} is not newer than the latest release {}.{}.{}",
            newest.0, newest.1, newest.2
        )));
    }
    Ok(manifest)
}

/// Refuses a release whose version has no `## X.Y.Z` heading in CHANGELOG.md.
fn check_changelog(ds: &Dataset, version: &str) -> Result<(), DatasetError> {
    let changelog = ds.files.text("CHANGELOG.md").unwrap_or("");
    if !changelog
        .lines()
        .any(|l| l.starts_with("## ") && l.contains(version))
    {
        return Err(DatasetError::Other(format!(
            "CHANGELOG.md has no `## {version}` entry: describe what changed before releasing"
        )));
    }
    Ok(())
}

/// Validates the live records as a release; returns the manifest note (marked with the
/// error count when errors are allowed), or refuses when errors are not allowed.
fn release_note(ds: &Dataset, note: &str, allow_errors: bool) -> Result<String, DatasetError> {
    // A release treats a speed of unstated kind as an error (a warning in the live records).
    let problems = as_release_problems(validate(ds).problems);
    let errors = super::problem::count(&problems, super::Severity::Error);
    if errors > 0 && !allow_errors {
        let first = problems
            .iter()
            .find(|p| p.severity == super::Severity::Error)
            .map(|p| format!(", first: {}", p.to_line()))
            .unwrap_or_default();
        return Err(DatasetError::Other(format!(
            "the live records have {errors} error(s) for a release{first}; run `survey validate` and fix them first \
             (a speed of unstated kind is an error in a release; or --allow-errors to freeze a published table with its known errors)"
        )));
    }
    Ok(if errors > 0 {
        format!("{note} [frozen with {errors} known validation error(s)]")
            .trim()
            .to_string()
    } else {
        note.to_string()
    })
}

/// Writes the release files and manifest to temporaries under `dir`, then renames them in.
fn write_release(
    dir: &Path,
    version: &str,
    csv: &[u8],
    parquet: &[u8],
    manifest_text: &str,
) -> Result<(), DatasetError> {
    let releases_dir = dir.join("releases");
    let io = |p: &Path, e| DatasetError::Io {
        path: p.display().to_string(),
        source: e,
    };
    std::fs::create_dir_all(&releases_dir).map_err(|e| io(&releases_dir, e))?;
    let tmp = releases_dir.join(format!(".tmp-{version}"));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(|e| io(&tmp, e))?;
    }
    std::fs::create_dir_all(&tmp).map_err(|e| io(&tmp, e))?;
    for (name, bytes) in [(TABLE_CSV, csv), (TABLE_PARQUET, parquet)] {
        let p = tmp.join(name);
        std::fs::write(&p, bytes).map_err(|e| io(&p, e))?;
    }
    let manifest_tmp = releases_dir.join(".manifest.toml.tmp");
    let mut f = std::fs::File::create(&manifest_tmp).map_err(|e| io(&manifest_tmp, e))?;
    f.write_all(manifest_text.as_bytes())
        .map_err(|e| io(&manifest_tmp, e))?;
    let final_dir = releases_dir.join(version);
    std::fs::rename(&tmp, &final_dir).map_err(|e| io(&final_dir, e))?;
    let manifest_path = dir.join(MANIFEST);
    std::fs::rename(&manifest_tmp, &manifest_path).map_err(|e| io(&manifest_path, e))?;
    Ok(())
}
