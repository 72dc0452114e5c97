//! OpenVDB files (`.vdb`) of the exported density, for Blender, Houdini
//! and anything else built on OpenVDB: one float grid, `density`, of
//! class "fog volume", in the layout OpenVDB 10 writes (file format 224)
//! with zip compression, read back by OpenVDB's own library
//! (`tests/exports.rs`, through its Python binding) and by [`read_vdb`].
//!
//! No Rust crate writes VDB (`vdb-rs` only reads it), so the layout is
//! written here by hand, after OpenVDB's `io/Archive.cc`,
//! `tree/RootNode.h`, `tree/InternalNode.h`, `tree/LeafNode.h` and
//! `io/Compression.h`:
//! - the header: the magic number, the file version, the library's
//!   version, a flag for the grids' offsets, a 36-character UUID, the
//!   file's metadata and the number of grids;
//! - per grid, its descriptor (name, type `Tree_float_5_4_3`, no instance
//!   parent, and the byte offsets of the grid, its data and its end), the
//!   compression flags (`COMPRESS_ZIP`), the grid's metadata, its transform
//!   (`ScaleTranslateMap`: index to world), the tree's topology (the
//!   root's background and children; each internal node's child and
//!   value masks and its tile values, depth first; each leaf's value
//!   mask), then the leaves' values in the same order. Each node's
//!   values (an internal node's tiles, a leaf's voxels) follow a
//!   metadata byte as one zlib stream behind its length (an `i64`), or,
//!   where zlib does not make them smaller, raw behind their negated
//!   length (`io/Compression.cc`'s framing). A cloud's leaves keep about
//!   half their bytes, the internal nodes' empty tiles almost none.
//!
//! The tree is OpenVDB's standard one: a root over internal nodes of
//! 32³ children (4096 voxels a side), each over internal nodes of 16³
//! leaves (128 voxels), each leaf 8³ voxels, z varying fastest within a
//! node. Voxel `(i, j, k)` of the index space is cell `(i, j, k)` of the
//! [`Grid`], its centre at index `(i, j, k)` exactly, so the transform
//! takes index `(i, j, k)` to the cell's centre: scale the cell's size,
//! translation the first cell's centre. Cells of σ_t > 0 are active, the
//! rest inactive at the background 0; leaves with no active cell are not
//! written.

use std::collections::BTreeMap;
use std::path::Path;

use super::volume_export::VolumeError;
use crate::io::write_atomically;
use crate::render::cpu::density_grid::Grid;

/// OpenVDB's magic number, "` BDV`" (written as a little-endian `i64`).
pub const MAGIC: i64 = 0x5644_4220;
/// The file format written: OpenVDB 10's (multi-pass I/O, per-grid
/// compression flags, node metadata bytes).
pub const FILE_VERSION: u32 = 224;
/// The oldest file format [`read_vdb`] reads: the first with a metadata
/// byte before each node's values.
pub const FILE_VERSION_MIN: u32 = 222;
/// The OpenVDB library version the layout is that of.
pub const LIBRARY_VERSION: [u32; 2] = [10, 0];
/// The grid's type name: a float tree of 5, 4, 3 (log2 of the children
/// per axis of each level).
pub const GRID_TYPE: &str = "Tree_float_5_4_3";
/// The grid's name, as Blender's and Houdini's volume shaders expect it.
pub const GRID_NAME: &str = "density";

/// Log2 of the voxels along a leaf's side (8).
const LEAF_LOG2: u32 = 3;
/// Log2 of the voxels along a lower internal node's side (128).
const LOWER_TOTAL: u32 = LEAF_LOG2 + 4;
/// Log2 of the voxels along an upper internal node's side (4096).
const UPPER_TOTAL: u32 = LOWER_TOTAL + 5;
/// A leaf's voxels.
const LEAF_SIZE: usize = 1 << (3 * LEAF_LOG2);
/// The metadata byte before a node's values: no mask, all values follow
/// (`NO_MASK_AND_ALL_VALS`).
const ALL_VALUES: u8 = 6;
/// The grid's compression flags: OpenVDB's `COMPRESS_ZIP` (no active
/// mask compression, so every node's values are all written).
pub const COMPRESS_ZIP: u32 = 1;

