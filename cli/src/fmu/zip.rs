//! A zip archive written in one pass (PKWARE APPNOTE 6.3: local headers with sizes and
//! CRC-32 known in advance, then the central directory): what an FMU is. Entries are
//! deflated (method 8) and dated 1980-01-01, so that the same model gives the same bytes.

use flate2::Compression;
use flate2::write::DeflateEncoder;
use std::io::{self, Write};

/// The DOS date of 1980-01-01 (the earliest a zip can hold), time 00:00.
const DOS_DATE: u16 = (1 << 5) | 1;

fn too_large(what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{what} is over 4 GiB: a zip without ZIP64 cannot hold it"),
    )
}

/// Writes `entries` (path inside the archive, bytes) as a zip archive to `out`.
pub fn write(out: &mut dyn Write, entries: &[(String, Vec<u8>)]) -> io::Result<()> {
    let mut central = Vec::new();
    let mut offset: u64 = 0;
    for (name, data) in entries {
        let mut encoder = DeflateEncoder::new(Vec::new(), Compression::default());
        encoder.write_all(data)?;
        let packed = encoder.finish()?;
        let crc = crc32fast::hash(data);
        let size = u32::try_from(data.len()).map_err(|_| too_large(name))?;
        let packed_size = u32::try_from(packed.len()).map_err(|_| too_large(name))?;
        let name_len = u16::try_from(name.len()).map_err(|_| too_large(name))?;
        let at = u32::try_from(offset).map_err(|_| too_large("the archive"))?;
        // The fields the local header and the central directory share: version needed
        // (2.0), flags (bit 11: UTF-8 names), method, time, date, CRC, sizes, name length.
        let mut common = Vec::new();
        for half in [20u16, 1 << 11, 8, 0, DOS_DATE] {
            common.extend(half.to_le_bytes());
        }
        for word in [crc, packed_size, size] {
            common.extend(word.to_le_bytes());
        }
        common.extend(name_len.to_le_bytes());
        let mut local = 0x0403_4b50u32.to_le_bytes().to_vec();
        local.extend(&common);
        local.extend(0u16.to_le_bytes()); // no extra field
        local.extend(name.as_bytes());
        out.write_all(&local)?;
        out.write_all(&packed)?;
        offset += (local.len() + packed.len()) as u64;
        central.extend(0x0201_4b50u32.to_le_bytes());
        central.extend(((3u16 << 8) | 20).to_le_bytes()); // made by: Unix, 2.0
        central.extend(&common);
        for half in [0u16, 0, 0, 0] {
            // extra field, comment, disk number, internal attributes
            central.extend(half.to_le_bytes());
        }
        central.extend((0o100_644u32 << 16).to_le_bytes()); // a regular file, rw-r--r--
        central.extend(at.to_le_bytes());
        central.extend(name.as_bytes());
    }
    let count = u16::try_from(entries.len()).map_err(|_| too_large("the entry count"))?;
    let central_size = u32::try_from(central.len()).map_err(|_| too_large("the directory"))?;
    let central_at = u32::try_from(offset).map_err(|_| too_large("the archive"))?;
    out.write_all(&central)?;
    let mut end = 0x0605_4b50u32.to_le_bytes().to_vec();
    for half in [0u16, 0, count, count] {
        end.extend(half.to_le_bytes());
    }
    end.extend(central_size.to_le_bytes());
    end.extend(central_at.to_le_bytes());
    end.extend(0u16.to_le_bytes()); // no comment
    out.write_all(&end)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Python's zipfile reads the archive back (an independent reader), entry by entry.
    #[test]
    fn python_reads_the_archive_back() {
        let entries = vec![
            ("modelDescription.xml".to_string(), b"<x/>\n".repeat(100)),
            (
                "binaries/x86_64-linux/m.so".to_string(),
                (0..=255u8).collect(),
            ),
        ];
        let mut bytes = Vec::new();
        write(&mut bytes, &entries).expect("written");
        let dir = std::env::temp_dir().join(format!("camchain-zip-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("t.zip");
        std::fs::write(&path, &bytes).expect("zip");
        let script = "import sys, zipfile\n\
                      z = zipfile.ZipFile(sys.argv[1])\n\
                      assert z.testzip() is None\n\
                      for i in z.infolist(): print(i.filename, i.file_size, z.read(i).hex())";
        let output = std::process::Command::new("python3")
            .args(["-c", script])
            .arg(&path)
            .output();
        let _ = std::fs::remove_dir_all(&dir);
        let Ok(output) = output else {
            eprintln!("python3 is not here: the archive is checked by the FMPy tests only");
            return;
        };
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let listed = String::from_utf8_lossy(&output.stdout);
        let lines: Vec<&str> = listed.lines().collect();
        assert_eq!(lines.len(), 2);
        for ((name, data), line) in entries.iter().zip(lines) {
            let hex: String = data.iter().map(|b| format!("{b:02x}")).collect();
            assert_eq!(line, format!("{name} {} {hex}", data.len()));
        }
    }
}
