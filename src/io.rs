//! Output files are written atomically: to a temporary file beside the
//! target (`.NAME.PID.tmp`), then renamed over it, so a failure never
//! leaves a partial file. [`remove_temp_files`] clears what an interrupted
//! or killed run left. A symbolic link is written through (its target is
//! replaced, the link kept), and what is not a regular file (a pipe, a
//! FIFO, `/dev/stdout`, `/dev/null`) is written into as a stream
//! ([`output_target`]).

use std::io::Write;
use std::path::{Path, PathBuf};

/// Where the bytes for output `path` go ([`output_target`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file, new or existing, written atomically: the path
    /// with its symbolic links followed, so the link stays a link.
    File(PathBuf),
    /// Something that is not a regular file (a FIFO, a character device
    /// such as `/dev/null`, a socket), or this process's own standard
    /// output or error, whatever it was redirected to (`/dev/stdout` into
    /// a log): written into as it is, appended to. Renaming a file over
    /// it would replace it: a FIFO's reader would get nothing, a log
    /// what it held.
    Stream(PathBuf),
}

/// The most symbolic links followed from an output path (Linux's own
/// limit): more is a loop.
const MAX_LINKS: usize = 40;

/// Where output `path` writes: the regular file its symbolic links lead
/// to (existing or, for a dangling link, to be created), or a stream.
/// A folder is an error (the caller names the path).
pub fn output_target(path: &Path) -> std::io::Result<OutputTarget> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is a folder, expected a file name",
        )),
        Ok(m) if m.is_file() && !is_standard_stream(path, &m) => {
            Ok(OutputTarget::File(std::fs::canonicalize(path)?))
        }
        Ok(_) => Ok(OutputTarget::Stream(path.to_owned())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Ok(OutputTarget::File(follow_dangling_links(path)?))
        }
        Err(e) => Err(e),
    }
}

/// Whether `path` (its metadata `m`) is this process's standard output
/// or error: a path under `/dev` or `/proc` (`/dev/stdout`,
/// `/dev/fd/1`, `/proc/self/fd/2`), or the very file either was
/// redirected to. Through `/dev/stdout` redirected into a file, a
/// renamed temporary file would have replaced that file, with what the
/// run had printed to it before.
fn is_standard_stream(path: &Path, m: &std::fs::Metadata) -> bool {
    if path.starts_with("/dev") || path.starts_with("/proc") {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        use std::os::unix::fs::MetadataExt;
        let same = |fd: std::os::fd::BorrowedFd<'_>| {
            fd.try_clone_to_owned()
                .ok()
                .and_then(|fd| std::fs::File::from(fd).metadata().ok())
                .is_some_and(|s| s.dev() == m.dev() && s.ino() == m.ino())
        };
        same(std::io::stdout().as_fd()) || same(std::io::stderr().as_fd())
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        false
    }
}

/// `path` with its symbolic links followed one by one where the last
/// one's target does not exist yet (or `path` itself when it is no link).
fn follow_dangling_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_owned();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("more than {MAX_LINKS} symbolic links (a loop?)"),
    ))
}

