//! Reading back the OpenVDB files [`super::write_vdb`] writes: float
//! grids of OpenVDB's standard 5-4-3 tree, uncompressed or zipped
//! (`COMPRESS_ZIP`, no active-mask compression), with no active
//! tiles (what [`super::vdb_bytes`] makes). Anything else is refused with
//! the reason, not guessed at: this is the writer's check, not a general
//! VDB reader (OpenVDB's own library is, and `tests/exports.rs` reads the
//! files with it too).

use std::path::{Path, PathBuf};

use super::{FILE_VERSION, FILE_VERSION_MIN, GRID_TYPE, LEAF_LOG2, LOWER_TOTAL, MAGIC};
use crate::report::volume_export::VolumeError;

/// A grid read from a `.vdb` file.
#[derive(Debug, Clone, PartialEq)]
pub struct VdbGrid {
    pub name: String,
    /// The grid's `class` metadata ("fog volume"), if any.
    pub class: Option<String>,
    /// World position of index `(0, 0, 0)`, and the world size of one
    /// index step along each axis.
    pub translation: [f64; 3],
    pub scale: [f64; 3],
    /// The background value of inactive voxels.
    pub background: f32,
    /// Every active voxel: its index and value, in the file's order.
    pub voxels: Vec<([i32; 3], f32)>,
}

/// Reads `path` and a cursor over it; errors name the file.
struct Reader<'a> {
    path: &'a Path,
    bytes: Vec<u8>,
    at: usize,
    /// The grid's values are zip-framed ([`super::COMPRESS_ZIP`]).
    zip: bool,
}

impl Reader<'_> {
    fn bad(&self, reason: impl Into<String>) -> VolumeError {
        VolumeError::Vdb {
            path: PathBuf::from(self.path),
            reason: reason.into(),
        }
    }
    fn take(&mut self, n: usize) -> Result<&[u8], VolumeError> {
        if self.bytes.len() - self.at < n {
            return Err(self.bad(format!(
                "ends at byte {} inside a field of {n} bytes at byte {}",
                self.bytes.len(),
                self.at
            )));
        }
        self.at += n;
        Ok(&self.bytes[self.at - n..self.at])
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], VolumeError> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, VolumeError> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, VolumeError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn i32(&mut self) -> Result<i32, VolumeError> {
        Ok(i32::from_le_bytes(self.array()?))
    }
    fn i64(&mut self) -> Result<i64, VolumeError> {
        Ok(i64::from_le_bytes(self.array()?))
    }
    fn f32(&mut self) -> Result<f32, VolumeError> {
        Ok(f32::from_le_bytes(self.array()?))
    }
    fn vec3d(&mut self) -> Result<[f64; 3], VolumeError> {
        let mut v = [0.0; 3];
        for x in &mut v {
            *x = f64::from_le_bytes(self.array()?);
        }
        Ok(v)
    }
    fn string(&mut self) -> Result<String, VolumeError> {
        let n = self.u32()? as usize;
        let at = self.at;
        let s = self.take(n)?.to_vec();
        String::from_utf8(s).map_err(|_| self.bad(format!("the string at byte {at} is not UTF-8")))
    }
    fn seek(&mut self, pos: i64) -> Result<(), VolumeError> {
        if pos < 0 || pos as usize > self.bytes.len() {
            return Err(self.bad(format!("an offset {pos} outside the file")));
        }
        self.at = pos as usize;
        Ok(())
    }
    /// A mask of `bits` bits.
    fn mask(&mut self, bits: usize) -> Result<Vec<u64>, VolumeError> {
        (0..bits / 64)
            .map(|_| Ok(u64::from_le_bytes(self.array()?)))
            .collect()
    }
    /// A node's `count` values: the metadata byte must say all of them
    /// follow (no active-mask compression); raw, or zip-framed.
    fn values(&mut self, count: usize) -> Result<Vec<f32>, VolumeError> {
        let meta = self.u8()?;
        if meta != super::ALL_VALUES {
            return Err(self.bad(format!(
                "node metadata {meta} at byte {}, expected {} (all values)",
                self.at - 1,
                super::ALL_VALUES
            )));
        }
        if !self.zip {
            return (0..count).map(|_| self.f32()).collect();
        }
        let bytes = 4 * count;
        let at = self.at;
        let n = self.i64()?;
        let raw = if n <= 0 {
            if n.unsigned_abs() != bytes as u64 {
                return Err(self.bad(format!(
                    "a raw chunk of {} bytes at byte {at}, expected {bytes}",
                    n.unsigned_abs()
                )));
            }
            self.take(bytes)?.to_vec()
        } else {
            let len = usize::try_from(n).unwrap_or(usize::MAX);
            let stream = self.take(len)?;
            // At most one byte past the expected size, so a damaged
            // stream cannot inflate without bound.
            let mut out = Vec::with_capacity(bytes);
            let read = std::io::Read::read_to_end(
                &mut std::io::Read::take(flate2::read::ZlibDecoder::new(stream), bytes as u64 + 1),
                &mut out,
            );
            match read {
                Ok(_) if out.len() == bytes => out,
                Ok(_) => {
                    return Err(self.bad(format!(
                        "the zip chunk at byte {at} holds {} bytes, expected {bytes}",
                        out.len()
                    )));
                }
                Err(e) => {
                    return Err(self.bad(format!("the zip chunk at byte {at} is damaged: {e}")));
                }
            }
        };
        Ok(raw
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    }
    /// A metadata map: the string entries by name (others skipped).
    fn meta(&mut self) -> Result<Vec<(String, String)>, VolumeError> {
        let count = self.u32()?;
        let mut strings = Vec::new();
        for _ in 0..count {
            let name = self.string()?;
            let kind = self.string()?;
            if kind == "string" {
                strings.push((name, self.string()?));
            } else {
                let n = self.u32()? as usize;
                self.take(n)?;
            }
        }
        Ok(strings)
    }
}

