//! The WGSL and its CPU twins, checked by machine with naga (no GPU
//! needed): every WGSL function is the twin of a Rust function of the same
//! name in the Rust module its file mirrors (`shaders/density.wgsl` and
//! `src/render/cpu/density.rs`, see `MIRRORS`), or on the short GPU-only
//! list below with the reason; no WGSL file is over 500 lines; every WGSL constant equals its Rust twin; the `Frame` uniform's
//! members sit at the offsets of `FrameUniforms`' fields, `Spheroid`'s at
//! those of the spheroid renderer's `Spheroid`, and the sky tables' `SkyParams` and
//! `SkyView` at those of `SkyParamsUniforms` and `SkyViewUniforms`. The
//! sources are `all_variants()`, which include `shaders/sky_luts/`.

use std::collections::BTreeSet;
use std::mem::offset_of;
use std::path::Path;

use cumulus::render::cpu::spheroids::{self, Spheroid};
use cumulus::render::cpu::{
    cirrus, density, frame, glare, land, light_grid, light_transport, lighting, renderer, sea, sky,
    sky_luts, waves,
};
use cumulus::render::gpu::light_volume_pass::{self, LightVolumeGridUniforms};
use cumulus::render::gpu::shaders::all_variants;
use cumulus::render::gpu::uniforms::{FrameUniforms, SkyParamsUniforms, SkyViewUniforms};

/// WGSL functions with no Rust function of the same name, and why.
const GPU_ONLY: &[(&str, &str)] = &[
    // The fragment body of the cloud pass; the CPU loop is render_linear.
    ("cloud_pixel", "per-pixel glue around march_ray"),
    // The GPU's early exit over empty sky; the CPU has CoverageMask::build
    // and tests the mask conservative against density_at.
    ("coarse_empty", "reads CoverageMask's cells"),
    // The terrain pass's depth buffer stores a reversed view's depth
    // flipped; the CPU intersects the heightfield and has no depth buffer.
    ("view_depth", "no depth buffer on the CPU"),
    // Tone map plus sRGB encode of the composite; the CPU's to_srgb8.
    ("display", "the CPU's to_srgb8"),
    // An sRGB target encodes the composite's dithered value again in
    // hardware; the CPU rounds the encoded value itself (to_srgb8).
    ("srgb_decode", "to_srgb8 rounds the encoded value"),
    // glam's Vec3::normalize_or on the CPU.
    ("normalize_or", "glam's Vec3::normalize_or"),
    // glam's Vec3::lerp (the sky tables' bilinear, Lut2::sample_texels).
    ("lerp", "glam's Vec3::lerp"),
    // The composite's background: sky_radiance + sun_disk on the CPU.
    ("sky_background", "background_radiance per pixel"),
    // The composite's glare at one pixel: add_sun_glare's loop over the
    // image on the CPU (glare_source, sun_glare).
    ("glare_at", "add_sun_glare per pixel"),
    // Integer wrap of texel indices (rem_euclid on the CPU).
    ("wrap_i", "i64::rem_euclid on the CPU"),
    // The light volume's grid: LightVolumeGrid's methods index, cell, centre.
    ("light_index", "LightVolumeGrid::index"),
    ("light_cell", "LightVolumeGrid::cell"),
    ("light_centre", "LightVolumeGrid::centre"),
    // Dispatch glue: the CPU iterates over LightVolumeGrid::len() cells.
    ("light_total", "LightVolumeGrid::len"),
    (
        "light_invocation",
        "a folded dispatch's cell (workgroups())",
    ),
    // The photons' random numbers: the CPU's Rng::new and Rng::next.
    ("rng_seed", "Rng::new"),
    ("rng_next", "Rng::next"),
];

