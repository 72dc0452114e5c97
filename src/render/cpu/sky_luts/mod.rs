//! A physically based clear sky after Hillaire 2020 ("A Scalable and
//! Production Ready Sky and Atmosphere Rendering Technique", EGSR 2020):
//! Rayleigh, Mie and ozone layers over a spherical planet, tabulated in a
//! transmittance table (Bruneton's horizon-aware parametrisation), a
//! multiple-scattering table (Ψ_ms, Hillaire's Eqs. 5-10) and a sky-view
//! table for one camera altitude and sun; aerial perspective is a short
//! per-pixel march through the first two tables instead of a froxel volume.
//!
//! Units: inside this module lengths are km (radii `r` from the planet's
//! centre, altitudes `h`) and coefficients 1/km; world altitudes and
//! distances come in as metres (`_m`). World frame as in `super`: `y` up,
//! the ground flat, so a direction's cosine to the zenith is its `y`.
//! Radiance is relative: the sun's irradiance at the top of the atmosphere
//! is [`SkyParams::sun_irradiance`] (8, the renderer's `SUN_INTENSITY`); the
//! clear zenith then has luminance 0.12 under a sun 60° high and 0.24 under
//! one 85° high (Mie glow included), below the analytic sky's ~0.3.
//!
//! WGSL twin: each per-texel function is a pure function of `f32`/`Vec3`
//! and the tables it reads; [`Lut2::sample_texels`] is four `textureLoad`s
//! and two lerps (texel centres, clamp to edge), and every march has a
//! fixed step count.

mod atmosphere;
mod lookups;
mod tables;
#[cfg(test)]
mod tests;

pub use atmosphere::*;
pub use lookups::*;
pub use tables::*;
