//! Physics parameters: a plain struct passed in, never a global. Every field
//! documents its unit, domain and default; `docs/scene.md` lists the same
//! keys as the scene's `[physics]` tables.

use serde::{Deserialize, Serialize};

use super::check::Check;

impl PhysicsConfig {
    /// Every field against its domain (the scene reports the first that
    /// fails).
    pub fn checks(&self) -> Vec<Check> {
        let p = self;
        let r = Check::range;
        vec![
            r("physics.dt_s", p.dt_s, 1e-3, 600.0, "1e-3..=600 s"),
            Check::new(
                "physics.parcels",
                p.parcels <= 200_000,
                "0..=200000",
                p.parcels as f64,
            ),
            r(
                "physics.domain_size_m",
                p.domain_size_m,
                1.0,
                1e7,
                "1..=1e7 m",
            ),
            r("physics.radius_m", p.radius_m, 1e-3, 1e5, "1e-3..=1e5 m"),
            r(
                "physics.radius_jitter",
                p.radius_jitter,
                0.0,
                0.99,
                "0..=0.99",
            ),
            r(
                "physics.release_height_m",
                p.release_height_m,
                0.0,
                1e5,
                "0..=1e5 m",
            ),
            r(
                "physics.release_stagger_s",
                p.release_stagger_s,
                0.0,
                1e7,
                "0..=1e7 s",
            ),
            r(
                "physics.initial_excess_k",
                p.initial_excess_k,
                -50.0,
                50.0,
                "-50..=50 K",
            ),
            r(
                "physics.initial_excess_qt_gkg",
                p.initial_excess_qt_gkg,
                -50.0,
                50.0,
                "-50..=50 g/kg",
            ),
            r("physics.virtual_mass", p.virtual_mass, 0.0, 2.0, "0..=2"),
            r(
                "physics.drag_coefficient",
                p.drag_coefficient,
                0.0,
                5.0,
                "0..=5",
            ),
            r(
                "physics.fill_full_condensed_fraction",
                p.fill_full_condensed_fraction,
                1e-6,
                1.0,
                "(0, 1]",
            ),
            r(
                "physics.entrainment.coefficient",
                p.entrainment.coefficient,
                0.0,
                2.0,
                "0..=2",
            ),
            r(
                "physics.detrainment.rate_per_s",
                p.detrainment.rate_per_s,
                0.0,
                1.0,
                "0..=1 1/s",
            ),
            r(
                "physics.detrainment.sorting_factor",
                p.detrainment.sorting_factor,
                0.0,
                100.0,
                "0..=100",
            ),
            r(
                "physics.recycling.spent_fraction_of_peak",
                p.recycling.spent_fraction_of_peak,
                0.0,
                1.0,
                "0..=1",
            ),
            r(
                "physics.recycling.max_age_s",
                p.recycling.max_age_s,
                1e-3,
                1e9,
                "1e-3..=1e9 s",
            ),
            r(
                "physics.sph.smoothing_radii",
                p.sph.smoothing_radii,
                1e-3,
                100.0,
                "1e-3..=100",
            ),
            // The SPH kernel's reach must fit in half the domain. Said of
            // the parcels' radius, with the two other keys' values, not of
            // `smoothing_radii`, a default the user seldom writes: a user
            // who meets it has set `radius_m` or `domain_size_m`.
            Check::new(
                "physics.radius_m",
                !p.sph.enabled
                    || !p.sph.smoothing_radii.is_finite()
                    || p.sph.smoothing_radii * p.radius_m <= 0.5 * p.domain_size_m,
                format!(
                    "at most domain_size_m / (2 * sph.smoothing_radii) = {} / (2 * {}) = {:.1} m \
                     with SPH on: the kernel's reach, smoothing_radii radii, fits in half \
                     the domain (a larger domain_size_m or fewer smoothing_radii allow more)",
                    p.domain_size_m,
                    p.sph.smoothing_radii,
                    0.5 * p.domain_size_m / p.sph.smoothing_radii
                ),
                p.radius_m,
            ),
            r(
                "physics.sph.sound_speed_mps",
                p.sph.sound_speed_mps,
                1e-6,
                1e3,
                "1e-6..=1000 m/s",
            ),
            r(
                "physics.sph.viscosity_m2ps",
                p.sph.viscosity_m2ps,
                0.0,
                1e7,
                "0..=1e7 m²/s",
            ),
            r(
                "physics.wind.speed_mps",
                p.wind.speed_mps,
                0.0,
                200.0,
                "0..=200 m/s",
            ),
            Check::new(
                "physics.wind.direction_deg",
                p.wind.direction_deg.is_finite(),
                "a finite angle",
                p.wind.direction_deg,
            ),
            r(
                "physics.wind.shear_per_km",
                p.wind.shear_per_km,
                -1.0,
                10.0,
                "-1..=10 1/km",
            ),
            r(
                "physics.substeps.max_buoyancy_phase",
                p.substeps.max_buoyancy_phase,
                1e-6,
                1.0,
                "(0, 1]",
            ),
            r(
                "physics.substeps.max_rise_m",
                p.substeps.max_rise_m,
                1e-3,
                1e5,
                "1e-3..=1e5 m",
            ),
            r(
                "physics.substeps.sph_courant",
                p.substeps.sph_courant,
                1e-6,
                1.0,
                "(0, 1]",
            ),
            Check::new(
                "physics.substeps.max_per_frame",
                (1..=1_000_000).contains(&p.substeps.max_per_frame),
                "1..=1000000",
                p.substeps.max_per_frame as f64,
            ),
        ]
    }
}