/// Every WGSL constant and its Rust twin's value.
fn rust_constants() -> Vec<(&'static str, f64)> {
    vec![
        ("PI", std::f32::consts::PI as f64),
        ("GLARE_CORE", glare::GLARE_CORE as f64),
        ("GLARE_MIN_DEG", glare::GLARE_MIN_DEG as f64),
        ("GLARE_TAPS", glare::GLARE_TAPS as f64),
        ("GLARE_TAP_REACH", glare::GLARE_TAP_REACH as f64),
        ("SPHEROID_KAPPA", spheroids::SPHEROID_KAPPA as f64),
        ("MAX_CANDIDATES", spheroids::MAX_CANDIDATES as f64),
        ("FBM_OCTAVES", spheroids::FBM_OCTAVES as f64),
        ("FBM_CONTRAST", spheroids::FBM_CONTRAST as f64),
        (
            "TERRAIN_REACH_MAX",
            cumulus::render::gpu::terrain_pass::TERRAIN_REACH_MAX as f64,
        ),
        (
            "VOLUME_SHADOW_STEPS",
            cumulus::render::cpu::volume::VOLUME_SHADOW_STEPS as f64,
        ),
        (
            "VOLUME_SHADOW_RAY_M",
            cumulus::render::cpu::volume::VOLUME_SHADOW_RAY_M as f64,
        ),
        ("CIRRUS_ALONG_M", cirrus::CIRRUS_ALONG_M as f64),
        ("CIRRUS_ACROSS_M", cirrus::CIRRUS_ACROSS_M as f64),
        ("CIRRUS_OCTAVES", cirrus::CIRRUS_OCTAVES as f64),
        ("CIRRUS_FIBRE_GROWTH", cirrus::CIRRUS_FIBRE_GROWTH as f64),
        ("CIRRUS_CONTRAST", cirrus::CIRRUS_CONTRAST as f64),
        ("CIRRUS_EDGE", cirrus::CIRRUS_EDGE as f64),
        ("CIRRUS_PHASE_G", cirrus::CIRRUS_PHASE_G as f64),
        ("CIRRUS_MU_MIN", cirrus::CIRRUS_MU_MIN as f64),
        ("FIELD_LENGTH_M", land::FIELD_LENGTH_M as f64),
        ("FIELD_WIDTH_M", land::FIELD_WIDTH_M as f64),
        ("FIELD_ANGLE", land::FIELD_ANGLE as f64),
        ("FARM_TURN", land::FARM_TURN as f64),
        ("FARM_M", land::FARM_M as f64),
        ("FARM_BEND_M", land::FARM_BEND_M as f64),
        ("WOODS_TILE_M", land::WOODS_TILE_M as f64),
        ("WOODS_DETAIL_TILE_M", land::WOODS_DETAIL_TILE_M as f64),
        ("WOODS_THRESHOLD", land::WOODS_THRESHOLD as f64),
        ("WOODS_EDGE", land::WOODS_EDGE as f64),
        ("WOODS_SHARP_M", land::WOODS_SHARP_M as f64),
        ("WOODS_SOFTEST", land::WOODS_SOFTEST as f64),
        ("WOODS_FADE_M", land::WOODS_FADE_M as f64),
        ("WOODS_SHARE", land::WOODS_SHARE as f64),
        ("HEDGE_M", land::HEDGE_M as f64),
        ("HEDGE_CHANCE", land::HEDGE_CHANCE as f64),
        ("PATCH_TILE_M", land::PATCH_TILE_M as f64),
        ("PATCH_CONTRAST", land::PATCH_CONTRAST as f64),
        ("CROWN_M", land::CROWN_M as f64),
        ("SMALL_CROWN_M", land::SMALL_CROWN_M as f64),
        ("CANOPY_FLOOR", land::CANOPY_FLOOR as f64),
        ("CROWN_LIGHT_MEAN", land::CROWN_LIGHT_MEAN as f64),
        ("BASE_RAMP", density::BASE_RAMP as f64),
        ("TOP_ROUNDING", density::TOP_ROUNDING as f64),
        ("FRINGE_PRESENCE", density::FRINGE_PRESENCE as f64),
        ("P_COVERAGE_MIN", density::P_COVERAGE_MIN as f64),
        ("WEATHER_MAX", density::WEATHER_MAX as f64),
        ("EROSION_BASE", density::EROSION_BASE as f64),
        ("SURFACE_RAMP", density::SURFACE_RAMP as f64),
        ("DETAIL_CONTRAST", density::DETAIL_CONTRAST as f64),
        ("WARP_SCALE_M", density::WARP_SCALE_M as f64),
        ("WARP_AMPLITUDE_M", density::WARP_AMPLITUDE_M as f64),
        ("WARP_RAMP_INNER", density::WARP_RAMP.0 as f64),
        ("WARP_RAMP_OUTER", density::WARP_RAMP.1 as f64),
        ("WEATHER_SCALE_M", density::WEATHER_SCALE_M as f64),
        ("REFINE", renderer::REFINE as f64),
        ("NEAR_M", renderer::NEAR_M as f64),
        ("MARCH_LOG_SPAN", renderer::MARCH_LOG_SPAN as f64),
        (
            "MARCH_STEP_FACTOR_MAX",
            renderer::MARCH_STEP_FACTOR_MAX as f64,
        ),
        ("DETAIL_TILE", density::DETAIL_TILE as f64),
        ("BILLOW_FREQUENCY", density::BILLOW_FREQUENCY as f64),
        ("BASE_WEIGHT", density::BASE_WEIGHT as f64),
        ("FINE_FREQUENCY", density::FINE_FREQUENCY as f64),
        ("FINE_WEIGHT", density::FINE_WEIGHT as f64),
        ("FINE_SHARP_M", density::FINE_SHARP_M as f64),
        (
            "GROUND_SHADOW_FOOTPRINT_M",
            lighting::GROUND_SHADOW_FOOTPRINT_M as f64,
        ),
        ("NOISE_MAX_LOD", density::NOISE_MAX_LOD as f64),
        ("NOISE_SIZE", cumulus::render::noise_volume::SIZE as f64),
        ("BLUE_NOISE_SIZE", cumulus::render::sampling::SIZE as f64),
        ("ALBEDO", lighting::ALBEDO as f64),
        ("MIN_TRANSMITTANCE", frame::MIN_TRANSMITTANCE as f64),
        ("SUN_DISK_COS", sky::SUN_DISK_COS as f64),
        ("WATER_F0", sky::WATER_F0 as f64),
        ("SHADOW_RAY_M", lighting::SHADOW_RAY_M as f64),
        ("SHADOW_STEP_SPAN_M", lighting::SHADOW_STEP_SPAN_M as f64),
        (
            "SHADOW_STEP_FACTOR_MAX",
            lighting::SHADOW_STEP_FACTOR_MAX as f64,
        ),
        ("FORWARD_STEP_BOOST", lighting::FORWARD_STEP_BOOST as f64),
        ("NEAR_SHADOW_M", lighting::NEAR_SHADOW_M as f64),
        ("NEAR_SHADOW_STEPS", lighting::NEAR_SHADOW_STEPS as f64),
        (
            "SUN_DEPTH_STEPS_MAX",
            light_grid::SUN_DEPTH_STEPS_MAX as f64,
        ),
        ("FORWARD_COS_MIN", lighting::FORWARD_COS_MIN as f64),
        ("FORWARD_COS_MAX", lighting::FORWARD_COS_MAX as f64),
        ("OCTAVE_SCATTERING", lighting::OCTAVE_SCATTERING as f64),
        ("OCTAVE_EXTINCTION", lighting::OCTAVE_EXTINCTION as f64),
        ("OCTAVE_ECCENTRICITY", lighting::OCTAVE_ECCENTRICITY as f64),
        ("MULTIPLE_GAIN", lighting::MULTIPLE_GAIN as f64),
        (
            "MULTIPLE_ISOTROPIC_GAIN",
            lighting::MULTIPLE_ISOTROPIC_GAIN as f64,
        ),
        ("MULTIPLE_SUN_POWER", lighting::MULTIPLE_SUN_POWER as f64),
        ("DIFFUSE_GAIN", lighting::DIFFUSE_GAIN as f64),
        ("DIFFUSE_GAIN_ALONE", lighting::DIFFUSE_GAIN_ALONE as f64),
        ("MULTIPLE_GAIN_ALONE", lighting::MULTIPLE_GAIN_ALONE as f64),
        (
            "MULTIPLE_ISOTROPIC_GAIN_ALONE",
            lighting::MULTIPLE_ISOTROPIC_GAIN_ALONE as f64,
        ),
        ("AMBIENT_GAIN_ALONE", lighting::AMBIENT_GAIN_ALONE as f64),
        (
            "GROUND_LIGHT_GAIN_ALONE",
            lighting::GROUND_LIGHT_GAIN_ALONE as f64,
        ),
        ("DIFFUSE_DEPTH_M", lighting::DIFFUSE_DEPTH_M as f64),
        ("AMBIENT_GAIN", lighting::AMBIENT_GAIN as f64),
        ("GROUND_LIGHT_GAIN", lighting::GROUND_LIGHT_GAIN as f64),
        ("GROUND_SHADOW_STEPS", renderer::GROUND_SHADOW_STEPS as f64),
        ("RAY_DEPTH", cumulus::render::camera::RAY_DEPTH as f64),
        // shaders/sky_luts/atmosphere.wgsl (PI above is shared).
        ("GOLDEN_ANGLE", sky_luts::GOLDEN_ANGLE as f64),
        ("TRANSMITTANCE_WIDTH", sky_luts::TRANSMITTANCE_SIZE.0 as f64),
        (
            "TRANSMITTANCE_HEIGHT",
            sky_luts::TRANSMITTANCE_SIZE.1 as f64,
        ),
        (
            "MULTI_SCATTERING_WIDTH",
            sky_luts::MULTI_SCATTERING_SIZE.0 as f64,
        ),
        (
            "MULTI_SCATTERING_HEIGHT",
            sky_luts::MULTI_SCATTERING_SIZE.1 as f64,
        ),
        ("SKY_VIEW_WIDTH", sky_luts::SKY_VIEW_SIZE.0 as f64),
        ("SKY_VIEW_HEIGHT", sky_luts::SKY_VIEW_SIZE.1 as f64),
        ("SKY_VIEW_HALF", sky_luts::SKY_VIEW_HALF as f64),
        ("TRANSMITTANCE_STEPS", sky_luts::TRANSMITTANCE_STEPS as f64),
        (
            "MULTI_SCATTERING_DIRECTIONS",
            sky_luts::MULTI_SCATTERING_DIRECTIONS as f64,
        ),
        (
            "MULTI_SCATTERING_STEPS",
            sky_luts::MULTI_SCATTERING_STEPS as f64,
        ),
        ("SKY_VIEW_STEPS", sky_luts::SKY_VIEW_STEPS as f64),
        (
            "AERIAL_PERSPECTIVE_STEPS",
            sky_luts::AERIAL_PERSPECTIVE_STEPS as f64,
        ),
        ("LIMB_DARKENING_U", sky_luts::LIMB_DARKENING_U as f64),
        ("REFLECTION_RAYS", sea::REFLECTION_RAYS as f64),
        ("GROUND_CLOUD_LIGHT", sky::GROUND_CLOUD_LIGHT as f64),
        ("REFLECTION_STEPS", sea::REFLECTION_STEPS as f64),
        ("REFLECTION_STEPS_MAX", sea::REFLECTION_STEPS_MAX as f64),
        ("REFLECTION_STEP_M", sea::REFLECTION_STEP_M as f64),
        (
            "REFLECTION_MIN_ELEVATION",
            waves::REFLECTION_MIN_ELEVATION as f64,
        ),
        ("GOLDEN", cumulus::render::sampling::GOLDEN as f64),
        ("WAVE_COUNT", waves::WAVE_COUNT as f64),
        ("WAVE_OCTAVES", waves::WAVE_OCTAVES as f64),
        ("GRAVITY", waves::GRAVITY as f64),
        ("WAVE_ANISOTROPY_MAX", waves::WAVE_ANISOTROPY_MAX as f64),
        ("SKY_MIRROR_RAYS", sky::SKY_MIRROR_RAYS as f64),
        ("WAVE_LONGEST_M", waves::WAVE_LONGEST_M as f64),
        ("WAVE_SPREAD", waves::WAVE_SPREAD as f64),
        ("WAVE_SHARE_MAX", waves::WAVE_SHARE_MAX as f64),
        ("WAVE_FADE_START", waves::WAVE_FADE_START as f64),
        ("WAVE_FADE_END", waves::WAVE_FADE_END as f64),
        (
            "REFLECTION_SHADOW_STEPS",
            sea::REFLECTION_SHADOW_STEPS as f64,
        ),
        ("SKY_AMBIENT_ROWS", sky_luts::SKY_AMBIENT_SAMPLES.0 as f64),
        ("FLUENCE_GAIN", lighting::FLUENCE_GAIN as f64),
        ("LIGHT_SUN_MIN", light_grid::LIGHT_SUN_MIN as f64),
        ("LIGHT_SEED", light_grid::LIGHT_SEED as f64),
        (
            "CELLS_PER_PHOTON_MAX",
            light_transport::CELLS_PER_PHOTON_MAX as f64,
        ),
        ("ROULETTE_WEIGHT", light_transport::ROULETTE_WEIGHT as f64),
        ("TRACK_UNIT", light_volume_pass::TRACK_UNIT as f64),
        ("PHASE_MOMENT_1", light_transport::PHASE_MOMENTS[1] as f64),
        ("PHASE_MOMENT_2", light_transport::PHASE_MOMENTS[2] as f64),
        ("LIGHT_WORKGROUP", light_volume_pass::LIGHT_WORKGROUP as f64),
        (
            "SKY_AMBIENT_COLUMNS",
            sky_luts::SKY_AMBIENT_SAMPLES.1 as f64,
        ),
    ]
}