/// The offset of `(x, y, z)` within a node whose children span
/// `1 << child_log2` voxels and which has `1 << log2` of them a side: x
/// slowest, z fastest, as OpenVDB numbers them.
fn child_offset(x: i32, y: i32, z: i32, log2: u32, child_log2: u32) -> usize {
    let mask = (1_i32 << (log2 + child_log2)) - 1;
    let at = |v: i32| ((v & mask) >> child_log2) as usize;
    (at(x) << (2 * log2)) | (at(y) << log2) | at(z)
}

/// The bit mask of `bits` bits as OpenVDB saves it: little-endian 64-bit
/// words, bit `n` in word `n / 64`.
#[derive(Clone)]
struct Mask(Vec<u64>);

impl Mask {
    fn new(bits: usize) -> Self {
        Self(vec![0; bits / 64])
    }
    fn set(&mut self, n: usize) {
        self.0[n / 64] |= 1 << (n % 64);
    }
}

/// A leaf: its origin, active voxels and values (z fastest).
struct Leaf {
    origin: [i32; 3],
    mask: Mask,
    values: Vec<f32>,
}

/// The tree: upper nodes by origin (the root's order: x, then y, then
/// z), each holding its lower nodes by offset, each its leaves by offset.
type Tree = BTreeMap<[i32; 3], BTreeMap<usize, BTreeMap<usize, Leaf>>>;

/// The leaves of `values` on `grid` (σ_t > 0 active, +∞ included; NaN
/// and the rest inactive at 0), gathered into the tree.
fn build_tree(grid: &Grid, values: &[f32]) -> Tree {
    let [nx, ny, nz] = grid.resolution.map(|n| n as i32);
    let side = 1 << LEAF_LOG2;
    let mut tree = Tree::new();
    for lx in (0..nx).step_by(side) {
        for ly in (0..ny).step_by(side) {
            for lz in (0..nz).step_by(side) {
                let mut leaf = Leaf {
                    origin: [lx, ly, lz],
                    mask: Mask::new(LEAF_SIZE),
                    values: vec![0.0; LEAF_SIZE],
                };
                // x innermost: the grid's own order.
                for z in lz..(lz + side as i32).min(nz) {
                    for y in ly..(ly + side as i32).min(ny) {
                        for x in lx..(lx + side as i32).min(nx) {
                            let v = values[grid.index(x as u32, y as u32, z as u32)];
                            if v > 0.0 {
                                let n = child_offset(x, y, z, LEAF_LOG2, 0);
                                leaf.mask.set(n);
                                leaf.values[n] = v;
                            }
                        }
                    }
                }
                if leaf.mask.0.iter().all(|&w| w == 0) {
                    continue;
                }
                let upper = [lx, ly, lz].map(|v| v >> UPPER_TOTAL << UPPER_TOTAL);
                tree.entry(upper)
                    .or_default()
                    .entry(child_offset(lx, ly, lz, 5, LOWER_TOTAL))
                    .or_default()
                    .insert(child_offset(lx, ly, lz, 4, LEAF_LOG2), leaf);
            }
        }
    }
    tree
}

/// Little-endian bytes, with OpenVDB's strings (a `u32` length, then
/// the bytes) and metadata entries.
#[derive(Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn i64(&mut self, v: i64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32s(&mut self, v: &[f32]) {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
    }
    fn f64s(&mut self, v: [f64; 3]) {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
    }
    fn mask(&mut self, m: &Mask) {
        for w in &m.0 {
            self.0.extend_from_slice(&w.to_le_bytes());
        }
    }
    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.0.extend_from_slice(s.as_bytes());
    }
    /// A node's values: the metadata byte, then all of them, zipped
    /// ([`Self::zipped`]).
    fn values(&mut self, v: &[f32]) {
        self.u8(ALL_VALUES);
        let raw: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        self.zipped(&raw);
    }
    /// `raw` as OpenVDB's `zipToStream` frames it: the zlib stream's
    /// length and the stream, or, where that is no smaller, minus the
    /// raw length and the raw bytes.
    fn zipped(&mut self, raw: &[u8]) {
        use std::io::Write;
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        let stream = z.write_all(raw).and_then(|()| z.finish());
        match stream {
            Ok(stream) if stream.len() < raw.len() => {
                self.i64(stream.len() as i64);
                self.0.extend_from_slice(&stream);
            }
            _ => {
                self.i64(-(raw.len() as i64));
                self.0.extend_from_slice(raw);
            }
        }
    }
    /// An internal node's topology, `1 << (3 log2)` places: its child
    /// mask (the places in `children`), no active tiles, and its tile
    /// values, all the background 0.
    fn internal_node(&mut self, children: impl Iterator<Item = usize>, log2: u32) {
        let places = 1 << (3 * log2);
        let mut mask = Mask::new(places);
        children.for_each(|n| mask.set(n));
        self.mask(&mask);
        self.mask(&Mask::new(places));
        self.values(&vec![0.0; places]);
    }
}

