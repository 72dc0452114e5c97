// The light volume's build: four compute entry points, the twins of the
// CPU's `cell_extinction`, `trace` and `sh_planes`
// (src/render/cpu/light_grid.rs, light_volume.rs, light_transport.rs), and the folding of
// each batch's fixed-point tracks into floats. Appended after CLOUDS
// (density.wgsl's `density_at` reads group 0), light_grid.wgsl and
// light_transport.wgsl.
//
// `light_step` (a dynamic offset into one buffer) says which photons a
// `trace` dispatch follows: from x, y of them, of z in all.

@group(1) @binding(0) var<uniform> volume_grid: LightVolumeGrid;
@group(1) @binding(1) var<uniform> light_step: vec4u;
// The cells' mean extinction, then their extinction as the sunlight
// crossing them sees it (the CPU's `cell_extinctions`).
@group(1) @binding(2) var<storage, read_write> light_cells: array<f32>;
// One batch's tracks, nine a cell, fixed point (TRACK_UNIT metres).
@group(1) @binding(3) var<storage, read_write> light_tracks: array<atomic<i32>>;
// The tracks of every batch so far, nine a cell, metres.
@group(1) @binding(4) var<storage, read_write> light_sum: array<f32>;
// The three planes the cloud pass samples (`light_toward`, filtered).
@group(1) @binding(5) var light_plane0: texture_storage_3d<rgba16float, write>;
@group(1) @binding(6) var light_plane1: texture_storage_3d<rgba16float, write>;
@group(1) @binding(7) var light_plane2: texture_storage_3d<rgba16float, write>;
// What a fold keeps of the sums (x) and the gain on a batch's tracks (y):
// 1 and 1 in a whole build, a running mean's weights in a progressive one.
@group(1) @binding(8) var<uniform> light_fold: vec4f;

const LIGHT_WORKGROUP: u32 = 64u;
const PHASE_MOMENT_1: f32 = 0.525;
const PHASE_MOMENT_2: f32 = 0.5025;

fn light_total() -> u32 {
    return volume_grid.cells.w * volume_grid.cells.y;
}

// The invocation's cell (or photon): dispatches wider than 65535
// workgroups fold into rows of 4096 workgroups.
fn light_invocation(id: vec3u) -> u32 {
    return id.x + id.y * 4096u * LIGHT_WORKGROUP;
}

@compute @workgroup_size(64)
fn cell_extinction(@builtin(global_invocation_id) id: vec3u) {
    let idx = light_invocation(id);
    if idx >= light_total() {
        return;
    }
    let c = light_centre(light_cell(idx));
    let quarter = volume_grid.cell_m.xyz * 0.25;
    let footprint = 0.5 * volume_grid.cell_m.x;
    let l = sun_cell_length(frame.sun_dir.xyz);
    var sum = 0.0;
    var seen = 0.0;
    for (var o = 0u; o < 8u; o++) {
        let s = vec3f(
            select(-1.0, 1.0, (o & 1u) != 0u),
            select(-1.0, 1.0, (o & 2u) != 0u),
            select(-1.0, 1.0, (o & 4u) != 0u),
        );
        let sigma = density_at(c + s * quarter, true, footprint);
        sum += sigma;
        seen += exp(-sigma * l);
    }
    light_cells[idx] = sum / 8.0;
    light_cells[light_total() + idx] = -log(max(seen / 8.0, 1e-30)) / l;
}

// The length over which a ray along sun_dir crosses one cell along its
// fastest axis (the CPU's `sun_cell_length`).
fn sun_cell_length(sun_dir: vec3f) -> f32 {
    let per = abs(sun_dir) / volume_grid.cell_m.xyz;
    return 1.0 / max(max(per.x, max(per.y, per.z)), 1e-6);
}

// The photons light_step.x .. + light_step.y, each from the band's top.
@compute @workgroup_size(64)
fn trace(@builtin(global_invocation_id) id: vec3u) {
    let n = light_invocation(id);
    let sun_dir = frame.sun_dir.xyz;
    if n >= light_step.y || sun_dir.y < LIGHT_SUN_MIN {
        return;
    }
    var state = rng_seed(light_step.x + n, LIGHT_SEED);
    let start = sun_photon(&state);
    follow(start, sun_dir, &state);
}

// One batch's fixed-point tracks added to the sums (through `light_fold`)
// and cleared: a batch holds few enough photons that no cell's sum
// overflows.
@compute @workgroup_size(64)
fn fold_tracks(@builtin(global_invocation_id) id: vec3u) {
    let i = light_invocation(id);
    if i >= 9u * light_total() {
        return;
    }
    let tracks = f32(atomicExchange(&light_tracks[i], 0)) * TRACK_UNIT;
    light_sum[i] = light_sum[i] * light_fold.x + tracks * light_fold.y;
}