fn modules() -> Vec<naga::Module> {
    all_variants()
        .iter()
        .map(|src| {
            naga::front::wgsl::parse_str(src)
                .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)))
        })
        .collect()
}

/// Every `.rs` file's text under `dir`.
fn rust_sources(dir: &Path, out: &mut String) {
    for entry in std::fs::read_dir(dir).expect("src/render") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push_str(&std::fs::read_to_string(&path).expect("read"));
        }
    }
}

fn has_rust_fn(sources: &str, name: &str) -> bool {
    sources.contains(&format!("fn {name}(")) || sources.contains(&format!("fn {name}<"))
}

#[test]
fn every_wgsl_function_has_a_rust_twin_or_a_reason() {
    let mut wgsl = BTreeSet::new();
    for m in modules() {
        for (_, f) in m.functions.iter() {
            wgsl.extend(f.name.clone());
        }
    }
    let mut rust = String::new();
    rust_sources(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render"),
        &mut rust,
    );
    let gpu_only: BTreeSet<&str> = GPU_ONLY.iter().map(|(n, _)| *n).collect();
    let mut missing = Vec::new();
    for name in &wgsl {
        let twin = has_rust_fn(&rust, name);
        let listed = gpu_only.contains(name.as_str());
        if twin == listed {
            missing.push(if twin {
                format!("{name}: on GPU_ONLY but has a Rust twin (take it off the list)")
            } else {
                format!("{name}: no Rust fn {name} under src/render and not on GPU_ONLY")
            });
        }
    }
    for name in &gpu_only {
        if !wgsl.contains(*name) {
            missing.push(format!(
                "{name}: on GPU_ONLY but no WGSL function has that name"
            ));
        }
    }
    assert!(missing.is_empty(), "{missing:#?}");
    // The twins are most of the shader, not a token few.
    assert!(wgsl.len() - gpu_only.len() >= 20, "{wgsl:?}");
}

