//! `cumulus export`: the density field the renderer marches, sampled on a
//! regular grid, for offline renderers (Mitsuba, Blender, Houdini).
//!
//! The grid is written as an OpenVDB file ([`super::vdb`]) or as a
//! Mitsuba 3 grid volume (`.vol`, the format its
//! `gridvolume` texture reads): the bytes `VOL`, version 3, encoding 1
//! (32-bit float), the resolution (x, y, z) and one channel as
//! little-endian `i32`, the bounding box (min x, y, z, max x, y, z) as
//! `f32`, then the values with x varying fastest, then y, then z. Each
//! value is the extinction coefficient σ_t in 1/m at a cell's centre,
//! `density_at` with the detail noise ([`crate::render::cpu::density_grid::sample`]), read at the level of detail of a
//! footprint one cell wide. A JSON sidecar ([`Sidecar`]) carries what an
//! offline renderer needs to light and frame the same clouds: the unit
//! cube's placement in the world, the sun, the camera, the phase function
//! and the albedo.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Serialize;

use crate::io::write_atomically;
use crate::render::cpu::density_grid::{Grid, GridError};
use crate::render::cpu::frame::Frame;
use crate::render::cpu::lighting::ALBEDO;
use crate::render::cpu::sky::{SkyLight, sea_radiance, sky_radiance, sun_direction, sun_light_at};
use crate::render::cpu::waves::flat_sea;

/// What the exported values are (the sidecar's `quantity`, and the
/// `.vdb` grid's `cumulus_quantity` metadata).
pub const QUANTITY: &str = "extinction coefficient sigma_t, 1/m, at cell centres";

/// The size of a `.vol` file's header, bytes.
pub const HEADER_BYTES: usize = 48;

