// The cloud march: one ray through the band, its steps, dither, ground
// shadow and ambient light; the twins of src/render/cpu/renderer.rs.
// `cloud_pixel` is the per-pixel glue the cloud pass's entry point calls.

const REFINE: u32 = 4u;
const NEAR_M: f32 = 3000.0;

// A band segment wider than MARCH_LOG_SPAN of ln(t + NEAR_M) takes more
// steps, at most MARCH_STEP_FACTOR_MAX times (march_step_count).
const MARCH_LOG_SPAN: f32 = 0.35;
const MARCH_STEP_FACTOR_MAX: f32 = 4.0;
const BLUE_NOISE_SIZE: u32 = 64u;

// Samples of the clouds' shadow on the ground (the CPU's renderer.rs).
const GROUND_SHADOW_STEPS: u32 = 12u;

// The golden ratio's fraction (the CPU's sampling::GOLDEN).
const GOLDEN: f32 = 0.618034;

// The clouds' shadow where a ray that meets no terrain reaches the flat
// ground (the CPU's `flat_ground_shadow`).
fn flat_ground_shadow(origin: vec3f, dir: vec3f, sun_dir: vec3f) -> f32 {
    if dir.y >= 0.0 || origin.y <= 0.0 || SHADOW_STEPS == 0u || sun_dir.y <= 0.0 {
        return 1.0;
    }
    let t = origin.y / -dir.y;
    if t > frame.sun_light.w {
        return 1.0;
    }
    let p = vec3f(origin.x + dir.x * t, 0.0, origin.z + dir.z * t);
    return cloud_shadow(p, sun_dir, GROUND_SHADOW_STEPS);
}

// The blue-noise tile's offset of pixel (x, y) (the CPU's `pixel_dither`).
fn pixel_dither(x: u32, y: u32) -> f32 {
    return textureLoad(blue_tex, vec2u(x % BLUE_NOISE_SIZE, y % BLUE_NOISE_SIZE), 0).r;
}

// The distance at march parameter s (the CPU's `march_distance`).
fn march_distance(t0: f32, log_ratio: f32, s: f32) -> f32 {
    return (t0 + NEAR_M) * exp(s * log_ratio) - NEAR_M;
}

// The coarse steps of a band segment that spans log_ratio of
// ln(t + NEAR_M): more where it is wider than MARCH_LOG_SPAN (the CPU's
// `march_step_count`).
fn march_step_count(steps: u32, log_ratio: f32) -> u32 {
    let factor = clamp(log_ratio / MARCH_LOG_SPAN, 1.0, MARCH_STEP_FACTOR_MAX);
    return u32(ceil(f32(max(steps, 1u)) * factor));
}

// The result of one ray: premultiplied cloud radiance (the light of the
// clouds plus the haze in front of them) and opacity, the transmittance-
// weighted cloud distance (for TSAA), and the density samples taken.
struct CloudSample {
    premultiplied: vec4f,
    distance: f32,
    samples: u32,
}

