use glam::Vec3;

use super::*;

/// A grid over two lower nodes along x (130 cells > 128) and several
/// leaves along y and z, cloudy in a few scattered cells.
fn cloudy_grid() -> (Grid, Vec<f32>) {
    let g = Grid::new(
        [130, 11, 17],
        Vec3::new(-100.0, 500.0, 20.0),
        Vec3::new(1200.0, 610.0, 190.0),
    )
    .expect("grid");
    let mut values = vec![0.0; g.len()];
    for (n, [i, j, k]) in [[0, 0, 0], [7, 8, 16], [8, 3, 9], [129, 10, 16], [64, 5, 2]]
        .into_iter()
        .enumerate()
    {
        values[g.index(i, j, k)] = 0.01 * (n + 1) as f32;
    }
    (g, values)
}

/// What was written is read back: every cloudy cell at its index with
/// its value, nothing else active, and the transform taking index
/// `(i, j, k)` to the cell's centre.
#[test]
fn vdb_files_round_trip() {
    let (g, values) = cloudy_grid();
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("v.vdb");
    write_vdb(&path, &g, &values, "sigma_t").expect("write");
    let back = read_vdb(&path).expect("read");
    assert_eq!(back.name, GRID_NAME);
    assert_eq!(back.class.as_deref(), Some("fog volume"));
    assert_eq!(back.background, 0.0);
    let mut expected: Vec<([i32; 3], f32)> = Vec::new();
    for k in 0..17 {
        for j in 0..11 {
            for i in 0..130 {
                let v = values[g.index(i, j, k)];
                if v > 0.0 {
                    expected.push(([i as i32, j as i32, k as i32], v));
                }
            }
        }
    }
    let mut got = back.voxels.clone();
    got.sort_by_key(|(ijk, _)| [ijk[2], ijk[1], ijk[0]]);
    assert_eq!(got, expected);
    for ijk in [[0, 0, 0], [129, 10, 16], [64, 5, 2]] {
        let world: [f64; 3] =
            std::array::from_fn(|a| back.translation[a] + back.scale[a] * ijk[a] as f64);
        let centre = g.centre(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
        for a in 0..3 {
            assert!(
                (world[a] - centre[a] as f64).abs() < 1e-3,
                "{world:?} {centre}"
            );
        }
    }
}

/// The bytes start as OpenVDB's do, are the same for the same grid, and
/// leave out the empty leaves: an empty grid is the header, the
/// descriptor and a root with no children.
#[test]
fn vdb_bytes_follow_openvdbs_header() {
    let (g, values) = cloudy_grid();
    let b = vdb_bytes(&g, &values, "sigma_t").expect("bytes");
    assert_eq!(&b[..8], b" BDV\0\0\0\0");
    assert_eq!(u32::from_le_bytes(b[8..12].try_into().expect("4")), 224);
    assert_eq!(b[20], 1);
    let uuid = std::str::from_utf8(&b[21..57]).expect("uuid");
    assert_eq!(uuid.len(), 36);
    assert_eq!(uuid.matches('-').count(), 4);
    assert_eq!(b, vdb_bytes(&g, &values, "sigma_t").expect("again"));
    // Five cloudy cells in five leaves: each leaf costs its topology
    // mask (64 bytes) and its data (64 + 1 + 2048 bytes).
    let empty = vdb_bytes(&g, &vec![0.0; g.len()], "sigma_t").expect("empty");
    assert!(b.len() > empty.len() + 5 * (64 + 64 + 1 + 2048));
    assert!(empty.len() < 1000, "{}", empty.len());
    assert!(vdb_bytes(&g, &[1.0], "sigma_t").is_err());
    // Another box or quantity, another UUID; the same export, the same.
    let other = Grid::new(g.resolution, g.min_m, g.max_m + Vec3::X).expect("grid");
    let uuid_of = |b: &[u8]| b[21..57].to_vec();
    let empty_other = vdb_bytes(&other, &vec![0.0; g.len()], "sigma_t").expect("empty");
    assert_ne!(uuid_of(&empty), uuid_of(&empty_other));
    let relabelled = vdb_bytes(&g, &values, "density").expect("bytes");
    assert_ne!(uuid_of(&b), uuid_of(&relabelled));
}

/// A grid with no cloud is a root with no children, read back empty.
#[test]
fn an_empty_grid_reads_back_empty() {
    let (g, _) = cloudy_grid();
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("empty.vdb");
    write_vdb(&path, &g, &vec![0.0; g.len()], "sigma_t").expect("write");
    let back = read_vdb(&path).expect("read");
    assert!(back.voxels.is_empty());
    assert_eq!(back.class.as_deref(), Some("fog volume"));
}

/// No file makes the reader panic: every cut of a good file, and every
/// byte of it flipped, is read or refused, never a crash.
#[test]
fn damaged_vdb_files_never_panic_the_reader() {
    let (g, values) = cloudy_grid();
    let good = vdb_bytes(&g, &values, "sigma_t").expect("bytes");
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("d.vdb");
    let mut refused = 0;
    let mut tried = 0;
    let mut check = |bytes: &[u8]| {
        write_atomically(&path, |out| out.write_all(bytes)).expect("write");
        tried += 1;
        refused += read_vdb(&path).is_err() as u32;
    };
    for cut in (0..good.len()).step_by(97) {
        check(&good[..cut]);
    }
    // Flips in the header, the descriptor, the metadata, the transform
    // and the topology (the values themselves read as other values).
    for at in (0..good.len().min(700)).chain((700..good.len()).step_by(211)) {
        for flip in [0x01_u8, 0x80, 0xff] {
            let mut bad = good.clone();
            bad[at] ^= flip;
            check(&bad);
        }
    }
    assert!(tried > 2000 && refused > tried / 3, "{refused} of {tried}");
}

#[test]
fn broken_vdb_files_are_refused_with_the_reason() {
    let dir = tempfile::tempdir().expect("dir");
    let (g, values) = cloudy_grid();
    let good = vdb_bytes(&g, &values, "sigma_t").expect("bytes");
    let grid_pos = {
        // The compression flags follow the descriptor's three offsets.
        let at = good
            .windows(GRID_TYPE.len())
            .position(|w| w == GRID_TYPE.as_bytes());
        let at = at.expect("type") + GRID_TYPE.len() + 4;
        i64::from_le_bytes(good[at..at + 8].try_into().expect("8")) as usize
    };
    let mut compressed = good.clone();
    compressed[grid_pos] = 4; // COMPRESS_BLOSC
    let find = |what: &[u8]| {
        good.windows(what.len())
            .position(|w| w == what)
            .expect("found")
    };
    // The upper node's origin, after the transform and the root's
    // buffer count, background, tiles and children: off its 4096 grid,
    // near i32::MAX, where its children's indices would overflow.
    let origin_at = find(b"ScaleTranslateMap") + 17 + 6 * 24 + 16;
    let mut far = good.clone();
    far[origin_at..origin_at + 4].copy_from_slice(&0x7fff_f001_i32.to_le_bytes());
    // Two billion grids in a small file.
    let count_at = find(b"\x07\0\0\0density") - 4;
    let mut many = good.clone();
    many[count_at..count_at + 4].copy_from_slice(&i32::MAX.to_le_bytes());
    // The grid's end before its start.
    let end_at = find(GRID_TYPE.as_bytes()) + GRID_TYPE.len() + 4 + 16;
    let mut backwards = good.clone();
    backwards[end_at..end_at + 8].copy_from_slice(&8_i64.to_le_bytes());
    let cases: [(&str, Vec<u8>, &str); 7] = [
        ("far", far, "a node at [2147479553"),
        ("many", many, "2147483647 grids"),
        ("backwards", backwards, "not in order"),
        ("magic", [b"VDB ".as_slice(), &good[4..]].concat(), "magic"),
        ("cut", good[..good.len() - 10].to_vec(), "ends at byte"),
        (
            "version",
            [&good[..8], &300_u32.to_le_bytes()[..], &good[12..]].concat(),
            "file format 300",
        ),
        ("compressed", compressed, "compressed"),
    ];
    for (name, bytes, says) in cases {
        let p = dir.path().join(format!("{name}.vdb"));
        write_atomically(&p, |out| out.write_all(&bytes)).expect("write");
        let e = read_vdb(&p).expect_err(name).to_string();
        assert!(
            e.contains(says) && e.contains(&format!("{name}.vdb")),
            "{e}"
        );
    }
}

#[test]
fn child_offsets_are_openvdbs() {
    // z fastest, x slowest, within each level.
    assert_eq!(child_offset(0, 0, 1, LEAF_LOG2, 0), 1);
    assert_eq!(child_offset(0, 1, 0, LEAF_LOG2, 0), 8);
    assert_eq!(child_offset(1, 0, 0, LEAF_LOG2, 0), 64);
    assert_eq!(child_offset(9, 0, 0, LEAF_LOG2, 0), 64);
    assert_eq!(child_offset(8, 0, 0, 4, LEAF_LOG2), 256);
    assert_eq!(child_offset(0, 0, 8, 4, LEAF_LOG2), 1);
    assert_eq!(child_offset(128, 0, 0, 5, LOWER_TOTAL), 1024);
    assert_eq!(child_offset(4096 + 128, 0, 0, 5, LOWER_TOTAL), 1024);
}

/// Node values are zip-framed as OpenVDB's `zipToStream` frames them:
/// a zlib stream behind its length where that is smaller (empty tiles,
/// smooth clouds), raw behind the negated length where it is not
/// (noise); both read back bit for bit, and a cloud's file is well under
/// its uncompressed size.
#[test]
fn node_values_are_zipped_or_kept_raw_and_read_back() {
    use std::io::Read;
    let mut b = Bytes::default();
    b.zipped(&[0u8; 4096]);
    let n = i64::from_le_bytes(b.0[..8].try_into().expect("8 bytes"));
    assert!(n > 0 && (n as usize) < 100, "zeros zip to {n} bytes");
    let mut out = Vec::new();
    flate2::read::ZlibDecoder::new(&b.0[8..])
        .read_to_end(&mut out)
        .expect("a zlib stream");
    assert_eq!(out, vec![0u8; 4096]);
    // Bytes zlib cannot shrink are written raw.
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    let noise: Vec<u8> = (0..4096)
        .map(|_| {
            // xorshift64: bytes with no pattern for zlib to find.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 32) as u8
        })
        .collect();
    let mut b = Bytes::default();
    b.zipped(&noise);
    assert_eq!(
        i64::from_le_bytes(b.0[..8].try_into().expect("8 bytes")),
        -4096
    );
    assert_eq!(&b.0[8..], &noise[..]);

    // A whole grid: a smooth cloud (zipped leaves) beside a leaf of noise
    // (kept raw) round-trips, and the file is a fraction of the raw one.
    let g = Grid::new([64, 16, 64], Vec3::ZERO, Vec3::new(640.0, 160.0, 640.0)).expect("grid");
    let mut values = vec![0.0; g.len()];
    for k in 0..64 {
        for j in 0..16 {
            for i in 0..64 {
                let r2 = ((i as f32 - 32.0).powi(2) + (k as f32 - 32.0).powi(2)) / 400.0;
                values[g.index(i, j, k)] = (0.05 * (1.0 - r2)).max(0.0);
            }
        }
    }
    // The first leaf (8x8x8 cells at the corner, outside the cloud):
    // noise, which zlib cannot shrink.
    for k in 0..8 {
        for j in 0..8 {
            for i in 0..8 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                // Any positive finite float: 31 random bits of 32.
                values[g.index(i, j, k)] = f32::from_bits(((x >> 33) as u32 & 0x7f7f_ffff) | 1);
            }
        }
    }
    let bytes = vdb_bytes(&g, &values, "sigma_t").expect("bytes");
    // The noise leaf is stored raw: its 2048 bytes behind -2048.
    let raw_mark = (-2048_i64).to_le_bytes();
    assert!(bytes.windows(8).any(|w| w == raw_mark), "no raw chunk");
    let leaves = values.chunks(512).count();
    assert!(
        bytes.len() < leaves * 2048 / 2,
        "{} bytes for {leaves} leaves' 2 KiB each",
        bytes.len()
    );
    let dir = tempfile::tempdir().expect("dir");
    let path = dir.path().join("z.vdb");
    write_vdb(&path, &g, &values, "sigma_t").expect("write");
    let back = read_vdb(&path).expect("read");
    let active = values.iter().filter(|v| **v > 0.0).count();
    assert_eq!(back.voxels.len(), active);
    for (ijk, v) in back.voxels {
        let [i, j, k] = ijk.map(|x| x as u32);
        assert_eq!(v, values[g.index(i, j, k)], "{ijk:?}");
    }
}
