//! Files: output directories, and files that are never left incomplete under their final
//! name, never shared by two runs, and never the wrong file.
//!
//! Every destination is resolved and claimed before a run starts ([`claim`],
//! [`create_dir`]), so that a run whose results could not be kept is refused before it
//! computes anything:
//!
//! - a regular file, or a path where nothing exists yet, is replaced by a complete new file
//!   through a rename, keeping the old file's permissions (and owner and group, where the
//!   process may set them); a symbolic link is followed to its final target, which is
//!   replaced (created, for a dangling link whose directory exists), the link kept; a file
//!   with other hard links, a directory, a link loop or a missing directory is refused with
//!   the reason ([`target`]);
//! - a FIFO, a character device such as `/dev/stdout` or a null device, a socket is written
//!   directly and never replaced, so that its reader gets the data and the node stays what
//!   it was;
//! - each destination file and run directory is locked for the run's whole length
//!   ([`lock`]): a second run that wants it fails at once, naming it.
//!
//! Temporary and partial files are the run's own: created exclusively under names no other
//! file has ([`stream`]), so nothing a run did not create is ever truncated, replaced or
//! removed. A run's CSV streams to `<name>.partial.csv` (or `<name>.partial-2.csv`, … when
//! that name is taken) and takes its final name only when complete: a failed or interrupted
//! run leaves an existing result untouched and its own rows in its partial file, which no
//! later run touches. A special destination gets nothing from a failed run (it is opened and
//! closed, so that a reader waiting on a FIFO sees the end of the data instead of blocking).

mod lock;
mod stream;
pub mod target;

pub use lock::Lock;
pub use stream::{Stream, create_unique};
pub use target::Target;

use super::csv;
use camchain_runtime::{ModelInfo, Sample};
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The files a command wrote, for its last line: "out/x/: a.csv, b.png" for files of one
/// directory (the first file's; others by their whole path), a lone file by its path.
pub fn list_files(paths: &[PathBuf]) -> String {
    let dir = match paths {
        [] => return String::new(),
        [only] => return only.display().to_string(),
        [first, ..] => first.parent(),
    };
    let (inside, outside): (Vec<&PathBuf>, Vec<&PathBuf>) =
        paths.iter().partition(|p| p.parent() == dir);
    let names: Vec<String> = inside
        .iter()
        .filter_map(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    let mut text = match dir.map(|d| d.display().to_string()) {
        Some(d) if d.is_empty() => names.join(", "),
        Some(d) if d.ends_with('/') => format!("{d}: {}", names.join(", ")),
        Some(d) => format!("{d}/: {}", names.join(", ")),
        None => names.join(", "),
    };
    for path in outside {
        text.push_str(&format!("; {}", path.display()));
    }
    text
}

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

/// Creates `dir` and its parents and locks it for this run (which also checks, before a
/// run rather than after it, that files can be created in it), with a one-line error.
///
/// # Errors
/// The directory cannot be created or written, or another run holds it.
pub fn create_dir(dir: &Path) -> Result<Lock, String> {
    if fs::symlink_metadata(dir).is_ok_and(|m| !m.is_dir()) && !dir.is_dir() {
        return Err(format!(
            "cannot create output directory {}: a file of that name exists",
            dir.display()
        ));
    }
    fs::create_dir_all(dir)
        .map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    Lock::dir(dir).map_err(|e| format!("cannot write in output directory {}: {e}", dir.display()))
}

/// Checks before a run that a file can be written at `path` as documented (see the module
/// documentation) and, for a file that is replaced, locks it for this run. `None` for a
/// special file (written directly, not locked).
///
/// # Errors
/// One line naming the path and the reason.
pub fn claim(path: &Path) -> Result<Option<Lock>, String> {
    match target::resolve(path)? {
        Target::Replace { path: real, .. } => Lock::file(&real).map(Some),
        Target::Special(_) => Ok(None),
    }
}

/// True when `path` exists and is a special file (after links): a FIFO, a device, a socket.
pub fn is_special(path: &Path) -> bool {
    matches!(target::resolve(path), Ok(Target::Special(_)))
}

/// Writes `path` with `write`: a regular (or new) file through a temporary file of this
/// run's own beside it, renamed into place once complete — on error the temporary file is
/// removed and `path` is left as it was —, any other kind of file directly, without
/// replacing it (see the module doc).
///
/// # Errors
/// The destination is refused (see [`target::resolve`]) or cannot be written; the message
/// names the file.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), String> {
    match target::resolve(path)? {
        Target::Special(real) => {
            let cannot = |e: io::Error| format!("cannot write {}: {e}", real.display());
            let file = fs::OpenOptions::new()
                .write(true)
                .open(&real)
                .map_err(cannot)?;
            let mut out = BufWriter::new(file);
            write(&mut out).and_then(|()| out.flush()).map_err(cannot)
        }
        Target::Replace { path: real, keep } => write_through_rename(&real, keep, write),
    }
}