/// What went wrong making, writing or reading a volume.
#[derive(Debug, thiserror::Error)]
pub enum VolumeError {
    #[error("{what}: {value}, expected {expected}")]
    Bad {
        what: &'static str,
        value: String,
        expected: &'static str,
    },
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a Mitsuba grid volume: {reason}")]
    Format { path: PathBuf, reason: String },
    #[error("{path}: not an OpenVDB file cumulus reads: {reason}")]
    Vdb { path: PathBuf, reason: String },
    #[error(transparent)]
    Grid(#[from] GridError),
}

/// The `.vol` bytes of `values` on `grid` (header, then the values).
pub fn vol_bytes(grid: &Grid, values: &[f32]) -> Result<Vec<u8>, VolumeError> {
    if values.len() != grid.len() {
        return Err(VolumeError::Bad {
            what: "values",
            value: values.len().to_string(),
            expected: "one per grid cell",
        });
    }
    let mut b = Vec::with_capacity(HEADER_BYTES + 4 * values.len());
    b.extend_from_slice(b"VOL");
    b.push(3);
    b.extend_from_slice(&1_i32.to_le_bytes());
    for n in grid.resolution {
        b.extend_from_slice(&(n as i32).to_le_bytes());
    }
    b.extend_from_slice(&1_i32.to_le_bytes());
    for v in grid
        .min_m
        .to_array()
        .into_iter()
        .chain(grid.max_m.to_array())
    {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
    Ok(b)
}

/// Writes `values` on `grid` to `path` as a `.vol` file, atomically.
pub fn write_vol(path: &Path, grid: &Grid, values: &[f32]) -> Result<(), VolumeError> {
    let bytes = vol_bytes(grid, values)?;
    write_atomically(path, |out| out.write_all(&bytes)).map_err(|source| VolumeError::Io {
        path: path.to_owned(),
        source,
    })
}

/// Reads a one-channel, 32-bit float `.vol` file (as [`write_vol`]
/// writes): its grid and values.
pub fn read_vol(path: &Path) -> Result<(Grid, Vec<f32>), VolumeError> {
    let bytes = std::fs::read(path).map_err(|source| VolumeError::Io {
        path: path.to_owned(),
        source,
    })?;
    let bad = |reason: String| VolumeError::Format {
        path: path.to_owned(),
        reason,
    };
    if bytes.len() < HEADER_BYTES {
        return Err(bad(format!(
            "{} bytes, shorter than the 48-byte header",
            bytes.len()
        )));
    }
    if &bytes[0..3] != b"VOL" || bytes[3] != 3 {
        return Err(bad("the file does not start with VOL and version 3".into()));
    }
    let word = |at: usize| [bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]];
    let int = |at: usize| i32::from_le_bytes(word(at));
    let float = |at: usize| f32::from_le_bytes(word(at));
    if int(4) != 1 {
        return Err(bad(format!(
            "encoding {}, expected 1 (32-bit float)",
            int(4)
        )));
    }
    if int(20) != 1 {
        return Err(bad(format!("{} channels, expected 1", int(20))));
    }
    let res = [int(8), int(12), int(16)];
    if res.iter().any(|&n| n <= 0) {
        return Err(bad(format!("resolution {res:?}")));
    }
    let resolution = res.map(|n| n as u32);
    let min_m = Vec3::new(float(24), float(28), float(32));
    let max_m = Vec3::new(float(36), float(40), float(44));
    let grid = Grid::new(resolution, min_m, max_m).map_err(|e| bad(e.to_string()))?;
    let expected = HEADER_BYTES + 4 * grid.len();
    if bytes.len() != expected {
        return Err(bad(format!(
            "{} bytes, expected {expected} for {resolution:?} cells",
            bytes.len()
        )));
    }
    let values = bytes[HEADER_BYTES..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Ok((grid, values))
}

/// The direction of pixel `(i, j)`'s centre in a `width x height`
/// latitude-longitude map as Mitsuba 3's `envmap` reads it: `u = atan2(x,
/// -z) / 2π`, `v = acos(y) / π` (y up).
pub fn envmap_direction(i: u32, j: u32, width: u32, height: u32) -> Vec3 {
    let phi = (i as f32 + 0.5) / width as f32 * std::f32::consts::TAU;
    let theta = (j as f32 + 0.5) / height as f32 * std::f32::consts::PI;
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// The renderer's sky (`sky_radiance`: the sky above the horizon, the
/// ground seen through haze below it, or the scene's sea,
/// `sea_radiance`; no sun disk, which an offline renderer gets as a
/// directional light) as a `width x height`
/// latitude-longitude map of linear RGB, row-major, laid out for
/// Mitsuba 3's `envmap` ([`envmap_direction`]). The land in it is the
/// clear sky's, without the light the clouds scatter down onto it
/// (`ground_cloud_light`): an offline renderer's clouds and ground plane
/// make that light themselves, and the renderer's own clouds take the
/// clear sky's land as their light from below (`ground_up`).
pub fn sky_envmap(frame: &Frame, width: u32, height: u32) -> Vec<f32> {
    let sun = sun_direction(frame.sun_elevation_deg, frame.sun_azimuth_deg);
    let sky = &SkyLight {
        ground_cloud_light: Vec3::ZERO,
        ..frame.sky_light()
    };
    (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            let d = envmap_direction(i, j, width, height);
            match frame.quality.sea_wind_mps {
                Some(wind) if d.y < 0.0 => {
                    sea_radiance(sky, d, sun, flat_sea(wind), 1.0, (Vec3::ZERO, 1.0))
                }
                _ => sky_radiance(sky, d, sun),
            }
            .to_array()
        })
        .collect()
}

/// One Henyey-Greenstein lobe of the phase function.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Lobe {
    pub weight: f32,
    pub g: f32,
}

/// What an offline renderer needs besides the grid to render the same
/// clouds as ours (written beside the `.vol` or `.vdb` as JSON).
#[derive(Debug, Clone, Serialize)]
pub struct Sidecar {
    /// The volume file's name (`.vol` or `.vdb`).
    pub volume: String,
    pub quantity: &'static str,
    /// World axes and units.
    pub world: &'static str,
    pub resolution: [u32; 3],
    pub box_min_m: [f32; 3],
    pub box_max_m: [f32; 3],
    pub cell_m: [f32; 3],
    /// The volume file's own space, which [`Self::to_world`] places.
    pub volume_space: &'static str,
    /// Row-major 4x4 matrix placing the volume in the world: for a `.vol`
    /// the unit cube `[0, 1]³` (Mitsuba's volume space) onto the box;
    /// for a `.vdb` the identity (its own transform already places its
    /// voxels in metres).
    pub to_world: [[f32; 4]; 4],
    /// The largest value in the grid, 1/m (a majorant for delta tracking).
    pub max_extinction_per_m: f32,
    pub albedo: f32,
    /// The single-scattering phase function: a sum of HG lobes (our
    /// renderer's `phase_dual` at full eccentricity).
    pub phase: [Lobe; 2],
    /// Unit vector toward the sun.
    pub sun_direction: [f32; 3],
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    /// The sun's irradiance on a surface facing it, linear RGB in the
    /// renderer's units (its in-scattered radiance is this times the
    /// phase function), at the cloud band's middle (the physical sky's
    /// sun reddens with its path through the air).
    pub sun_irradiance_rgb: [f32; 3],
    /// The scene's camera: eye, the point it looks at, up, vertical field
    /// of view and image size.
    pub camera_origin_m: [f32; 3],
    pub camera_target_m: [f32; 3],
    pub camera_up: [f32; 3],
    pub camera_fov_y_deg: f32,
    pub width: u32,
    pub height: u32,
    /// Physics seconds simulated before the field was taken.
    pub time_s: f64,
}

impl Sidecar {
    /// The sidecar of `values` on `grid` written to `volume`, for `frame`
    /// (camera and sun) and a vertical field of view of `fov_y_deg`.
    pub fn new(
        volume: &Path,
        grid: &Grid,
        values: &[f32],
        frame: &Frame,
        (fov_y_deg, width, height, time_s): (f32, u32, u32, f64),
    ) -> Self {
        let sun = sun_direction(frame.sun_elevation_deg, frame.sun_azimuth_deg);
        let size = grid.max_m - grid.min_m;
        let (min, eye) = (grid.min_m, frame.view.eye());
        let forward = frame.view.camera_ray(0.5, 0.5, 1, 1);
        let vdb = volume
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
        Self {
            volume: volume
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            quantity: QUANTITY,
            world: "metres; x east, y up, z north",
            resolution: grid.resolution,
            box_min_m: grid.min_m.to_array(),
            box_max_m: grid.max_m.to_array(),
            cell_m: grid.cell_m().to_array(),
            volume_space: if vdb {
                "OpenVDB index space, placed in metres by the file's own transform"
            } else {
                "Mitsuba's unit cube [0, 1]^3"
            },
            to_world: if vdb {
                [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0, 0.0],
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ]
            } else {
                [
                    [size.x, 0.0, 0.0, min.x],
                    [0.0, size.y, 0.0, min.y],
                    [0.0, 0.0, size.z, min.z],
                    [0.0, 0.0, 0.0, 1.0],
                ]
            },
            max_extinction_per_m: values.iter().copied().fold(0.0, f32::max),
            albedo: ALBEDO,
            phase: [
                Lobe {
                    weight: 0.75,
                    g: 0.8,
                },
                Lobe {
                    weight: 0.25,
                    g: -0.3,
                },
            ],
            sun_direction: sun.to_array(),
            sun_elevation_deg: frame.sun_elevation_deg,
            sun_azimuth_deg: frame.sun_azimuth_deg,
            sun_irradiance_rgb: sun_light_at(
                &frame.sky_light(),
                0.5 * (frame.density.band_bottom_m + frame.density.band_top_m),
                sun,
            )
            .to_array(),
            camera_origin_m: eye.to_array(),
            camera_target_m: (eye + forward * 1000.0).to_array(),
            camera_up: [0.0, 1.0, 0.0],
            camera_fov_y_deg: fov_y_deg,
            width,
            height,
            time_s,
        }
    }

