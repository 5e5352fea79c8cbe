//! Files: output directories, and files that are never left incomplete under their final
//! name.
//!
//! Every file the command line writes (CSV, figures, reports) goes through [`write_file`]:
//! a regular file, or one that does not exist yet, is written to a hidden temporary file
//! beside it and renamed into place once complete; anything else (a FIFO, a character
//! device such as `/dev/stdout` or a null device, a socket) is written directly and never
//! replaced, so that its reader gets the data and the node stays what it was. A symbolic
//! link to a regular file is followed: its target is replaced, the link kept.
//!
//! A run's CSV streams to `<name>.partial.csv` while it runs ([`CsvSink`]) and takes its
//! final name only when complete: a failed or interrupted run leaves an existing result
//! untouched and its own rows in the partial file. A special destination gets nothing from
//! a failed run (it is opened and closed, so that a reader waiting on a FIFO sees the end of
//! the data instead of blocking).

use super::csv;
use camchain_runtime::{ModelInfo, Sample};
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Where a run's CSV goes.
#[derive(Debug, Clone, PartialEq)]
pub enum CsvTarget {
    /// Standard output (`--csv -`); written only when the run completed.
    Stdout,
    /// A file.
    File(PathBuf),
}

/// What was saved of a CSV.
#[derive(Debug, Clone, PartialEq)]
pub enum Saved {
    /// The complete CSV, at this path (`None`: standard output).
    Complete(Option<PathBuf>),
    /// The partial CSV of a failed run, at this path.
    Partial(PathBuf),
    /// Nothing (a failed run whose CSV was to go to standard output, or had no samples).
    Nothing,
}

/// Creates `dir` and its parents and checks that files can be created in it (before a
/// run, rather than after it), with a one-line error.
pub fn create_dir(dir: &Path) -> Result<(), String> {
    fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    let probe = dir.join(".camchain-write-test");
    fs::write(&probe, b"")
        .and_then(|()| fs::remove_file(&probe))
        .map_err(|e| format!("cannot write in output directory {}: {e}", dir.display()))
}

/// Checks before a run that a CSV file can be created at `path`: it is not a directory and
/// its directory exists.
pub fn check_csv_destination(path: &Path) -> Result<(), String> {
    if path.is_dir() {
        return Err(format!(
            "cannot write {}: it is a directory (--csv takes a file name)",
            path.display()
        ));
    }
    let dir = parent_dir(path);
    if dir.is_dir() {
        Ok(())
    } else {
        Err(format!(
            "cannot write {}: directory {} does not exist",
            path.display(),
            dir.display()
        ))
    }
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// `name.csv` → `name.partial.csv` (`name` → `name.partial`).
pub fn partial_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!("{stem}.partial.{}", ext.to_string_lossy()),
        None => format!("{stem}.partial"),
    };
    path.with_file_name(name)
}

/// What kind of file a destination is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// A regular file, or a path where nothing exists yet: written through a temporary
    /// sibling of this path (the link's target for a symbolic link) and a rename.
    Replaceable(PathBuf),
    /// A FIFO, a device, a socket, or a dangling symbolic link: written directly.
    Special,
}

/// Classifies `path` (following symbolic links).
///
/// # Errors
/// A directory, or metadata that cannot be read.
pub fn destination(path: &Path) -> io::Result<Destination> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_file() => {
            let is_link = fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
            let real = if is_link {
                fs::canonicalize(path)?
            } else {
                path.to_path_buf()
            };
            Ok(Destination::Replaceable(real))
        }
        Ok(meta) if meta.is_dir() => Err(io::Error::other("it is a directory")),
        Ok(_) => Ok(Destination::Special),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            // A dangling link is written through (creating its target), not replaced.
            if fs::symlink_metadata(path).is_ok() {
                Ok(Destination::Special)
            } else {
                Ok(Destination::Replaceable(path.to_path_buf()))
            }
        }
        Err(e) => Err(e),
    }
}

/// True when `path` exists and is not a regular file (after links) nor a directory.
pub fn is_special(path: &Path) -> bool {
    matches!(destination(path), Ok(Destination::Special)) && path.exists()
}

/// Writes `path` with `write`: a regular (or new) file through a temporary sibling renamed
/// into place once complete — on error the temporary file is removed and `path` is left as
/// it was —, any other kind of file directly, without replacing it (see the module doc).
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    match destination(path)? {
        Destination::Special => {
            let file = fs::OpenOptions::new().write(true).open(path)?;
            let mut out = BufWriter::new(file);
            write(&mut out)?;
            out.flush()
        }
        Destination::Replaceable(real) => write_through_rename(&real, write),
    }
}

/// Writes `path` through a temporary sibling renamed into place once complete.
fn write_through_rename(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let temporary = path.with_file_name(format!(".{name}.tmp"));
    let result = fs::File::create(&temporary).and_then(|file| {
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        out.into_inner().map_err(|e| e.into_error())?.sync_all()
    });
    match result.and_then(|()| fs::rename(&temporary, path)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = fs::remove_file(&temporary);
            Err(e)
        }
    }
}

/// [`write_file`] of bytes.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_file(path, |out| out.write_all(bytes))
}

/// Where a run's CSV rows go while it runs.
///
/// A regular (or new) destination gets the rows as they are computed, in
/// `<name>.partial.csv` beside it (flushed at least every second, so a crash keeps what was
/// computed); the complete file is renamed to the destination when the run ends, so an
/// existing result is only ever replaced by a complete new one, and a failed or interrupted
/// run leaves the destination as it was. Standard output and special files (FIFO, device)
/// get the CSV at the end of a complete run only.
pub enum CsvSink {
    /// Rows streamed to `partial`, renamed to `dest` when complete.
    Stream {
        /// The final name (a link's target for a symbolic link).
        dest: PathBuf,
        /// `<name>.partial.csv` beside it.
        partial: PathBuf,
        /// The open partial file.
        out: BufWriter<fs::File>,
        /// Rows written.
        rows: usize,
        /// When the rows were last flushed to the file.
        flushed: Instant,
    },
    /// Written at the end, from the trajectory.
    AtEnd(CsvTarget),
}

