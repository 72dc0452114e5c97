//! `cumulus export`: simulate a scene, then write the density field the
//! renderer marches as a Mitsuba 3 grid volume (`.vol`) or an OpenVDB
//! file (`.vdb`), with a JSON sidecar of the sun, camera, phase function
//! and albedo.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use glam::Vec3;

use cumulus::prepare::Prepared;
use cumulus::render::cpu::density_grid::{self, Grid};
use cumulus::report::vdb;
use cumulus::report::volume_export::{self, Sidecar};

use crate::{
    check_output_file, guard_output_file, load_scene, progress_bar, with_overrides, write_exr,
};

#[derive(clap::Args)]
#[command(
    after_help = "Example:\n  cumulus export --scene scenes/fair_weather.toml --out clouds.vol --sky sky.exr\n  cumulus export --scene scenes/bomex.toml --out bomex.vol --cells 512 --box 0,500,0,4000,2500,4000\n  cumulus export --scene scenes/fair_weather.toml --out clouds.vdb --cells 512"
)]
pub struct ExportArgs {
    /// Scene TOML file, or the name of a built-in shipped scene
    /// (fair_weather, evening, strong_inversion, ...: `--scene fair_weather`).
    #[arg(long)]
    scene: PathBuf,
    /// Output volume of the extinction per metre: .vol (a Mitsuba 3 grid
    /// volume) or .vdb (OpenVDB: a fog volume named "density", for
    /// Blender and Houdini; y up). The sidecar is written beside it with
    /// the extension .json. Both are written atomically.
    #[arg(long)]
    out: PathBuf,
    /// Cells along the box's longest side (1..=2048); the other sides get
    /// as many as keep the cells nearly cubic.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=2048))]
    cells: u32,
    /// The box, metres: x0,y0,z0,x1,y1,z1 (x east, y up, z north).
    /// Default: the simulated domain across the cloud band.
    // A box starting at a negative x reads as one (`--box -500,...`), not
    // as an unknown flag.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "X0,Y0,Z0,X1,Y1,Z1",
        allow_hyphen_values = true
    )]
    r#box: Option<Vec<f32>>,
    /// Also write the renderer's sky (no sun disk) as a 512x256
    /// latitude-longitude OpenEXR map, laid out for Mitsuba 3's envmap.
    #[arg(long)]
    sky: Option<PathBuf>,
    /// Simulated seconds before the field is taken (overrides render.time_s).
    #[arg(long)]
    time_s: Option<f64>,
}

pub fn run(a: ExportArgs) -> Result<()> {
    let ext = a
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase());
    let vdb = match ext.as_deref() {
        Some("vol") => false,
        Some("vdb") => true,
        _ => bail!(
            "{}: --out must end in .vol (a Mitsuba 3 grid volume) or .vdb (OpenVDB)",
            a.out.display()
        ),
    };
    if let Some(b) = &a.r#box
        && b.len() != 6
    {
        bail!(
            "--box has {} numbers, expected 6: x0,y0,z0,x1,y1,z1 in metres",
            b.len()
        );
    }
    let sidecar_path = a.out.with_extension("json");
    check_output_file(&a.out)?;
    check_output_file(&sidecar_path)?;
    if let Some(sky) = &a.sky {
        let ext = sky.extension().map(|e| e.to_string_lossy().to_lowercase());
        if ext.as_deref() != Some("exr") {
            bail!("{}: --sky must end in .exr (OpenEXR)", sky.display());
        }
        check_output_file(sky)?;
    }
    let flags = [("--time-s", "render.time_s")];
    let scene = with_overrides(load_scene(&a.scene)?, &flags, |s| {
        if let Some(t) = a.time_s {
            s.render.time_s = t;
        }
    })?;
    let inputs = crate::scene_inputs(&scene, None);
    crate::refuse_overwriting_inputs(&a.out, &inputs)?;
    crate::refuse_overwriting_inputs(&sidecar_path, &inputs)?;
    // The grid is checked before the simulation: the default box is the
    // domain across the band, both known from the scene alone.
    let r = &scene.render;
    let density = r.density(
        scene.band(&scene.atmosphere(None)?),
        scene.physics.domain_size_m,
    );
    let (min, max) = match &a.r#box {
        Some(b) => (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5])),
        None => {
            let e = density.map_extent_m;
            (
                Vec3::new(0.0, density.band_bottom_m, 0.0),
                Vec3::new(e, density.band_top_m, e),
            )
        }
    };
    let grid = Grid::cubic(a.cells, min, max).context("--cells and --box")?;
    let bar = progress_bar(Prepared::frames(&scene), "simulating");
    let prepared = Prepared::from_scene(&scene, || bar.inc(1))?;
    bar.finish_and_clear();
    let frame = prepared.density_frame(r, r.quality());
    guard_output_file(&a.out);
    guard_output_file(&sidecar_path);
    let values = density_grid::sample(&frame, &grid);
    if vdb {
        vdb::write_vdb(&a.out, &grid, &values, volume_export::QUANTITY)?;
    } else {
        volume_export::write_vol(&a.out, &grid, &values)?;
    }
    let info = (r.fov_deg, r.width, r.height, r.time_s);
    Sidecar::new(&a.out, &grid, &values, &frame, info).write(&sidecar_path)?;
    if let Some(sky) = &a.sky {
        let (w, h) = (512, 256);
        let rgb = volume_export::sky_envmap(&frame, w, h);
        guard_output_file(sky);
        write_exr(sky, w, h, rgb)?;
        println!("wrote {}", sky.display());
    }
    let cloudy = values.iter().filter(|&&v| v > 0.0).count();
    let [nx, ny, nz] = grid.resolution;
    let cell = grid.cell_m().min_element();
    println!(
        "{nx}x{ny}x{nz} cells of {} m over {} to {} m; {:.1} % cloudy, max extinction {:.4} /m",
        // A thin box's cells are under a decimetre ("0.0 m" before).
        if cell >= 0.1 {
            format!("{cell:.1}")
        } else {
            format!("{cell:.2e}")
        },
        min,
        max,
        100.0 * cloudy as f64 / values.len() as f64,
        values.iter().copied().fold(0.0, f32::max)
    );
    println!("wrote {} and {}", a.out.display(), sidecar_path.display());
    Ok(())
}
