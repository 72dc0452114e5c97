// The sun's glare (src/render/cpu/glare.rs, the twins of its functions):
// the CIE glare spread's small-angle term around the sun, lit by the sun
// disk's irradiance at the camera times its visibility through the cloud
// layer at GLARE_TAPS pixels across the disk (a tap below the horizon, on
// the flat ground or sea, hidden), times render.sun_glare
// (frame.exposure.w). Only a tone-mapped target gets it. Each variant of
// fs_composite defines terrain_hides(px): whether its background hides
// the sky at pixel px.
const GLARE_CORE: f32 = 10.0;
const GLARE_MIN_DEG: f32 = 0.27;
const GLARE_TAPS: u32 = 5u;
const GLARE_TAP_REACH: f32 = 0.6;

fn glare_spread(cos_theta: f32) -> f32 {
    let chord = sqrt(max(2.0 - 2.0 * clamp(cos_theta, -1.0, 1.0), 0.0));
    let theta = max(degrees(2.0 * asin(min(0.5 * chord, 1.0))), GLARE_MIN_DEG);
    return GLARE_CORE / (theta * theta * theta);
}

fn sun_glare(dir: vec3f, sun_dir: vec3f, source: vec3f) -> vec3f {
    return source * glare_spread(dot(dir, sun_dir));
}

// The sun's centre in pixels (xy) and 1 (z), or z 0 behind the camera.
fn sun_pixel(sun_dir: vec3f) -> vec3f {
    let c = frame.view_proj * vec4f(sun_dir, 0.0);
    if c.w <= 1e-6 {
        return vec3f(0.0);
    }
    return vec3f(
        (c.x / c.w + 1.0) * 0.5 * frame.screen.x,
        (1.0 - c.y / c.w) * 0.5 * frame.screen.y,
        1.0,
    );
}

fn glare_tap(centre: vec2f, radius_px: f32, tap: u32) -> vec2i {
    let r = GLARE_TAP_REACH * radius_px;
    var o = vec2f(0.0);
    switch tap {
        case 1u: { o = vec2f(-r, 0.0); }
        case 2u: { o = vec2f(r, 0.0); }
        case 3u: { o = vec2f(0.0, -r); }
        case 4u: { o = vec2f(0.0, r); }
        default: {}
    }
    let p = floor(centre + o);
    return vec2i(clamp(p, vec2f(0.0), max(frame.screen.xy, vec2f(1.0)) - 1.0));
}

fn sun_radius_px(pixel_spread: f32) -> f32 {
    return radians(GLARE_MIN_DEG) / max(pixel_spread, 1e-9);
}

fn sun_visibility(sun_dir: vec3f) -> f32 {
    let centre = sun_pixel(sun_dir);
    if centre.z < 0.5 {
        return 0.0;
    }
    let radius = sun_radius_px(frame.cam_pos.w);
    var sum = 0.0;
    for (var tap = 0u; tap < GLARE_TAPS; tap++) {
        let p = glare_tap(centre.xy, radius, tap);
        if !terrain_hides(p) && camera_ray(vec2f(p) + 0.5).y >= 0.0 {
            sum += 1.0 - textureLoad(cloud_tex, p, 0).a;
        }
    }
    return sum / f32(GLARE_TAPS);
}

// The glare's radiance at pixel pos: none without a tone map or with
// render.sun_glare 0.
fn glare_at(pos: vec2f) -> vec3f {
    if !TONE_MAP || frame.exposure.w <= 0.0 {
        return vec3f(0.0);
    }
    let sun_dir = frame.sun_dir.xyz;
    let irradiance = sun_disk_irradiance(sun_dir);
    if all(irradiance == vec3f(0.0)) {
        return vec3f(0.0);
    }
    let source = irradiance * (sun_visibility(sun_dir) * frame.exposure.w);
    return sun_glare(camera_ray(pos), sun_dir, source);
}

