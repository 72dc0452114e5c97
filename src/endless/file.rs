//! The database on disk, so the volumes are precomputed once and played
//! back by later runs (`[simulation.endless] database = "FILE"`). The file:
//! a first line `cumulus-volumes 1 <fingerprint>` (a hash of every scene
//! setting the volumes depend on), a second line of the header as JSON,
//! then the volumes' bytes and the distances (`f64`, little-endian). A
//! file whose fingerprint does not match the scene is rebuilt, never
//! played.

use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::Database;
use crate::io::write_atomically;
use crate::scene::{EndlessConfig, Scene};

/// What went wrong reading or writing a database file.
#[derive(Debug, thiserror::Error)]
pub enum DatabaseFileError {
    #[error("{path}: {err}")]
    Io { path: PathBuf, err: std::io::Error },
    #[error("{path}: not a cumulus volume database ({what})")]
    Format { path: PathBuf, what: String },
}

#[derive(Serialize, Deserialize)]
struct Header {
    dims: [usize; 3],
    count: usize,
    interval_s: f64,
    origin: [f32; 3],
    extent: [f32; 3],
    extinction_per_m: f32,
    build_s: f64,
}

/// FNV-1a of every setting the volumes depend on: the atmosphere, the
/// physics, the projection, the database's own keys, the spin-up time and
/// the renderer's density (cloud map, coverage, detail).
pub fn fingerprint(scene: &Scene, cfg: &EndlessConfig) -> u64 {
    let r = &scene.render;
    // Where the file lies is not what it holds.
    let cfg = EndlessConfig {
        database: None,
        ..cfg.clone()
    };
    let text = format!(
        "{:?}|{:?}|{:?}|{:?}|{}|{:?}|{}|{}|{}|{}|{}",
        scene.atmosphere,
        scene.physics,
        scene.projection,
        cfg,
        r.time_s,
        r.cloud_map,
        r.coverage,
        r.detail_strength,
        r.detail_scale_m,
        r.extinction_per_m,
        r.fine_detail,
    );
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

impl Database {
    /// Writes the database to `path` atomically, stamped with `print`.
    pub fn save(&self, path: &Path, print: u64) -> Result<(), DatabaseFileError> {
        let header = Header {
            dims: self.dims,
            count: self.len(),
            interval_s: self.interval_s,
            origin: self.origin.to_array(),
            extent: self.extent.to_array(),
            extinction_per_m: self.extinction_per_m,
            build_s: self.build_s,
        };
        write_atomically(path, |out| {
            writeln!(out, "cumulus-volumes 1 {print:016x}")?;
            serde_json::to_writer(&mut *out, &header).map_err(std::io::Error::other)?;
            writeln!(out)?;
            for v in &self.volumes {
                out.write_all(v)?;
            }
            for d in &self.distance {
                out.write_all(&d.to_le_bytes())?;
            }
            Ok(())
        })
        .map_err(|err| DatabaseFileError::Io {
            path: path.to_owned(),
            err,
        })
    }

    /// Reads a database from `path`; `None` when its fingerprint is not
    /// `print` (made for other settings).
    pub fn load(path: &Path, print: u64) -> Result<Option<Self>, DatabaseFileError> {
        let io = |err| DatabaseFileError::Io {
            path: path.to_owned(),
            err,
        };
        let bad = |what: &str| DatabaseFileError::Format {
            path: path.to_owned(),
            what: what.to_owned(),
        };
        let file = std::fs::File::open(path).map_err(io)?;
        let size = file.metadata().map_err(io)?.len();
        let mut r = std::io::BufReader::new(file);
        let mut first = String::new();
        r.read_line(&mut first).map_err(io)?;
        let mut words = first.split_whitespace();
        if words.next() != Some("cumulus-volumes") || words.next() != Some("1") {
            return Err(bad("its first line is not `cumulus-volumes 1 FINGERPRINT`"));
        }
        let stamp = words
            .next()
            .and_then(|w| u64::from_str_radix(w, 16).ok())
            .ok_or_else(|| bad("no fingerprint on its first line"))?;
        if stamp != print {
            return Ok(None);
        }
        let mut line = String::new();
        r.read_line(&mut line).map_err(io)?;
        let h: Header =
            serde_json::from_str(&line).map_err(|e| bad(&format!("header line 2: {e}")))?;
        let voxels = h.dims.iter().try_fold(1_usize, |n, &d| n.checked_mul(d));
        let voxels = match voxels {
            Some(v) if v > 0 && h.count > 0 && v.saturating_mul(h.count) <= 1 << 31 => v,
            _ => return Err(bad("header line 2: empty or oversized volumes")),
        };
        // What the header promises, against what the file holds, before
        // anything is allocated for it: a count of 2^31 asked for 48 GiB
        // of volume list (and 2^65 bytes of distances), and the
        // allocation's failure aborted the program.
        let body = (h.count as u64)
            .checked_mul(h.count as u64)
            .and_then(|d| d.checked_mul(8))
            .and_then(|d| d.checked_add(voxels as u64 * h.count as u64));
        let rest = size.saturating_sub((first.len() + line.len()) as u64);
        if body.is_none_or(|b| b > rest) {
            return Err(bad("shorter than its header says"));
        }
        let mut volumes = Vec::with_capacity(h.count);
        for _ in 0..h.count {
            let mut v = vec![0u8; voxels];
            r.read_exact(&mut v)
                .map_err(|_| bad("shorter than its header says"))?;
            volumes.push(v);
        }
        let mut distance = vec![0.0; h.count * h.count];
        let mut b = [0u8; 8];
        for d in &mut distance {
            r.read_exact(&mut b)
                .map_err(|_| bad("shorter than its header says"))?;
            *d = f64::from_le_bytes(b);
        }
        Ok(Some(Self {
            dims: h.dims,
            volumes,
            distance,
            interval_s: h.interval_s,
            origin: Vec3::from_array(h.origin),
            extent: Vec3::from_array(h.extent),
            extinction_per_m: h.extinction_per_m,
            build_s: h.build_s,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> Database {
        let volumes = vec![vec![0u8, 10, 200, 255], vec![5u8, 0, 0, 1]];
        Database {
            dims: [2, 1, 2],
            distance: super::super::distances(&volumes),
            volumes,
            interval_s: 30.0,
            origin: Vec3::new(0.0, 500.0, 0.0),
            extent: Vec3::new(100.0, 50.0, 100.0),
            extinction_per_m: 0.05,
            build_s: 1.5,
        }
    }

    #[test]
    fn a_saved_database_reads_back_and_another_fingerprint_is_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("db.volumes");
        let db = tiny();
        db.save(&path, 0xabc).expect("saves");
        let back = Database::load(&path, 0xabc)
            .expect("reads")
            .expect("same print");
        assert_eq!(back.volumes, db.volumes);
        assert_eq!(back.distance, db.distance);
        assert_eq!(
            (back.dims, back.origin, back.extent),
            (db.dims, db.origin, db.extent)
        );
        assert!(Database::load(&path, 0xabd).expect("reads").is_none());
        // Truncated: a clear error, not a panic.
        let bytes = std::fs::read(&path).unwrap();
        write_atomically(&path, |o| o.write_all(&bytes[..bytes.len() - 3])).unwrap();
        let e = Database::load(&path, 0xabc).expect_err("truncated");
        assert!(
            e.to_string().contains("shorter than its header says"),
            "{e}"
        );
        write_atomically(&path, |o| o.write_all(b"hello\n")).unwrap();
        let e = Database::load(&path, 0xabc).expect_err("not ours");
        assert!(
            e.to_string().contains("not a cumulus volume database"),
            "{e}"
        );
    }

    #[test]
    fn the_fingerprint_follows_the_settings_the_volumes_depend_on() {
        let scene = Scene::default();
        let cfg = EndlessConfig::default();
        let a = fingerprint(&scene, &cfg);
        let mut other = scene.clone();
        other.render.sun_elevation_deg += 10.0;
        assert_eq!(
            fingerprint(&other, &cfg),
            a,
            "the sun is not in the volumes"
        );
        other.physics.seed += 1;
        assert_ne!(fingerprint(&other, &cfg), a);
        let more = EndlessConfig {
            volumes: cfg.volumes + 1,
            ..cfg.clone()
        };
        assert_ne!(fingerprint(&scene, &more), a);
    }
}