/// How often a streamed CSV is flushed to its file.
const FLUSH_EVERY: Duration = Duration::from_secs(1);

impl CsvSink {
    /// Opens the sink of `target`; for a regular destination this creates (or truncates a
    /// stale) `<name>.partial.csv` and writes the header.
    pub fn open(target: &CsvTarget, info: &ModelInfo) -> Result<Self, String> {
        let path = match target {
            CsvTarget::File(path) => path,
            CsvTarget::Stdout => return Ok(CsvSink::AtEnd(target.clone())),
        };
        let dest = match destination(path) {
            Ok(Destination::Replaceable(real)) => real,
            Ok(Destination::Special) => return Ok(CsvSink::AtEnd(target.clone())),
            Err(e) => return Err(format!("cannot write {}: {e}", path.display())),
        };
        let partial = partial_path(&dest);
        let file = fs::File::create(&partial)
            .map_err(|e| format!("cannot create {}: {e}", partial.display()))?;
        let mut out = BufWriter::new(file);
        writeln!(out, "{}", csv::header(info).join(","))
            .map_err(|e| format!("cannot write {}: {e}", partial.display()))?;
        Ok(CsvSink::Stream {
            dest,
            partial,
            out,
            rows: 0,
            flushed: Instant::now(),
        })
    }

    /// Appends a sample's row (streamed sinks only).
    pub fn row(&mut self, info: &ModelInfo, sample: &Sample) -> io::Result<()> {
        if let CsvSink::Stream {
            out, rows, flushed, ..
        } = self
        {
            csv::write_row(out, info, sample)?;
            *rows += 1;
            if flushed.elapsed() >= FLUSH_EVERY {
                out.flush()?;
                *flushed = Instant::now();
            }
        }
        Ok(())
    }

    /// Ends the CSV of a run: a complete one takes its final name (or is written out, for
    /// standard output and special files); a failed one keeps its rows in the partial file
    /// (removed when it holds none), and the destination is never touched.
    pub fn finish(
        self,
        info: &ModelInfo,
        samples: &[Sample],
        complete: bool,
    ) -> Result<Saved, String> {
        match self {
            CsvSink::Stream {
                dest,
                partial,
                out,
                rows,
                ..
            } => finish_stream(&dest, &partial, out, rows, complete),
            CsvSink::AtEnd(target) => save_at_end(&target, info, samples, complete),
        }
    }
}

fn finish_stream(
    dest: &Path,
    partial: &Path,
    out: BufWriter<fs::File>,
    rows: usize,
    complete: bool,
) -> Result<Saved, String> {
    let closed = out
        .into_inner()
        .map_err(|e| e.into_error())
        .and_then(|file| file.sync_all());
    if let Err(e) = closed {
        return Err(format!("cannot write {}: {e}", partial.display()));
    }
    if complete {
        fs::rename(partial, dest).map_err(|e| {
            format!(
                "cannot rename {} to {}: {e}",
                partial.display(),
                dest.display()
            )
        })?;
        Ok(Saved::Complete(Some(dest.to_path_buf())))
    } else if rows == 0 {
        // Only the header: the file this run created says nothing; remove it.
        let _ = fs::remove_file(partial);
        Ok(Saved::Nothing)
    } else {
        Ok(Saved::Partial(partial.to_path_buf()))
    }
}

/// The CSV of standard output or a special file, written once the run is complete; after
/// a failure a special file is opened and closed (its reader sees the end of the data) and
/// standard output gets nothing.
fn save_at_end(
    target: &CsvTarget,
    info: &ModelInfo,
    samples: &[Sample],
    complete: bool,
) -> Result<Saved, String> {
    let write = |out: &mut dyn Write| csv::write(out, info, samples);
    match (target, complete) {
        (CsvTarget::Stdout, true) => {
            let stdout = io::stdout();
            let mut lock = stdout.lock();
            match write(&mut lock) {
                Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
                    Err(format!("cannot write the CSV to standard output: {e}"))
                }
                _ => Ok(Saved::Complete(None)),
            }
        }
        (CsvTarget::Stdout, false) => Ok(Saved::Nothing),
        (CsvTarget::File(path), true) => {
            write_file(path, write).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            Ok(Saved::Complete(Some(path.clone())))
        }
        (CsvTarget::File(path), false) => {
            write_file(path, |_| Ok(()))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            Ok(Saved::Nothing)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("camchain-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn partial_names() {
        assert_eq!(
            partial_path(Path::new("out/a.csv")),
            PathBuf::from("out/a.partial.csv")
        );
        assert_eq!(partial_path(Path::new("a")), PathBuf::from("a.partial"));
    }

    #[test]
    fn a_failed_write_leaves_nothing_under_the_final_name() {
        let dir = scratch("atomic");
        let path = dir.join("x.csv");
        let result = write_file(&path, |out| {
            out.write_all(b"t,q\n0,1\n")?;
            Err(io::Error::other("interrupted"))
        });
        assert!(result.is_err());
        assert!(!path.exists());
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 0, "no temporary left");
        write_file(&path, |out| out.write_all(b"t\n0\n")).unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "t\n0\n");
        let _ = fs::remove_dir_all(&dir);
    }
}
