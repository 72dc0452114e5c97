// The sky's light shared by both sky models, the flat land's and the sea's
// surface light; the twins of src/render/cpu/sky.rs.

const SUN_DISK_COS: f32 = 0.999989;
const WATER_F0: f32 = 0.0204;

// The share of the sun's horizontal irradiance a whole sky of cloud sends
// down onto the land (the CPU's sky.rs).
const GROUND_CLOUD_LIGHT: f32 = 0.53;

// Strata of the unresolved slopes the mirrored sky averages (the CPU's
// sky.rs).
const SKY_MIRROR_RAYS: u32 = 8u;

// (inscattered light, transmittance) of the air in front of something
// (the CPU's `aerial`, a tuple there).
struct Aerial {
    inscatter: vec3f,
    transmittance: vec3f,
}

// The sky file appended after this one (sky_analytic.wgsl or
// sky_physical.wgsl) defines sun_light_at, sky_above, aerial, ground_haze
// and sun_disk, the twins of src/render/cpu/sky.rs.

// The flat land's albedo (the CPU's sky.rs).
const LAND_ALBEDO: vec3f = vec3f(0.08, 0.1, 0.06);

// The flat land's own light (the CPU's `land_surface`).
fn land_surface(sun_dir: vec3f, shadow: f32, albedo: vec3f) -> vec3f {
    let sun = sun_light_at(0.0, sun_dir);
    let lit = sun * (max(sun_dir.y, 0.0) * shadow / PI) + sky_ambient(sun_dir);
    return albedo * lit;
}

// The flat land through the air, its sunlit part dimmed by the clouds'
// shadow, with the sunlight the clouds scatter down onto it (the CPU's
// `land_radiance`).
fn land_radiance(dir: vec3f, sun_dir: vec3f, shadow: f32, albedo: vec3f) -> vec3f {
    let surface = land_surface(sun_dir, shadow, albedo) + albedo * ground_cloud_light(sun_dir);
    return ground_haze(surface, dir, sun_dir);
}

// The sunlight the clouds scatter down onto the land, its irradiance over
// π per unit albedo, for the share frame.exposure.z of the ground under
// cloud (the CPU's `ground_cloud_light`).
fn ground_cloud_light(sun_dir: vec3f) -> vec3f {
    let cover = clamp(frame.exposure.z, 0.0, 1.0);
    return sun_light_at(0.5 * (frame.band.x + frame.band.y), sun_dir) * (GROUND_CLOUD_LIGHT * cover * max(sun_dir.y, 0.0) / PI);
}

// Schlick's Fresnel reflectance of water (the CPU's `fresnel_water`).
fn fresnel_water(cos_i: f32) -> f32 {
    let c = 1.0 - clamp(cos_i, 0.0, 1.0);
    return WATER_F0 + (1.0 - WATER_F0) * c * c * c * c * c;
}

// The water's own light (the CPU's `water_light`).
fn water_light(sun: vec3f, sun_dir: vec3f) -> vec3f {
    return vec3f(0.004, 0.012, 0.02)
        * (sun * (max(sun_dir.y, 0.0) / PI) + sky_ambient(sun_dir));
}

// The ray the sea sends up along `dir` under the resolved waves, at least
// 1e-3 up (the CPU's `sea_mirror`).
fn sea_mirror(dir: vec3f, waves: vec3f) -> vec3f {
    let n = wave_normal(waves);
    let r = dir - n * (2.0 * dot(dir, n));
    return normalize_or(vec3f(r.x, max(r.y, 1e-3), r.z), vec3f(0.0, 1.0, 0.0));
}

// The sea's Fresnel reflectance under the resolved waves (the CPU's
// `sea_fresnel`).
fn sea_fresnel(dir: vec3f, waves: vec3f) -> f32 {
    return fresnel_water(max(-dot(dir, wave_normal(waves)), 1e-3));
}

// The wind-roughened sea along `dir` (pointing down) under `waves`: the
// sky mirrored by the resolved waves, the sun's glint (the unresolved
// slopes about the resolved one, Beckmann), the water's own blue, the air
// in front (the CPU's `sea_radiance`).
fn sea_radiance(dir: vec3f, sun_dir: vec3f, waves: vec3f, shadow: f32, reflection: vec4f) -> vec3f {
    let mu = max(-dir.y, 1e-3);
    let f = sea_fresnel(dir, waves);
    let reflected = reflection.rgb + mirrored_sky(dir, waves, sun_dir) * reflection.a;
    let sun = sun_light_at(0.0, sun_dir) * shadow;
    let variance = waves.z;
    let h = normalize_or(sun_dir - dir, vec3f(0.0, 1.0, 0.0));
    let cos_b = max(h.y, 1e-3);
    let tan2 = (h.x / cos_b + waves.x) * (h.x / cos_b + waves.x) + (h.z / cos_b + waves.y) * (h.z / cos_b + waves.y);
    let cos2 = cos_b * cos_b;
    let d = exp(-tan2 / variance) / (PI * variance * cos2 * cos2);
    var glint = vec3f(0.0);
    if sun_dir.y > 0.0 {
        glint = sun * (fresnel_water(dot(h, sun_dir)) * d / (4.0 * mu));
    }
    let surface = reflected * f + glint + water_light(sun, sun_dir) * (1.0 - f);
    return ground_haze(surface, dir, sun_dir);
}

// The sky the sea mirrors along `dir` under the waves: the mean over
// SKY_MIRROR_RAYS strata of the unresolved slopes about the resolved
// waves' mirror ray (the CPU's `mirrored_sky`).
fn mirrored_sky(dir: vec3f, waves: vec3f, sun_dir: vec3f) -> vec3f {
    let r0 = sea_mirror(dir, waves);
    let across = normalize_or(vec3f(r0.x, 0.0, r0.z), vec3f(0.0, 0.0, 1.0));
    let mirror = asin(clamp(r0.y, -1.0, 1.0));
    var sum = vec3f(0.0);
    for (var k = 0u; k < SKY_MIRROR_RAYS; k++) {
        let u = (f32(k) + 0.5) / f32(SKY_MIRROR_RAYS);
        let e = reflected_elevation(mirror, waves.z, u);
        sum += sky_above(reflected_ray(across, mirror, e, 0.0), sun_dir);
    }
    return sum / f32(SKY_MIRROR_RAYS);
}

// The light rising from the flat ground, unshadowed (the CPU's
// `ground_up`).
fn ground_up(sun_dir: vec3f, sea: bool) -> vec3f {
    if sea {
        let sun = sun_light_at(0.0, sun_dir);
        return sky_above(vec3f(0.0, 1.0, 0.0), sun_dir) * WATER_F0 + water_light(sun, sun_dir) * (1.0 - WATER_F0);
    }
    return land_surface(sun_dir, 1.0, LAND_ALBEDO);
}

// The sky and the sun disk, or below the horizon the land (of albedo
// `land`) or the sea in the clouds' shadow (the CPU's
// `background_radiance`).
fn background_radiance(dir: vec3f, sun_dir: vec3f, waves: vec3f, shadow: f32, land: vec3f, reflection: vec4f) -> vec3f {
    if dir.y >= 0.0 {
        return sky_above(dir, sun_dir) + sun_disk(dir, sun_dir);
    }
    if SEA {
        return sea_radiance(dir, sun_dir, waves, shadow, reflection);
    }
    return land_radiance(dir, sun_dir, shadow, land);
}
