// The light volume's build: three compute entry points, the twins of the
// CPU's `cell_extinction`, `sun_depth_layer` and `relax`
// (src/render/cpu/light_volume.rs). Appended after clouds.wgsl (whose
// `density_at` reads group 0) and light_volume.wgsl.
//
// `light_step` (a dynamic offset into one buffer) says which layer
// `sun_depth_layer` fills (x) and which colour a `relax` dispatch updates
// (y): the layers are filled from the band's top down, one dispatch
// each, and every sweep is two dispatches, the cells with i + j + k even,
// then the odd ones.

@group(1) @binding(0) var<uniform> diffusion_grid: DiffusionGrid;
@group(1) @binding(1) var<uniform> light_step: vec4u;
// The cells' extinction (what `read_cells` reads while building).
@group(1) @binding(2) var<storage, read_write> light_cells: array<f32>;
@group(1) @binding(3) var<storage, read_write> light_tau: array<f32>;
@group(1) @binding(4) var<storage, read_write> light_phi: array<f32>;
// The fluence and flux as the cloud pass reads them (`light_at`, filtered).
@group(1) @binding(5) var light_texture: texture_storage_3d<rgba16float, write>;

const LIGHT_WORKGROUP: u32 = 64u;
// The optical depth under a sun too low: exp(-x) of it is 0.
const LIGHT_DEPTH_NONE: f32 = 3.0e38;

fn light_total() -> u32 {
    return diffusion_grid.cells.w * diffusion_grid.cells.y;
}

// The invocation's cell (or column): dispatches wider than 65535
// workgroups fold into rows of 4096 workgroups.
fn light_invocation(id: vec3u) -> u32 {
    return id.x + id.y * 4096u * LIGHT_WORKGROUP;
}

// `read_layer` over layer `j`'s optical depths toward the sun.
fn read_layer(j: i32, x: f32, z: f32) -> f32 {
    let u = x / diffusion_grid.cell_m.x - 0.5;
    let w = z / diffusion_grid.cell_m.z - 0.5;
    let i = i32(floor(u));
    let k = i32(floor(w));
    let fx = u - floor(u);
    let fz = w - floor(w);
    let a00 = light_tau[light_index(i, j, k)];
    let a10 = light_tau[light_index(i + 1, j, k)];
    let a01 = light_tau[light_index(i, j, k + 1)];
    let a11 = light_tau[light_index(i + 1, j, k + 1)];
    let lo = a00 + fx * (a10 - a00);
    let hi = a01 + fx * (a11 - a01);
    return lo + fz * (hi - lo);
}

