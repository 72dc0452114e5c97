// What the two stand-alone passes share, the pseudo-spheroids
// (spheroids.wgsl) and the precomputed volumes (volume.wgsl); appended
// before either. The CPU twin is src/render/cpu/standalone.rs.

// The per-pixel dither (interleaved gradient noise, Jimenez 2014), so the
// passes need no blue-noise texture.
fn standalone_dither(x: u32, y: u32) -> f32 {
    return fract(52.982918 * fract(0.06711056 * f32(x) + 0.00583715 * f32(y)));
}

// The end of a march: the clouds' scattered light seen through the air to
// their transmittance-weighted mean distance, premultiplied, opacity in w.
fn hazed_clouds(light: vec3f, transmittance: f32, depth_weighted: f32, dir: vec3f, sun_dir: vec3f) -> vec4f {
    let opacity = 1.0 - transmittance;
    var distance = 0.0;
    if opacity > 0.0 {
        distance = depth_weighted / opacity;
    }
    let a = aerial(dir, distance, sun_dir);
    return vec4f(light * a.transmittance + a.inscatter * opacity, opacity);
}

// The stand-alone passes have no cloud layer to read the sun's visibility
// from, and draw no glare (composite.wgsl's glare_at is not called): the
// sky counts as hidden.
fn terrain_hides(px: vec2i) -> bool {
    return true;
}