/// The simulator's parameters (scene table `[physics]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsConfig {
    /// Frame time step, s. Domain 1e-3..=600. Default 5 (chosen from
    /// `cumulus convergence`; docs/physics.md, "Error against run time
    /// (physics)").
    pub dt_s: f64,
    /// Number of parcels. Domain 0..=200000. Default 12 (as in the paper).
    pub parcels: usize,
    /// Seed of every random choice (positions, radii, re-births). Default 1.
    pub seed: u64,
    /// Side of the square, horizontally periodic domain, m. Default 10000.
    pub domain_size_m: f64,
    /// Mean parcel radius, m (> 0). Default 300.
    pub radius_m: f64,
    /// Relative spread of radii, 0..<1: radius in `R (1 ± jitter)`. Default 0.3.
    pub radius_jitter: f64,
    /// Height of the parcels' release above ground, m (>= 0). Default 50.
    pub release_height_m: f64,
    /// Releases are staggered uniformly over this time, s (>= 0), so parcels
    /// do not rise in lock-step. Default 900.
    pub release_stagger_s: f64,
    /// Initial `θ_l` excess of a released parcel over its environment, K.
    /// Default 0.5 ("initialised parcels are slightly warmer").
    pub initial_excess_k: f64,
    /// Initial total-water excess of a released parcel, g/kg. Capped so the
    /// parcel cannot saturate below the surface air's LCL: at most the
    /// saturation mixing ratio of the parcel lifted dry-adiabatically to it
    /// (in cold air that is less than the excess itself). Default 1.0.
    pub initial_excess_qt_gkg: f64,
    /// Virtual-mass coefficient γ in `dw/dt = B/(1+γ) - ...`. Domain 0..=2.
    /// Default 0.5 (Simpson & Wiggert 1969).
    pub virtual_mass: f64,
    /// Aerodynamic drag coefficient `C_D` of the thermal (`(3/8) C_D w|w|/R`).
    /// Domain 0..=5. Default 0.5.
    pub drag_coefficient: f64,
    /// Entrainment of environment air (`[physics.entrainment]`).
    pub entrainment: Entrainment,
    /// Detrainment of cloud water (`[physics.detrainment]`).
    pub detrainment: Detrainment,
    /// Re-birth of spent parcels (`[physics.recycling]`).
    pub recycling: Recycling,
    /// SPH pressure and viscosity between parcels (`[physics.sph]`).
    pub sph: Sph,
    /// Horizontal wind (`[physics.wind]`).
    pub wind: Wind,
    /// Adaptive sub-stepping of the explicit parts (`[physics.substeps]`).
    pub substeps: Substeps,
    /// Condensed fraction `q_c/q_t` at which the projected fill density
    /// reaches 1. Domain (0, 1]. Default 0.08.
    pub fill_full_condensed_fraction: f64,
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        Self {
            dt_s: 5.0,
            parcels: 12,
            seed: 1,
            domain_size_m: 10_000.0,
            radius_m: 300.0,
            radius_jitter: 0.3,
            release_height_m: 50.0,
            release_stagger_s: 900.0,
            initial_excess_k: 0.5,
            initial_excess_qt_gkg: 1.0,
            virtual_mass: 0.5,
            drag_coefficient: 0.5,
            entrainment: Entrainment::default(),
            detrainment: Detrainment::default(),
            recycling: Recycling::default(),
            sph: Sph::default(),
            wind: Wind::default(),
            substeps: Substeps::default(),
            fill_full_condensed_fraction: 0.08,
        }
    }
}