/// Writes `path` through a temporary sibling (`.<name>.<pid>.<n>.tmp`, created exclusively)
/// renamed into place once complete.
fn write_through_rename(
    path: &Path,
    keep: Option<target::Keep>,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), String> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let pid = std::process::id();
    let (file, temporary) =
        create_unique(|n| path.with_file_name(format!(".{name}.{pid}.{n}.tmp"))).map_err(|e| {
            format!(
                "cannot create a temporary file beside {}: {e}",
                path.display()
            )
        })?;
    let mut out = BufWriter::new(file);
    let result = write(&mut out)
        .and_then(|()| out.into_inner().map_err(|e| e.into_error()))
        .and_then(|file| target::apply(&file, keep).and_then(|()| file.sync_all()))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
        .and_then(|()| {
            fs::rename(&temporary, path).map_err(|e| {
                format!(
                    "cannot rename {} to {}: {e}",
                    temporary.display(),
                    path.display()
                )
            })
        });
    if result.is_err() {
        let _ = fs::remove_file(&temporary);
    }
    result
}

/// [`write_file`] of bytes.
///
/// # Errors
/// As [`write_file`].
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_file(path, |out| out.write_all(bytes))
}

/// Where a run's CSV rows go while it runs.
///
/// A regular (or new) destination gets the rows as they are computed, in this run's own
/// partial file beside it ([`Stream`]: flushed at least every second, so a crash keeps what
/// was computed, and never ending in a torn row); the complete file is renamed to the
/// destination when the run ends, so an existing result is only ever replaced by a complete
/// new one, and a failed or interrupted run leaves the destination as it was. Standard
/// output and special files (FIFO, device) get the CSV at the end of a complete run only.
pub enum CsvSink {
    /// Rows streamed to a partial file, renamed to the destination when complete.
    Stream(Stream),
    /// Written at the end, from the trajectory.
    AtEnd(CsvTarget),
}

impl CsvSink {
    /// Opens the sink of `target`; for a regular destination this creates this run's
    /// partial file (a new one, never an existing file) and writes the header.
    ///
    /// # Errors
    /// The destination is refused or the partial file cannot be created.
    pub fn open(target: &CsvTarget, info: &ModelInfo) -> Result<Self, String> {
        let path = match target {
            CsvTarget::File(path) => path,
            CsvTarget::Stdout => return Ok(CsvSink::AtEnd(target.clone())),
        };
        match target::resolve(path)? {
            Target::Special(_) => Ok(CsvSink::AtEnd(target.clone())),
            Target::Replace { path, keep } => {
                let head = format!("{}\n", csv::header(info).join(","));
                Stream::open(&path, keep, head.as_bytes()).map(CsvSink::Stream)
            }
        }
    }

    /// Appends a sample's row (streamed sinks only).
    ///
    /// # Errors
    /// The row could not be written; the partial file keeps every complete row before it.
    pub fn row(&mut self, info: &ModelInfo, sample: &Sample) -> io::Result<()> {
        match self {
            CsvSink::Stream(stream) => stream.row(|out| csv::write_row(out, info, sample)),
            CsvSink::AtEnd(_) => Ok(()),
        }
    }

    /// The partial file rows are streamed to, if any.
    pub fn partial(&self) -> Option<&Path> {
        match self {
            CsvSink::Stream(stream) => Some(stream.partial()),
            CsvSink::AtEnd(_) => None,
        }
    }

    /// Ends the CSV of a run: a complete one takes its final name (or is written out, for
    /// standard output and special files); a failed one keeps its rows in its partial file
    /// (removed when it holds none), and the destination is never touched.
    ///
    /// # Errors
    /// The CSV could not be completed; the message names the file.
    pub fn finish(
        self,
        info: &ModelInfo,
        samples: &[Sample],
        complete: bool,
    ) -> Result<Saved, String> {
        match self {
            CsvSink::Stream(stream) if complete => {
                stream.complete().map(|p| Saved::Complete(Some(p)))
            }
            CsvSink::Stream(stream) => match stream.abandon() {
                (Some(partial), Some(error)) => Err(format!(
                    "{error} (its complete rows before that are kept in {})",
                    partial.display()
                )),
                (None, Some(error)) => Err(error),
                (Some(partial), None) => Ok(Saved::Partial(partial)),
                (None, None) => Ok(Saved::Nothing),
            },
            CsvSink::AtEnd(target) => save_at_end(&target, info, samples, complete),
        }
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
            write_file(path, write)?;
            Ok(Saved::Complete(Some(path.clone())))
        }
        (CsvTarget::File(path), false) => {
            write_file(path, |_| Ok(()))?;
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
