//! The CPU still from fewer marches (`render_still_adaptive`, the default
//! `render.cpu_sampling`): what it marches, and how close it lands to the
//! converged still.

use cumulus::prepare::Prepared;
use cumulus::render::cpu::frame::Frame;
use cumulus::render::cpu::renderer::{RaySample, march_ray, pixel_dither};
use cumulus::render::cpu::still_reconstruction::render_still_adaptive;
use cumulus::render::cpu::stills::{render_clouds_linear, render_still};
use cumulus::render::cpu::tone_map::to_srgb8;
use cumulus::render::sampling::jitter;
use cumulus::report::render_quality::highpass_energy;
use cumulus::scene::Scene;
use glam::Vec3;

const W: u32 = 96;
const H: u32 = 72;

fn prepared() -> (Scene, Prepared) {
    let mut sc =
        Scene::load(std::path::Path::new("scenes/fair_weather.toml")).expect("shipped scene");
    sc.render.time_s = 1800.0;
    sc.render.light_photons = 16;
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    (sc, p)
}

/// Frame 0's march through pixel `(x, y)`, by definition: its jitter, its
/// dither with frame 0's offset (0).
fn first_march(f: &Frame, x: u32, y: u32) -> RaySample {
    let [jx, jy, _] = jitter(0);
    let dir = f
        .view
        .camera_ray(x as f32 + 0.5 + jx, y as f32 + 0.5 + jy, W, H);
    march_ray(
        f.view.eye(),
        dir,
        pixel_dither(x, y),
        f.view.pixel_spread(W, H),
        f,
    )
}

/// Every pixel takes one march, edges all eight and nothing else more;
/// a pixel whose ray meets no cloud keeps its one march untouched (the
/// sky and ground are not filtered).
#[test]
fn an_adaptive_still_takes_every_march_only_at_edges() {
    let (sc, p) = prepared();
    let f = p.frame(&sc.render, sc.render.quality());
    let still = render_still_adaptive(W, H, &f, 8, &|_| {});
    let pixels = (W * H) as u64;
    assert_eq!(still.marches, pixels + 7 * still.edge_pixels);
    let per_pixel = still.marches_per_pixel();
    eprintln!(
        "{per_pixel:.2} marches a pixel, {} edge pixels",
        still.edge_pixels
    );
    // Under half the uniform still's marches, on an image this small
    // (at 640x480 on this scene, 1.4 with four at edges).
    assert!(still.edge_pixels > 0 && per_pixel < 4.0, "{per_pixel}");
    let eight = render_still(W, H, &f, 8);
    let (mut checked, mut edges) = (0, 0);
    for y in 0..H {
        for x in (0..W).step_by(3) {
            let first = first_march(&f, x, y);
            if first.transmittance < 1.0 {
                continue;
            }
            let i = (y * W + x) as usize;
            let got = still.linear[i];
            let close = |want: Vec3| {
                (got - want).abs().max_element() <= 1e-5 * want.max_element().max(1e-3)
            };
            if close(first.radiance) {
                checked += 1;
            } else {
                // Otherwise an edge pixel: the mean of its eight marches.
                assert!(
                    close(eight[i]),
                    "pixel ({x}, {y}): {got}, first march {}, eight {}",
                    first.radiance,
                    eight[i]
                );
                edges += 1;
            }
        }
    }
    eprintln!("{checked} clear pixels kept their march, {edges} took eight");
    assert!(
        checked > 100 && edges > 0,
        "{checked} clear pixels checked, {edges} edges"
    );
}

/// Against the converged still (16 marches a pixel), the adaptive still
/// of 8 at edges lands closer than one march a pixel and has less grain
/// in its clouds (high-pass energy), for under half the eight uniform
/// marches' cost.
#[test]
fn an_adaptive_still_is_closer_to_converged_than_one_march() {
    let (sc, p) = prepared();
    let r = &sc.render;
    let f = p.frame(r, r.quality());
    let converged = to_srgb8(&render_still(W, H, &f, 16), r.exposure);
    let mask: Vec<bool> = render_clouds_linear(W, H, &f, 1)
        .iter()
        .map(|c| c.w > 0.05)
        .collect();
    let measure = |img: &[Vec3]| {
        let b = to_srgb8(img, r.exposure);
        let err = b
            .iter()
            .zip(&converged)
            .map(|(x, y)| x.abs_diff(*y) as f64)
            .sum::<f64>()
            / b.len() as f64;
        (err, highpass_energy(&b, &mask, W, H))
    };
    let adaptive = render_still_adaptive(W, H, &f, 8, &|_| {});
    let (e_a, g_a) = measure(&adaptive.linear);
    let (e_1, g_1) = measure(&render_still(W, H, &f, 1));
    eprintln!(
        "adaptive ({:.2} marches): error {e_a:.3} levels, grain {g_a:.6}; one march: {e_1:.3}, {g_1:.6}",
        adaptive.marches_per_pixel()
    );
    assert!(adaptive.marches_per_pixel() < 4.0);
    assert!(e_a < 0.85 * e_1, "error {e_a} against one march's {e_1}");
    assert!(g_a < g_1, "grain {g_a} against one march's {g_1}");
}
