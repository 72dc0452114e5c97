// The land's albedo: plain, or fields in rows with woods across them
// (`[render.ground] land`), the twins of src/render/cpu/land.rs. Appended
// after clouds.wgsl; the woods read the detail volume (group 0's
// noise_tex). With LAND_FIELDS off the land is LAND_ALBEDO and nothing
// here runs.

override LAND_FIELDS: bool = false;

const FIELD_LENGTH_M: f32 = 210.0;
const FIELD_WIDTH_M: f32 = 130.0;
const FIELD_ANGLE: f32 = 0.41;
const FARM_TURN: f32 = 0.39;
const FARM_M: f32 = 1700.0;
const FARM_BEND_M: f32 = 300.0;
const WOODS_TILE_M: f32 = 7300.0;
const WOODS_DETAIL_TILE_M: f32 = 2330.0;
const WOODS_THRESHOLD: f32 = 0.617;
const WOODS_EDGE: f32 = 0.02;
const WOODS_SHARP_M: f32 = 40.0;
const WOODS_SOFTEST: f32 = 5.0;
const WOODS_FADE_M: f32 = 1000.0;
const WOODS_SHARE: f32 = 0.3;
const CROP_GRASS: vec3f = vec3f(0.95, 1.1, 0.85);
const CROP_YOUNG: vec3f = vec3f(1.3, 1.25, 0.85);
const CROP_SOIL: vec3f = vec3f(1.35, 0.95, 0.85);
const CROP_STUBBLE: vec3f = vec3f(1.65, 1.35, 1.3);
const WOODS: vec3f = vec3f(0.45, 0.55, 0.45);
const CROPS_MEAN: vec3f = vec3f(1.3125, 1.1625, 0.9625);
const LAND_TINT_MEAN: vec3f = vec3f(1.05375, 0.97875, 0.80875);

// A hash of a field's cell (the CPU's `field_hash`).
fn field_hash(i: i32, j: i32) -> u32 {
    var h = (bitcast<u32>(i) * 0x8da6b343u) ^ (bitcast<u32>(j) * 0xd8163841u);
    h ^= h >> 15u;
    h *= 0x2c1b3c6du;
    h ^= h >> 12u;
    h *= 0x297a2d39u;
    return h ^ (h >> 15u);
}

// Crop k's albedo over the plain land's (the CPU's `crop`).
fn crop(k: u32) -> vec3f {
    switch k & 3u {
        case 0u: {
            return CROP_GRASS;
        }
        case 1u: {
            return CROP_YOUNG;
        }
        case 2u: {
            return CROP_SOIL;
        }
        default: {
            return CROP_STUBBLE;
        }
    }
}

// The hash of the farm at (x, z) (the CPU's `farm`).
fn farm(x: f32, z: f32) -> u32 {
    let bx = i32(floor((x + FARM_BEND_M * sin(z / 900.0)) / FARM_M));
    let bz = i32(floor((z + FARM_BEND_M * sin(x / 1100.0)) / FARM_M));
    return field_hash(2 * bx + 1, 2 * bz);
}

// The fields' tint at world (x, z) (the CPU's `field_tint`).
fn field_tint(x: f32, z: f32, footprint_m: f32) -> vec3f {
    let fade = clamp(2.0 - 2.0 * footprint_m / FIELD_WIDTH_M, 0.0, 1.0);
    if fade <= 0.0 {
        return CROPS_MEAN;
    }
    let b = farm(x, z);
    let angle = FIELD_ANGLE + FARM_TURN * f32(b & 3u);
    let s = sin(angle);
    let c = cos(angle);
    let along = x * c + z * s;
    let across = -x * s + z * c;
    let row = i32(floor(across / FIELD_WIDTH_M));
    let r = field_hash(row, i32(b >> 8u));
    let length = FIELD_LENGTH_M * (0.6 + 0.8 * f32((r >> 12u) & 255u) / 255.0);
    let field = i32(floor(along / length + f32(r & 1023u) / 1024.0));
    let h = field_hash(row, field) ^ b;
    let shade = 1.0 + 0.24 * (f32((h >> 8u) & 255u) / 255.0 - 0.5);
    return mix(CROPS_MEAN, crop(h) * shade, fade);
}

// One scale of the woods' noise (the CPU's `woods_noise`).
fn woods_noise(x: f32, z: f32, footprint_m: f32, tile_m: f32, y: f32) -> f32 {
    let lod = min(lod_of(footprint_m, tile_m / NOISE_SIZE), NOISE_MAX_LOD);
    return gained(textureSampleLevel(noise_tex, wrap_linear, vec3f(x / tile_m, y, z / tile_m), lod).r, lod);
}

// How much of the land at (x, z) is wood (the CPU's `woods_cover`).
fn woods_cover(x: f32, z: f32, footprint_m: f32) -> f32 {
    let fade = clamp(footprint_m / WOODS_FADE_M - 1.0, 0.0, 1.0);
    if fade >= 1.0 {
        return WOODS_SHARE;
    }
    let n = 0.65 * woods_noise(x, z, footprint_m, WOODS_TILE_M, 0.37)
        + 0.35 * woods_noise(x, z, footprint_m, WOODS_DETAIL_TILE_M, 0.71);
    let edge = WOODS_EDGE * clamp(footprint_m / WOODS_SHARP_M, 1.0, WOODS_SOFTEST);
    let cover = smoothstep(WOODS_THRESHOLD - edge, WOODS_THRESHOLD + edge, n);
    return cover + (WOODS_SHARE - cover) * fade;
}

// The land's albedo at (x, z) (the CPU's `land_albedo`).
fn land_albedo(x: f32, z: f32, footprint_m: f32) -> vec3f {
    let tint = mix(field_tint(x, z, footprint_m), WOODS, woods_cover(x, z, footprint_m));
    return LAND_ALBEDO * tint / LAND_TINT_MEAN;
}

// A pixel's width on the ground (the CPU's `ground_footprint`).
fn ground_footprint(spread: f32, t: f32, cos_n: f32) -> f32 {
    return spread * t / max(abs(cos_n), 0.05);
}

// The flat ground's albedo where the ray meets it (the CPU's
// `flat_ground_albedo`).
fn flat_ground_albedo(origin: vec3f, dir: vec3f, spread: f32) -> vec3f {
    if !LAND_FIELDS || dir.y >= 0.0 || origin.y <= 0.0 {
        return LAND_ALBEDO;
    }
    let t = origin.y / -dir.y;
    if t > frame.sun_light.w {
        return LAND_ALBEDO;
    }
    let x = origin.x + dir.x * t;
    let z = origin.z + dir.z * t;
    let land = land_albedo(x, z, ground_footprint(spread, t, dir.y));
    let far = clamp(4.0 * t / frame.sun_light.w - 3.0, 0.0, 1.0);
    return mix(land, LAND_ALBEDO, far);
}
