// The sky tables' four compute entry points, appended to SKY_LUTS (sky_luts/)
// (src/render/gpu/sky_luts_pass.rs builds them): one invocation per texel.

const PI: f32 = 3.14159265358979;

@group(0) @binding(0) var<uniform> params: SkyParams;
@group(0) @binding(1) var lut_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var transmittance_lut: texture_2d<f32>;
@group(0) @binding(3) var multi_scattering_lut: texture_2d<f32>;
@group(0) @binding(4) var<uniform> sky_view_inputs: SkyView;
@group(0) @binding(5) var sky_view_lut: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn cs_transmittance(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= TRANSMITTANCE_WIDTH || id.y >= TRANSMITTANCE_HEIGHT {
        return;
    }
    textureStore(lut_out, id.xy, vec4f(transmittance_texel(id.x, id.y, params), 1.0));
}

@compute @workgroup_size(8, 8)
fn cs_multi_scattering(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= MULTI_SCATTERING_WIDTH || id.y >= MULTI_SCATTERING_HEIGHT {
        return;
    }
    let c = multi_scattering_texel(id.x, id.y, params, transmittance_lut);
    textureStore(lut_out, id.xy, vec4f(c, 1.0));
}

@compute @workgroup_size(8, 8)
fn cs_sky_view(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= SKY_VIEW_WIDTH || id.y >= SKY_VIEW_HEIGHT {
        return;
    }
    let c = sky_view_texel(
        id.x,
        id.y,
        sky_view_inputs.camera_radius_km,
        sky_view_inputs.sun_cos_zenith,
        params,
        transmittance_lut,
        multi_scattering_lut,
    );
    textureStore(lut_out, id.xy, vec4f(c, 1.0));
}

// One texel: the sky's mean radiance over the upper hemisphere.
@compute @workgroup_size(8, 8)
fn cs_sky_ambient(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= 1u || id.y >= 1u {
        return;
    }
    let c = sky_ambient_texel(sky_view_lut, sky_view_inputs.camera_radius_km, params);
    textureStore(lut_out, id.xy, vec4f(c, 1.0));
}
