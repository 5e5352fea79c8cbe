//! Where a sweep's rows go while it runs: a regular (or new) file through this sweep's own
//! partial file renamed when complete ([`output::Stream`]), or standard output and special
//! files directly.

use crate::output::{self, Stream, Target};
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// The sweep's CSV sink.
pub enum Sink {
    /// Rows streamed to a partial file, renamed to the destination when complete.
    Partial(Stream),
    /// Written directly; `name` says where, in messages.
    Direct {
        /// Standard output or the special file.
        out: Box<dyn Write>,
        /// "standard output" or the file's path.
        name: String,
    },
}

impl Sink {
    /// Opens the sink of `csv` (`None`: standard output) and writes `head` (the preamble and
    /// the header).
    ///
    /// # Errors
    /// One line naming the file.
    pub fn open(csv: Option<&Path>, head: &[u8]) -> Result<Self, String> {
        let mut sink = match csv {
            None => Sink::Direct {
                out: Box::new(BufWriter::new(io::stdout())),
                name: "standard output".to_string(),
            },
            Some(path) => match output::target::resolve(path)? {
                Target::Replace { path, keep } => {
                    return Stream::open(&path, keep, head).map(Sink::Partial);
                }
                Target::Special(real) => {
                    let file = fs::OpenOptions::new()
                        .write(true)
                        .open(&real)
                        .map_err(|e| format!("cannot write {}: {e}", real.display()))?;
                    Sink::Direct {
                        out: Box::new(BufWriter::new(file)),
                        name: real.display().to_string(),
                    }
                }
            },
        };
        if let Sink::Direct { out, name } = &mut sink {
            out.write_all(head)
                .map_err(|e| format!("cannot write {name}: {e}"))?;
        }
        Ok(sink)
    }

    /// Appends one row (its cells joined).
    ///
    /// # Errors
    /// One line naming the file; a partial file keeps every complete row before it.
    pub fn row(&mut self, line: &str) -> Result<(), String> {
        match self {
            Sink::Partial(stream) => stream
                .row(|out| writeln!(out, "{line}"))
                .map_err(|e| stream.cannot(&e)),
            Sink::Direct { out, name } => {
                writeln!(out, "{line}").map_err(|e| format!("cannot write {name}: {e}"))
            }
        }
    }

    /// Sends buffered rows to the file.
    ///
    /// # Errors
    /// As [`Sink::row`].
    pub fn flush(&mut self) -> Result<(), String> {
        match self {
            Sink::Partial(stream) => stream.flush().map_err(|e| stream.cannot(&e)),
            Sink::Direct { out, name } => {
                out.flush().map_err(|e| format!("cannot write {name}: {e}"))
            }
        }
    }

    /// Complete: the partial file takes the final name (returned).
    ///
    /// # Errors
    /// As [`Sink::row`].
    pub fn finish(mut self) -> Result<Option<PathBuf>, String> {
        self.flush()?;
        match self {
            Sink::Partial(stream) => stream.complete().map(Some),
            Sink::Direct { .. } => Ok(None),
        }
    }

    /// Interrupted or failed: the partial file keeps the rows written (its path), or is
    /// removed when it holds none.
    pub fn abandon(self) -> Option<PathBuf> {
        match self {
            Sink::Partial(stream) => stream.abandon().0,
            Sink::Direct { mut out, .. } => {
                let _ = out.flush();
                None
            }
        }
    }
}
