//! Cameras, for both renderers and the public API.
//!
//! - [`Camera`]: the scene's camera (position, yaw, pitch, vertical field of
//!   view), what `[render]` describes and the demo flies.
//! - [`View`]: any perspective camera an application has, given by its own
//!   view and projection matrices: roll, off-axis (asymmetric) frusta,
//!   either handedness, standard or reversed depth, finite or infinite far
//!   plane. Both renderers march the rays of a `View`; a `Camera` becomes
//!   one through [`ToView`].
//!
//! # Conventions
//! - **World frame**: cumulus's, in metres, `y` up; `x` east and `z` north
//!   for the scene's yaw and the sun's azimuth (clockwise from `+z` toward
//!   `+x`). The cloud band is the slab between the band's bottom and top
//!   heights in `y`. An application whose world is `z`-up multiplies a
//!   `y`-up change of basis into its view matrix; one whose horizontal axes
//!   are mirrored (a right-handed `y`-up world with `z` south) sees the same
//!   clouds mirrored, which only matters for the sun's azimuth.
//! - **View matrix**: world to the camera's own space (an isometry: no
//!   scale). Either handedness: the renderers never assume which way the
//!   camera space's `z` points; they unproject.
//! - **Projection**: camera space to wgpu clip space: after the divide by
//!   `w`, `x` and `y` in `[-1, 1]` with `+y` up the screen, depth in
//!   `[0, 1]`. Perspective only (the eye must map to `w = 0`); standard
//!   depth (near 0, far 1) or reversed (near 1, far 0) is read off the
//!   matrix, and the far plane may be at infinity.
//! - **Depth buffers**: the application's depth buffer must be written with
//!   the same projection. A pixel whose depth is the far value (1, or 0
//!   reversed: what a depth buffer is cleared to) is sky; any other value is
//!   geometry at the distance the projection gives it, and the clouds are
//!   marched only up to it.

use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};

/// Near plane of the projection a [`Camera`] makes, m.
pub const NEAR_M: f32 = 1.0;

/// The clip-space depth at which [`View`] unprojects ray directions: any
/// depth strictly between 0 and 1 is finite for every perspective
/// projection (standard or reversed, finite or infinite far plane).
pub const RAY_DEPTH: f32 = 0.5;

/// The scene's camera: position, yaw (clockwise from north, `+z`), pitch
/// (up), vertical field of view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub position_m: Vec3,
    pub yaw_deg: f32,
    pub pitch_deg: f32,
    pub fov_deg: f32,
}

impl Camera {
    /// Forward, right and up unit vectors.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let (y, p) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        let forward = Vec3::new(p.cos() * y.sin(), p.sin(), p.cos() * y.cos());
        // x east, y up, z north: facing north, east is to the right.
        let right = Vec3::Y.cross(forward).normalize_or(Vec3::X);
        let up = forward.cross(right);
        (forward, right, up)
    }

    /// The camera as a [`View`]: left-handed `look_to` along the forward
    /// vector with `+y` up, a symmetric perspective of the field of view
    /// and `aspect`, standard depth from [`NEAR_M`] (0) to `far_m` (1).
    pub fn view(&self, aspect: f32, far_m: f32) -> View {
        let (forward, _, _) = self.basis();
        let world_to_view = Mat4::look_to_lh(self.position_m, forward, Vec3::Y);
        let far = far_m.max(2.0 * NEAR_M);
        let projection = Mat4::perspective_lh(
            self.fov_deg.clamp(1e-3, 179.0).to_radians(),
            aspect.max(1e-6),
            NEAR_M,
            far,
        );
        View::from_parts(world_to_view, projection)
    }
}

/// What the renderers accept as a camera: the scene's [`Camera`] (made a
/// [`View`] with the target's aspect and the renderer's longest ray as the
/// far plane) or the application's own [`View`] (used as it is).
pub trait ToView {
    /// The view for a target of `aspect` (width / height) and rays of at
    /// most `far_m`.
    fn to_view(&self, aspect: f32, far_m: f32) -> View;
}

impl ToView for Camera {
    fn to_view(&self, aspect: f32, far_m: f32) -> View {
        self.view(aspect, far_m)
    }
}

impl ToView for View {
    fn to_view(&self, _aspect: f32, _far_m: f32) -> View {
        *self
    }
}

