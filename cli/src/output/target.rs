//! What a destination path is, resolved before anything runs: the file that will be
//! replaced (a symbolic link's final target, even a dangling one's), or a special file that
//! is written directly; refused with a reason when it cannot be written as documented.
//!
//! - A regular file, or a path where nothing exists: replaced by a complete new file through
//!   a rename, keeping the old file's permissions (and its owner and group, where the
//!   process may set them).
//! - A symbolic link: followed to its final target, which is treated as above (created when
//!   the link dangles, if the target's directory exists); the link itself stays.
//! - A regular file with other hard links: refused. A rename would detach those links from
//!   the new content, and writing in place would show them a file half written.
//! - A FIFO, a character device, a socket: written directly, never replaced.
//! - A directory, or a target whose directory does not exist or cannot be written: refused.

use std::fs;
use std::io;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// Permissions and ownership a replaced file keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Keep {
    /// Mode bits.
    pub mode: u32,
    /// Owner.
    pub uid: u32,
    /// Group.
    pub gid: u32,
}

/// A destination, resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// Replaced through a rename: the path of the file itself (a link's final target), and
    /// what the existing file's permissions and owner are, if it exists.
    Replace {
        /// The file to replace or create.
        path: PathBuf,
        /// The existing file's permissions and owner.
        keep: Option<Keep>,
    },
    /// Written directly (FIFO, device, socket).
    Special(PathBuf),
}

/// How many symbolic links are followed before a destination is called a loop.
const MAX_LINKS: usize = 40;

/// Resolves `path` (see the module documentation).
///
/// # Errors
/// One line naming the path and the reason: a directory, a file with other hard links, a
/// link loop, a target whose directory does not exist, metadata that cannot be read.
pub fn resolve(path: &Path) -> Result<Target, String> {
    let cannot = |why: String| format!("cannot write {}: {why}", path.display());
    let mut current = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match fs::symlink_metadata(&current) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                let dir = parent_dir(&current);
                if !dir.is_dir() {
                    let via = if current == path {
                        String::new()
                    } else {
                        format!(" (the target of a link, {})", current.display())
                    };
                    return Err(cannot(format!(
                        "directory {} does not exist{via}",
                        dir.display()
                    )));
                }
                return Ok(Target::Replace {
                    path: current,
                    keep: None,
                });
            }
            Err(e) => return Err(cannot(e.to_string())),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let link = fs::read_link(&current).map_err(|e| cannot(e.to_string()))?;
            current = if link.is_absolute() {
                link
            } else {
                parent_dir(&current).join(link)
            };
            continue;
        }
        if kind.is_dir() {
            return Err(cannot(if current == path {
                "it is a directory (a file name is expected)".to_string()
            } else {
                format!(
                    "its link's target {} is a directory (a file name is expected)",
                    current.display()
                )
            }));
        }
        if !kind.is_file() {
            return Ok(Target::Special(current));
        }
        if meta.nlink() > 1 {
            return Err(cannot(format!(
                "{} has {} hard links: replacing it would detach the others from the new \
                 content; write to another name or remove the other links",
                current.display(),
                meta.nlink()
            )));
        }
        return Ok(Target::Replace {
            path: current,
            keep: Some(Keep {
                mode: meta.mode() & 0o7777,
                uid: meta.uid(),
                gid: meta.gid(),
            }),
        });
    }
    Err(cannot(format!(
        "more than {MAX_LINKS} symbolic links (a loop?)"
    )))
}

/// The directory a path's file is in (`.` for a bare name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Gives a new file the permissions and owner of the one it replaces. The owner and group
/// only where the process may set them (as root, or a group it belongs to); otherwise the
/// file keeps the creator's, as any replaced file does.
pub fn apply(file: &fs::File, keep: Option<Keep>) -> io::Result<()> {
    let Some(keep) = keep else {
        return Ok(());
    };
    let _ = std::os::unix::fs::fchown(file, Some(keep.uid), Some(keep.gid));
    file.set_permissions(std::os::unix::fs::PermissionsExt::from_mode(keep.mode))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("camchain-target-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn links_are_followed_and_hard_links_refused() {
        let dir = scratch("links");
        let real = dir.join("real.csv");
        fs::write(&real, "x").unwrap();
        std::os::unix::fs::symlink(&real, dir.join("link.csv")).unwrap();
        std::os::unix::fs::symlink("missing.csv", dir.join("dangling.csv")).unwrap();
        let Target::Replace { path, keep } = resolve(&dir.join("link.csv")).unwrap() else {
            panic!("a link to a file is replaced through its target");
        };
        assert_eq!(path, real);
        assert!(keep.is_some());
        let Target::Replace { path, keep } = resolve(&dir.join("dangling.csv")).unwrap() else {
            panic!("a dangling link creates its target");
        };
        assert_eq!(path, dir.join("missing.csv"));
        assert_eq!(keep, None);
        fs::hard_link(&real, dir.join("hard.csv")).unwrap();
        let error = resolve(&real).unwrap_err();
        assert!(error.contains("2 hard links"), "{error}");
        std::os::unix::fs::symlink("nowhere/x.csv", dir.join("deep.csv")).unwrap();
        let error = resolve(&dir.join("deep.csv")).unwrap_err();
        assert!(error.contains("does not exist"), "{error}");
        std::os::unix::fs::symlink("loop.csv", dir.join("loop.csv")).unwrap();
        assert!(resolve(&dir.join("loop.csv")).unwrap_err().contains("loop"));
        assert!(resolve(&dir).unwrap_err().contains("is a directory"));
        let _ = fs::remove_dir_all(&dir);
    }
}
