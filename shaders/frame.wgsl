// The frame's shared values, the twin of src/render/cpu/frame.rs (the
// march's early exit), with what every pass reads: the `Frame`
// uniform (FrameUniforms in src/render/gpu/uniforms.rs), bind group 0, the
// pipeline-overridable feature switches and the full-screen triangle.
//
// src/render/gpu/shaders.rs assembles the cloud pass from this file, then
// camera, density, lighting, sky, waves, sea, tone_map, renderer (each the
// twin of the Rust module of the same name), land and the sky model's file,
// and appends each variant's bindings and entry point, so a variant that a
// scene does not need is not built.

// Pipeline-overridable constants: features that are off are folded away
// by the shader compiler, so they cost nothing.
override SHADOW_STEPS: u32 = 20u;
override OCTAVES: u32 = 3u;
override DETAIL: bool = true;

// The fine billows near the camera (`[render] fine_detail`), read only
// with DETAIL.
override FINE_DETAIL: bool = true;
override DEBUG_COUNT: bool = false;

// The sea below the horizon (else land), its wind speed (m/s) and the
// direction the wind blows toward (degrees clockwise from north).
override SEA: bool = false;
override SEA_WIND_MPS: f32 = 7.0;
override SEA_WIND_TOWARD_DEG: f32 = 90.0;

// Fade clouds and ground with distance (`[render.atmosphere]
// aerial_perspective`), read by the sky file's `aerial`.
override AERIAL_PERSPECTIVE: bool = true;

// The cloud pass reads the light volume: the light's gains fitted beside
// it (`light_gains`), else those of the renderers without one.
override LIGHT_VOLUME: bool = false;

const PI: f32 = 3.14159265358979;
// Transmittance below which the march stops (opacity early exit).
const MIN_TRANSMITTANCE: f32 = 0.01;

// Mirrors `FrameUniforms` in src/render/gpu/uniforms.rs (432 bytes). The
// camera is `View`'s (src/render/camera.rs): any perspective projection,
// standard or reversed depth.
struct Frame {
    cam_pos: vec4f,      // eye xyz (m), pixel spread (rad)
    screen: vec4f,       // width, height (px), depth of an empty pixel (1, or 0 reversed), 1 if the depth read is stored flipped
    sun_dir: vec4f,      // xyz, haze distance (m)
    sun_light: vec4f,    // sun colour * SUN_INTENSITY, max distance (m)
    exposure: vec4f,     // exposure before the tone map, 1 when the cloud layer carries the sea's mirrored clouds (else 0), the share of the ground under cloud, the sun glare's strength (render.sun_glare)
    band: vec4f,         // bottom (m), top (m), coverage, extinction (1/m)
    map: vec4f,          // extent (m), detail strength, detail scale (m), map texel (m)
    jitter: vec4f,       // sub-pixel offset x, y (px), dither offset, TSAA blend
    terrain: vec4f,      // extent (m), highest point (m), the sea's clock (s), mesh stride
    counts: vec4u,       // steps, P width, P height, frame index
    mask: vec4u,         // mask width, height, P texels per mask cell, unused
    view_proj: mat4x4f,
    prev_view_proj: mat4x4f,
    inverse_projection: mat4x4f,
    view_to_world: mat4x4f,
}
@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var p_tex: texture_2d<f32>;
@group(0) @binding(2) var cm_tex: texture_2d<f32>;
@group(0) @binding(3) var mask_tex: texture_2d<u32>;
@group(0) @binding(4) var wrap_linear: sampler;
@group(0) @binding(5) var noise_tex: texture_3d<f32>;
@group(0) @binding(6) var blue_tex: texture_2d<f32>;

fn normalize_or(v: vec3f, fallback: vec3f) -> vec3f {
    let l = length(v);
    if l > 0.0 && l < 3.4e38 {
        return v / l;
    }
    return fallback;
}

struct FullScreen {
    @builtin(position) position: vec4f,
}

@vertex
fn vs_full_screen(@builtin(vertex_index) i: u32) -> FullScreen {
    // One triangle that covers the screen.
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    var out: FullScreen;
    out.position = vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
    return out;
}
