//! The demo's camera: orbit around a point or fly (mouse + WASD), reset,
//! and bookmarked views.

use cumulus::render::camera::Camera;
use glam::Vec3;

/// How the mouse and keys move the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Drag turns around `target`; the wheel zooms.
    Orbit,
    /// Drag looks around; W/A/S/D move, Q/E down/up, Shift faster.
    Fly,
}

/// The views a user can jump to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bookmark {
    GroundLookingUp,
    AboveTheLayer,
    AlongTheHorizon,
}

impl Bookmark {
    pub const ALL: [Bookmark; 3] = [
        Bookmark::GroundLookingUp,
        Bookmark::AboveTheLayer,
        Bookmark::AlongTheHorizon,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Bookmark::GroundLookingUp => "ground, looking up",
            Bookmark::AboveTheLayer => "above the cloud layer",
            Bookmark::AlongTheHorizon => "along the horizon",
        }
    }
}

/// The camera and its controller state.
pub struct Controller {
    pub camera: Camera,
    pub mode: Mode,
    /// Orbit centre, m.
    pub target: Vec3,
    /// Orbit distance, m.
    pub distance_m: f32,
    /// Fly speed, m/s.
    pub speed_mps: f32,
    home: Camera,
    keys: Keys,
}

#[derive(Default, Clone, Copy)]
struct Keys {
    forward: bool,
    back: bool,
    left: bool,
    right: bool,
    up: bool,
    down: bool,
    fast: bool,
}

impl Controller {
    /// Starts at `home` (the scene's camera), flying.
    pub fn new(home: Camera) -> Self {
        Self {
            camera: home,
            mode: Mode::Fly,
            target: home.position_m + home.basis().0 * 3000.0,
            distance_m: 3000.0,
            speed_mps: 150.0,
            home,
            keys: Keys::default(),
        }
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        self.camera = self.home;
        self.mode = Mode::Fly;
    }

    /// Jumps to a bookmark for a cloud band `[bottom, top]` m.
    pub fn go_to(&mut self, b: Bookmark, band_bottom_m: f32, band_top_m: f32) {
        let p = self.camera.position_m;
        self.mode = Mode::Fly;
        (self.camera.position_m, self.camera.pitch_deg) = match b {
            Bookmark::GroundLookingUp => (Vec3::new(p.x, 20.0, p.z), 45.0),
            Bookmark::AboveTheLayer => (Vec3::new(p.x, band_top_m + 1500.0, p.z), -25.0),
            Bookmark::AlongTheHorizon => (Vec3::new(p.x, 0.5 * band_bottom_m, p.z), 3.0),
        };
    }

    /// A key went down (`true`) or up.
    pub fn key(&mut self, code: winit::keyboard::KeyCode, down: bool) {
        use winit::keyboard::KeyCode as K;
        match code {
            K::KeyW | K::ArrowUp => self.keys.forward = down,
            K::KeyS | K::ArrowDown => self.keys.back = down,
            K::KeyA | K::ArrowLeft => self.keys.left = down,
            K::KeyD | K::ArrowRight => self.keys.right = down,
            K::KeyE | K::Space => self.keys.up = down,
            K::KeyQ => self.keys.down = down,
            K::ShiftLeft | K::ShiftRight => self.keys.fast = down,
            _ => {}
        }
    }

    /// The mouse was dragged by `(dx, dy)` pixels.
    pub fn drag(&mut self, dx: f32, dy: f32) {
        let c = &mut self.camera;
        match self.mode {
            Mode::Fly => {
                c.yaw_deg = (c.yaw_deg + 0.15 * dx).rem_euclid(360.0);
                c.pitch_deg = (c.pitch_deg - 0.15 * dy).clamp(-89.0, 89.0);
            }
            Mode::Orbit => {
                c.yaw_deg = (c.yaw_deg + 0.25 * dx).rem_euclid(360.0);
                c.pitch_deg = (c.pitch_deg - 0.25 * dy).clamp(-89.0, 89.0);
                self.place_on_orbit();
            }
        }
    }

    /// The wheel turned by `lines`.
    pub fn scroll(&mut self, lines: f32) {
        match self.mode {
            Mode::Orbit => {
                self.distance_m = (self.distance_m * 0.9_f32.powf(lines)).clamp(50.0, 50_000.0);
                self.place_on_orbit();
            }
            Mode::Fly => self.speed_mps = (self.speed_mps * 1.2_f32.powf(lines)).clamp(5.0, 5000.0),
        }
    }

    /// Switches mode; orbiting starts around the point looked at.
    pub fn set_mode(&mut self, mode: Mode) {
        if mode == Mode::Orbit && self.mode != Mode::Orbit {
            self.target = self.camera.position_m + self.camera.basis().0 * self.distance_m;
        }
        self.mode = mode;
    }

    fn place_on_orbit(&mut self) {
        let f = self.camera.basis().0;
        self.camera.position_m = self.target - f * self.distance_m;
        self.camera.position_m.y = self.camera.position_m.y.max(2.0);
    }

    /// Moves for `dt_s` seconds of held keys (fly mode).
    pub fn update(&mut self, dt_s: f32) {
        if self.mode != Mode::Fly {
            return;
        }
        let (f, r, _) = self.camera.basis();
        let k = self.keys;
        let axis = |a: bool, b: bool| (a as i32 - b as i32) as f32;
        let v =
            f * axis(k.forward, k.back) + r * axis(k.right, k.left) + Vec3::Y * axis(k.up, k.down);
        let speed = self.speed_mps * if k.fast { 5.0 } else { 1.0 };
        self.camera.position_m += v.normalize_or_zero() * speed * dt_s;
        self.camera.position_m.y = self.camera.position_m.y.max(2.0);
    }
}
