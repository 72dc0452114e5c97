//! `render` with the other methods: the pseudo-spheroids
//! (`[render] renderer = "spheroids"`) and the endless volumes
//! (`[simulation] method = "endless"`), each on the GPU or its CPU twin.

use anyhow::{Result, bail};

use cumulus::prepare::Prepared;
use cumulus::render::gpu::GpuContext;
use cumulus::render::gpu::headless::TARGET_FORMAT;
use cumulus::scene::Scene;

use super::{Picture, RenderArgs, write_linear, write_rgb8};

use crate::progress_bar;

/// `render` with `[render] renderer = "spheroids"`: the pseudo-spheroid
/// renderer on the GPU, or its CPU twin.
pub(super) fn render_spheroids(
    gpu: Option<&GpuContext>,
    a: &RenderArgs,
    scene: &Scene,
    prepared: &Prepared,
    picture: Option<Picture>,
) -> Result<()> {
    use cumulus::render::cpu::sky::sun_direction;
    use cumulus::render::cpu::spheroids::{LightGrid, render_spheroids as cpu_render};
    use cumulus::render::gpu::spheroids::SpheroidRenderer;

    let r = &scene.render;
    if a.time_frames.is_some() {
        bail!(
            "--time-frames times the cloud map; `cumulus bench` times the spheroids (methods.csv)"
        );
    }
    let Some(out) = &a.out else { return Ok(()) };
    let spheroids = prepared.spheroids();
    let start = std::time::Instant::now();
    match gpu {
        Some(ctx) => {
            if picture == Some(Picture::Exr) {
                bail!(
                    "{}: the spheroid renderer writes PNG on the GPU; use --backend cpu for OpenEXR",
                    out.display()
                );
            }
            eprintln!("backend: gpu ({})", ctx.describe());
            let settings = prepared.gpu_settings(r, r.quality());
            let mut s = SpheroidRenderer::new(
                &ctx.device,
                &ctx.queue,
                TARGET_FORMAT,
                &settings,
                prepared.cloud_map.noise(),
            );
            s.update_spheroids(&spheroids);
            write_rgb8(
                out,
                r.width,
                r.height,
                s.read_rgb8(ctx, &r.camera(), r.width, r.height)?,
            )?;
        }
        None => {
            // The spheroids light themselves (their light grid): no light
            // volume.
            let frame = prepared.density_frame(r, r.quality());
            let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
            let grid = LightGrid::build(&spheroids, sun, frame.density.extinction_per_m);
            let linear = cpu_render(r.width, r.height, &frame, &spheroids, &grid);
            write_linear(out, picture, r, &linear)?;
        }
    }
    eprintln!(
        "rendered {}x{} with {} pseudo-spheroids in {:.2} s; wrote {}",
        r.width,
        r.height,
        spheroids.len(),
        start.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}

/// `render` with `[simulation] method = "endless"`: the database built,
/// the first moment of its playback drawn by the volume renderer on the
/// GPU, or by its CPU twin.
pub(super) fn render_endless(
    gpu: Option<&GpuContext>,
    a: &RenderArgs,
    scene: &Scene,
    picture: Option<Picture>,
) -> Result<()> {
    use cumulus::endless::{Database, Player, Source};
    use cumulus::render::cpu::volume::render_volume;
    use cumulus::render::gpu::volume_pass::VolumeRenderer;

    let r = &scene.render;
    let cfg = &scene.simulation.endless;
    if a.time_frames.is_some() || a.quality_report.is_some() || a.stills_report.is_some() {
        bail!(
            "--time-frames, --quality-report and --stills-report are for the cloud map; `cumulus bench --methods` times the volumes"
        );
    }
    // The physics' frames, then one step per volume compared with the
    // others (the player's distances).
    let frames = Prepared::frames(scene)
        + (cfg.volumes.saturating_sub(1) as f64 * cfg.interval_s / scene.physics.dt_s).ceil()
            as u64
        + cfg.volumes as u64;
    let bar = progress_bar(frames, "simulating, sampling and comparing the volumes");
    let (db, source) = Database::load_or_build(scene, cfg, || bar.inc(1))?;
    bar.finish_and_clear();
    let whence = match source {
        Source::Built => format!("built in {:.1} s", db.build_s),
        Source::Read(p) => format!("read from {} (built in {:.1} s)", p.display(), db.build_s),
        Source::Written(p) => format!("built in {:.1} s, wrote {}", db.build_s, p.display()),
    };
    eprintln!(
        "database: {} volumes of {}x{}x{} ({:.1} MB) {whence}",
        db.len(),
        db.dims[0],
        db.dims[1],
        db.dims[2],
        db.bytes() as f64 / 1e6,
    );
    let Some(out) = &a.out else { return Ok(()) };
    let mut player = Player::new(&db, cfg.similarity, scene.physics.seed);
    let (stack, params) = db.stack(player.at(0.0, db.interval_s));
    match gpu {
        Some(ctx) => {
            if picture == Some(Picture::Exr) {
                bail!(
                    "{}: the volume renderer writes PNG on the GPU; use --backend cpu for OpenEXR",
                    out.display()
                );
            }
            eprintln!("backend: gpu ({})", ctx.describe());
            let settings = db.gpu_settings(r);
            // The land's fields read the cloud map's detail volume.
            let p = Prepared::unsimulated(scene)?;
            let mut v = VolumeRenderer::new(
                &ctx.device,
                &ctx.queue,
                TARGET_FORMAT,
                &settings,
                &stack,
                params,
                p.cloud_map.noise(),
            )?;
            write_rgb8(
                out,
                r.width,
                r.height,
                v.read_rgb8(ctx, &r.camera(), r.width, r.height)?,
            )?;
        }
        None => {
            let p = Prepared::unsimulated(scene)?;
            let frame = p.density_frame(r, r.quality());
            let linear = render_volume(r.width, r.height, &frame, &params, &stack, r.cpu_offsets);
            write_linear(out, picture, r, &linear)?;
        }
    }
    eprintln!(
        "rendered {}x{} from the volumes; wrote {}",
        r.width,
        r.height,
        out.display()
    );
    Ok(())
}
