// The light volume's grid, its trilinear read and the diffusion's
// coefficients: the twins of src/render/cpu/light_volume.rs (same names).
// Appended after clouds.wgsl by the light volume's build, before
// light_volume_build.wgsl, which declares `diffusion_grid` and
// `light_cells` (the cells' extinction). The cloud pass reads the
// fluence and flux from the texture the build writes last (`light_at` in
// src/render/gpu/shaders.rs), filtered by the hardware as `read_cells`
// filters on the CPU.

const LIGHT_RELAXATION: f32 = 1.8;
const AIR_TRANSPORT_M: f32 = 2000.0;
const CLOUD_EXTINCTION_MIN: f32 = 0.004;
const CLEAR_AIR_LOSS_M: f32 = 1600.0;
const LIGHT_SUN_MIN: f32 = 0.05;
const FLUX_LIMIT: f32 = 0.63492066;

// Mirrors `DiffusionGridUniforms` in src/render/gpu/light_volume_pass.rs.
struct DiffusionGrid {
    cells: vec4u,   // nx, ny, nz, nx * nz
    cell_m: vec4f,  // cell sides x, y, z (m), the band's bottom (m)
}

// The index of cell (i, j, k); i and k wrap around the domain.
fn light_index(i: i32, j: i32, k: i32) -> u32 {
    let nx = i32(diffusion_grid.cells.x);
    let nz = i32(diffusion_grid.cells.z);
    let a = ((i % nx) + nx) % nx;
    let c = ((k % nz) + nz) % nz;
    return u32((j * nz + c) * nx + a);
}

fn light_cell(idx: u32) -> vec3i {
    let nx = diffusion_grid.cells.x;
    let nz = diffusion_grid.cells.z;
    return vec3i(i32(idx % nx), i32(idx / (nx * nz)), i32((idx / nx) % nz));
}

fn light_centre(c: vec3i) -> vec3f {
    return vec3f(
        (f32(c.x) + 0.5) * diffusion_grid.cell_m.x,
        diffusion_grid.cell_m.w + (f32(c.y) + 0.5) * diffusion_grid.cell_m.y,
        (f32(c.z) + 0.5) * diffusion_grid.cell_m.z,
    );
}

// `light_cells` read trilinearly at p: wrapping across the domain,
// clamped to the band's outer cell centres.
fn read_cells(p: vec3f) -> f32 {
    let u = p.x / diffusion_grid.cell_m.x - 0.5;
    let v = clamp((p.y - diffusion_grid.cell_m.w) / diffusion_grid.cell_m.y - 0.5, 0.0, f32(diffusion_grid.cells.y) - 1.0);
    let w = p.z / diffusion_grid.cell_m.z - 0.5;
    let base = floor(vec3f(u, v, w));
    let f = vec3f(u, v, w) - base;
    let i = i32(base.x);
    let k = i32(base.z);
    let j0 = i32(base.y);
    let j1 = min(j0 + 1, i32(diffusion_grid.cells.y) - 1);
    var layers = vec2f(0.0);
    for (var n = 0; n < 2; n++) {
        let b = select(j0, j1, n == 1);
        let a00 = light_cells[light_index(i, b, k)];
        let a10 = light_cells[light_index(i + 1, b, k)];
        let a01 = light_cells[light_index(i, b, k + 1)];
        let a11 = light_cells[light_index(i + 1, b, k + 1)];
        let lo = a00 + f.x * (a10 - a00);
        let hi = a01 + f.x * (a11 - a01);
        layers[n] = lo + f.z * (hi - lo);
    }
    return layers.x + f.y * (layers.y - layers.x);
}

fn diffusion_coefficient(sigma_t: f32) -> f32 {
    return 1.0 / (3.0 * max((1.0 - PHASE_MEAN_COSINE) * sigma_t, 1.0 / AIR_TRANSPORT_M));
}

fn absorption(sigma_t: f32) -> f32 {
    let clear = 1.0 - clamp(sigma_t / CLOUD_EXTINCTION_MIN, 0.0, 1.0);
    return sigma_t * (1.0 - ALBEDO) + clear / CLEAR_AIR_LOSS_M;
}

fn first_scattering(sigma_t: f32, tau_sun: f32) -> f32 {
    return ALBEDO * sigma_t * exp(-(1.0 - PHASE_MEAN_COSINE) * tau_sun);
}