/// Why a pair of matrices is not a camera the renderers can use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum CameraError {
    #[error("the {0} matrix has a non-finite entry")]
    NotFinite(&'static str),
    #[error("the {0} matrix is not invertible")]
    Singular(&'static str),
    #[error(
        "the projection is not a perspective one (the eye must map to clip w = 0, points in front of it to w > 0); orthographic projections are not supported"
    )]
    NotPerspective,
    #[error(
        "the view matrix is not a rigid motion (its rotation part must be orthonormal and its bottom row 0 0 0 1; distances are in metres)"
    )]
    NotRigid,
}

/// A perspective camera given by an application's view and projection
/// matrices (see the module's conventions). Build it with [`View::new`];
/// the inverses both renderers need are computed once here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    world_to_view: Mat4,
    projection: Mat4,
    view_to_world: Mat4,
    inverse_projection: Mat4,
    reversed: bool,
}

impl View {
    /// The view of `world_to_view` (world to camera space) and
    /// `projection` (camera to wgpu clip space), checked: finite,
    /// invertible, a rigid view, a perspective projection.
    pub fn new(world_to_view: Mat4, projection: Mat4) -> Result<Self, CameraError> {
        for (name, m) in [("view", world_to_view), ("projection", projection)] {
            if !m.is_finite() {
                return Err(CameraError::NotFinite(name));
            }
            let det = m.determinant();
            if !det.is_finite() || det.abs() < 1e-30 {
                return Err(CameraError::Singular(name));
            }
        }
        let r = glam::Mat3::from_mat4(world_to_view);
        let gram = r.transpose() * r;
        let bottom = world_to_view.row(3);
        if !gram.abs_diff_eq(glam::Mat3::IDENTITY, 1e-3) || !bottom.abs_diff_eq(glam::Vec4::W, 1e-6)
        {
            return Err(CameraError::NotRigid);
        }
        // The eye maps to w = 0 and a point in front of it to w > 0.
        let eye_w = projection.w_axis.w;
        let inverse = projection.inverse();
        let front = inverse * glam::Vec4::new(0.0, 0.0, RAY_DEPTH, 1.0);
        if !inverse.is_finite() || front.w.abs() < 1e-30 {
            return Err(CameraError::Singular("projection"));
        }
        let front_w = (projection * (front.xyz() / front.w).extend(1.0)).w;
        if eye_w.abs() > 1e-6 * front_w.abs().max(1e-30) || front_w <= 0.0 {
            return Err(CameraError::NotPerspective);
        }
        Ok(Self::from_parts(world_to_view, projection))
    }

    /// The view of checked (or made-here) matrices.
    fn from_parts(world_to_view: Mat4, projection: Mat4) -> Self {
        let inverse_projection = projection.inverse();
        let mut v = Self {
            world_to_view,
            projection,
            view_to_world: world_to_view.inverse(),
            inverse_projection,
            reversed: false,
        };
        // Depth along the centre ray: A + B / distance, monotonic. Twice as
        // far as the point at RAY_DEPTH, standard depth grows, reversed
        // shrinks.
        let p = v.view_point(Vec2::ZERO, RAY_DEPTH);
        let q = projection * (2.0 * p).extend(1.0);
        v.reversed = q.z / q.w < RAY_DEPTH;
        v
    }

    /// World to camera space.
    pub fn world_to_view(&self) -> Mat4 {
        self.world_to_view
    }

    /// Camera space to clip space.
    pub fn projection(&self) -> Mat4 {
        self.projection
    }

    /// World to clip space.
    pub fn view_projection(&self) -> Mat4 {
        self.projection * self.world_to_view
    }

    /// Camera space to world.
    pub fn view_to_world(&self) -> Mat4 {
        self.view_to_world
    }

    /// Clip space to camera space.
    pub fn inverse_projection(&self) -> Mat4 {
        self.inverse_projection
    }

    /// The eye (the rays' origin), world, m.
    pub fn eye(&self) -> Vec3 {
        self.view_to_world.w_axis.xyz()
    }

    /// The unit ray through the centre of the screen.
    pub fn forward(&self) -> Vec3 {
        self.ray_ndc(Vec2::ZERO)
    }

