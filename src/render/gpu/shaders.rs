//! WGSL sources, assembled per variant. Each file under `shaders/` that
//! holds shared functions is the twin of the Rust module of the same name
//! (`density.wgsl` of `render::cpu::density`, and so on; `tests/shader_twins.rs`
//! checks it function by function). [`CLOUDS`] is those files in one
//! string; then `shaders/land.wgsl` (the land's albedo) and the sky
//! model's file (`sky_analytic.wgsl`, or the sky tables and
//! `sky_physical.wgsl` with the tables' bindings); each pass appends its
//! own file, and the variant's bindings and entry point are appended here,
//! so a feature a scene does not use has no binding, no output and no code.

/// The shared functions of every pass: the frame's values and bindings,
/// then the twins of `render::camera` and of `render::cpu`'s `density`,
/// `lighting`, `sky`, `cirrus`, `waves`, `sea`, `tone_map` and `renderer`.
pub const CLOUDS: &str = concat!(
    include_str!("../../../shaders/frame.wgsl"),
    "\n",
    include_str!("../../../shaders/camera.wgsl"),
    "\n",
    include_str!("../../../shaders/density.wgsl"),
    "\n",
    include_str!("../../../shaders/lighting.wgsl"),
    "\n",
    include_str!("../../../shaders/sky.wgsl"),
    "\n",
    include_str!("../../../shaders/cirrus.wgsl"),
    "\n",
    include_str!("../../../shaders/waves.wgsl"),
    "\n",
    include_str!("../../../shaders/sea.wgsl"),
    "\n",
    include_str!("../../../shaders/tone_map.wgsl"),
    "\n",
    include_str!("../../../shaders/renderer.wgsl"),
);
/// The composite pass: its tone map and output (`composite.wgsl`, the
/// twins of `render::cpu::tone_map`) and the sun's glare (`glare.wgsl`,
/// of `render::cpu::glare`).
pub const COMPOSITE: &str = concat!(
    include_str!("../../../shaders/composite.wgsl"),
    "\n",
    include_str!("../../../shaders/glare.wgsl"),
);
/// The TSAA resolve pass.
pub const TSAA: &str = include_str!("../../../shaders/tsaa.wgsl");
/// The terrain pass.
pub const TERRAIN: &str = include_str!("../../../shaders/terrain.wgsl");
/// The sky tables' functions (a library: no bindings, no entry points).
pub const SKY_LUTS: &str = concat!(
    include_str!("../../../shaders/sky_luts/atmosphere.wgsl"),
    "\n",
    include_str!("../../../shaders/sky_luts/tables.wgsl"),
    "\n",
    include_str!("../../../shaders/sky_luts/lookups.wgsl"),
);
/// The sky tables' compute entry points (after [`SKY_LUTS`]).
pub const SKY_LUTS_BUILD: &str = include_str!("../../../shaders/sky_luts_build.wgsl");
/// What the spheroid and volume passes share (after [`COMPOSITE`]).
pub const STANDALONE: &str = include_str!("../../../shaders/standalone.wgsl");
/// The analytic sky's functions (after [`CLOUDS`]).
pub const SKY_ANALYTIC: &str = include_str!("../../../shaders/sky_analytic.wgsl");
/// The physical sky's functions and table bindings (after [`CLOUDS`] and
/// [`SKY_LUTS`]).
pub const SKY_PHYSICAL: &str = include_str!("../../../shaders/sky_physical.wgsl");
/// The land's albedo, plain or fields and woods (after [`CLOUDS`]).
pub const LAND: &str = include_str!("../../../shaders/land.wgsl");
/// The spheroid renderer's pass (after [`COMPOSITE`] and [`STANDALONE`]).
pub const SPHEROIDS: &str = include_str!("../../../shaders/spheroids.wgsl");
/// The volume renderer's pass (after [`COMPOSITE`] and [`STANDALONE`]).
pub const VOLUME: &str = include_str!("../../../shaders/volume.wgsl");

/// The light volume's grid (after [`CLOUDS`]; each module that appends it
/// declares `volume_grid`).
pub const LIGHT_GRID: &str = include_str!("../../../shaders/light_grid.wgsl");
/// The sunlight's transport (after [`LIGHT_GRID`]; reads `light_cells`,
/// adds to `light_tracks`).
pub const LIGHT_TRANSPORT: &str = include_str!("../../../shaders/light_transport.wgsl");
/// The light volume's compute entry points (after [`LIGHT_TRANSPORT`]).
pub const LIGHT_VOLUME_BUILD: &str = include_str!("../../../shaders/light_volume_build.wgsl");

/// `light_toward` where there is no light volume: nothing transported.
const NO_LIGHT: &str = "fn light_toward(p: vec3f, to_eye: vec3f) -> f32 {\n    return 0.0;\n}\n\nfn light_volume_bound() -> bool {\n    return false;\n}\n\nfn sun_depth_at(p: vec3f) -> f32 {\n    return 0.0;\n}\n";

