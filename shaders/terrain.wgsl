// The terrain pass (appended to CLOUDS, shaders.rs), built only when the scene has
// terrain: the heightfield rasterised as a grid mesh, tiled around the
// camera to the longest ray, into an HDR colour target and a depth buffer.
// It is lit by the sun through the clouds (their shadow) and the sky, and
// faded by aerial perspective: the twins of `height_at`, `normal_at`,
// `terrain_albedo`, `terrain_radiance` and `cloud_shadow` in src/render/.

@group(1) @binding(0) var height_tex: texture_2d<f32>;

// Bilinear, periodic height at world (x, z), m (`Heightfield::height_at`).
fn height_at(x: f32, z: f32) -> f32 {
    let n = i32(textureDimensions(height_tex).x);
    let extent = frame.terrain.x;
    let fx = x / extent * f32(n);
    let fz = z / extent * f32(n);
    let x0 = floor(fx);
    let z0 = floor(fz);
    let tx = fx - x0;
    let tz = fz - z0;
    let xa = wrap_i(i32(x0), n);
    let xb = wrap_i(i32(x0) + 1, n);
    let za = wrap_i(i32(z0), n);
    let zb = wrap_i(i32(z0) + 1, n);
    let h00 = textureLoad(height_tex, vec2i(xa, za), 0).r;
    let h10 = textureLoad(height_tex, vec2i(xb, za), 0).r;
    let h01 = textureLoad(height_tex, vec2i(xa, zb), 0).r;
    let h11 = textureLoad(height_tex, vec2i(xb, zb), 0).r;
    let top = h00 + (h10 - h00) * tx;
    let bottom = h01 + (h11 - h01) * tx;
    return top + (bottom - top) * tz;
}

fn normal_at(x: f32, z: f32) -> vec3f {
    let e = frame.terrain.x / f32(textureDimensions(height_tex).x);
    let dx = height_at(x + e, z) - height_at(x - e, z);
    let dz = height_at(x, z + e) - height_at(x, z - e);
    return normalize(vec3f(-dx, 2.0 * e, -dz));
}

// The terrain's albedo flat and from a slope of a third (the CPU's
// land.rs).
const TERRAIN_ALBEDO_FLAT: vec3f = vec3f(0.07, 0.11, 0.04);
const TERRAIN_ALBEDO_STEEP: vec3f = vec3f(0.16, 0.13, 0.09);

// The terrain's albedo, tinted by the fields and woods when LAND_FIELDS
// (the CPU's `land::terrain_albedo`).
fn terrain_albedo(p: vec3f, n: vec3f, dir: vec3f, t: f32) -> vec3f {
    var flat = TERRAIN_ALBEDO_FLAT;
    if LAND_FIELDS {
        let footprint_m = ground_footprint(frame.cam_pos.w, t, dot(dir, n));
        flat = TERRAIN_ALBEDO_FLAT * land_albedo(p.x, p.z, footprint_m) / LAND_ALBEDO;
    }
    return mix(flat, TERRAIN_ALBEDO_STEEP, min((1.0 - n.y) * 3.0, 1.0));
}

fn terrain_radiance(p: vec3f, t: f32, dir: vec3f, sun_dir: vec3f) -> vec3f {
    let n = normal_at(p.x, p.z);
    let albedo = terrain_albedo(p, n, dir, t);
    var shadow = 1.0;
    if SHADOW_STEPS > 0u && sun_dir.y > 0.0 {
        shadow = cloud_shadow(p, sun_dir, GROUND_SHADOW_STEPS);
    }
    let sun = sun_light_at(p.y, sun_dir);
    let sky = sky_ambient(sun_dir) + ground_cloud_light(sun_dir);
    let lit = albedo * (sun * (max(dot(n, sun_dir), 0.0) * shadow / PI) + sky * (0.5 + 0.5 * n.y));
    let a = aerial(dir, t, sun_dir);
    return lit * a.transmittance + a.inscatter;
}

struct TerrainVertex {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
}

// The most tiles the mesh reaches out in each direction (the scene
// refuses tiles so small that rays would reach further).
const TERRAIN_REACH_MAX: u32 = 512u;

// One vertex of tile `ii`'s mesh: every `frame.terrain.w`-th height of
// the heightfield (1 unless the full mesh of every tile out to the
// longest ray would exceed the pass's vertex budget, `mesh_stride`), the
// last quad of a row narrower when the stride does not divide the side.
@vertex
fn vs_terrain(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> TerrainVertex {
    let n = textureDimensions(height_tex).x;
    let extent = frame.terrain.x;
    let stride = max(u32(frame.terrain.w), 1u);
    let m = (n + stride - 1u) / stride;
    let quad = vi / 6u;
    let corner = vi % 6u;
    var d = vec2u(0u, 0u);
    if corner == 1u || corner == 4u {
        d = vec2u(1u, 0u);
    } else if corner == 2u || corner == 3u {
        d = vec2u(0u, 1u);
    } else if corner == 5u {
        d = vec2u(1u, 1u);
    }
    let g = min((vec2u(quad % m, quad / m) + d) * stride, vec2u(n));
    // Tiles around the camera's tile, enough to reach the longest ray.
    let reach = i32(min(u32(ceil(frame.sun_light.w / extent)), TERRAIN_REACH_MAX));
    let side = 2 * reach + 1;
    let tile = vec2i(i32(ii) % side - reach, i32(ii) / side - reach)
        + vec2i(floor(frame.cam_pos.xz / extent));
    let xz = (vec2f(tile) + vec2f(g) / f32(n)) * extent;
    let y = textureLoad(height_tex, vec2i(g % n), 0).r;
    var out: TerrainVertex;
    out.world = vec3f(xz.x, y, xz.y);
    out.clip = frame.view_proj * vec4f(out.world, 1.0);
    // A reversed-depth view's depth is stored flipped (1 - d), so this
    // buffer is always cleared to 1 and compared with `Less`; the cloud
    // pass flips it back (`frame.screen.w`). `screen.z` is the view's far
    // depth: 1 standard (no flip), 0 reversed.
    out.clip.z = mix(out.clip.w - out.clip.z, out.clip.z, frame.screen.z);
    return out;
}

@fragment
fn fs_terrain(in: TerrainVertex) -> @location(0) vec4f {
    let to = in.world - frame.cam_pos.xyz;
    let t = length(to);
    let dir = to / max(t, 1e-3);
    return vec4f(terrain_radiance(in.world, t, dir, frame.sun_dir.xyz), 1.0);
}