    /// Whether depth is reversed (1 at the near plane, 0 at the far).
    pub fn reversed_depth(&self) -> bool {
        self.reversed
    }

    /// The depth of a pixel with no geometry (what the depth buffer is
    /// cleared to): 1, or 0 with reversed depth.
    pub fn far_depth(&self) -> f32 {
        if self.reversed { 0.0 } else { 1.0 }
    }

    /// Whether depth `d` is geometry, not the far value a depth buffer is
    /// cleared to; `is_geometry` in WGSL.
    pub fn is_geometry(&self, d: f32) -> bool {
        d != self.far_depth()
    }

    /// The angle between the rays through the middle of the top and the
    /// bottom edge, degrees (the vertical field of view of a symmetric
    /// projection).
    pub fn vertical_fov_deg(&self) -> f32 {
        let (a, b) = (self.ray_ndc(Vec2::Y), self.ray_ndc(-Vec2::Y));
        // 2 asin(|a - b| / 2): exact for nearly parallel rays, where the
        // acos of their dot product has only a few ulps left at 1080p.
        2.0 * (0.5 * (a - b).length()).min(1.0).asin().to_degrees()
    }

    /// The camera-space point of clip `(ndc, depth)`.
    fn view_point(&self, ndc: Vec2, depth: f32) -> Vec3 {
        let q = self.inverse_projection * ndc.extend(depth).extend(1.0);
        q.xyz() / q.w
    }

    /// The unit world ray through normalised device coordinates `ndc`.
    pub fn ray_ndc(&self, ndc: Vec2) -> Vec3 {
        let v = self.view_point(ndc, RAY_DEPTH);
        self.view_to_world.transform_vector3(v).normalize()
    }

    /// Unit ray through pixel `(x, y)` (sub-pixel offsets allowed; `0.5` is
    /// the pixel centre) of a `width x height` image; `camera_ray` in WGSL.
    pub fn camera_ray(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        self.ray_ndc(pixel_ndc(x, y, width, height))
    }

    /// The angle (radians) between the rays through the centre pixel of a
    /// `width x height` image and its neighbour below: a pixel's cone, so
    /// that a point at distance `t` is seen over a footprint `t` times
    /// this wide (the level of detail of texture lookups).
    pub fn pixel_spread(&self, width: u32, height: u32) -> f32 {
        let (cx, cy) = (0.5 * width.max(1) as f32, 0.5 * height.max(1) as f32);
        let a = self.camera_ray(cx, cy, width, height);
        let b = self.camera_ray(cx, cy + 1.0, width, height);
        // 2 asin(|a - b| / 2): exact for nearly parallel rays, where the
        // acos of their dot product has only a few ulps left at 1080p.
        2.0 * (0.5 * (a - b).length()).min(1.0).asin()
    }

    /// Distance from the eye to the surface a depth buffer holds `depth`
    /// for at pixel `(x, y)`, m: infinite for a far-plane depth at
    /// infinity; `depth_to_distance` in WGSL.
    pub fn depth_to_distance(&self, depth: f32, x: f32, y: f32, width: u32, height: u32) -> f32 {
        let ndc = pixel_ndc(x, y, width, height);
        let q = self.inverse_projection * ndc.extend(depth).extend(1.0);
        if q.w.abs() <= 1e-30 * q.xyz().length() || q.w == 0.0 {
            return f32::INFINITY;
        }
        (q.xyz() / q.w).length()
    }
}