    /// Writes the sidecar to `path` as pretty JSON, atomically.
    pub fn write(&self, path: &Path) -> Result<(), VolumeError> {
        let io = |source| VolumeError::Io {
            path: path.to_owned(),
            source,
        };
        let text = serde_json::to_string_pretty(self).map_err(|e| io(e.into()))?;
        write_atomically(path, |out| out.write_all(text.as_bytes())).map_err(io)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The map's directions follow Mitsuba's envmap convention: its
    /// `uv` of each direction is the pixel's centre.
    #[test]
    fn envmap_directions_invert_mitsubas_lookup() {
        let (w, h) = (64, 32);
        for j in 0..h {
            for i in 0..w {
                let d = envmap_direction(i, j, w, h);
                assert!((d.length() - 1.0).abs() < 1e-5);
                let u = d.x.atan2(-d.z).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU;
                let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
                assert!(
                    (u * w as f32 - (i as f32 + 0.5)).abs() < 1e-2,
                    "{i} {j}: u {u}"
                );
                assert!(
                    (v * h as f32 - (j as f32 + 0.5)).abs() < 1e-2,
                    "{i} {j}: v {v}"
                );
            }
        }
        // The top row looks up, the bottom row down.
        assert!(envmap_direction(0, 0, w, h).y > 0.99);
        assert!(envmap_direction(0, h - 1, w, h).y < -0.99);
    }

    #[test]
    fn grids_are_checked() {
        let (a, b) = (Vec3::ZERO, Vec3::splat(100.0));
        assert!(Grid::new([0, 4, 4], a, b).is_err());
        assert!(Grid::new([4, 4, 3000], a, b).is_err());
        assert!(Grid::new([2048, 2048, 2048], a, b).is_err());
        assert!(Grid::new([4, 4, 4], b, a).is_err());
        assert!(Grid::new([4, 4, 4], a, Vec3::new(100.0, 0.0, 100.0)).is_err());
        assert!(Grid::new([4, 4, 4], a, Vec3::new(f32::NAN, 1.0, 1.0)).is_err());
        assert!(Grid::cubic(0, a, b).is_err());
        assert!(Grid::cubic(2049, a, b).is_err());
        let g = Grid::cubic(
            100,
            Vec3::new(0.0, 500.0, 0.0),
            Vec3::new(10_000.0, 1_500.0, 5_000.0),
        )
        .expect("grid");
        assert_eq!(g.resolution, [100, 10, 50]);
        assert_eq!(g.cell_m(), Vec3::splat(100.0));
        assert_eq!(g.centre(0, 0, 0), Vec3::new(50.0, 550.0, 50.0));
        assert_eq!(g.index(1, 2, 3), (3 * 10 + 2) * 100 + 1);
    }

    /// The bytes follow Mitsuba's layout, read back by a parse written
    /// here from the format's description (not by `read_vol`), and
    /// `read_vol` returns what was written.
    #[test]
    fn vol_files_round_trip() {
        let g = Grid::new(
            [3, 2, 4],
            Vec3::new(-1.0, 2.0, 3.0),
            Vec3::new(5.0, 4.0, 11.0),
        )
        .expect("grid");
        let values: Vec<f32> = (0..g.len()).map(|i| i as f32 * 0.001 + 0.5).collect();
        let b = vol_bytes(&g, &values).expect("bytes");
        assert_eq!(b.len(), 48 + 4 * 24);
        assert_eq!(&b[..4], b"VOL\x03");
        let i32_at = |o: usize| i32::from_le_bytes(b[o..o + 4].try_into().expect("4"));
        let f32_at = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().expect("4"));
        assert_eq!(
            [i32_at(4), i32_at(8), i32_at(12), i32_at(16), i32_at(20)],
            [1, 3, 2, 4, 1]
        );
        assert_eq!(
            [24, 28, 32, 36, 40, 44].map(f32_at),
            [-1.0, 2.0, 3.0, 5.0, 4.0, 11.0]
        );
        // Cell (x 2, y 1, z 3) sits at ((3·2 + 1)·3 + 2) = 23.
        assert_eq!(f32_at(48 + 4 * 23), values[23]);
        assert_eq!(g.index(2, 1, 3), 23);
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("v.vol");
        write_vol(&path, &g, &values).expect("write");
        let (g2, v2) = read_vol(&path).expect("read");
        assert_eq!((g2, v2), (g, values));
        assert!(vol_bytes(&g, &[1.0]).is_err());
    }

    #[test]
    fn broken_vol_files_are_refused_with_the_reason() {
        let dir = tempfile::tempdir().expect("dir");
        let g = Grid::new([2, 2, 2], Vec3::ZERO, Vec3::ONE).expect("grid");
        let good = vol_bytes(&g, &[0.0; 8]).expect("bytes");
        let cases: [(&str, Vec<u8>, &str); 4] = [
            (
                "short",
                good[..20].to_vec(),
                "shorter than the 48-byte header",
            ),
            (
                "magic",
                [b"VOX".as_slice(), &good[3..]].concat(),
                "VOL and version 3",
            ),
            ("cut", good[..good.len() - 4].to_vec(), "expected 80"),
            (
                "encoding",
                [&good[..4], &2_i32.to_le_bytes()[..], &good[8..]].concat(),
                "encoding 2",
            ),
        ];
        for (name, bytes, says) in cases {
            let p = dir.path().join(format!("{name}.vol"));
            write_atomically(&p, |out| out.write_all(&bytes)).expect("write");
            let e = read_vol(&p).expect_err(name).to_string();
            assert!(
                e.contains(says) && e.contains(&format!("{name}.vol")),
                "{e}"
            );
        }
    }
}
