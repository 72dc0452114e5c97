// The sunlight's Monte Carlo transport on the light grid: the twin of
// src/render/cpu/light_transport.rs (same names; the same random numbers
// for the same photon and seed). Appended after light_grid.wgsl;
// `follow` reads the cells' extinction (`light_cells`) and adds its
// tracks to `light_tracks`, fixed point (TRACK_UNIT metres), which
// light_volume_build.wgsl declares.

const CELLS_PER_PHOTON_MAX: u32 = 20000u;
const ROULETTE_WEIGHT: f32 = 0.1;
const TRACK_UNIT: f32 = 0.00390625;

// The stream of photon `photon` under `seed` (the CPU's `Rng::new`).
fn rng_seed(photon: u32, seed: u32) -> u32 {
    var state = photon ^ (seed * 0x9E3779B9u);
    rng_next(&state);
    return state;
}

// Uniform in [0, 1): PCG's RXS-M-XS output (the CPU's `Rng::next`).
fn rng_next(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    let x = (word >> 22u) ^ word;
    return f32(x >> 8u) / 16777216.0;
}

// A cosine drawn from the Henyey-Greenstein phase of asymmetry `g`.
fn sample_hg(g: f32, u: f32) -> f32 {
    if abs(g) < 1e-3 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// Two unit vectors square to unit `d` and to each other.
fn orthonormal_pair(d: vec3f) -> array<vec3f, 2> {
    let sign = select(-1.0, 1.0, d.z >= 0.0);
    let a = -1.0 / (sign + d.z);
    let b = d.x * d.y * a;
    return array<vec3f, 2>(
        vec3f(1.0 + sign * d.x * d.x * a, sign * b, -sign * d.x),
        vec3f(b, sign + d.y * d.y * a, -d.y),
    );
}

// A direction scattered from `dir` by the dual lobe.
fn scatter(dir: vec3f, state: ptr<function, u32>) -> vec3f {
    let g = select(-0.3, 0.8, rng_next(state) < 0.75);
    let cos_t = sample_hg(g, rng_next(state));
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let phi = 2.0 * PI * rng_next(state);
    let ab = orthonormal_pair(dir);
    return normalize(dir * cos_t + (ab[0] * cos(phi) + ab[1] * sin(phi)) * sin_t);
}

// Where a photon enters the band's top (in cells) under the sun.
fn sun_photon(state: ptr<function, u32>) -> vec3f {
    let cells = vec3f(volume_grid.cells.xyz);
    let x = rng_next(state) * cells.x;
    let z = rng_next(state) * cells.z;
    return vec3f(x, cells.y - 1e-4, z);
}

// The factor from track lengths to radiance per unit sun irradiance.
fn transport_scale(sun_dir: vec3f, photons: u32) -> f32 {
    let h = volume_grid.cell_m.xyz;
    let area = h.x * f32(volume_grid.cells.x) * h.z * f32(volume_grid.cells.z);
    return sun_dir.y * area / f32(max(photons, 1u)) / (h.x * h.y * h.z);
}

// One photon's walk from the band's top along the sun, its tracks after
// its first scattering added to `light_tracks` (nine a cell).
fn follow(start: vec3f, sun_dir: vec3f, state: ptr<function, u32>) {
    var pos = start;
    var dir = -sun_dir;
    let h = volume_grid.cell_m.xyz;
    let cells = vec3i(volume_grid.cells.xyz);
    var weight = 1.0;
    var scattered = false;
    var crossed = 0u;
    loop {
        var left = -log(1.0 - rng_next(state));
        loop {
            let cell = vec3i(floor(pos));
            if cell.y < 0 || cell.y >= cells.y {
                return;
            }
            crossed += 1u;
            if crossed > CELLS_PER_PHOTON_MAX {
                return;
            }
            let idx = light_index(cell.x, cell.y, cell.z);
            var exit = 3.0e38;
            var axis = 0;
            for (var a = 0; a < 3; a++) {
                let d = dir[a];
                if abs(d) < 1e-9 {
                    continue;
                }
                let face = select(f32(cell[a]), f32(cell[a]) + 1.0, d > 0.0);
                let t = (face - pos[a]) * h[a] / d;
                if t < exit {
                    exit = t;
                    axis = a;
                }
            }
            exit = max(exit, 0.0);
            let s = light_cells[idx];
            var travel = exit;
            let hit = s * exit >= left;
            if hit {
                travel = left / s;
            } else {
                left -= s * exit;
            }
            if travel > 1.0e30 || travel != travel {
                return;
            }
            if scattered {
                var y = sh9(dir);
                for (var k = 0u; k < 9u; k++) {
                    let units = i32(round(y[k] * weight * travel / TRACK_UNIT));
                    if units != 0 {
                        atomicAdd(&light_tracks[idx * 9u + k], units);
                    }
                }
            }
            pos += dir * travel / h;
            if hit {
                break;
            }
            pos[axis] = select(f32(cell[axis]) - 1e-4, f32(cell[axis]) + 1.0, dir[axis] > 0.0);
            let n = vec3f(cells);
            pos.x -= n.x * floor(pos.x / n.x);
            pos.z -= n.z * floor(pos.z / n.z);
        }
        weight *= ALBEDO;
        scattered = true;
        if weight < ROULETTE_WEIGHT {
            if rng_next(state) < 0.5 {
                return;
            }
            weight *= 2.0;
        }
        dir = scatter(dir, state);
    }
}
