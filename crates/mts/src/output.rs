//! Writing output files whole or not at all.
//!
//! Every file this workspace writes (meshes, `.mts` models, packet streams,
//! PNGs, the bench's report) goes through [`write_with`]: the bytes go to a
//! temporary file beside the target (same folder, so the same file system),
//! which is flushed, synced and then renamed over the target. A write cut
//! short — a full disk, an error half-way, a kill, a crash — leaves the
//! previous file as it was and at most a hidden `.STEM.PID.N.partial.EXT`
//! beside it (removed on every error this process sees; a kill cannot be
//! cleaned up after, and the name says what it is). Rename is atomic on
//! POSIX file systems for a target in the same folder; the target's
//! permissions become the new file's defaults.
//!
//! Cost: one extra `fsync` per file (milliseconds on a disk), which is what
//! makes the rename safe after a power loss: without it the rename may
//! reach the disk before the data does.

use crate::error::{Error, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary files made by this process so far: part of each one's name,
/// so two writes to the same target from two threads do not collide.
static TEMPORARIES: AtomicU64 = AtomicU64::new(0);

/// Writes `contents` to `path` atomically (see the module docs).
///
/// # Errors
/// [`Error::Io`] naming `path` when the temporary file cannot be created,
/// written, synced or renamed; the target is then untouched.
pub fn write_file(path: &Path, contents: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(contents))
}

/// Writes `path` atomically through `write`, which receives a buffered
/// writer on a temporary file beside `path` (see the module docs). The
/// target is replaced only when `write` returns `Ok` and the data is on
/// disk. A symbolic link is followed (the file it names is replaced, the
/// link kept); a target that is a device or a pipe is written in place.
///
/// # Errors
/// [`Error::Io`] naming `path` for any failure, `write`'s included; the
/// temporary file is removed and the target is untouched.
pub fn write_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<()> {
    let io = |source| Error::Io {
        file: path.to_owned(),
        source,
    };
    // A device or pipe named as the output (`/dev/null`, a FIFO) cannot be
    // replaced by a rename, and must not be: it is written in place.
    let target = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => std::fs::canonicalize(path).map_err(io)?,
        _ => path.to_owned(),
    };
    if let Ok(meta) = std::fs::metadata(&target) {
        if !meta.is_file() && !meta.is_dir() {
            let mut w = BufWriter::new(File::create(&target).map_err(io)?);
            return write(&mut w).and_then(|()| w.flush()).map_err(io);
        }
    }
    let temporary = temporary_beside(&target);
    let result = (|| {
        let file = File::create(&temporary)?;
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&temporary, &target)
    })();
    result.map_err(|source| {
        // Best effort: the temporary may not exist (create failed).
        let _ = std::fs::remove_file(&temporary);
        io(source)
    })
}

/// Writes `path` atomically through a writer that wants a path of its own
/// (an image library's file backend, say): `write` gets the temporary
/// path beside `path`, and the file it leaves there is synced and renamed
/// over `path` when it returns `Ok`; on an error it is removed.
///
/// # Errors
/// `write`'s error, or [`Error::Io`] naming `path` when the file left
/// cannot be synced or renamed; the target is then untouched.
pub fn write_through<E: From<Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), E>,
) -> std::result::Result<(), E> {
    let temporary = temporary_beside(path);
    if let Err(e) = write(&temporary) {
        let _ = std::fs::remove_file(&temporary);
        return Err(e);
    }
    let result = File::open(&temporary)
        .and_then(|f| f.sync_all())
        .and_then(|()| std::fs::rename(&temporary, path));
    result.map_err(|source| {
        let _ = std::fs::remove_file(&temporary);
        E::from(Error::Io {
            file: path.to_owned(),
            source,
        })
    })
}

/// `folder/.STEM.PID.N.partial.EXT` for the target `folder/STEM.EXT`: the
/// extension kept last, for writers that choose a format by it.
fn temporary_beside(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy());
    let ext = path
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    let n = TEMPORARIES.fetch_add(1, Ordering::Relaxed);
    let temporary = format!(".{stem}.{}.{n}.partial{ext}", std::process::id());
    match path.parent() {
        Some(folder) => folder.join(temporary),
        None => PathBuf::from(temporary),
    }
}

/// Whether writing `output` would replace one of `inputs` (the same file,
/// by device and inode on Unix, by canonical path elsewhere). Commands call
/// it before writing so that `-o` naming the input is refused instead of
/// replacing what was read. Paths that do not exist yet never match.
#[must_use]
pub fn is_same_file(output: &Path, input: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(output), std::fs::metadata(input)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(output), std::fs::canonicalize(input)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("mts-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_write_that_fails_half_way_leaves_the_previous_file() {
        let dir = folder("half");
        let target = dir.join("model.mts");
        write_file(&target, b"the good file").unwrap();
        // Half the bytes written, then the writer fails, as a full disk or
        // an error in the middle of an encoder would.
        let err = write_with(&target, |w| {
            w.write_all(b"the new fi")?;
            w.flush()?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("model.mts"), "{err}");
        assert_eq!(std::fs::read(&target).unwrap(), b"the good file");
        assert_eq!(entries(&dir), ["model.mts"], "no partial file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_successful_write_replaces_the_file_whole() {
        let dir = folder("whole");
        let target = dir.join("a.obj");
        write_file(&target, b"old").unwrap();
        write_with(&target, |w| {
            w.write_all(b"new ")?;
            w.write_all(b"contents")
        })
        .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new contents");
        assert_eq!(entries(&dir), ["a.obj"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_the_target() {
        let dir = folder("missing");
        let target = dir.join("no/such/folder/x.ply");
        let err = write_file(&target, b"x").unwrap_err().to_string();
        assert!(err.contains("no/such/folder/x.ply"), "{err}");
        assert!(entries(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_kept_and_a_device_written_in_place() {
        let dir = folder("link");
        let real = dir.join("real.ply");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.ply");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        write_file(Path::new("/dev/null"), b"nothing").unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_same_file_is_recognised_through_another_path() {
        let dir = folder("same");
        let a = dir.join("a.obj");
        std::fs::write(&a, b"v 0 0 0\n").unwrap();
        let via_dot = dir.join(".").join("a.obj");
        assert!(is_same_file(&via_dot, &a));
        assert!(!is_same_file(&dir.join("b.obj"), &a));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