#[test]
fn every_wgsl_constant_equals_its_rust_twin() {
    let rust = rust_constants();
    let mut seen = BTreeSet::new();
    for m in modules() {
        for (_, c) in m.constants.iter() {
            let Some(name) = &c.name else { continue };
            let value = match m.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::F32(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::U32(v)) => v as f64,
                naga::Expression::Literal(naga::Literal::I32(v)) => v as f64,
                naga::Expression::Compose { ref components, .. } => {
                    let wgsl: Vec<f32> = components
                        .iter()
                        .map(|&h| match m.global_expressions[h] {
                            naga::Expression::Literal(naga::Literal::F32(v)) => v,
                            ref e => panic!("WGSL const {name}: a component is {e:?}"),
                        })
                        .collect();
                    let Some((_, twin)) = rust_vectors().into_iter().find(|(n, _)| n == name)
                    else {
                        panic!("WGSL const {name} has no Rust twin in rust_vectors()");
                    };
                    assert_eq!(wgsl, twin.to_array(), "const {name}");
                    seen.insert(name.clone());
                    continue;
                }
                ref e => panic!("WGSL const {name} is not a plain literal: {e:?}"),
            };
            let Some((_, twin)) = rust.iter().find(|(n, _)| n == name) else {
                panic!("WGSL const {name} has no Rust twin in rust_constants()");
            };
            assert_eq!(value as f32, *twin as f32, "const {name}");
            seen.insert(name.clone());
        }
    }
    for name in rust
        .iter()
        .map(|c| c.0)
        .chain(rust_vectors().iter().map(|c| c.0))
    {
        assert!(seen.contains(name), "no WGSL const {name}");
    }
}

