//! Atomic writes: a temp file in the destination's directory, renamed over the destination only once
//! fully written, so an existing file is never half-overwritten and a failed write leaves nothing.

use crate::error::Problem;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The folder an output goes to (`.` for a bare file name).
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Whether an output could be written at `path`, checked before any work is done: not a folder,
/// in an existing folder where a file can be created (a temporary one is made and removed).
pub(crate) fn check_writable(path: &Path) -> Result<(), Problem> {
    if path.is_dir() {
        return Err(Problem::Unsupported("is a directory".into()));
    }
    let dir = folder(path);
    if !dir.is_dir() {
        return Err(Problem::Unsupported(format!(
            "the folder {} does not exist",
            dir.display()
        )));
    }
    tempfile::Builder::new()
        .prefix(".delamesh-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| Problem::Unsupported(format!("cannot write in {}: {e}", dir.display())))?;
    Ok(())
}

pub(crate) fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> Result<(), Problem>,
) -> Result<(), Problem> {
    let dir = folder(path);
    if path.is_dir() {
        return Err(Problem::Unsupported("is a directory".into()));
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".delamesh-").suffix(".tmp");
    // tempfile creates private (0600) files; a mesh is an ordinary document (0666 less the umask).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir)?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        body(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| Problem::Io(e.error))?;
    Ok(())
}
