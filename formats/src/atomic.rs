//! Atomic writes: a temp file in the destination's directory, renamed over the destination only once
//! fully written, so an existing file is never half-overwritten and a failed write leaves nothing.

use crate::error::Problem;
use std::io::{BufWriter, Write};
use std::path::Path;

pub(crate) fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> Result<(), Problem>,
) -> Result<(), Problem> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if path.is_dir() {
        return Err(Problem::Unsupported("is a directory".into()));
    }
    let mut tmp = tempfile::Builder::new()
        .prefix(".delamesh-")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        body(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| Problem::Io(e.error))?;
    Ok(())
}