@compute @workgroup_size(64)
fn cell_extinction(@builtin(global_invocation_id) id: vec3u) {
    let idx = light_invocation(id);
    if idx >= light_total() {
        return;
    }
    let c = light_centre(light_cell(idx));
    let quarter = diffusion_grid.cell_m.xyz * 0.25;
    let footprint = 0.5 * diffusion_grid.cell_m.x;
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

@compute @workgroup_size(64)
fn sun_depth_layer(@builtin(global_invocation_id) id: vec3u) {
    let column = light_invocation(id);
    let n = diffusion_grid.cells.w;
    if column >= n {
        return;
    }
    let j = i32(light_step.x);
    let idx = u32(j) * n + column;
    let sun_dir = frame.sun_dir.xyz;
    if sun_dir.y < LIGHT_SUN_MIN {
        light_tau[idx] = LIGHT_DEPTH_NONE;
        return;
    }
    let top = j == i32(diffusion_grid.cells.y) - 1;
    let rise = select(1.0, 0.5, top) * diffusion_grid.cell_m.y;
    let path = rise / sun_dir.y;
    let sideways = path * length(sun_dir.xz);
    let samples = max(ceil(sideways / diffusion_grid.cell_m.x), 1.0);
    let dt = path / samples;
    let nx = diffusion_grid.cells.x;
    let p = light_centre(vec3i(i32(column % nx), j, i32(column / nx)));
    var tau = 0.0;
    for (var s = 0u; s < u32(samples); s++) {
        tau += read_cells(p + sun_dir * ((f32(s) + 0.5) * dt)) * dt;
    }
    if !top {
        let q = p + sun_dir * path;
        tau += read_layer(j + 1, q.x, q.z);
    }
    light_tau[idx] = tau;
}

@compute @workgroup_size(64)
fn relax(@builtin(global_invocation_id) id: vec3u) {
    let idx = light_invocation(id);
    if idx >= light_total() {
        return;
    }
    let c = light_cell(idx);
    if (u32(c.x + c.y + c.z) & 1u) != light_step.y {
        return;
    }
    let cell_m = diffusion_grid.cell_m.xyz;
    let s = light_cells[idx];
    let d = diffusion_coefficient(s);
    var diagonal = absorption(s);
    var sum = first_scattering(s, light_tau[idx]);
    let ny = i32(diffusion_grid.cells.y);
    let offsets = array<vec3i, 6>(
        vec3i(-1, 0, 0), vec3i(1, 0, 0), vec3i(0, 0, -1),
        vec3i(0, 0, 1), vec3i(0, -1, 0), vec3i(0, 1, 0),
    );
    let sides = array<f32, 6>(cell_m.x, cell_m.x, cell_m.z, cell_m.z, cell_m.y, cell_m.y);
    for (var m = 0; m < 6; m++) {
        let q = c + offsets[m];
        let h = sides[m];
        if q.y < 0 || q.y >= ny {
            diagonal += 2.0 * d / (h * h);
            continue;
        }
        let n = light_index(q.x, q.y, q.z);
        let dn = diffusion_coefficient(light_cells[n]);
        let w = 2.0 * d * dn / ((d + dn) * h * h);
        diagonal += w;
        sum += w * light_phi[n];
    }
    let old = light_phi[idx];
    light_phi[idx] = old + LIGHT_RELAXATION * (sum / diagonal - old);
}

// The net flux of the diffused light through cell `idx`: Fick's law by
// central differences, one-sided at the band's floor and ceiling, at most
// FLUX_LIMIT of the fluence (the CPU's `light_flux`).
fn light_flux(idx: u32) -> vec3f {
    let c = light_cell(idx);
    let h = diffusion_grid.cell_m.xyz;
    let ny = i32(diffusion_grid.cells.y);
    let dx = (light_phi[light_index(c.x + 1, c.y, c.z)] - light_phi[light_index(c.x - 1, c.y, c.z)]) / (2.0 * h.x);
    let dz = (light_phi[light_index(c.x, c.y, c.z + 1)] - light_phi[light_index(c.x, c.y, c.z - 1)]) / (2.0 * h.z);
    var up = 0.0;
    var span_up = 0.5 * h.y;
    if c.y + 1 < ny {
        up = light_phi[light_index(c.x, c.y + 1, c.z)];
        span_up = h.y;
    }
    var down = 0.0;
    var span_down = 0.5 * h.y;
    if c.y > 0 {
        down = light_phi[light_index(c.x, c.y - 1, c.z)];
        span_down = h.y;
    }
    let dy = (up - down) / (span_up + span_down);
    let f = -diffusion_coefficient(light_cells[idx]) * vec3f(dx, dy, dz);
    let limit = FLUX_LIMIT * max(light_phi[idx], 0.0);
    let size = length(f);
    if size > limit {
        return f * (limit / size);
    }
    return f;
}

// The fluence and the net flux into the texture the cloud pass samples:
// texel (i, j, k) is cell (i, j, k).
@compute @workgroup_size(64)
fn fluence_texture(@builtin(global_invocation_id) id: vec3u) {
    let idx = light_invocation(id);
    if idx >= light_total() {
        return;
    }
    textureStore(light_texture, light_cell(idx), vec4f(light_phi[idx], light_flux(idx)));
}