/// The Rust twins of the WGSL `vec3f` constants.
fn rust_vectors() -> Vec<(&'static str, glam::Vec3)> {
    vec![
        ("LAND_ALBEDO", sky::LAND_ALBEDO),
        ("TERRAIN_ALBEDO_FLAT", land::TERRAIN_ALBEDO_FLAT),
        ("TERRAIN_ALBEDO_STEEP", land::TERRAIN_ALBEDO_STEEP),
        ("WOODS", land::WOODS),
        ("CROP_GRASS", land::CROP_GRASS),
        ("CROP_YOUNG", land::CROP_YOUNG),
        ("CROP_SOIL", land::CROP_SOIL),
        ("CROP_STUBBLE", land::CROP_STUBBLE),
        ("CROPS_MEAN", land::CROPS_MEAN),
        ("LAND_TINT_MEAN", land::LAND_TINT_MEAN),
        ("HEDGE", land::HEDGE),
        ("FIELDS_MEAN", land::FIELDS_MEAN),
    ]
}

/// The members of the WGSL struct `name` as (member, byte offset).
fn wgsl_struct(name: &str) -> (Vec<(String, u32)>, u32) {
    for m in modules() {
        for (_, t) in m.types.iter() {
            if t.name.as_deref() == Some(name)
                && let naga::TypeInner::Struct { members, span } = &t.inner
            {
                let ms = members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                    .collect();
                return (ms, *span);
            }
        }
    }
    panic!("no WGSL struct {name}");
}