/// Writes the bytes `write` produces to `path` atomically. On error the
/// temporary file is removed and `path` is untouched. Through a symbolic
/// link the link's target is written; into a FIFO or a device, the bytes
/// as a stream ([`output_target`]).
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let path = match output_target(path)? {
        OutputTarget::File(p) => p,
        OutputTarget::Stream(p) => {
            let file = std::fs::OpenOptions::new().append(true).open(&p)?;
            let mut buf = std::io::BufWriter::new(file);
            write(&mut buf)?;
            return buf.flush();
        }
    };
    let path = path.as_path();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{}: not a file name", path.display()),
        )
    })?;
    let tmp = dir.join(temp_name(&name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let file = std::fs::File::create(&tmp)?;
        let mut buf = std::io::BufWriter::new(file);
        write(&mut buf)?;
        let file = buf.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The temporary file's name for target file `name` written by process
/// `pid`: `.NAME.PID.tmp`, hidden, beside the target.
fn temp_name(name: &str, pid: u32) -> String {
    format!(".{name}.{pid}.tmp")
}

/// The process id in a temporary file name of ours (`.NAME.PID.tmp`).
fn temp_pid(file_name: &str) -> Option<u32> {
    let stem = file_name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (_, pid) = stem.rsplit_once('.')?;
    pid.parse().ok()
}

/// Removes, in `dir`, the temporary files of ours (`.NAME.PID.tmp`) whose
/// process is `pid`, or (with `None`) whose process is gone: what an
/// interrupted or killed run left behind. The processes are looked up in
/// `/proc`; where there is none, only `Some(pid)` removes anything.
/// Returns the files removed.
pub fn remove_temp_files(dir: &Path, pid: Option<u32>) -> Vec<std::path::PathBuf> {
    let proc_fs = Path::new("/proc/self").exists();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(p) = temp_pid(&name.to_string_lossy()) else {
            continue;
        };
        let ours = match pid {
            Some(pid) => p == pid,
            None => {
                proc_fs
                    && p != std::process::id()
                    && !Path::new("/proc").join(p.to_string()).exists()
            }
        };
        if ours && std::fs::remove_file(e.path()).is_ok() {
            removed.push(e.path());
        }
    }
    removed
}

/// Encodes an RGB image as PNG and writes it atomically.
#[cfg(feature = "images")]
pub fn write_png_atomically(path: &Path, img: &image::RgbImage) -> std::io::Result<()> {
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(std::io::Error::other)?;
    write_atomically(path, |out| out.write_all(&png))
}

/// Encodes linear RGB radiance as OpenEXR (32-bit float channels, scene
/// linear, no tone map) and writes it atomically.
#[cfg(feature = "images")]
pub fn write_exr_atomically(path: &Path, img: &image::Rgb32FImage) -> std::io::Result<()> {
    let mut exr = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut exr),
        image::ImageFormat::OpenExr,
    )
    .map_err(std::io::Error::other)?;
    write_atomically(path, |out| out.write_all(&exr))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_is_written_through_and_stays_a_link() {
        let dir = tempfile::tempdir().expect("dir");
        #[cfg(unix)]
        {
            let real = dir.path().join("real.csv");
            std::fs::write(&real, "old").expect("write");
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink("real.csv", &link).expect("link");
            write_atomically(&link, |o| o.write_all(b"new")).expect("written");
            assert_eq!(std::fs::read_to_string(&real).expect("read"), "new");
            let m = std::fs::symlink_metadata(&link).expect("meta");
            assert!(m.file_type().is_symlink(), "the link was replaced");
            // A dangling link creates its target.
            let dangling = dir.path().join("next.csv");
            std::os::unix::fs::symlink("made.csv", &dangling).expect("link");
            write_atomically(&dangling, |o| o.write_all(b"made")).expect("written");
            let made = dir.path().join("made.csv");
            assert_eq!(std::fs::read_to_string(made).expect("read"), "made");
            assert!(
                std::fs::symlink_metadata(&dangling)
                    .expect("meta")
                    .file_type()
                    .is_symlink()
            );
            // A loop is refused.
            let a = dir.path().join("a.csv");
            std::os::unix::fs::symlink("a.csv", &a).expect("link");
            let e = write_atomically(&a, |o| o.write_all(b"x")).expect_err("loop");
            assert!(e.to_string().contains("symbolic links"), "{e}");
        }
        // A folder is refused by name.
        let e = write_atomically(dir.path(), |o| o.write_all(b"x")).expect_err("folder");
        assert!(e.to_string().contains("is a folder"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_or_a_device_is_written_into_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let null = Path::new("/dev/null");
        if null.exists() {
            write_atomically(null, |o| o.write_all(b"gone")).expect("written");
            let m = std::fs::metadata(null).expect("meta");
            assert!(m.file_type().is_char_device(), "/dev/null was replaced");
        }
        let dir = tempfile::tempdir().expect("dir");
        let fifo = dir.path().join("curves.csv");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !matches!(made, Ok(s) if s.success()) {
            eprintln!("SKIPPED: no mkfifo");
            return;
        }
        let (sent, got) = std::sync::mpsc::channel();
        {
            let fifo = fifo.clone();
            std::thread::spawn(move || sent.send(std::fs::read_to_string(fifo).expect("read")));
        }
        write_atomically(&fifo, |o| o.write_all(b"t,z\n0,1\n")).expect("written");
        // A FIFO replaced by a file leaves the reader waiting for ever:
        // fail, not hang.
        let read = got.recv_timeout(std::time::Duration::from_secs(20));
        assert_eq!(read.as_deref(), Ok("t,z\n0,1\n"));
        let m = std::fs::symlink_metadata(&fifo).expect("meta");
        assert!(m.file_type().is_fifo(), "the FIFO was replaced by a file");
    }

    #[cfg(unix)]
    #[test]
    fn the_standard_streams_are_written_into_whatever_they_lead_to() {
        // /dev/stdout redirected into a log is a regular file, but the
        // run's own: appended to, not replaced.
        for p in ["/dev/stdout", "/dev/fd/2", "/proc/self/fd/1"] {
            let p = Path::new(p);
            if let Ok(m) = std::fs::metadata(p) {
                assert!(is_standard_stream(p, &m), "{}", p.display());
            }
        }
        let dir = tempfile::tempdir().expect("dir");
        let plain = dir.path().join("plain.csv");
        std::fs::write(&plain, "x").expect("write");
        let m = std::fs::metadata(&plain).expect("meta");
        assert!(!is_standard_stream(&plain, &m));
        assert_eq!(
            output_target(&plain).expect("target"),
            OutputTarget::File(std::fs::canonicalize(&plain).expect("canonical"))
        );
    }

    #[test]
    fn temp_names_carry_their_process() {
        assert_eq!(temp_pid(&temp_name("sky.png", 4242)), Some(4242));
        assert_eq!(temp_pid("sky.png"), None);
        assert_eq!(temp_pid(".sky.png.tmp"), None);
    }

    #[test]
    fn stale_temp_files_of_gone_processes_are_removed() {
        let dir = tempfile::tempdir().expect("dir");
        // u32::MAX is never a live pid; ours is.
        let gone = dir.path().join(temp_name("a.csv", u32::MAX));
        let live = dir.path().join(temp_name("b.csv", std::process::id()));
        let other = dir.path().join("c.csv");
        for f in [&gone, &live, &other] {
            std::fs::write(f, "x").expect("write");
        }
        let removed = remove_temp_files(dir.path(), None);
        if Path::new("/proc/self").exists() {
            assert_eq!(removed, vec![gone.clone()]);
        }
        assert!(live.exists() && other.exists());
        assert_eq!(
            remove_temp_files(dir.path(), Some(std::process::id())),
            vec![live]
        );
        assert!(other.exists());
    }
}