/// The tree's leaves, in the file's order (the topology's and the
/// buffers').
fn leaves(tree: &Tree) -> impl Iterator<Item = &Leaf> {
    tree.values()
        .flat_map(|lowers| lowers.values())
        .flat_map(|leaves| leaves.values())
}

/// The active voxels' count and index bounds (inclusive), from the
/// leaves; with none, the empty box OpenVDB writes (min `i32::MAX`, max
/// `i32::MIN`).
fn active_stats(tree: &Tree) -> (i64, [i32; 3], [i32; 3]) {
    let (mut count, mut lo, mut hi) = (0, [i32::MAX; 3], [i32::MIN; 3]);
    for leaf in leaves(tree) {
        for n in (0..LEAF_SIZE).filter(|&n| leaf.mask.0[n / 64] >> (n % 64) & 1 == 1) {
            count += 1;
            let at = [n >> 6, (n >> 3) & 7, n & 7];
            for a in 0..3 {
                let v = leaf.origin[a] + at[a] as i32;
                lo[a] = lo[a].min(v);
                hi[a] = hi[a].max(v);
            }
        }
    }
    (count, lo, hi)
}

/// One metadata entry's value.
enum Meta {
    Str(String),
    Vec3i([i32; 3]),
    Int64(i64),
    Bool(bool),
}

/// A metadata map: the count, then each entry's name, type name, size in
/// bytes and value.
fn write_meta(b: &mut Bytes, entries: &[(&str, Meta)]) {
    b.u32(entries.len() as u32);
    for (name, value) in entries {
        b.string(name);
        match value {
            Meta::Str(s) => {
                b.string("string");
                b.string(s);
            }
            Meta::Vec3i(v) => {
                b.string("vec3i");
                b.u32(12);
                v.iter().for_each(|&x| b.i32(x));
            }
            Meta::Int64(v) => {
                b.string("int64");
                b.u32(8);
                b.i64(*v);
            }
            Meta::Bool(v) => {
                b.string("bool");
                b.u32(1);
                b.u8(*v as u8);
            }
        }
    }
}

