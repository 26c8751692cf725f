//! A run's output folder, held for the run: no two runs write into one
//! folder at once, and a folder never mixes the files of two runs.
//!
//! Claiming a folder takes an advisory lock on its `.softarm-lock` (the
//! operating system drops it when the process ends, however it ends), then
//! deletes the files the previous run recorded in `.softarm-files` and
//! nothing else: a user's own files in the folder are left alone. Every
//! file a run writes is recorded there before it is written, so that even
//! an interrupted run's files are cleared by the next.

use std::collections::BTreeSet;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};

/// The lock file and the list of the files the run wrote.
const LOCK: &str = ".softarm-lock";
const FILES: &str = ".softarm-files";

/// An output folder held by this process.
pub struct OutputDir {
    dir: PathBuf,
    recorded: BTreeSet<String>,
    // Held for the lock's sake: dropping it releases the folder.
    _lock: File,
}

impl OutputDir {
    /// Hold `dir` for a new run: create it, lock it, and clear the files
    /// the previous run there wrote.
    pub fn claim(dir: &Path) -> Result<Self> {
        let mut held = Self::hold(dir)?;
        for name in std::mem::take(&mut held.recorded) {
            match std::fs::remove_file(dir.join(&name)) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(anyhow!(
                        "cannot clear {} of the previous run: {e}",
                        dir.join(&name).display()
                    ));
                }
                _ => {}
            }
        }
        std::fs::write(dir.join(FILES), "")
            .with_context(|| format!("cannot write {}", dir.join(FILES).display()))?;
        Ok(held)
    }

    /// Hold `dir` to add files to the run that just wrote there (an
    /// animation after its simulation), keeping that run's files.
    pub fn reopen(dir: &Path) -> Result<Self> {
        Self::hold(dir)
    }

    fn hold(dir: &Path) -> Result<Self> {
        if dir.exists() && !dir.is_dir() {
            return Err(anyhow!(
                "{} is a file: the output goes into a folder (choose another --out)",
                dir.display()
            ));
        }
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let lock = OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(dir.join(LOCK))
            .with_context(|| format!("cannot open {}", dir.join(LOCK).display()))?;
        match lock.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(anyhow!(
                    "another softarm run is writing into {}: wait for it to end, or choose another --out",
                    dir.display()
                ));
            }
            Err(TryLockError::Error(e)) => {
                return Err(anyhow!("cannot lock {}: {e}", dir.join(LOCK).display()));
            }
        }
        let recorded = std::fs::read_to_string(dir.join(FILES))
            .unwrap_or_default()
            .lines()
            .filter(|l| is_plain_name(l))
            .map(str::to_string)
            .collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            recorded,
            _lock: lock,
        })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The path of file `name` in the folder, recorded as this run's
    /// before anything is written to it.
    pub fn file(&mut self, name: &str) -> Result<PathBuf> {
        if !is_plain_name(name) {
            return Err(anyhow!("{name:?} cannot name an output file"));
        }
        if self.recorded.insert(name.to_string()) {
            let mut list = OpenOptions::new()
                .create(true)
                .append(true)
                .open(self.dir.join(FILES))
                .with_context(|| format!("cannot write {}", self.dir.join(FILES).display()))?;
            writeln!(list, "{name}")
                .with_context(|| format!("cannot write {}", self.dir.join(FILES).display()))?;
        }
        Ok(self.dir.join(name))
    }

    /// The stem of a plot (`stem.png` and `stem.svg`), both recorded.
    pub fn plot(&mut self, stem: &str) -> Result<PathBuf> {
        self.file(&format!("{stem}.svg"))?;
        self.file(&format!("{stem}.png"))?;
        Ok(self.dir.join(stem))
    }
}

/// A file name with no path in it: nothing recorded can reach outside the
/// folder, whatever `.softarm-files` holds.
fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\'])
        && Path::new(name).file_name().is_some_and(|f| f == name)
}
