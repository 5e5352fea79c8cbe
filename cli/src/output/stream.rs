//! Rows streamed to a run's own partial file, renamed to the destination once complete.
//!
//! The partial file is created exclusively beside the destination as `<name>.partial.csv`,
//! or `<name>.partial-2.csv`, `-3`, … when that name is taken (by another run, or by the
//! rows an earlier interrupted run kept): a run never opens, truncates or removes a partial
//! file it did not create, so what an earlier run kept stays as it was.
//!
//! Rows are written whole: each row is formatted into memory and appended to a buffer that
//! goes to the file at least every second; when a write fails (a full disk), the file is cut
//! back to the end of the last row that was written completely, so a partial file never ends
//! in a torn row.

use super::target::{self, Keep};
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often buffered rows go to the file.
const FLUSH_EVERY: Duration = Duration::from_secs(1);

/// Buffered bytes beyond which rows go to the file at once.
const BUFFER: usize = 1 << 16;

/// Most partial names tried (`-2` … `-N`) before giving up.
const NAMES: usize = 10_000;

/// A run's partial file.
#[derive(Debug)]
pub struct Stream {
    /// The final name (a link's target for a symbolic link).
    dest: PathBuf,
    /// The destination's permissions and owner, given to the new file.
    keep: Option<Keep>,
    /// This run's partial file.
    partial: PathBuf,
    file: File,
    /// Bytes not yet written to the file.
    buffer: Vec<u8>,
    /// Length of the file up to the last complete row written.
    committed: u64,
    /// Rows (after the header) written or buffered.
    rows: usize,
    /// Rows in the file up to `committed`.
    committed_rows: usize,
    flushed: Instant,
}

/// `name.csv` → `name.partial.csv` (n = 1), `name.partial-n.csv` (n ≥ 2); `name` →
/// `name.partial`, `name.partial-n`.
pub fn partial_name(path: &Path, n: usize) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let counter = if n <= 1 {
        String::new()
    } else {
        format!("-{n}")
    };
    let name = match path.extension() {
        Some(ext) => format!("{stem}.partial{counter}.{}", ext.to_string_lossy()),
        None => format!("{stem}.partial{counter}"),
    };
    path.with_file_name(name)
}

