//! Output files are written atomically: to a temporary file beside the
//! target (`.NAME.PID.tmp`), then renamed over it, so a failure never
//! leaves a partial file. [`remove_temp_files`] clears what an interrupted
//! or killed run left.

use std::io::Write;
use std::path::Path;

/// Writes the bytes `write` produces to `path` atomically. On error the
/// temporary file is removed and `path` is untouched.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
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
pub fn write_png_atomically(path: &Path, img: &image::RgbImage) -> std::io::Result<()> {
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(std::io::Error::other)?;
    write_atomically(path, |out| out.write_all(&png))
}

/// Encodes linear RGB radiance as OpenEXR (32-bit float channels, scene
/// linear, no tone map) and writes it atomically.
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
