// The camera's rays and the depth buffer, the twins of src/render/camera.rs.

// The clip depth at which rays are unprojected.
const RAY_DEPTH: f32 = 0.5;

// Normalised device coordinates of a pixel position (y up; 0.5 = a
// pixel's centre).
fn pixel_ndc(px: vec2f) -> vec2f {
    return vec2f(2.0 * px.x / frame.screen.x - 1.0, 1.0 - 2.0 * px.y / frame.screen.y);
}

// The unit world ray through pixel position `px` (unprojected at depth
// RAY_DEPTH, finite for every perspective projection).
fn camera_ray(px: vec2f) -> vec3f {
    let q = frame.inverse_projection * vec4f(pixel_ndc(px), RAY_DEPTH, 1.0);
    return normalize((frame.view_to_world * vec4f(q.xyz / q.w, 0.0)).xyz);
}

// The view's depth of a depth-buffer value: the terrain's buffer under a
// reversed-depth view stores it flipped (1 - d).
fn view_depth(d: f32) -> f32 {
    return mix(d, 1.0 - d, frame.screen.w);
}

// Distance from the eye to the surface at the view's depth `z` at pixel
// position `px` (any perspective projection; infinite at an infinite far
// plane).
fn depth_to_distance(z: f32, px: vec2f) -> f32 {
    let q = frame.inverse_projection * vec4f(pixel_ndc(px), z, 1.0);
    if abs(q.w) <= 1e-30 * length(q.xyz) || q.w == 0.0 {
        return 3.0e38;
    }
    return length(q.xyz / q.w);
}

// Whether the view's depth `z` is geometry (not the far value a depth
// buffer is cleared to).
fn is_geometry(z: f32) -> bool {
    return z != frame.screen.z;
}
