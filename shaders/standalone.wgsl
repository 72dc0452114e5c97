// What the two stand-alone passes share, the pseudo-spheroids
// (spheroids.wgsl) and the precomputed volumes (volume.wgsl); appended
// before either. The CPU twin is src/render/cpu/standalone.rs.

// The per-pixel dither (interleaved gradient noise, Jimenez 2014), so the
// passes need no blue-noise texture.
fn standalone_dither(x: u32, y: u32) -> f32 {
    return fract(52.982918 * fract(0.06711056 * f32(x) + 0.00583715 * f32(y)));
}

// What lights the samples of one march, the same all along the ray `dir`
// (the CPU's `standalone_light`).
struct StandaloneLight {
    sun: vec3f,
    sky_top: vec3f,
    ground: vec3f,
    cos_theta: f32,
    sun_dir: vec3f,
}

fn standalone_light(dir: vec3f, sun_dir: vec3f) -> StandaloneLight {
    return StandaloneLight(
        sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir),
        sky_ambient(sun_dir) * 0.25,
        ground_up(sun_dir, SEA) * 0.25,
        dot(dir, sun_dir),
        sun_dir,
    );
}

// A march's running sums: the light toward the eye, the transmittance so
// far, the transmittance-weighted distance.
struct StandaloneMarch {
    light: vec3f,
    transmittance: f32,
    depth_weighted: f32,
}

// Adds one sample (extinction `sigma_t` at `p`, `t` along the ray, over
// `dt`, optical depth `tau_sun` toward the sun) to the march `m`; true
// once it is opaque (the CPU's `standalone_step`).
fn standalone_step(m: ptr<function, StandaloneMarch>, l: StandaloneLight, p: vec3f, t: f32, dt: f32, sigma_t: f32, tau_sun: f32) -> bool {
    let eta = clamp((p.y - frame.band.x) / (frame.band.y - frame.band.x), 0.0, 1.0);
    let ambient = ambient_light(l.sky_top, l.ground, eta);
    let src = (l.sun * sun_scattering(tau_sun, l.cos_theta, l.sun_dir.y, sigma_t) + ambient) * (sigma_t * ALBEDO);
    let step_t = exp(-sigma_t * dt);
    (*m).light += integrate_step(src, sigma_t, dt) * (*m).transmittance;
    (*m).depth_weighted += t * (*m).transmittance * (1.0 - step_t);
    (*m).transmittance *= step_t;
    return (*m).transmittance < MIN_TRANSMITTANCE;
}

// The end of a march: the clouds' scattered light seen through the air to
// their transmittance-weighted mean distance, premultiplied, opacity in w.
fn hazed_clouds(m: StandaloneMarch, dir: vec3f, sun_dir: vec3f) -> vec4f {
    let opacity = 1.0 - m.transmittance;
    var distance = 0.0;
    if opacity > 0.0 {
        distance = m.depth_weighted / opacity;
    }
    let a = aerial(dir, distance, sun_dir);
    return vec4f(m.light * a.transmittance + a.inscatter * opacity, opacity);
}

// The stand-alone passes have no cloud layer to read the sun's visibility
// from, and draw no glare (composite.wgsl's glare_at is not called): the
// sky counts as hidden.
fn terrain_hides(px: vec2i) -> bool {
    return true;
}