/// A UUID (version 4's layout) made from the grid's placement, what its
/// values are and the values themselves: the same export gives the same
/// bytes, and two different ones (an empty grid over another box
/// included) different UUIDs.
fn uuid(grid: &Grid, quantity: &str, values: &[f32]) -> String {
    let mut h = [0xcbf2_9ce4_8422_2325_u64, 0x6c62_272e_07bb_0142];
    let placement = grid.resolution.iter().map(|&n| n as u64);
    let corners = grid
        .min_m
        .to_array()
        .into_iter()
        .chain(grid.max_m.to_array());
    let words = placement
        .chain(corners.map(|c| c.to_bits() as u64))
        .chain(quantity.bytes().map(u64::from))
        .chain(
            values
                .iter()
                .enumerate()
                .map(|(n, v)| v.to_bits() as u64 ^ (n as u64) << 32),
        );
    for word in words {
        h[0] = (h[0] ^ word).wrapping_mul(0x0000_0100_0000_01b3);
        h[1] = (h[1] ^ word.rotate_left(17)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    let hex = format!("{:016x}{:016x}", h[0], h[1]);
    let mut s: Vec<char> = hex.chars().collect();
    s[12] = '4';
    s[16] = ['8', '9', 'a', 'b'][(h[1] >> 60) as usize & 3];
    let s: String = s.into_iter().collect();
    format!(
        "{}-{}-{}-{}-{}",
        &s[0..8],
        &s[8..12],
        &s[12..16],
        &s[16..20],
        &s[20..32]
    )
}

/// The `.vdb` bytes of `values` on `grid` (one per cell, in the grid's
/// order): a fog volume named [`GRID_NAME`] whose transform takes index
/// `(i, j, k)` to the centre of cell `(i, j, k)` in metres, with
/// `quantity` (what the values are) in its metadata.
pub fn vdb_bytes(grid: &Grid, values: &[f32], quantity: &str) -> Result<Vec<u8>, VolumeError> {
    if values.len() != grid.len() {
        return Err(VolumeError::Bad {
            what: "values",
            value: values.len().to_string(),
            expected: "one per grid cell",
        });
    }
    // The transform in f64 from the box itself (not the f32 cell size).
    let (min, max) = (grid.min_m.as_dvec3(), grid.max_m.as_dvec3());
    let cell = (max - min) / glam::UVec3::from_array(grid.resolution).as_dvec3();
    if !cell.is_finite() || cell.min_element() <= 0.0 {
        return Err(VolumeError::Bad {
            what: "grid",
            value: format!(
                "{:?} cells over {} to {}",
                grid.resolution, grid.min_m, grid.max_m
            ),
            expected: "cells of finite, positive size (Grid::new checks this)",
        });
    }
    let tree = build_tree(grid, values);
    let (active, lo, hi) = active_stats(&tree);
    let mut b = Bytes::default();
    // The header.
    b.i64(MAGIC);
    b.u32(FILE_VERSION);
    b.u32(LIBRARY_VERSION[0]);
    b.u32(LIBRARY_VERSION[1]);
    b.u8(1); // the grids' offsets follow their descriptors
    b.0.extend_from_slice(uuid(grid, quantity, values).as_bytes());
    let creator = format!("cumulus {}", env!("CARGO_PKG_VERSION"));
    write_meta(&mut b, &[("creator", Meta::Str(creator))]);
    b.i32(1); // one grid
    // The grid's descriptor; its three offsets are filled in below.
    b.string(GRID_NAME);
    b.string(GRID_TYPE);
    b.string(""); // no instance parent
    let offsets_at = b.0.len();
    b.0.extend_from_slice(&[0; 24]);
    let grid_pos = b.0.len();
    b.u32(COMPRESS_ZIP);
    write_meta(
        &mut b,
        &[
            ("class", Meta::Str("fog volume".into())),
            ("cumulus_quantity", Meta::Str(quantity.into())),
            ("file_bbox_max", Meta::Vec3i(hi)),
            ("file_bbox_min", Meta::Vec3i(lo)),
            ("file_compression", Meta::Str("zip".into())),
            ("file_voxel_count", Meta::Int64(active)),
            ("is_saved_as_half_float", Meta::Bool(false)),
            ("name", Meta::Str(GRID_NAME.into())),
        ],
    );
    // The transform: index (i, j, k) to cell (i, j, k)'s centre.
    let first = min + 0.5 * cell;
    b.string("ScaleTranslateMap");
    b.f64s(first.to_array());
    b.f64s(cell.to_array());
    b.f64s(cell.abs().to_array());
    b.f64s(cell.recip().to_array());
    b.f64s((cell * cell).recip().to_array());
    b.f64s((2.0 * cell).recip().to_array());
    // The topology: one buffer, the root's background, no tiles.
    b.u32(1);
    b.f32s(&[0.0]);
    b.u32(0);
    b.u32(tree.len() as u32);
    for (origin, lowers) in &tree {
        origin.iter().for_each(|&v| b.i32(v));
        b.internal_node(lowers.keys().copied(), 5);
        for leaves in lowers.values() {
            b.internal_node(leaves.keys().copied(), 4);
            for leaf in leaves.values() {
                b.mask(&leaf.mask);
            }
        }
    }
    // The leaves' values, in the topology's order.
    let block_pos = b.0.len();
    for leaf in leaves(&tree) {
        b.mask(&leaf.mask);
        b.values(&leaf.values);
    }
    let end_pos = b.0.len();
    for (n, pos) in [grid_pos, block_pos, end_pos].into_iter().enumerate() {
        let at = offsets_at + 8 * n;
        b.0[at..at + 8].copy_from_slice(&(pos as i64).to_le_bytes());
    }
    Ok(b.0)
}

/// Writes `values` on `grid` to `path` as an OpenVDB file
/// ([`vdb_bytes`]), atomically.
pub fn write_vdb(
    path: &Path,
    grid: &Grid,
    values: &[f32],
    quantity: &str,
) -> Result<(), VolumeError> {
    let bytes = vdb_bytes(grid, values, quantity)?;
    write_atomically(path, |out| out.write_all(&bytes)).map_err(|source| VolumeError::Io {
        path: path.to_owned(),
        source,
    })
}

#[path = "vdb_read.rs"]
mod read;
pub use read::{VdbGrid, read_vdb};

#[cfg(test)]
#[path = "vdb_tests.rs"]
mod tests;
