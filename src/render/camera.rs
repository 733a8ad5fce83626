//! The view's orbit camera. Part of [`crate::render`].

use glam::{DMat4, DVec3};

/// An orbit camera around a target, +Z up (the printer's).
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub target: DVec3,
    pub distance: f64,
    /// Azimuth about +Z and elevation above the XY plane, radians.
    pub yaw: f64,
    pub pitch: f64,
    /// Radius of the scene's bounding sphere (near/far planes, pan speed).
    pub radius: f64,
    pub aspect: f64,
    pub height_px: f64,
}

/// Vertical field of view: 40 degrees.
pub(super) const FOV: f64 = 0.698;
/// Elevation stops short of the poles, where look-at has no "up".
const MAX_PITCH: f64 = 1.5690;

impl Camera {
    pub(super) fn framing(lo: DVec3, hi: DVec3, aspect: f64, height_px: f64) -> Camera {
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        let fit = radius / (0.5 * FOV).sin() / aspect.min(1.0);
        Camera {
            target: 0.5 * (lo + hi),
            distance: 1.05 * fit,
            yaw: -1.9,
            pitch: 0.6,
            radius,
            aspect,
            height_px,
        }
    }

    pub(super) fn eye(&self) -> DVec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * DVec3::new(cp * cy, cp * sy, sp)
    }

    pub(super) fn view_proj(&self) -> DMat4 {
        let near = (self.distance - 2.0 * self.radius).max(self.distance * 1e-3);
        let far = self.distance + 2.0 * self.radius;
        glam::dcamera::rh::proj::opengl::perspective(FOV, self.aspect, near, far)
            * glam::dcamera::rh::view::look_at_mat4(self.eye(), self.target, DVec3::Z)
    }

    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * 0.008;
        self.pitch = (self.pitch + dy * 0.008).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target so the scene follows the pointer.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let per_px = 2.0 * self.distance * (0.5 * FOV).tan() / self.height_px.max(1.0);
        let f = (self.target - self.eye()).normalize();
        let right = f.cross(DVec3::Z).normalize_or_zero();
        let up = right.cross(f);
        self.target += (-dx * right + dy * up) * per_px;
    }

    pub fn zoom(&mut self, delta: f64) {
        let k = (delta * 0.0015).clamp(-1.0, 1.0).exp();
        self.distance = (self.distance * k).clamp(self.radius * 0.02, self.radius * 50.0);
    }

    /// The ray through the pixel (x, y) of a `width` x `height` drawing
    /// buffer (device pixels from the top-left corner): its origin on the
    /// near plane and its unit direction, in the frame the mesh is drawn in.
    /// `None` when the camera matrix cannot be inverted.
    pub fn ray(&self, x_px: f64, y_px: f64, width: f64, height: f64) -> Option<(DVec3, DVec3)> {
        let ndc_x = 2.0 * x_px / width.max(1.0) - 1.0;
        let ndc_y = 1.0 - 2.0 * y_px / height.max(1.0);
        let inv = self.view_proj().inverse();
        let near = inv.project_point3(DVec3::new(ndc_x, ndc_y, -1.0));
        let far = inv.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
        let dir = (far - near).normalize_or_zero();
        (near.is_finite() && dir != DVec3::ZERO).then_some((near, dir))
    }

    pub fn top(&mut self) {
        self.yaw = -std::f64::consts::FRAC_PI_2;
        self.pitch = MAX_PITCH;
    }

    /// The drawing-buffer pixel (from the top-left) where `p` is drawn, or
    /// `None` when it lies behind the camera.
    pub fn project(&self, p: DVec3, width: f64, height: f64) -> Option<(f64, f64)> {
        let clip = self.view_proj() * p.extend(1.0);
        if clip.w <= 0.0 || !clip.is_finite() {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some(((ndc.x + 1.0) * 0.5 * width, (1.0 - ndc.y) * 0.5 * height))
    }

    /// The angle one pixel of the drawing buffer spans at its centre.
    pub fn pixel_angle(&self) -> f64 {
        FOV / self.height_px.max(1.0)
    }
}