fn same_layout(name: &str, rust: &[(&str, usize)], rust_size: usize) {
    let (wgsl, span) = wgsl_struct(name);
    assert_eq!(span as usize, rust_size, "{name}: size");
    let wgsl: Vec<(String, usize)> = wgsl.into_iter().map(|(n, o)| (n, o as usize)).collect();
    let rust: Vec<(String, usize)> = rust.iter().map(|(n, o)| (n.to_string(), *o)).collect();
    assert_eq!(wgsl, rust, "{name}: members and offsets");
}

#[test]
fn frame_uniform_members_match_frame_uniforms_offsets() {
    macro_rules! offsets {
        ($t:ty: $($f:ident),*) => { [$((stringify!($f), offset_of!($t, $f))),*] };
    }
    let rust = offsets!(FrameUniforms: cam_pos, screen, sun_dir, sun_light, exposure,
        band, map, jitter, terrain, counts, mask, view_proj, prev_view_proj,
        inverse_projection, view_to_world);
    same_layout("Frame", &rust, size_of::<FrameUniforms>());
    let rust = offsets!(Spheroid: centre_radius, shape);
    same_layout("Spheroid", &rust, size_of::<Spheroid>());
    use cumulus::render::cpu::volume::VolumeParams;
    let rust = offsets!(VolumeParams: origin, extent, dims, pick);
    same_layout("VolumeParams", &rust, size_of::<VolumeParams>());
    let rust = offsets!(LightVolumeGridUniforms: cells, cell_m);
    same_layout(
        "LightVolumeGrid",
        &rust,
        size_of::<LightVolumeGridUniforms>(),
    );
}