/// Creates a new file at the first free name `name(1)`, `name(2)`, … (never one that
/// exists).
pub fn create_unique(name: impl Fn(usize) -> PathBuf) -> io::Result<(File, PathBuf)> {
    for n in 1..=NAMES {
        let path = name(n);
        match OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(file) => return Ok((file, path)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::other(format!(
        "{NAMES} names like {} are taken",
        name(1).display()
    )))
}

impl Stream {
    /// Creates this run's partial file for the destination `dest` (a resolved file path),
    /// starting with `head` (the header lines).
    ///
    /// # Errors
    /// One line naming the file that could not be created or written.
    pub fn open(dest: &Path, keep: Option<Keep>, head: &[u8]) -> Result<Stream, String> {
        let (file, partial) = create_unique(|n| partial_name(dest, n)).map_err(|e| {
            format!(
                "cannot create a partial file beside {}: {e}",
                dest.display()
            )
        })?;
        let mut stream = Stream {
            dest: dest.to_path_buf(),
            keep,
            partial,
            file,
            buffer: Vec::with_capacity(BUFFER),
            committed: 0,
            rows: 0,
            committed_rows: 0,
            flushed: Instant::now(),
        };
        stream.buffer.extend_from_slice(head);
        stream.flush().map_err(|e| stream.cannot(&e))?;
        Ok(stream)
    }

    /// The partial file's path.
    pub fn partial(&self) -> &Path {
        &self.partial
    }

    /// "cannot write <partial>: <e>".
    pub fn cannot(&self, e: &io::Error) -> String {
        format!("cannot write {}: {e}", self.partial.display())
    }

    /// Appends one complete row (`row` writes it, with its line end).
    ///
    /// # Errors
    /// The file could not be written; it then ends with the last complete row.
    pub fn row(&mut self, row: impl FnOnce(&mut Vec<u8>) -> io::Result<()>) -> io::Result<()> {
        let start = self.buffer.len();
        if let Err(e) = row(&mut self.buffer) {
            self.buffer.truncate(start);
            return Err(e);
        }
        self.rows += 1;
        if self.buffer.len() >= BUFFER || self.flushed.elapsed() >= FLUSH_EVERY {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the buffered rows; on failure cuts the file back to its last complete row.
    pub fn flush(&mut self) -> io::Result<()> {
        self.flushed = Instant::now();
        if self.buffer.is_empty() {
            return Ok(());
        }
        match self.file.write_all(&self.buffer) {
            Ok(()) => {
                self.committed += self.buffer.len() as u64;
                self.committed_rows = self.rows;
                self.buffer.clear();
                Ok(())
            }
            Err(e) => {
                self.buffer.clear();
                self.rows = self.committed_rows;
                // Best effort: a disk too full to take the rows can still give back space.
                let _ = self.file.set_len(self.committed);
                Err(e)
            }
        }
    }

    /// The run is complete: the partial file, flushed and synced, takes the destination's
    /// permissions and owner and its name. Returns the destination.
    ///
    /// # Errors
    /// One line naming the file; the partial file then stays (with every complete row).
    pub fn complete(mut self) -> Result<PathBuf, String> {
        self.flush().map_err(|e| self.cannot(&e))?;
        target::apply(&self.file, self.keep)
            .and_then(|()| self.file.sync_all())
            .map_err(|e| self.cannot(&e))?;
        fs::rename(&self.partial, &self.dest).map_err(|e| {
            format!(
                "cannot rename {} to {}: {e}",
                self.partial.display(),
                self.dest.display()
            )
        })?;
        Ok(self.dest)
    }

    /// The run failed or was interrupted: the rows written so far stay in the partial file,
    /// whose path is returned; a partial file with no rows (only the header) says nothing
    /// and is removed (this run created it). `Err` when the last rows could not be written
    /// (the file keeps every complete row before them).
    pub fn abandon(mut self) -> (Option<PathBuf>, Option<String>) {
        let error = self.flush().err().map(|e| self.cannot(&e));
        let _ = self.file.sync_all();
        if self.rows == 0 {
            let _ = fs::remove_file(&self.partial);
            (None, error)
        } else {
            (Some(self.partial), error)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_names_never_reuse_an_existing_file() {
        assert_eq!(
            partial_name(Path::new("out/a.csv"), 1),
            PathBuf::from("out/a.partial.csv")
        );
        assert_eq!(
            partial_name(Path::new("out/a.csv"), 3),
            PathBuf::from("out/a.partial-3.csv")
        );
        assert_eq!(partial_name(Path::new("a"), 1), PathBuf::from("a.partial"));
        let dir = std::env::temp_dir().join(format!("camchain-stream-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let dest = dir.join("r.csv");
        fs::write(dir.join("r.partial.csv"), "kept\n").unwrap();
        let mut stream = Stream::open(&dest, None, b"t\n").unwrap();
        assert_eq!(stream.partial(), dir.join("r.partial-2.csv"));
        stream.row(|out| out.write_all(b"1\n")).unwrap();
        let (kept, error) = stream.abandon();
        assert_eq!(kept, Some(dir.join("r.partial-2.csv")));
        assert!(error.is_none());
        assert_eq!(
            fs::read_to_string(dir.join("r.partial.csv")).unwrap(),
            "kept\n"
        );
        assert_eq!(
            fs::read_to_string(dir.join("r.partial-2.csv")).unwrap(),
            "t\n1\n"
        );
        let stream = Stream::open(&dest, None, b"t\n").unwrap();
        assert_eq!(stream.partial(), dir.join("r.partial-3.csv"));
        assert_eq!(stream.complete().unwrap(), dest);
        assert_eq!(fs::read_to_string(&dest).unwrap(), "t\n");
        let _ = fs::remove_dir_all(&dir);
    }
}
