//! One run per destination: an advisory lock held on a hidden file beside each file (or
//! inside each directory) a run writes, from before the run starts until its outputs are
//! complete.
//!
//! A second `camchain` run that wants the same destination while the first holds it fails
//! at once, before running, with a message naming the destination: two runs never write
//! one file, so a destination always holds one run's complete output, and no run exits 0
//! over a file another run replaced.
//!
//! The lock is `flock(2)` on `.<name>.lock` (on `.camchain.lock` for a directory), which
//! the kernel releases when the process ends, however it ends. A lock file this run created
//! is removed when the run ends (while still locked, then checked by the next holder, so
//! that two runs can never hold locks on two different files of one name); a lock file
//! left by a killed run is used as it is and left in place, since this run did not create
//! it.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// A held lock; released (and its file removed, if this run created it) when dropped.
#[derive(Debug)]
#[must_use = "the lock is released when dropped: keep it until the outputs are written"]
pub struct Lock {
    file: File,
    path: PathBuf,
    created: bool,
}

/// How many times a lock is tried again when its file was removed between opening and
/// locking it (another run released it meanwhile).
const RETRIES: usize = 20;

impl Lock {
    /// The lock of the file `path` (its final path: a link's target), held by this run.
    ///
    /// # Errors
    /// The destination is held by another run, or the lock file cannot be created.
    pub fn file(path: &Path) -> Result<Lock, String> {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let lock = path.with_file_name(format!(".{name}.lock"));
        Lock::acquire(&lock, path)
    }

    /// The lock of the directory `dir`, held by this run.
    ///
    /// # Errors
    /// As [`Lock::file`].
    pub fn dir(dir: &Path) -> Result<Lock, String> {
        Lock::acquire(&dir.join(".camchain.lock"), dir)
    }

    fn acquire(lock: &Path, guarded: &Path) -> Result<Lock, String> {
        let cannot = |e: io::Error| {
            format!(
                "cannot lock {} (through {}): {e}",
                guarded.display(),
                lock.display()
            )
        };
        for _ in 0..RETRIES {
            if let Some(file) = create_locked(lock).map_err(cannot)? {
                return Ok(Lock {
                    file,
                    path: lock.to_path_buf(),
                    created: true,
                });
            }
            let file = match OpenOptions::new().read(true).open(lock) {
                Ok(file) => file,
                // Removed by its holder meanwhile: try again.
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(cannot(e)),
            };
            match file.try_lock() {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => {
                    return Err(format!(
                        "{} is being written by another camchain run (it holds {}); wait \
                         for that run to end or write to another name",
                        guarded.display(),
                        lock.display()
                    ));
                }
                Err(TryLockError::Error(e)) => return Err(cannot(e)),
            }
            // The file may have been removed (and another created) by a run that released
            // it between our opening and locking: the lock only counts on the file that is
            // at the path now.
            let same = match (file.metadata(), fs::symlink_metadata(lock)) {
                (Ok(held), Ok(now)) => held.ino() == now.ino() && held.dev() == now.dev(),
                _ => false,
            };
            if same {
                // A lock file left by a killed run: used, and left in place.
                return Ok(Lock {
                    file,
                    path: lock.to_path_buf(),
                    created: false,
                });
            }
        }
        Err(format!(
            "cannot lock {}: {} keeps being replaced",
            guarded.display(),
            lock.display()
        ))
    }
}

/// Creates the lock file already locked, so that no other run can lock it first and leave
/// it behind: a file of this run's own is locked, then linked to the lock's name (which
/// fails if the name exists) and its own name removed. `None` when the lock file exists.
/// On a file system without hard links, the file is created in place and locked at once.
fn create_locked(lock: &Path) -> io::Result<Option<File>> {
    let name = lock.file_name().unwrap_or_default().to_string_lossy();
    let pid = std::process::id();
    let (file, own) = super::create_unique(|n| lock.with_file_name(format!("{name}.{pid}.{n}")))?;
    let linked = file.lock().and_then(|()| fs::hard_link(&own, lock));
    let _ = fs::remove_file(&own);
    match linked {
        Ok(()) => Ok(Some(file)),
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Ok(None),
        Err(_) => match OpenOptions::new().write(true).create_new(true).open(lock) {
            Ok(file) => file.lock().map(|()| Some(file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Ok(None),
            Err(e) => Err(e),
        },
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        if self.created {
            // Removed while still held: a run that opened it meanwhile finds, once it gets
            // the lock, that the path no longer names its file and tries again.
            let _ = fs::remove_file(&self.path);
        }
        let _ = self.file.unlock();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_holder_is_refused_and_the_lock_file_removed_after_use() {
        let dir = std::env::temp_dir().join(format!("camchain-lock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.csv");
        let first = Lock::file(&path).unwrap();
        let error = Lock::file(&path).unwrap_err();
        assert!(error.contains("another camchain run"), "{error}");
        drop(first);
        assert!(!dir.join(".out.csv.lock").exists());
        // A lock file left by a killed run is used and left in place.
        fs::write(dir.join(".out.csv.lock"), "").unwrap();
        drop(Lock::file(&path).unwrap());
        assert!(dir.join(".out.csv.lock").exists());
        let held = Lock::dir(&dir).unwrap();
        assert!(Lock::dir(&dir).is_err());
        drop(held);
        let _ = fs::remove_dir_all(&dir);
    }
}