#[test]
fn sky_uniform_members_match_their_rust_blocks() {
    macro_rules! offsets {
        ($t:ty: $($f:ident),*) => { [$((stringify!($f), offset_of!($t, $f))),*] };
    }
    // SkyParamsUniforms' `_pad` is the WGSL struct's implicit tail padding.
    let rust = offsets!(SkyParamsUniforms: rayleigh_scattering, ground_radius_km,
        ozone_absorption, top_radius_km, ground_albedo, rayleigh_scale_height_km,
        sun_irradiance, mie_scattering, mie_extinction, mie_scale_height_km, mie_g,
        ozone_center_km, ozone_width_km, sun_angular_radius_deg);
    same_layout("SkyParams", &rust, size_of::<SkyParamsUniforms>());
    let rust = offsets!(SkyViewUniforms: camera_radius_km, sun_cos_zenith);
    same_layout("SkyView", &rust, size_of::<SkyViewUniforms>());
}

/// Each WGSL file and the Rust files whose functions it mirrors, one to one
/// by name. A pass's own file (its entry points, bindings and glue) may
/// mirror none, and says so with an empty list.
const MIRRORS: &[(&str, &[&str])] = &[
    ("frame.wgsl", &["src/render/cpu/frame.rs"]),
    ("camera.wgsl", &["src/render/camera.rs"]),
    ("density.wgsl", &["src/render/cpu/density.rs"]),
    ("lighting.wgsl", &["src/render/cpu/lighting.rs"]),
    ("sky.wgsl", &["src/render/cpu/sky.rs"]),
    ("cirrus.wgsl", &["src/render/cpu/cirrus.rs"]),
    ("sky_analytic.wgsl", &["src/render/cpu/sky.rs"]),
    ("sky_physical.wgsl", &["src/render/cpu/sky.rs"]),
    ("waves.wgsl", &["src/render/cpu/waves.rs"]),
    ("sea.wgsl", &["src/render/cpu/sea.rs"]),
    ("tone_map.wgsl", &["src/render/cpu/tone_map.rs"]),
    ("composite.wgsl", &["src/render/cpu/tone_map.rs"]),
    ("glare.wgsl", &["src/render/cpu/glare.rs"]),
    ("renderer.wgsl", &["src/render/cpu/renderer.rs"]),
    ("land.wgsl", &["src/render/cpu/land.rs"]),
    ("light_grid.wgsl", &["src/render/cpu/light_grid.rs"]),
    (
        "light_transport.wgsl",
        &["src/render/cpu/light_transport.rs"],
    ),
    (
        "light_volume_build.wgsl",
        &[
            "src/render/cpu/light_volume.rs",
            "src/render/cpu/light_grid.rs",
        ],
    ),
    ("spheroids.wgsl", &["src/render/cpu/spheroids.rs"]),
    ("volume.wgsl", &["src/render/cpu/volume.rs"]),
    // `terrain_hides` is each composite variant's, written in shaders.rs.
    (
        "standalone.wgsl",
        &["src/render/cpu/standalone.rs", "src/render/gpu/shaders.rs"],
    ),
    // The terrain pass: the heightfield's functions (render::terrain), its
    // albedo (land) and its shading, which the CPU does where it marches
    // (terrain_radiance).
    (
        "terrain.wgsl",
        &[
            "src/render/terrain.rs",
            "src/render/cpu/land.rs",
            "src/render/cpu/renderer.rs",
        ],
    ),
    (
        "sky_luts/atmosphere.wgsl",
        &["src/render/cpu/sky_luts/atmosphere.rs"],
    ),
    (
        "sky_luts/tables.wgsl",
        &["src/render/cpu/sky_luts/tables.rs"],
    ),
    (
        "sky_luts/lookups.wgsl",
        &["src/render/cpu/sky_luts/lookups.rs"],
    ),
    ("sky_luts_build.wgsl", &[]),
    ("tsaa.wgsl", &[]),
];

