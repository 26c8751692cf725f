//! The on-disk cache of derived tapes, keyed by structural hash.
//!
//! A model that is not compiled in is derived at run time; its tapes are
//! stored as `<cache>/<hash>.json` so the next run starts at once. Entries
//! are written atomically (temporary file + rename) and checked on read: a
//! corrupt or mismatched entry is re-derived, never trusted.

use std::path::{Path, PathBuf};

use runtime::TapeSet;

/// `$SOFTARM_CACHE_DIR`, or `.softarm-cache` in the working directory.
pub fn default_dir() -> PathBuf {
    std::env::var_os("SOFTARM_CACHE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(".softarm-cache"))
}

pub fn entry_path(dir: &Path, hash: &str) -> PathBuf {
    dir.join(format!("{hash}.json"))
}

/// The cached tapes of `hash`, if present and intact.
pub fn load(dir: &Path, hash: &str) -> Option<TapeSet> {
    let text = std::fs::read_to_string(entry_path(dir, hash)).ok()?;
    let tapes: TapeSet = serde_json::from_str(&text).ok()?;
    (tapes.info.hash == hash).then_some(tapes)
}

/// Store tapes; failures are reported but not fatal (the run goes on).
pub fn store(dir: &Path, tapes: &TapeSet) -> Result<(), String> {
    let write = || -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        let bytes = serde_json::to_vec(tapes).map_err(std::io::Error::other)?;
        eomgen::atomic_write::write_atomic(&entry_path(dir, &tapes.info.hash), &bytes)
    };
    write().map_err(|e| format!("could not write the tape cache in {}: {e}", dir.display()))
}
