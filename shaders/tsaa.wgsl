// Temporal anti-aliasing of the cloud layer (appended to CLOUDS, shaders.rs).
// Each frame's rays start at a Halton-jittered sub-pixel position and
// dither; this pass reprojects the history to where the current pixel's
// cloud was in the previous frame (through its transmittance-weighted
// cloud distance and the previous view-projection: camera rotation and
// translation alike; rays without cloud reproject by direction), clamps
// it to the current 3x3 neighbourhood (no ghosting) and blends in the new
// frame with weight `frame.jitter.w` (1 on a reset).

@group(1) @binding(0) var current_tex: texture_2d<f32>;
@group(1) @binding(1) var distance_tex: texture_2d<f32>;
@group(1) @binding(2) var history_tex: texture_2d<f32>;
@group(1) @binding(3) var clamp_linear: sampler;

@fragment
fn fs_tsaa(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let px = vec2i(pos.xy);
    let cur = textureLoad(current_tex, px, 0);
    let blend = frame.jitter.w;
    if blend >= 1.0 {
        return cur;
    }
    let size = vec2i(textureDimensions(current_tex));
    var lo = cur;
    var hi = cur;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = clamp(px + vec2i(dx, dy), vec2i(0), size - 1);
            let s = textureLoad(current_tex, q, 0);
            lo = min(lo, s);
            hi = max(hi, s);
        }
    }
    let dist = textureLoad(distance_tex, px, 0).r;
    let world = frame.cam_pos.xyz + camera_ray(pos.xy) * dist;
    let clip = frame.prev_view_proj * vec4f(world, 1.0);
    if clip.w <= 1e-6 {
        return cur;
    }
    let ndc = clip.xy / clip.w;
    let uv = vec2f(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if any(uv < vec2f(0.0)) || any(uv > vec2f(1.0)) {
        return cur;
    }
    let history = clamp(textureSampleLevel(history_tex, clamp_linear, uv, 0.0), lo, hi);
    return mix(history, cur, blend);
}