/// Every `.wgsl` file under `shaders/`, relative to it.
fn wgsl_files() -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).expect("shaders/") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                walk(root, &p, out);
            } else if p.extension().is_some_and(|e| e == "wgsl") {
                let rel = p.strip_prefix(root).expect("under shaders/");
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut out = Vec::new();
    walk(&root, &root, &mut out);
    out.sort();
    out
}

/// The names of the functions a WGSL text defines at module scope, less
/// its entry points (a `fn` right after `@compute`, `@fragment` or
/// `@vertex`, or on the same line).
fn wgsl_fn_names(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut after_stage = false;
    for l in text.lines() {
        let t = l.trim();
        let stage = ["@compute", "@fragment", "@vertex"]
            .iter()
            .any(|a| t.starts_with(a));
        if let Some(rest) = l.strip_prefix("fn ")
            && !after_stage
        {
            out.push(rest.split('(').next().unwrap_or("").trim().to_string());
        }
        if stage && !t.contains("fn ") {
            after_stage = true;
        } else if !t.starts_with('@') {
            after_stage = false;
        }
    }
    out
}

#[test]
fn each_wgsl_file_mirrors_its_rust_module() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let gpu_only: BTreeSet<&str> = GPU_ONLY.iter().map(|(n, _)| *n).collect();
    let mut wrong = Vec::new();
    for file in wgsl_files() {
        let Some((_, rust_files)) = MIRRORS.iter().find(|(f, _)| *f == file) else {
            wrong.push(format!(
                "shaders/{file}: not in MIRRORS (name its Rust twin)"
            ));
            continue;
        };
        let text = std::fs::read_to_string(root.join("shaders").join(&file)).expect("read");
        let lines = text.lines().count();
        if lines > 500 {
            wrong.push(format!("shaders/{file}: {lines} lines (at most 500)"));
        }
        let rust: String = rust_files
            .iter()
            .map(|f| std::fs::read_to_string(root.join(f)).expect("a mirrored Rust file"))
            .collect();
        for name in wgsl_fn_names(&text) {
            if !gpu_only.contains(name.as_str()) && !has_rust_fn(&rust, &name) {
                wrong.push(format!(
                    "shaders/{file}: fn {name} has no twin in {rust_files:?}"
                ));
            }
        }
    }
    for (file, _) in MIRRORS {
        if !wgsl_files().iter().any(|f| f == file) {
            wrong.push(format!(
                "MIRRORS names shaders/{file}, which does not exist"
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}
