//! Writing a file so that nobody ever reads half of it.

use std::path::{Path, PathBuf};

/// Write `bytes` to `path` through a sibling temporary file renamed over
/// it: a failure or an interruption leaves the old file or none, never a
/// half-written one (a rename within a folder is atomic). The temporary's
/// name carries the process id, so concurrent writers never share one; a
/// failed write removes it. The error names the file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            std::io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()))
        })
}

/// [`write_atomic`] of what `fill` writes, streamed through a buffer to
/// the temporary file (nothing of it held in memory).
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    use std::io::Write;
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    std::fs::File::create(&tmp)
        .and_then(|f| {
            let mut w = std::io::BufWriter::new(f);
            fill(&mut w)?;
            w.flush()
        })
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            std::io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()))
        })
}
