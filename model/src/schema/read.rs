//! Reading model files and the table files they name, with a bound on their size.
//!
//! A model file is a few kilobytes of text and a table of points some tens; a path that
//! names something else (`/dev/zero`, a FIFO fed without end, a huge file given by mistake)
//! must not be read until memory runs out. Every model and table file is read through
//! [`read_text`], which reads at most [`MAX_FILE_BYTES`] and refuses the file beyond that.

use std::io::{self, Read};
use std::path::Path;

/// The largest model file or table file read: 16 MiB (a model of a thousand bodies is
/// about 250 kB; a table of a hundred thousand points about 4 MB).
pub const MAX_FILE_BYTES: usize = 16 << 20;

/// The text of the file at `path`, read with a bounded reader: a regular file longer than
/// [`MAX_FILE_BYTES`] is refused before it is read, and anything else (a device, a FIFO)
/// is refused as soon as it has given more than that. The error says so; other failures
/// are those of the file system (not found, permission denied, not UTF-8, …).
///
/// A FIFO that no process writes to blocks the call until one does, as reading it with
/// any other program would.
pub fn read_text(path: &Path) -> io::Result<String> {
    let file = std::fs::File::open(path)?;
    if let Ok(meta) = file.metadata() {
        if meta.is_file() && meta.len() > MAX_FILE_BYTES as u64 {
            return Err(too_large(Some(meta.len())));
        }
    }
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(too_large(None));
    }
    String::from_utf8(bytes).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// The error of a file beyond [`MAX_FILE_BYTES`] (`len`: its length when known).
fn too_large(len: Option<u64>) -> io::Error {
    let limit = format!(
        "more than {} MiB (the limit for a model or table file)",
        MAX_FILE_BYTES >> 20
    );
    let message = match len {
        Some(len) => format!("it is {len} bytes long, {limit}"),
        None => format!("it gives {limit}"),
    };
    io::Error::new(io::ErrorKind::InvalidData, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_beyond_the_limit_is_refused_and_one_at_it_is_read() {
        let dir = std::env::temp_dir().join(format!("camchain-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        // A sparse file one byte over the limit: refused from its length, unread.
        let over = dir.join("over.ron");
        let file = std::fs::File::create(&over).expect("a file");
        file.set_len(MAX_FILE_BYTES as u64 + 1).expect("a length");
        let e = read_text(&over).expect_err("refused");
        assert!(
            e.to_string()
                .contains(&format!("{} bytes long", MAX_FILE_BYTES + 1))
                && e.to_string().contains("16 MiB"),
            "{e}"
        );
        // Exactly at the limit: read (zero bytes are valid UTF-8).
        file.set_len(MAX_FILE_BYTES as u64).expect("a length");
        assert_eq!(read_text(&over).expect("read").len(), MAX_FILE_BYTES);
        std::fs::remove_dir_all(&dir).expect("cleaned up");
    }

    #[cfg(unix)]
    #[test]
    fn a_device_without_end_is_refused_after_the_limit() {
        let e = read_text(Path::new("/dev/zero")).expect_err("refused");
        assert!(e.to_string().contains("it gives more than 16 MiB"), "{e}");
    }
}
