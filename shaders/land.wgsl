// The land's albedo: plain, or fields in rows with woods across them
// (`[render.ground] land`), the twins of src/render/cpu/land.rs. Appended
// after CLOUDS (shaders.rs); the woods read the detail volume (group 0's
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
const HEDGE_M: f32 = 4.0;
const HEDGE_CHANCE: f32 = 0.7;
const HEDGE: vec3f = vec3f(0.4, 0.5, 0.36);
const FIELDS_MEAN: vec3f = vec3f(1.2802312, 1.139072, 0.9411938);
const LAND_TINT_MEAN: vec3f = vec3f(1.0311618, 0.9623504, 0.7938356);
const PATCH_TILE_M: f32 = 530.0;
const PATCH_CONTRAST: f32 = 0.12;
const CROWN_M: f32 = 9.0;
const SMALL_CROWN_M: f32 = 5.5;
const CANOPY_FLOOR: f32 = 0.7;
const CROWN_LIGHT_MEAN: f32 = 0.534;

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
        return FIELDS_MEAN;
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
    let u = along / length + f32(r & 1023u) / 1024.0;
    let field = i32(floor(u));
    let h = field_hash(row, field) ^ b;
    let shade = 1.0 + 0.24 * (f32((h >> 8u) & 255u) / 255.0 - 0.5);
    let patches = 1.0 + 2.0 * PATCH_CONTRAST * (woods_noise(x, z, footprint_m, PATCH_TILE_M, 0.375) - 0.5);
    let next_row = field_hash(row + 1, i32(b >> 8u));
    let between_rows = hedge_cover(across - f32(row) * FIELD_WIDTH_M, FIELD_WIDTH_M, footprint_m,
        hedged(r), hedged(next_row));
    let between_fields = hedge_cover((u - f32(field)) * length, length, footprint_m, hedged(h),
        hedged(field_hash(row, field + 1) ^ b));
    let hedge = 1.0 - (1.0 - between_rows) * (1.0 - between_fields);
    let tint = mix(crop(h) * (shade * patches), HEDGE, hedge);
    return mix(FIELDS_MEAN, tint, fade);
}

// 1 where the boundary of hash h is hedged (the CPU's `hedged`).
fn hedged(h: u32) -> f32 {
    if f32(h >> 22u) < HEDGE_CHANCE * 1024.0 {
        return 1.0;
    }
    return 0.0;
}

// The hedges' cover of a footprint a metres into a parcel (the CPU's
// `hedge_cover`).
fn hedge_cover(a: f32, period: f32, footprint_m: f32, start: f32, end: f32) -> f32 {
    let half = 0.5 * max(footprint_m, 1e-3);
    let lo = a - half;
    let hi = a + half;
    let first = max(min(hi, HEDGE_M) - max(lo, 0.0), 0.0);
    let second = max(min(hi, period + HEDGE_M) - max(lo, period), 0.0);
    return min((start * first + end * second) / (2.0 * half), 1.0);
}

// The light of the tree crowns at (x, z) (the CPU's `crown_light`).
fn crown_light(x: f32, z: f32) -> f32 {
    return max(crown_layer(x / CROWN_M, z / CROWN_M, 0),
        0.8 * crown_layer(x / SMALL_CROWN_M + 0.37, z / SMALL_CROWN_M + 0.61, 7919));
}

// One layer of tree crowns (the CPU's `crown_layer`).
fn crown_layer(u: f32, w: f32, salt: i32) -> f32 {
    let ci = i32(floor(u));
    let ck = i32(floor(w));
    var nearest = 3.4028235e38;
    var light = 0.0;
    for (var dk = -1; dk <= 1; dk++) {
        for (var di = -1; di <= 1; di++) {
            let h = field_hash(ci + di + salt, ck + dk) * 0x9e3779b9u;
            let px = f32(ci + di) + (f32(h & 255u) + 0.5) / 256.0;
            let pz = f32(ck + dk) + (f32((h >> 8u) & 255u) + 0.5) / 256.0;
            let d2 = (u - px) * (u - px) + (w - pz) * (w - pz);
            if d2 < nearest {
                nearest = d2;
                let radius = 0.55 + 0.25 * f32((h >> 24u) & 255u) / 255.0;
                let shade = 0.6 + 0.4 * f32((h >> 16u) & 255u) / 255.0;
                light = max(1.0 - d2 / (radius * radius), 0.0) * shade;
            }
        }
    }
    return light;
}

// The woods' canopy at (x, z) (the CPU's `canopy`).
fn canopy(x: f32, z: f32, footprint_m: f32) -> f32 {
    let fade = clamp(2.0 - 2.0 * footprint_m / CROWN_M, 0.0, 1.0);
    if fade <= 0.0 {
        return 1.0;
    }
    let crowns = (CANOPY_FLOOR + crown_light(x, z)) / (CANOPY_FLOOR + CROWN_LIGHT_MEAN);
    return 1.0 + (crowns - 1.0) * fade;
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
    let woods = woods_cover(x, z, footprint_m);
    var trees = WOODS;
    if woods > 0.0 {
        trees = WOODS * canopy(x, z, footprint_m);
    }
    let tint = mix(field_tint(x, z, footprint_m), trees, woods);
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
