//! A pinhole camera.

use glam::Vec3;

/// Camera: position, yaw (clockwise from north, +z), pitch (up), vertical
/// field of view.
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

    /// Unit ray through pixel `(x, y)` (sub-pixel offsets allowed; `0.5` is
    /// the pixel centre) of a `width x height` image.
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        let (f, r, u) = self.basis();
        let tan = (0.5 * self.fov_deg.to_radians()).tan();
        let aspect = width as f32 / height.max(1) as f32;
        let sx = (2.0 * x / width as f32 - 1.0) * tan * aspect;
        let sy = (1.0 - 2.0 * y / height as f32) * tan;
        (f + r * sx + u * sy).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(
            c.ray(639.5, 240.0, 640, 480).x > 0.0,
            "right edge looks east"
        );
        assert!(c.ray(320.0, 0.5, 640, 480).y > 0.0, "top row looks up");
    }
}
