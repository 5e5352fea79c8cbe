//! One shard file read line by line: its `#` lines and header first, then its rows, each
//! line bounded in length and checked to be text, so that no file (empty, binary, a
//! multi-gigabyte line, truncated in the middle of a line) makes the merge fail other than
//! with a message naming the file and line.

use crate::sweep::table::Preamble;
use crate::sweep::table::rows::shown;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// The longest line a shard may have (bytes, its line break excluded): far above any row or
/// `#` line a sweep writes, and a bound on the memory a line takes.
pub const MAX_LINE: usize = 4 << 20;

/// One shard file being read.
pub struct ShardFile {
    /// The path as given.
    pub path: PathBuf,
    /// Its `#` lines.
    pub preamble: Preamble,
    /// Its header line.
    pub header: String,
    reader: BufReader<File>,
    /// The number of the last line read (1-based; 0 before the first).
    line: usize,
    /// The last line's bytes (kept to be reused: at most [`MAX_LINE`] + 2 bytes).
    bytes: Vec<u8>,
}

impl ShardFile {
    /// Opens `path` and reads its four `#` lines and its header.
    pub fn open(path: &Path) -> Result<Self, String> {
        let file = File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut shard = ShardFile {
            path: path.to_path_buf(),
            preamble: Preamble {
                sweep: String::new(),
                shard: (1, 1),
                parameters: String::new(),
                settings: String::new(),
            },
            header: String::new(),
            reader: BufReader::new(file),
            line: 0,
            bytes: Vec::new(),
        };
        let mut head = Vec::with_capacity(5);
        while head.len() < 5 {
            match shard.next_line()? {
                Some(line) => head.push(line),
                None if head.is_empty() => {
                    return Err(format!("{}: empty: not a sweep CSV", path.display()));
                }
                None => {
                    return Err(format!(
                        "{}:{}: the file ends after {} lines: a sweep CSV has four `#` lines \
                         and a header",
                        path.display(),
                        head.len() + 1,
                        head.len()
                    ));
                }
            }
        }
        let refs: Vec<&str> = head.iter().map(String::as_str).collect();
        shard.preamble = Preamble::parse(&refs[..4]).map_err(|(k, e)| {
            let text = refs.get(k - 1).copied().unwrap_or("");
            format!("{}:{k}: {e} (`{}`)", path.display(), shown(text))
        })?;
        shard.header = head.pop().unwrap_or_default();
        Ok(shard)
    }

    /// Where the next line is (`path:line`), for messages about it.
    pub fn next_place(&self) -> String {
        format!("{}:{}", self.path.display(), self.line + 1)
    }

    /// Where the last line read is (`path:line`).
    pub fn place(&self) -> String {
        format!("{}:{}", self.path.display(), self.line)
    }

    /// Whether anything follows the last line read.
    pub fn has_more(&mut self) -> Result<bool, String> {
        self.reader
            .fill_buf()
            .map(|rest| !rest.is_empty())
            .map_err(|e| format!("{}: {e}", self.next_place()))
    }

    /// The next line (without its line break, `\n` or `\r\n`), None at the end of the file.
    /// A line longer than [`MAX_LINE`], one that is not UTF-8 or one the file ends inside
    /// (a truncated file: the sweep ends every line) is an error naming it.
    pub fn next_line(&mut self) -> Result<Option<String>, String> {
        let bytes = &mut self.bytes;
        bytes.clear();
        let limit = MAX_LINE as u64 + 2;
        let read = (&mut self.reader)
            .take(limit)
            .read_until(b'\n', bytes)
            .map_err(|e| format!("{}:{}: {e}", self.path.display(), self.line + 1))?;
        if read == 0 {
            return Ok(None);
        }
        self.line += 1;
        let (path, line) = (&self.path, self.line);
        let place = || format!("{}:{line}", path.display());
        let too_long = || {
            format!(
                "{}: longer than {MAX_LINE} bytes: not a line of a sweep CSV",
                place()
            )
        };
        if bytes.pop() != Some(b'\n') {
            if read as u64 == limit {
                return Err(too_long());
            }
            return Err(format!(
                "{}: the file ends inside this line (the sweep ends every line with a line \
                 break: a truncated file?)",
                place()
            ));
        }
        if bytes.last() == Some(&b'\r') {
            bytes.pop();
        }
        if bytes.len() > MAX_LINE {
            return Err(too_long());
        }
        match std::str::from_utf8(bytes) {
            Ok(text) => Ok(Some(text.to_string())),
            Err(e) => Err(format!(
                "{}: not UTF-8 text (byte {} of the line): not a sweep CSV",
                place(),
                e.valid_up_to() + 1
            )),
        }
    }
}
