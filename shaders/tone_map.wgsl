// The ACES tone map; the twins of src/render/cpu/tone_map.rs.

// The fitted ACES curve (the CPU's `aces_curve`).
fn aces_curve(v: vec3f) -> vec3f {
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.432951) + 0.238081;
    return a / b;
}

// ACES filmic tone map of the radiance times `exposure`, to display-linear
// 0..1 (the CPU's `tone_map`). The matrices are the CPU's ACES_INPUT and
// ACES_OUTPUT, written column by column.
fn tone_map(c: vec3f, exposure: f32) -> vec3f {
    let to_working = mat3x3f(
        vec3f(0.59719, 0.07600, 0.02840),
        vec3f(0.35458, 0.90834, 0.13383),
        vec3f(0.04823, 0.01566, 0.83777),
    );
    let to_srgb = mat3x3f(
        vec3f(1.60475, -0.10208, -0.00327),
        vec3f(-0.53108, 1.10813, -0.07276),
        vec3f(-0.07367, -0.00605, 1.07602),
    );
    let v = to_working * (max(c, vec3f(0.0)) * exposure);
    return clamp(to_srgb * aces_curve(v), vec3f(0.0), vec3f(1.0));
}
