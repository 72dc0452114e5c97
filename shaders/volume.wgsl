// The volume renderer (after Iwasaki, Nishino & Dobashi 2011): clouds
// played back from precomputed density volumes, all in one 3D texture of
// 8-bit densities stacked along y; each frame blends two of them (the
// cross-dissolve) and marches the band. `[simulation] method = "endless"`
// draws a scene with it. The CPU twin is src/render/cpu/volume.rs. The
// sky, haze and tone map are the cloud pass's own functions. Appended to
// CLOUDS and COMPOSITE (src/render/gpu/shaders.rs).

// Keep in sync with src/render/cpu/volume.rs: VolumeParams.
struct VolumeParams {
    origin: vec4f, // the box's lowest corner (m)
    extent: vec4f, // the box's size (m); extinction of a full texel (1/m)
    dims: vec4u,   // voxels of one volume along x, y, z; volumes stacked
    pick: vec4f,   // the two volumes shown, the second's weight
}

@group(1) @binding(0) var volumes: texture_3d<f32>;
@group(1) @binding(1) var<uniform> volume: VolumeParams;

// Samples of a lit sample's shadow march towards the sun.
const VOLUME_SHADOW_STEPS: u32 = 6u;
// The longest of those marches, m (the CPU's `VOLUME_SHADOW_RAY_M`).
const VOLUME_SHADOW_RAY_M: f32 = 2000.0;

fn volume_texel(x: i32, y: i32, z: i32) -> f32 {
    return textureLoad(volumes, vec3i(x, y, z), 0).r;
}

// Volume `slab`'s density at p in 0..1: trilinear between voxel centres,
// periodic across, 0 past the band's ends.
fn volume_sample(p: vec3f, slab: f32) -> f32 {
    let dims = vec3f(volume.dims.xyz);
    let g = (p - volume.origin.xyz) / volume.extent.xyz * dims - vec3f(0.5);
    if g.y < -1.0 || g.y > dims.y {
        return 0.0;
    }
    let f = floor(g);
    let t = g - f;
    let nx = i32(volume.dims.x);
    let ny = i32(volume.dims.y);
    let nz = i32(volume.dims.z);
    let base = i32(slab) * ny;
    let x0 = wrap_i(i32(f.x), nx);
    let x1 = (x0 + 1) % nx;
    let z0 = wrap_i(i32(f.z), nz);
    let z1 = (z0 + 1) % nz;
    let y0 = i32(f.y);
    let y1 = y0 + 1;
    var a = vec4f(0.0); // rows y0: (x0,z0), (x1,z0), (x0,z1), (x1,z1)
    var b = vec4f(0.0); // rows y1
    if y0 >= 0 && y0 < ny {
        a = vec4f(volume_texel(x0, base + y0, z0), volume_texel(x1, base + y0, z0),
            volume_texel(x0, base + y0, z1), volume_texel(x1, base + y0, z1));
    }
    if y1 >= 0 && y1 < ny {
        b = vec4f(volume_texel(x0, base + y1, z0), volume_texel(x1, base + y1, z0),
            volume_texel(x0, base + y1, z1), volume_texel(x1, base + y1, z1));
    }
    let x00 = mix(a.x, a.y, t.x);
    let x10 = mix(b.x, b.y, t.x);
    let x01 = mix(a.z, a.w, t.x);
    let x11 = mix(b.z, b.w, t.x);
    return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

// Extinction (1/m) at p: the two picked volumes blended.
fn volume_density(p: vec3f) -> f32 {
    let a = volume_sample(p, volume.pick.x);
    let b = volume_sample(p, volume.pick.y);
    return volume.extent.w * mix(a, b, volume.pick.z);
}

// The sun's optical depth from p: even steps along the shadow ray.
fn volume_optical_depth(p: vec3f, sun_dir: vec3f, length: f32) -> f32 {
    let dt = length / f32(VOLUME_SHADOW_STEPS);
    var tau = 0.0;
    for (var i = 0u; i < VOLUME_SHADOW_STEPS; i++) {
        tau += volume_density(p + sun_dir * ((f32(i) + 0.5) * dt)) * dt;
    }
    return tau;
}

// The band's march with steps growing with distance (`march_distance`),
// one density read per step, a shadow march per lit step.
fn march_volume(origin: vec3f, dir: vec3f, dither: f32) -> vec4f {
    let seg = band_segment(origin, dir, frame.band.x, frame.band.y, frame.sun_light.w);
    if seg.y <= seg.x {
        return vec4f(0.0);
    }
    let t0 = seg.x;
    let sun_dir = frame.sun_dir.xyz;
    let log_ratio = log((seg.y + NEAR_M) / (t0 + NEAR_M));
    let steps = march_step_count(frame.counts.x, log_ratio);
    let l = standalone_light(dir, sun_dir);
    var march = StandaloneMarch(vec3f(0.0), 1.0, 0.0);
    for (var i = 0u; i < steps; i++) {
        let ta = march_distance(t0, log_ratio, f32(i) / f32(steps));
        let tb = march_distance(t0, log_ratio, f32(i + 1u) / f32(steps));
        let t = ta + dither * (tb - ta);
        let dt = tb - ta;
        let p = origin + dir * t;
        let sigma_t = volume_density(p);
        if sigma_t <= 0.0 {
            continue;
        }
        let length = min(shadow_ray_length(p, sun_dir), VOLUME_SHADOW_RAY_M);
        let tau_sun = volume_optical_depth(p, sun_dir, length);
        if standalone_step(&march, l, p, t, dt, sigma_t, tau_sun) {
            break;
        }
    }
    return hazed_clouds(march, dir, sun_dir);
}

@fragment
fn fs_volume(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let px = vec2u(pos.xy);
    let dir = camera_ray(pos.xy);
    let c = march_volume(frame.cam_pos.xyz, dir, standalone_dither(px.x, px.y));
    let bg = cirrus_over(frame.cam_pos.xyz, dir, frame.sun_dir.xyz, frame.cam_pos.w, background_radiance(dir, frame.sun_dir.xyz, sea_waves_at(frame.cam_pos.xyz, dir), 1.0, flat_ground_albedo(frame.cam_pos.xyz, dir, frame.cam_pos.w), vec4f(0.0, 0.0, 0.0, 1.0)));
    return vec4f(display(c.rgb + (1.0 - c.a) * bg, pos.xy), 1.0);
}
