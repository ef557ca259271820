//! File writing shared by the library and the command line.

use std::path::{Path, PathBuf};

/// A failed atomic write: the file that could not be written (the temporary) or renamed
/// onto (the target), and why.
#[derive(Debug)]
pub struct WriteError {
    pub path: PathBuf,
    pub error: std::io::Error,
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.error)
    }
}

// No `source()`: the message already ends with the I/O error, and a chain would repeat it.
impl std::error::Error for WriteError {}

/// Writes through a temporary file in the same folder and a rename, so a failure or a
/// crash never leaves half a file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = dir.join(format!(
        ".{}.tmp",
        path.file_name().and_then(|f| f.to_str()).unwrap_or("out")
    ));
    std::fs::write(&tmp, bytes).map_err(|error| WriteError {
        path: tmp.clone(),
        error,
    })?;
    std::fs::rename(&tmp, path).map_err(|error| WriteError {
        path: path.to_path_buf(),
        error,
    })
}