/// The cloud pass's bindings of the light volume (group 2: its three
/// planes and their sampler) and its read.
const LIGHT_READ: &str = "@group(2) @binding(0) var light_plane0: texture_3d<f32>;
@group(2) @binding(1) var light_plane1: texture_3d<f32>;
@group(2) @binding(2) var light_plane2: texture_3d<f32>;
@group(2) @binding(3) var light_sampler: sampler;

// The transported sunlight at p scattered toward `to_eye`, per unit
// scattering coefficient and sun irradiance, read where p reads P (the
// CPU's `LightVolume::light_toward`): the texel centres are the cells'.
fn light_toward(p: vec3f, to_eye: vec3f) -> f32 {
    let q = noise_point(p, warped_lookup(p.x, p.z));
    let uvw = vec3f(q.x / frame.map.x, (q.y - frame.band.x) / (frame.band.y - frame.band.x), q.z / frame.map.x);
    let a = textureSampleLevel(light_plane0, light_sampler, uvw, 0.0);
    let b = textureSampleLevel(light_plane1, light_sampler, uvw, 0.0);
    let c = textureSampleLevel(light_plane2, light_sampler, uvw, 0.0);
    let y = sh9(to_eye);
    let s = dot(a, vec4f(y[0], y[1], y[2], y[3])) + dot(b, vec4f(y[4], y[5], y[6], y[7])) + c.x * y[8];
    return max(s, 0.0);
}

// The march reads the sun's optical depth beyond its shadow rays' near
// steps from the light volume (the CPU's `Frame::light` is some).
fn light_volume_bound() -> bool {
    return true;
}

// The sun's optical depth from p through the clouds' mean extinction
// (the third plane's second channel), read where p reads P (the CPU's
// `LightVolume::sun_depth_at`).
fn sun_depth_at(p: vec3f) -> f32 {
    let q = noise_point(p, warped_lookup(p.x, p.z));
    let uvw = vec3f(q.x / frame.map.x, (q.y - frame.band.x) / (frame.band.y - frame.band.x), q.z / frame.map.x);
    return textureSampleLevel(light_plane2, light_sampler, uvw, 0.0).y;
}
";

/// The shared functions with the sky model's: the physical atmosphere's
/// tables (bindings 7 to 11 of group 0) when `physical`, else the
/// analytic sky; no light volume.
pub fn shared(physical: bool) -> String {
    format!("{}{NO_LIGHT}", sky_model(physical))
}

fn sky_model(physical: bool) -> String {
    if physical {
        format!("{CLOUDS}\n{LAND}\n{SKY_LUTS}\n{SKY_PHYSICAL}\n")
    } else {
        format!("{CLOUDS}\n{LAND}\n{SKY_ANALYTIC}\n")
    }
}

/// The cloud pass's source: marches to the depth buffer's surface when
/// `depth`, and writes the cloud distance for the TSAA reprojection when
/// `tsaa`, under the physical sky when `physical`, reading the light
/// volume (group 2) when `light`.
pub fn cloud_pass(depth: bool, tsaa: bool, physical: bool, light: bool) -> String {
    let mut s = if light {
        format!("{}{LIGHT_READ}", sky_model(physical))
    } else {
        shared(physical)
    };
    if depth {
        s.push_str("\n@group(1) @binding(0) var depth_tex: texture_depth_2d;\n");
    }
    if tsaa {
        s.push_str(
            "\nstruct CloudOut {\n    @location(0) cloud: vec4f,\n    @location(1) distance: f32,\n}\n",
        );
    }
    let out = if tsaa {
        "CloudOut"
    } else {
        "@location(0) vec4f"
    };
    s.push_str(&format!(
        "\n@fragment\nfn fs_clouds(@builtin(position) pos: vec4f) -> {out} {{\n    var max_t = frame.sun_light.w;\n    var sea = true;\n"
    ));
    if depth {
        s.push_str(
            "    let z = view_depth(textureLoad(depth_tex, vec2i(pos.xy), 0));\n    if is_geometry(z) {\n        max_t = min(max_t, depth_to_distance(z, pos.xy));\n        sea = false;\n    }\n",
        );
    }
    s.push_str("    let c = cloud_pixel(pos.xy, max_t, sea);\n");
    if tsaa {
        s.push_str("    return CloudOut(c.premultiplied, c.distance);\n}\n");
    } else {
        s.push_str("    return c.premultiplied;\n}\n");
    }
    s
}

/// What lies behind the clouds in the composite pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Background {
    /// The analytic sky and sun disk everywhere.
    Sky,
    /// The terrain pass's HDR colour where it drew (alpha 1), sky elsewhere.
    Terrain,
    /// An external depth buffer: sky where the depth is at the far plane;
    /// elsewhere the clouds are blended over the target's colour.
    ExternalDepth,
}