/// The set bits of `mask`, in order.
fn ones(mask: &[u64]) -> Vec<usize> {
    (0..mask.len() * 64)
        .filter(|&n| mask[n / 64] >> (n % 64) & 1 == 1)
        .collect()
}

/// The origin of child `n` of a node at `origin` with `1 << log2`
/// children a side, each `1 << child_log2` voxels.
fn child_origin(origin: [i32; 3], n: usize, log2: u32, child_log2: u32) -> [i32; 3] {
    let side = (1 << log2) - 1;
    let at = [n >> (2 * log2), n >> log2, n].map(|v| ((v & side) as i32) << child_log2);
    [origin[0] + at[0], origin[1] + at[1], origin[2] + at[2]]
}

/// Reads the first grid of type [`GRID_TYPE`] in the `.vdb` file `path`.
pub fn read_vdb(path: &Path) -> Result<VdbGrid, VolumeError> {
    let bytes = std::fs::read(path).map_err(|source| VolumeError::Io {
        path: path.to_owned(),
        source,
    })?;
    let mut r = Reader {
        path,
        bytes,
        at: 0,
        zip: false,
    };
    if r.i64()? != MAGIC {
        return Err(r.bad("no OpenVDB magic number at its start"));
    }
    let version = r.u32()?;
    if !(FILE_VERSION_MIN..=FILE_VERSION).contains(&version) {
        return Err(r.bad(format!(
            "file format {version}, expected {FILE_VERSION_MIN} to {FILE_VERSION}"
        )));
    }
    r.take(8)?; // the library's version
    if r.u8()? != 1 {
        return Err(r.bad("no grid offsets (a stream, not a file)"));
    }
    r.take(36)?; // the UUID
    r.meta()?;
    let grids = r.i32()?;
    // Each descriptor takes at least 40 bytes: a count beyond what the
    // rest of the file holds is not one.
    if grids < 0 || grids as usize > (r.bytes.len() - r.at) / 40 {
        return Err(r.bad(format!("{grids} grids in {} bytes", r.bytes.len())));
    }
    for _ in 0..grids {
        let name = r.string()?;
        let kind = r.string()?;
        r.string()?; // the instance parent
        let (grid_pos, block_pos, end_pos) = (r.i64()?, r.i64()?, r.i64()?);
        if !(r.at as i64 <= grid_pos && grid_pos <= block_pos && block_pos <= end_pos) {
            return Err(r.bad(format!(
                "grid {name}'s offsets {grid_pos}, {block_pos}, {end_pos} are not in order after byte {}",
                r.at
            )));
        }
        if kind != GRID_TYPE {
            r.seek(end_pos)?;
            continue;
        }
        r.seek(grid_pos)?;
        let compression = r.u32()?;
        if compression != 0 && compression != super::COMPRESS_ZIP {
            return Err(r.bad(format!(
                "grid {name} is compressed (flags {compression}); only uncompressed and \
                 zip-compressed grids are read"
            )));
        }
        r.zip = compression == super::COMPRESS_ZIP;
        let class = r
            .meta()?
            .into_iter()
            .find(|(k, _)| k == "class")
            .map(|(_, v)| v);
        let map = r.string()?;
        if map != "ScaleTranslateMap" && map != "UniformScaleTranslateMap" {
            return Err(r.bad(format!(
                "grid {name}'s transform is a {map}, expected a ScaleTranslateMap"
            )));
        }
        let translation = r.vec3d()?;
        let scale = r.vec3d()?;
        r.take(4 * 24)?; // the map's derived vectors
        if r.u32()? != 1 {
            return Err(r.bad(format!("grid {name} has more than one buffer")));
        }
        let background = r.f32()?;
        let (tiles, children) = (r.u32()?, r.u32()?);
        if tiles != 0 {
            return Err(r.bad(format!(
                "grid {name}'s root has {tiles} tiles, expected none"
            )));
        }
        let mut leaves = Vec::new();
        for _ in 0..children {
            let origin = [r.i32()?, r.i32()?, r.i32()?];
            // An upper node's origin is a multiple of its span, so its
            // children's and voxels' indices cannot overflow.
            if origin
                .iter()
                .any(|v| v & ((1 << super::UPPER_TOTAL) - 1) != 0)
            {
                return Err(r.bad(format!("grid {name} has a node at {origin:?}")));
            }
            let lowers = ones(&r.mask(1 << 15)?);
            if !ones(&r.mask(1 << 15)?).is_empty() {
                return Err(r.bad(format!("grid {name} has active tiles")));
            }
            r.values(1 << 15)?;
            for n in lowers {
                let lower = child_origin(origin, n, 5, LOWER_TOTAL);
                let leaf_ids = ones(&r.mask(1 << 12)?);
                if !ones(&r.mask(1 << 12)?).is_empty() {
                    return Err(r.bad(format!("grid {name} has active tiles")));
                }
                r.values(1 << 12)?;
                for m in leaf_ids {
                    leaves.push(child_origin(lower, m, 4, LEAF_LOG2));
                    r.mask(1 << 9)?;
                }
            }
        }
        if r.at as i64 != block_pos {
            return Err(r.bad(format!(
                "grid {name}'s topology ends at byte {}, its data starts at {block_pos}",
                r.at
            )));
        }
        let mut voxels = Vec::new();
        for origin in leaves {
            let active = ones(&r.mask(1 << 9)?);
            let values = r.values(1 << 9)?;
            for n in active {
                voxels.push((child_origin(origin, n, LEAF_LOG2, 0), values[n]));
            }
        }
        if r.at as i64 != end_pos {
            return Err(r.bad(format!(
                "grid {name}'s data ends at byte {}, its descriptor says {end_pos}",
                r.at
            )));
        }
        return Ok(VdbGrid {
            name,
            class,
            translation,
            scale,
            background,
            voxels,
        });
    }
    Err(r.bad(format!("no {GRID_TYPE} grid among its {grids}")))
}
