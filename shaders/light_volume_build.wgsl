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
// The cells' extinction.
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
    var sum = 0.0;
    for (var o = 0u; o < 8u; o++) {
        let s = vec3f(
            select(-1.0, 1.0, (o & 1u) != 0u),
            select(-1.0, 1.0, (o & 2u) != 0u),
            select(-1.0, 1.0, (o & 4u) != 0u),
        );
        sum += density_at(c + s * quarter, true, footprint);
    }
    light_cells[idx] = sum / 8.0;
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

// The sums as radiance per unit irradiance, their directional
// coefficients (1-8) smoothed (`filter_cells`), through the phase's
// moments, into the three planes: texel (i, j, k) is cell (i, j, k).
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
    textureStore(light_plane2, cell, vec4f(c[8] * m2, 0.0, 0.0, 0.0));
}
