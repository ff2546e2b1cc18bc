//! Lights with VTK's conventions (vtkLight): a headlight sits at the camera; camera lights
//! are given in camera coordinates (the camera at the origin looking down −z, as vtkLightKit
//! places them); scene lights in world coordinates. Directional lights shine from
//! `position` toward `focal_point`; positional lights attenuate with distance and may be
//! spotlights with a cone angle.

use super::camera::Camera;
use glam::{DMat4, DVec3};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSpace {
    Headlight,
    Camera,
    World,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub space: LightSpace,
    pub positional: bool,
    pub position: DVec3,
    pub focal_point: DVec3,
    /// Diffuse colour (VTK's vtkLight::DiffuseColor).
    pub diffuse: [f32; 3],
    /// Specular colour (VTK's vtkLight::SpecularColor).
    pub specular: [f32; 3],
    /// Ambient colour (VTK's vtkLight::AmbientColor).
    pub ambient: [f32; 3],
    pub intensity: f32,
    /// Constant, linear and quadratic attenuation (positional lights).
    pub attenuation: [f32; 3],
    /// Spotlight half-angle in degrees; 180 or more means no cone.
    pub cone_angle: f32,
    pub exponent: f32,
}

impl Light {
    /// VTK's default headlight: white, intensity 1, at the camera. Its ambient colour is
    /// white because VTK's single-headlight shading path uses the material's ambient
    /// coefficient times the sample colour.
    pub fn headlight() -> Light {
        Light {
            space: LightSpace::Headlight,
            positional: false,
            position: DVec3::new(0.0, 0.0, 1.0),
            focal_point: DVec3::ZERO,
            diffuse: [1.0; 3],
            specular: [1.0; 3],
            ambient: [1.0; 3],
            intensity: 1.0,
            attenuation: [1.0, 0.0, 0.0],
            cone_angle: 30.0,
            exponent: 1.0,
        }
    }

    /// A directional light in world space shining from `from` toward `to` (no ambient
    /// colour, as vtkLight's default).
    pub fn directional(from: DVec3, to: DVec3, intensity: f32) -> Light {
        Light {
            space: LightSpace::World,
            position: from,
            focal_point: to,
            intensity,
            ambient: [0.0; 3],
            ..Light::headlight()
        }
    }

    /// A positional light in world space.
    pub fn positional(at: DVec3, toward: DVec3, intensity: f32) -> Light {
        Light {
            positional: true,
            cone_angle: 180.0,
            ..Light::directional(at, toward, intensity)
        }
    }

    /// Position and focal point in world space for this camera.
    pub fn world_placement(&self, camera: &Camera) -> (DVec3, DVec3) {
        match self.space {
            LightSpace::World => (self.position, self.focal_point),
            LightSpace::Headlight => (camera.position, camera.focal_point),
            LightSpace::Camera => {
                let cam_to_world: DMat4 = camera.view_matrix().inverse();
                let d = camera.distance();
                let place = |p: DVec3| cam_to_world.transform_point3((p - DVec3::Z) * d);
                (place(self.position), place(self.focal_point))
            }
        }
    }
}