// Marches the band segment of one ray up to `max_t` (the twin of
// `march_ray` less the background, which the composite pass adds).
//
// The CPU's march nests three loops: coarse intervals, the REFINE
// sub-samples of those that touch cloud, and the shadow ray of each lit
// sub-sample. Here they are one loop that reads the density once per
// iteration, the same reads in the same order with the same arithmetic:
// neighbouring pixels that run in lockstep on a GPU (a SIMD group) then
// each go on with their own next read, instead of all waiting while one
// of them refines an interval or marches a shadow ray.
fn march_ray(origin: vec3f, dir: vec3f, dither: f32, max_t: f32) -> CloudSample {
    var out: CloudSample;
    out.premultiplied = vec4f(0.0);
    out.distance = frame.sun_light.w;
    out.samples = 0u;
    let seg = band_segment(origin, dir, frame.band.x, frame.band.y, max_t);
    if seg.y <= seg.x {
        return out;
    }
    let t0 = seg.x;
    let t1 = seg.y;
    let sun_dir = frame.sun_dir.xyz;
    let log_ratio = log((t1 + NEAR_M) / (t0 + NEAR_M));
    let steps = march_step_count(frame.counts.x, log_ratio);
    let spread = frame.cam_pos.w;
    let sun = sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir);
    let sky_top = sky_ambient(sun_dir) * 0.25;
    let ground = ground_up(sun_dir, SEA) * 0.25;
    let cos_theta = dot(dir, sun_dir);
    let forward = forward_step_factor(cos_theta);
    let offset = shadow_offset(dither);
    var transmittance = 1.0;
    var light = vec3f(0.0);
    var depth_weighted = 0.0;
    var samples = 1u;
    var sigma_a = density_at(origin + dir * t0, true, spread * t0);
    // Coarse intervals begun; the current one's sub-samples taken and
    // planned (planned = taken: probe the next interval's far end), its
    // start and sub-step.
    var i = 0u;
    var j = 0u;
    var n = 0u;
    var start = t0;
    var h = 0.0;
    var ta = t0;
    var tb = t0;
    // The lit sub-sample whose light is still to be added, and its shadow
    // ray: steps taken and to take (equal: done), the steps' weights'
    // sum, length, distance, optical depth so far (the whole ray's once
    // it is done, when the light is added).
    var lit = false;
    var lit_t = 0.0;
    var lit_p = vec3f(0.0);
    var lit_footprint = 0.0;
    var lit_sigma = 0.0;
    var k = 0u;
    var shadow_count = 0u;
    var parts = 0.0;
    var shadow_length = 0.0;
    var shadow_t = 0.0;
    var tau = 0.0;
    var lit_left = false;
    var lit_rest = false;
    let toward = toward_sun(cos_theta);
    loop {
        // What this iteration reads: the lit sample's next shadow step,
        // else (its light added first) the next sub-sample or interval end.
        var q = vec3f(0.0);
        var q_footprint = 0.0;
        var dt = 0.0;
        var kind = 0u; // 0: interval end, 1: sub-sample, 2: shadow step
        var t = 0.0;
        if k < shadow_count {
            dt = shadow_length * sqrt(f32(k + 1u)) / parts;
            q = lit_p + sun_dir * (shadow_t + offset * dt);
            if height_fraction(q.y) > 1.0 {
                k = shadow_count;
                lit_left = true;
            } else {
                kind = 2u;
                q_footprint = lit_footprint;
            }
        }
        if kind != 2u {
            if lit {
                lit = false;
                if light_volume_bound() && SHADOW_STEPS > 0u && lit_rest && !lit_left {
                    tau += sun_depth_at(lit_p + sun_dir * shadow_t);
                }
                let eta = clamp((lit_p.y - frame.band.x) / (frame.band.y - frame.band.x), 0.0, 1.0);
                let ambient = ambient_light(sky_top, ground, eta);
                let diffused = light_gains().fluence * light_toward(lit_p, -dir);
                let scatter = sun * (sun_scattering(tau, cos_theta, sun_dir.y, lit_sigma) + diffused) + ambient;
                let s = scatter * (lit_sigma * ALBEDO);
                let step_t = exp(-lit_sigma * h);
                light += integrate_step(s, lit_sigma, h) * transmittance;
                depth_weighted += lit_t * transmittance * (1.0 - step_t);
                transmittance *= step_t;
                if transmittance < MIN_TRANSMITTANCE {
                    break;
                }
            }
            if j == n {
                if i == steps {
                    break;
                }
                tb = march_distance(t0, log_ratio, f32(i + 1u) / f32(steps));
                q = origin + dir * tb;
                q_footprint = spread * tb;
            } else {
                kind = 1u;
                t = start + (f32(j) + dither) * h;
                q = origin + dir * t;
                q_footprint = spread * t;
            }
        }
        let sigma = density_at(q, true, q_footprint);
        samples += 1u;
        if kind == 2u {
            tau += sigma * dt;
            shadow_t += dt;
            k += 1u;
        } else if kind == 0u {
            let touched = sigma_a > 0.0 || sigma > 0.0;
            sigma_a = sigma;
            n = 1u;
            h = tb - ta;
            if touched {
                n = REFINE;
                h = (tb - ta) / f32(REFINE);
            }
            start = ta;
            ta = tb;
            j = 0u;
            i += 1u;
        } else {
            j += 1u;
            if sigma > 0.0 {
                lit = true;
                lit_t = t;
                lit_p = q;
                lit_footprint = q_footprint;
                lit_sigma = sigma;
                tau = 0.0;
                shadow_t = 0.0;
                shadow_length = shadow_ray_length(q, sun_dir);
                lit_left = false;
                lit_rest = false;
                if light_volume_bound() {
                    let r = near_shadow_ray(q, sun_dir, SHADOW_STEPS, forward, toward);
                    shadow_length = r.length;
                    shadow_count = r.count;
                    lit_rest = r.rest;
                } else {
                    shadow_count = shadow_step_count(SHADOW_STEPS, shadow_length, forward);
                }
                parts = shadow_parts(shadow_count);
                k = 0u;
            }
        }
    }
    let opacity = 1.0 - transmittance;
    var cloud_distance = 0.0;
    if opacity > 0.0 {
        cloud_distance = depth_weighted / opacity;
        out.distance = cloud_distance;
    }
    let a = aerial(dir, cloud_distance, sun_dir);
    out.premultiplied = vec4f(light * a.transmittance + a.inscatter * opacity, opacity);
    out.samples = samples;
    return out;
}

// The march of one pixel at fragment position `pos` up to `max_t`; with
// `sea`, the change the clouds the sea mirrors make to the sea behind,
// under the clouds' transmittance.
fn cloud_pixel(pos: vec2f, max_t: f32, sea: bool) -> CloudSample {
    let px = vec2u(pos);
    let dir = camera_ray(pos + frame.jitter.xy);
    let dither = fract(pixel_dither(px.x, px.y) + frame.jitter.z);
    var s = march_ray(frame.cam_pos.xyz, dir, dither, max_t);
    if SEA && sea && frame.exposure.y > 0.5 {
        let change = sea_reflection_change(frame.cam_pos.xyz, dir, dither, frame.sun_dir.xyz);
        s.premultiplied = vec4f(s.premultiplied.rgb + (1.0 - s.premultiplied.a) * change, s.premultiplied.a);
    }
    if DEBUG_COUNT {
        s.premultiplied = vec4f(f32(s.samples), 0.0, 0.0, 0.0);
    }
    return s;
}