/// Entrainment: `dφ/dt = -ε |w| (φ - φ_env)` for `φ ∈ {θ_l, q_t, u, v}`,
/// applied as the exact exponential relaxation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Entrainment {
    /// Off: the parcel never mixes (no work is done). Default true.
    pub enabled: bool,
    /// Coefficient `c` of the fractional rate `ε = c / R`, per metre of rise.
    /// Domain 0..=2. Default 0.2 (Turner; Simpson & Wiggert).
    pub coefficient: f64,
}

impl Default for Entrainment {
    fn default() -> Self {
        Self {
            enabled: true,
            coefficient: 0.2,
        }
    }
}

/// Detrainment: the parcel sheds cloud water to the environment at the
/// fractional rate `δ = rate (1 + sorting)` (`sorting` only while the parcel
/// is negatively buoyant: buoyancy sorting), applied as an exponential.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Detrainment {
    /// Off: the parcel keeps its condensate (no work is done). Default true.
    pub enabled: bool,
    /// Base fractional rate, 1/s (>= 0). Default 1/900 (15-minute e-folding).
    pub rate_per_s: f64,
    /// Extra factor while negatively buoyant (>= 0). Default 3.
    pub sorting_factor: f64,
}

impl Default for Detrainment {
    fn default() -> Self {
        Self {
            enabled: true,
            rate_per_s: 1.0 / 900.0,
            sorting_factor: 3.0,
        }
    }
}

/// Re-birth of spent parcels near the surface, so the animation runs
/// endlessly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Recycling {
    /// Off: parcels live forever (no check is made). Default true.
    pub enabled: bool,
    /// A parcel is spent once it has condensed and its condensate has fallen
    /// below this fraction of its peak. Domain 0..=1. Default 0.05.
    pub spent_fraction_of_peak: f64,
    /// A parcel older than this is spent whatever its water, s (> 0).
    /// Default 3600.
    pub max_age_s: f64,
}

impl Default for Recycling {
    fn default() -> Self {
        Self {
            enabled: true,
            spent_fraction_of_peak: 0.05,
            max_age_s: 3600.0,
        }
    }
}

/// SPH between parcels (Müller et al. 2003): density with the poly6 kernel,
/// pressure `p = c_s² (ρ - ρ_0)` clamped at 0 (parcels repel, never attract),
/// spiky-gradient pressure force, viscosity-kernel viscosity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sph {
    /// Off: no neighbour search and no forces. Default true.
    pub enabled: bool,
    /// Smoothing length `h` as a multiple of the mean radius (> 0): parcels
    /// interact when closer than `h`. Default 2 (spheres touching).
    pub smoothing_radii: f64,
    /// Numerical sound speed `c_s`, m/s (> 0): stiffness of the repulsion.
    /// Default 3.
    pub sound_speed_mps: f64,
    /// Kinematic viscosity between parcels, m²/s (>= 0). Default 100.
    pub viscosity_m2ps: f64,
}

impl Default for Sph {
    fn default() -> Self {
        Self {
            enabled: true,
            smoothing_radii: 2.0,
            sound_speed_mps: 3.0,
            viscosity_m2ps: 100.0,
        }
    }
}

/// Horizontal wind: `speed (1 + shear z)` towards `direction`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Wind {
    /// Off: still air (parcels are not advected by any wind). Default true.
    pub enabled: bool,
    /// Wind speed at the ground, m/s (>= 0). Default 3.
    pub speed_mps: f64,
    /// Direction the wind blows towards, degrees clockwise from +y. Default 90.
    pub direction_deg: f64,
    /// Relative increase of speed per km of height, 1/km. Default 0.2.
    pub shear_per_km: f64,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            enabled: true,
            speed_mps: 3.0,
            direction_deg: 90.0,
            shear_per_km: 0.2,
        }
    }
}

/// Bounds of the adaptive sub-steps of the explicit parts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Substeps {
    /// Largest `N Δt_sub` (buoyancy oscillation phase per sub-step). Domain
    /// (0, 1]. Default 0.5 (stable over `tests/stability.rs`'s matrix).
    pub max_buoyancy_phase: f64,
    /// Largest vertical travel of any parcel per sub-step, m (> 0), so that
    /// the environment is sampled finely. Default 25.
    pub max_rise_m: f64,
    /// SPH Courant number: `Δt_sub <= courant h / max(|v|, c_s)`. Default 0.4.
    pub sph_courant: f64,
    /// Cap on sub-steps per frame (>= 1). Reaching it is reported in
    /// [`StepStats`](crate::sim::StepStats), never silent. Default 4096.
    pub max_per_frame: usize,
}

impl Default for Substeps {
    fn default() -> Self {
        Self {
            max_buoyancy_phase: 0.5,
            max_rise_m: 25.0,
            sph_courant: 0.4,
            max_per_frame: 4096,
        }
    }
}