// Coefficient `k` of the sums of cell `c` smoothed over its layer: the
// binomial mean of the 3 x 3 cells about it (1-2-1 along x and z),
// wrapping across the domain.
fn filter_cells(c: vec3i, k: u32) -> f32 {
    var sum = 0.0;
    for (var dk = -1; dk <= 1; dk++) {
        for (var di = -1; di <= 1; di++) {
            let w = f32((2 - abs(di)) * (2 - abs(dk)));
            sum += w * light_sum[light_index(c.x + di, c.y, c.z + dk) * 9u + k];
        }
    }
    return sum / 16.0;
}

// The cells' extinction as the sunlight sees it (light_cells' second
// half) in layer `j`, read bilinearly at world (x, z), wrapping (the
// CPU's `read_layer`).
fn read_layer(j: i32, x: f32, z: f32) -> f32 {
    let u = x / volume_grid.cell_m.x - 0.5;
    let w = z / volume_grid.cell_m.z - 0.5;
    let i = floor(u);
    let k = floor(w);
    let fx = u - i;
    let fz = w - k;
    let a = i32(i);
    let c = i32(k);
    let o = light_total();
    let v00 = light_cells[o + light_index(a, j, c)];
    let v10 = light_cells[o + light_index(a + 1, j, c)];
    let v01 = light_cells[o + light_index(a, j, c + 1)];
    let v11 = light_cells[o + light_index(a + 1, j, c + 1)];
    let lo = v00 + (v10 - v00) * fx;
    let hi = v01 + (v11 - v01) * fx;
    return lo + (hi - lo) * fz;
}

// The cells' extinction as the sunlight sees it read trilinearly at p: wrapping across the
// domain, clamped to the band's outer cell centres (the CPU's
// `read_cells`).
fn read_cells(p: vec3f) -> f32 {
    let ny = f32(volume_grid.cells.y);
    let v = clamp((p.y - volume_grid.cell_m.w) / volume_grid.cell_m.y - 0.5, 0.0, ny - 1.0);
    let j = floor(v);
    let fy = v - j;
    let j0 = i32(j);
    let j1 = min(j0 + 1, i32(volume_grid.cells.y) - 1);
    let a = read_layer(j0, p.x, p.z);
    let b = read_layer(j1, p.x, p.z);
    return a + (b - a) * fy;
}

const SUN_DEPTH_STEPS_MAX: u32 = 160u;

// The optical depth from p toward the sun through the cells' extinction:
// to the grid's top, at most SHADOW_RAY_M, one read at the middle of each
// step, a step the length in which the ray crosses one cell along its
// fastest axis (the CPU's `sun_depth_from`).
fn sun_depth_from(p: vec3f, sun_dir: vec3f) -> f32 {
    let top = volume_grid.cell_m.w + f32(volume_grid.cells.y) * volume_grid.cell_m.y;
    var length = SHADOW_RAY_M;
    if sun_dir.y > 1e-3 {
        length = min(max(top - p.y, 0.0) / sun_dir.y, SHADOW_RAY_M);
    }
    let per = abs(sun_dir) / volume_grid.cell_m.xyz;
    let per_m = max(per.x, max(per.y, per.z));
    let n = clamp(u32(ceil(length * per_m)), 1u, SUN_DEPTH_STEPS_MAX);
    let ds = length / f32(n);
    var tau = 0.0;
    for (var i = 0u; i < n; i++) {
        tau += read_cells(p + sun_dir * ((f32(i) + 0.5) * ds));
    }
    return tau * ds;
}

// The sums as radiance per unit irradiance, their directional
// coefficients (1-8) smoothed (`filter_cells`), through the phase's
// moments, into the three planes: texel (i, j, k) is cell (i, j, k). The
// third plane's second channel holds the sun's optical depth from the
// cell's centre (`sun_depth_from`, the CPU's `with_sun_depth`).
@compute @workgroup_size(64)
fn sh_planes(@builtin(global_invocation_id) id: vec3u) {
    let idx = light_invocation(id);
    if idx >= light_total() {
        return;
    }
    let scale = transport_scale(frame.sun_dir.xyz, light_step.z);
    let cell = light_cell(idx);
    var c = array<f32, 9>();
    c[0] = light_sum[idx * 9u] * scale;
    for (var k = 1u; k < 9u; k++) {
        c[k] = filter_cells(cell, k) * scale;
    }
    let m1 = PHASE_MOMENT_1;
    let m2 = PHASE_MOMENT_2;
    textureStore(light_plane0, cell, vec4f(c[0], c[1] * m1, c[2] * m1, c[3] * m1));
    textureStore(light_plane1, cell, vec4f(c[4] * m2, c[5] * m2, c[6] * m2, c[7] * m2));
    let depth = sun_depth_from(light_centre(cell), frame.sun_dir.xyz);
    textureStore(light_plane2, cell, vec4f(c[8] * m2, depth, 0.0, 0.0));
}