/// Normalised device coordinates of pixel position `(x, y)`: `x` right,
/// `y` up, `[-1, 1]` across the image.
pub fn pixel_ndc(x: f32, y: f32, width: u32, height: u32) -> Vec2 {
    Vec2::new(
        2.0 * x / width.max(1) as f32 - 1.0,
        1.0 - 2.0 * y / height.max(1) as f32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Camera {
        Camera {
            position_m: Vec3::new(10.0, 300.0, -40.0),
            yaw_deg: 33.0,
            pitch_deg: 17.0,
            fov_deg: 55.0,
        }
    }

    #[test]
    fn facing_north_east_is_right_and_up_is_up() {
        let c = Camera {
            position_m: Vec3::ZERO,
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            fov_deg: 60.0,
        };
        let (f, r, u) = c.basis();
        assert!(
            (f - Vec3::Z).length() < 1e-6
                && (r - Vec3::X).length() < 1e-6
                && (u - Vec3::Y).length() < 1e-6
        );
        let v = c.view(640.0 / 480.0, 40_000.0);
        assert!(
            v.camera_ray(639.5, 240.0, 640, 480).x > 0.0,
            "right edge looks east"
        );
        assert!(
            v.camera_ray(320.0, 0.5, 640, 480).y > 0.0,
            "top row looks up"
        );
        assert!((v.vertical_fov_deg() - 60.0).abs() < 1e-3);
    }

    /// The camera's view sees through each pixel along the ray the old
    /// basis construction gave (`forward + right·sx + up·sy`).
    #[test]
    fn a_cameras_view_has_the_basis_rays() {
        let c = scene_camera();
        let (w, h) = (320, 200);
        let v = c.view(w as f32 / h as f32, 40_000.0);
        let (f, r, u) = c.basis();
        let tan = (0.5 * c.fov_deg.to_radians()).tan();
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 10.25), (3.0, 199.0)] {
            let sx = (2.0 * x / w as f32 - 1.0) * tan * w as f32 / h as f32;
            let sy = (1.0 - 2.0 * y / h as f32) * tan;
            let old = (f + r * sx + u * sy).normalize();
            assert!((v.camera_ray(x, y, w, h) - old).length() < 1e-5);
        }
        assert!((v.eye() - c.position_m).length() < 1e-3);
        assert!((v.forward() - f).length() < 1e-5);
        assert!(!v.reversed_depth() && v.far_depth() == 1.0);
    }

    /// The same camera as four applications would write it: left- and
    /// right-handed, standard and reversed, finite and infinite far.
    fn conventions(c: &Camera, aspect: f32) -> Vec<(&'static str, View)> {
        let (f, _, _) = c.basis();
        let fov = c.fov_deg.to_radians();
        let lh = Mat4::look_to_lh(c.position_m, f, Vec3::Y);
        let rh = Mat4::look_to_rh(c.position_m, f, Vec3::Y);
        let v = |m, p| View::new(m, p).expect("valid");
        vec![
            (
                "lh",
                v(lh, Mat4::perspective_lh(fov, aspect, 0.5, 30_000.0)),
            ),
            (
                "rh",
                v(rh, Mat4::perspective_rh(fov, aspect, 0.5, 30_000.0)),
            ),
            (
                "rh reversed infinite",
                v(rh, Mat4::perspective_infinite_reverse_rh(fov, aspect, 0.1)),
            ),
            (
                "lh infinite",
                v(lh, Mat4::perspective_infinite_lh(fov, aspect, 0.1)),
            ),
            (
                "rh reversed finite",
                v(rh, Mat4::perspective_rh(fov, aspect, 20_000.0, 0.25)),
            ),
        ]
    }

    /// Every convention sees the rays of the scene's camera (mirrored
    /// left-right when right-handed), and reads back the distance of a
    /// surface written into its depth buffer.
    #[test]
    fn every_convention_sees_the_same_rays_and_distances() {
        let c = scene_camera();
        let (w, h) = (320, 200);
        let reference = c.view(w as f32 / h as f32, 40_000.0);
        for (name, v) in conventions(&c, w as f32 / h as f32) {
            let reversed = name.contains("reversed");
            assert_eq!(v.reversed_depth(), reversed, "{name}");
            for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 10.25)] {
                let dir = v.camera_ray(x, y, w, h);
                // A right-handed camera looking north with +y up has west
                // on its right: the same world seen mirrored.
                let mirrored = if name.starts_with("rh") {
                    w as f32 - x
                } else {
                    x
                };
                let want = reference.camera_ray(mirrored, y, w, h);
                assert!((dir - want).length() < 1e-5, "{name}: {dir} vs {want}");
                // A surface 1234 m along the ray, written into a depth
                // buffer with this projection, reads back 1234 m.
                let p = v.eye() + dir * 1234.0;
                let clip = v.view_projection() * p.extend(1.0);
                let d = clip.z / clip.w;
                assert!((0.0..=1.0).contains(&d), "{name}: depth {d}");
                let t = v.depth_to_distance(d, x, y, w, h);
                // f32 standard depth near 1 resolves 1.2 km with a 0.1 m
                // near plane only to about a metre (ulp 6e-8 of
                // 1 - near/z): the reason engines reverse it. Reversed
                // depth keeps f32's relative precision.
                let tol = if reversed { 0.05 } else { 2.5 };
                assert!((t - 1234.0).abs() < tol, "{name}: {t}");
            }
            let far = v.depth_to_distance(v.far_depth(), 10.0, 20.0, w, h);
            assert!(
                far > 19_000.0,
                "{name}: far plane at {far} m (infinite: inf)"
            );
        }
    }

    /// A roll of the view matrix by 90° turns the image: the ray through
    /// the top edge's middle is the unrolled view's ray through the right
    /// edge's (a square image).
    #[test]
    fn a_rolled_view_turns_the_image() {
        let c = scene_camera();
        let (f, r, u) = c.basis();
        let p = Mat4::perspective_lh(c.fov_deg.to_radians(), 1.0, 1.0, 40_000.0);
        let plain = View::new(Mat4::look_to_lh(c.position_m, f, u), p).expect("valid");
        // Up is now the old right: rolled 90° counter-clockwise.
        let rolled = View::new(Mat4::look_to_lh(c.position_m, f, r), p).expect("valid");
        let n = 256;
        let a = rolled.camera_ray(n as f32 / 2.0, 0.0, n, n);
        let b = plain.camera_ray(n as f32, n as f32 / 2.0, n, n);
        assert!((a - b).length() < 1e-5, "{a} vs {b}");
        assert!((plain.forward() - rolled.forward()).length() < 1e-6);
    }

    #[test]
    fn off_axis_frusta_put_each_ray_through_its_pixel() {
        let c = scene_camera();
        let (f, _, _) = c.basis();
        let m = Mat4::look_to_lh(c.position_m, f, Vec3::Y);
        // A frustum shifted right and down (one eye of a stereo pair, or a
        // tile of a display wall), built by hand: x' = (2n x - (r+l) z) / (r-l).
        let (l, r, b, t, n, fa) = (-0.2_f32, 0.6_f32, -0.5_f32, 0.3_f32, 1.0_f32, 30_000.0_f32);
        let p = Mat4::from_cols_array(&[
            2.0 * n / (r - l),
            0.0,
            0.0,
            0.0,
            0.0,
            2.0 * n / (t - b),
            0.0,
            0.0,
            -(r + l) / (r - l),
            -(t + b) / (t - b),
            fa / (fa - n),
            1.0,
            0.0,
            0.0,
            -n * fa / (fa - n),
            0.0,
        ]);
        let v = View::new(m, p).expect("valid");
        let (w, h) = (400, 300);
        for (x, y) in [(0.5, 0.5), (200.0, 150.0), (399.5, 299.5)] {
            let q = v.eye() + v.camera_ray(x, y, w, h) * 500.0;
            let clip = v.view_projection() * q.extend(1.0);
            let ndc = clip.xy() / clip.w;
            let px = (
                (ndc.x + 1.0) * 0.5 * w as f32,
                (1.0 - ndc.y) * 0.5 * h as f32,
            );
            assert!((px.0 - x).abs() < 1e-2 && (px.1 - y).abs() < 1e-2, "{px:?}");
        }
        // The centre ray is not the view axis: the frustum is off-axis.
        assert!(v.forward().dot(f) < 0.999);
    }

    #[test]
    fn bad_matrices_are_errors() {
        let c = scene_camera();
        let (f, _, _) = c.basis();
        let m = Mat4::look_to_lh(c.position_m, f, Vec3::Y);
        let p = Mat4::perspective_lh(1.0, 1.5, 1.0, 1000.0);
        let ortho = Mat4::orthographic_lh(-10.0, 10.0, -10.0, 10.0, 1.0, 1000.0);
        assert_eq!(View::new(m, ortho), Err(CameraError::NotPerspective));
        assert_eq!(
            View::new(m, Mat4::ZERO),
            Err(CameraError::Singular("projection"))
        );
        let mut nan = p;
        nan.x_axis.x = f32::NAN;
        assert_eq!(View::new(m, nan), Err(CameraError::NotFinite("projection")));
        assert_eq!(
            View::new(Mat4::from_scale(Vec3::splat(2.0)) * m, p),
            Err(CameraError::NotRigid)
        );
    }
}