/// The composite pass's source for `background`, under the physical sky
/// when `physical`.
pub fn composite_pass(background: Background, physical: bool) -> String {
    let mut s = format!("{}{COMPOSITE}\n", shared(physical));
    match background {
        Background::Sky => s.push_str(
            "fn terrain_hides(px: vec2i) -> bool {\n    return false;\n}\n@fragment\nfn fs_composite(@builtin(position) pos: vec4f) -> @location(0) vec4f {\n    let c = textureLoad(cloud_tex, vec2i(pos.xy), 0);\n    return vec4f(display(c.rgb + (1.0 - c.a) * sky_background(pos.xy) + glare_at(pos.xy), pos.xy), 1.0);\n}\n",
        ),
        Background::Terrain => s.push_str(
            "@group(1) @binding(1) var background_tex: texture_2d<f32>;\nfn terrain_hides(px: vec2i) -> bool {\n    return textureLoad(background_tex, px, 0).a > 0.5;\n}\n@fragment\nfn fs_composite(@builtin(position) pos: vec4f) -> @location(0) vec4f {\n    let c = textureLoad(cloud_tex, vec2i(pos.xy), 0);\n    let b = textureLoad(background_tex, vec2i(pos.xy), 0);\n    var bg = sky_background(pos.xy);\n    if b.a > 0.5 {\n        bg = b.rgb;\n    }\n    return vec4f(display(c.rgb + (1.0 - c.a) * bg + glare_at(pos.xy), pos.xy), 1.0);\n}\n",
        ),
        Background::ExternalDepth => s.push_str(
            "@group(1) @binding(1) var depth_tex: texture_depth_2d;\nfn terrain_hides(px: vec2i) -> bool {\n    return true;\n}\n@fragment\nfn fs_composite(@builtin(position) pos: vec4f) -> @location(0) vec4f {\n    let c = textureLoad(cloud_tex, vec2i(pos.xy), 0);\n    let d = textureLoad(depth_tex, vec2i(pos.xy), 0);\n    if is_geometry(d) {\n        return vec4f(display(c.rgb, pos.xy), c.a);\n    }\n    return vec4f(display(c.rgb + (1.0 - c.a) * sky_background(pos.xy), pos.xy), 1.0);\n}\n",
        ),
    }
    s
}

/// The TSAA pass's source (it reads no sky: the analytic file only
/// completes the shared functions).
pub fn tsaa_pass() -> String {
    format!("{}{TSAA}", shared(false))
}

/// The terrain pass's source, under the physical sky when `physical`.
pub fn terrain_pass(physical: bool) -> String {
    format!("{}{TERRAIN}", shared(physical))
}

/// The spheroid renderer's source (its bind group 0 holds the uniforms
/// alone, so it draws under the analytic sky).
pub fn spheroids_pass() -> String {
    format!("{}{COMPOSITE}\n{STANDALONE}\n{}", shared(false), SPHEROIDS)
}

/// The volume renderer's source (bind group 0 the uniforms alone: the
/// analytic sky).
pub fn volume_pass() -> String {
    format!("{}{COMPOSITE}\n{STANDALONE}\n{}", shared(false), VOLUME)
}

/// The light volume's build: its four compute entry points over group 0
/// (the density) and group 1 (its buffers).
pub fn light_volume_build() -> String {
    format!(
        "{}{NO_LIGHT}\n{LIGHT_GRID}\n{LIGHT_TRANSPORT}\n{LIGHT_VOLUME_BUILD}",
        sky_model(false)
    )
}

/// The sky tables' source: three compute entry points.
pub fn sky_luts_pass() -> String {
    format!("{SKY_LUTS}\n{SKY_LUTS_BUILD}")
}

/// Every variant's source: under each sky model, the cloud pass with and
/// without depth and TSAA, the composite pass over each background and
/// the terrain; TSAA, the spheroids, the volumes and the sky tables.
pub fn all_variants() -> Vec<String> {
    let mut sources = vec![
        tsaa_pass(),
        spheroids_pass(),
        volume_pass(),
        sky_luts_pass(),
        light_volume_build(),
    ];
    for physical in [false, true] {
        sources.push(terrain_pass(physical));
        for depth in [false, true] {
            for tsaa in [false, true] {
                for light in [false, true] {
                    sources.push(cloud_pass(depth, tsaa, physical, light));
                }
            }
        }
        for b in [
            Background::Sky,
            Background::Terrain,
            Background::ExternalDepth,
        ] {
            sources.push(composite_pass(b, physical));
        }
    }
    sources
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every variant parses and validates with naga (no GPU needed).
    #[test]
    fn every_variant_validates() {
        for src in all_variants() {
            let module = naga::front::wgsl::parse_str(&src)
                .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::empty(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)));
        }
    }
}
