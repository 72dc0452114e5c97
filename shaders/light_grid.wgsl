// The light volume's grid: the twin of LightVolumeGrid in
// src/render/cpu/light_grid.rs (same names). Appended after CLOUDS
// by the light volume's build, before light_transport.wgsl and
// light_volume_build.wgsl, which declares `volume_grid`. The cloud
// pass reads the transported light from the three textures the build
// writes last (`light_toward` in src/render/gpu/shaders.rs), filtered by
// the hardware as `read_cells` filters on the CPU.

const LIGHT_SUN_MIN: f32 = 0.05;
const LIGHT_SEED: u32 = 1u;

// Mirrors `LightVolumeGridUniforms` in src/render/gpu/light_volume_pass.rs.
struct LightVolumeGrid {
    cells: vec4u,   // nx, ny, nz, nx * nz
    cell_m: vec4f,  // cell sides x, y, z (m), the band's bottom (m)
}

// The index of cell (i, j, k); i and k wrap around the domain.
fn light_index(i: i32, j: i32, k: i32) -> u32 {
    let nx = i32(volume_grid.cells.x);
    let nz = i32(volume_grid.cells.z);
    let a = ((i % nx) + nx) % nx;
    let c = ((k % nz) + nz) % nz;
    return u32((j * nz + c) * nx + a);
}

fn light_cell(idx: u32) -> vec3i {
    let nx = volume_grid.cells.x;
    let nz = volume_grid.cells.z;
    return vec3i(i32(idx % nx), i32(idx / (nx * nz)), i32((idx / nx) % nz));
}

fn light_centre(c: vec3i) -> vec3f {
    return vec3f(
        (f32(c.x) + 0.5) * volume_grid.cell_m.x,
        volume_grid.cell_m.w + (f32(c.y) + 0.5) * volume_grid.cell_m.y,
        (f32(c.z) + 0.5) * volume_grid.cell_m.z,
    );
}
