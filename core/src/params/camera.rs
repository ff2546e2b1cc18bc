//! Camera with VTK's conventions (vtkCamera): position, focal point, view up, vertical view
//! angle in degrees, parallel projection with a parallel scale (half the viewport height in
//! world units), clipping range. Projection follows OpenGL, so depth values are VTK's.

use glam::{DMat4, DVec3, DVec4};

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: DVec3,
    pub focal_point: DVec3,
    pub view_up: DVec3,
    /// Vertical view angle, degrees (VTK default 30).
    pub view_angle: f64,
    pub parallel: bool,
    pub parallel_scale: f64,
    pub clipping_range: [f64; 2],
    /// Raw matrices given by a host (world → view, view → clip, OpenGL conventions);
    /// when set they replace the ones derived from the fields above.
    pub raw: Option<(DMat4, DMat4)>,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            position: DVec3::new(0.0, 0.0, 1.0),
            focal_point: DVec3::ZERO,
            view_up: DVec3::Y,
            view_angle: 30.0,
            parallel: false,
            parallel_scale: 1.0,
            clipping_range: [0.01, 1000.01],
            raw: None,
        }
    }
}

impl Camera {
    /// Places the camera like vtkRenderer::ResetCamera: looking at the centre of `bounds`
    /// along the current view direction, far enough that the bounding sphere fits.
    pub fn reset(&mut self, bounds: [f64; 6]) {
        let center = DVec3::new(
            0.5 * (bounds[0] + bounds[1]),
            0.5 * (bounds[2] + bounds[3]),
            0.5 * (bounds[4] + bounds[5]),
        );
        let w = DVec3::new(
            bounds[1] - bounds[0],
            bounds[3] - bounds[2],
            bounds[5] - bounds[4],
        );
        let mut radius = 0.5 * w.length();
        if radius == 0.0 {
            radius = 0.5;
        }
        let dir = (self.position - self.focal_point)
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let distance = radius / (0.5 * self.view_angle.to_radians()).sin();
        self.focal_point = center;
        self.position = center + dir * distance;
        self.parallel_scale = radius;
        self.orthogonalize_view_up();
        self.reset_clipping_range(bounds);
    }

    /// Like vtkRenderer::ResetCameraClippingRange: near and far planes just around `bounds`.
    pub fn reset_clipping_range(&mut self, bounds: [f64; 6]) {
        let dir = self.direction();
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for c in 0..8 {
            let p = DVec3::new(
                bounds[(c & 1) as usize],
                bounds[2 + ((c >> 1) & 1) as usize],
                bounds[4 + ((c >> 2) & 1) as usize],
            );
            let d = (p - self.position).dot(dir);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        // widen a little, keep the near plane in front of the camera (VTK's tolerance 0.001)
        let pad = (hi - lo).max(1e-6) * 0.01;
        hi += pad;
        lo = (lo - pad).max(hi * 0.001);
        self.clipping_range = [lo, hi];
    }

    /// Unit vector from position to focal point.
    pub fn direction(&self) -> DVec3 {
        (self.focal_point - self.position)
            .try_normalize()
            .unwrap_or(DVec3::NEG_Z)
    }

    pub fn distance(&self) -> f64 {
        (self.focal_point - self.position).length()
    }

    /// Rotates the camera about the view up vector centred at the focal point (vtkCamera::Azimuth).
    pub fn azimuth(&mut self, degrees: f64) {
        let rot = DMat4::from_axis_angle(self.view_up.normalize(), degrees.to_radians());
        let rel = self.position - self.focal_point;
        self.position = self.focal_point + rot.transform_vector3(rel);
    }

    /// Rotates the camera about the cross product of the view plane normal and the view up
    /// (vtkCamera::Elevation). View up is left unchanged, as in VTK.
    pub fn elevation(&mut self, degrees: f64) {
        let rel = self.position - self.focal_point;
        let axis = rel.normalize().cross(self.view_up).try_normalize();
        if let Some(axis) = axis {
            let rot = DMat4::from_axis_angle(axis, degrees.to_radians());
            self.position = self.focal_point + rot.transform_vector3(rel);
        }
    }

    /// Rolls the camera about the direction of projection (vtkCamera::Roll).
    pub fn roll(&mut self, degrees: f64) {
        let rot = DMat4::from_axis_angle(self.direction(), -degrees.to_radians());
        self.view_up = rot.transform_vector3(self.view_up);
    }

    /// vtkCamera::Zoom: narrows the view angle (perspective) or the parallel scale.
    pub fn zoom(&mut self, factor: f64) {
        if factor <= 0.0 || !factor.is_finite() {
            return;
        }
        if self.parallel {
            self.parallel_scale /= factor;
        } else {
            self.view_angle /= factor;
        }
    }

    /// Makes view up perpendicular to the direction of projection (vtkCamera::OrthogonalizeViewUp).
    pub fn orthogonalize_view_up(&mut self) {
        let d = self.direction();
        let right = d
            .cross(self.view_up)
            .try_normalize()
            .unwrap_or_else(|| d.any_orthonormal_vector());
        self.view_up = right.cross(d).normalize();
    }

    /// World → view matrix.
    pub fn view_matrix(&self) -> DMat4 {
        if let Some((v, _)) = self.raw {
            return v;
        }
        DMat4::look_at_rh(self.position, self.focal_point, self.view_up)
    }

    /// View → clip matrix (OpenGL clip space, depth −1…1) for an aspect ratio width/height.
    pub fn projection_matrix(&self, aspect: f64) -> DMat4 {
        if let Some((_, p)) = self.raw {
            return p;
        }
        let [near, far] = self.clipping_range;
        if self.parallel {
            let h = self.parallel_scale;
            let w = h * aspect;
            DMat4::orthographic_rh_gl(-w, w, -h, h, near, far)
        } else {
            DMat4::perspective_rh_gl(self.view_angle.to_radians(), aspect, near, far)
        }
    }

    /// World → clip.
    pub fn view_projection(&self, aspect: f64) -> DMat4 {
        self.projection_matrix(aspect) * self.view_matrix()
    }

    /// The window depth (0 near … 1 far, OpenGL/VTK) of a world point.
    pub fn window_depth(&self, aspect: f64, p: DVec3) -> f64 {
        let c = self.view_projection(aspect) * DVec4::new(p.x, p.y, p.z, 1.0);
        0.5 * (c.z / c.w) + 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_fits_bounds_like_vtk() {
        let mut c = Camera::default();
        c.reset([-1.0, 1.0, -1.0, 1.0, -1.0, 1.0]);
        let r = 3f64.sqrt();
        let d = r / (15f64.to_radians()).sin();
        assert!((c.distance() - d).abs() < 1e-9);
        assert!(c.clipping_range[0] > 0.0 && c.clipping_range[0] < d - 1.0);
        assert!(c.clipping_range[1] > d + 1.0);
    }

    #[test]
    fn azimuth_keeps_distance_and_turns() {
        let mut c = Camera::default();
        c.azimuth(90.0);
        assert!(
            (c.position - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-12,
            "{:?}",
            c.position
        );
        c.elevation(90.0);
        assert!(
            (c.position - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12,
            "{:?}",
            c.position
        );
    }
}
