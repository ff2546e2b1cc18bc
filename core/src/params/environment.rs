//! Environment maps for image-based lighting of isosurfaces.
//!
//! An [`Environment`] is the radiance arriving from every direction: a procedural sky (the
//! default), an equirectangular image or six cube faces, given as texels (ferrovol-io reads
//! them from `.hdr`, `.exr`, `.png` and `.jpg` files). [`crate::Renderer::set_environment`]
//! turns it, once,
//! into GPU maps (shaders/environment.wgsl):
//!
//! - the **environment cube** (`rgba16float`, full mip chain by 2×2 box filtering), which
//!   specular lighting samples on the Phong lobe and the background shows;
//! - the **irradiance cube** (32² per face): the π-normalised irradiance
//!   `E(n)/π = (1/π)∫ L(ω) max(n·ω, 0) dω` per normal direction, by Monte Carlo filtering of
//!   the environment cube with cosine-weighted Hammersley directions, each read from the mip
//!   level its pdf calls for. A constant environment `L = c` gives `c`, so a white Lambertian
//!   surface under it reflects exactly `c`.
//!
//! Directions: the environment's own frame has +Y up; [`Environment::up`] says which world
//! direction that is and [`Environment::azimuth`] turns the environment about it. Values are
//! taken as linear radiance as they come: LDR images are not sRGB-decoded (the renderer's
//! output is not encoded either).

use crate::error::{Error, Result};
use glam::{DMat3, DQuat, DVec3};

/// Texels per edge of the irradiance cube's faces (irradiance is smooth).
pub const IRRADIANCE_SIZE: u32 = 32;
/// Largest cube face edge (texels).
pub const MAX_CUBE_SIZE: u32 = 2048;
/// Most cosine-weighted directions per irradiance texel.
pub const MAX_IRRADIANCE_SAMPLES: u32 = 65536;

/// A procedural sky in the environment's frame (+Y up): the sky colour runs from `horizon`
/// to `zenith` (with √elevation), `ground` fills the lower hemisphere behind a hard horizon,
/// and a sun disk with a soft halo sits in `sun_direction`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    pub zenith: [f32; 3],
    pub horizon: [f32; 3],
    pub ground: [f32; 3],
    /// Toward the sun (need not be unit length).
    pub sun_direction: DVec3,
    /// Radiance added inside the sun's disk; zero for no sun.
    pub sun_color: [f32; 3],
    /// Angular radius of the disk, degrees.
    pub sun_radius_deg: f32,
    /// A halo `sun_color · sun_halo · cos^256` around the sun (0: none).
    pub sun_halo: f32,
}

impl Default for Sky {
    /// A clear day: pale blue zenith, white horizon, grey-brown ground and a warm sun 40°
    /// up whose disk gives about as much irradiance as the sky (so surfaces show a light
    /// direction as well as soft sky light).
    fn default() -> Self {
        Sky {
            zenith: [0.32, 0.45, 0.7],
            horizon: [0.8, 0.82, 0.85],
            ground: [0.28, 0.26, 0.24],
            sun_direction: DVec3::new(0.45, 0.64, 0.62),
            sun_color: [200.0, 185.0, 160.0],
            sun_radius_deg: 2.0,
            sun_halo: 0.02,
        }
    }
}

impl Sky {
    /// The same radiance `c` from every direction.
    pub fn constant(c: [f32; 3]) -> Sky {
        Sky::hemisphere(c, c)
    }

    /// `above` over the whole upper hemisphere, `below` under it, no sun.
    pub fn hemisphere(above: [f32; 3], below: [f32; 3]) -> Sky {
        Sky {
            zenith: above,
            horizon: above,
            ground: below,
            sun_color: [0.0; 3],
            sun_halo: 0.0,
            ..Sky::default()
        }
    }

    /// The sky's radiance in environment direction `d` (unit), as the GPU evaluates it
    /// (`sky` in shaders/environment.wgsl).
    pub fn radiance(&self, d: DVec3) -> [f64; 3] {
        let mut c = [0.0; 3];
        for (i, v) in c.iter_mut().enumerate() {
            *v = if d.y >= 0.0 {
                let f = d.y.sqrt();
                self.horizon[i] as f64 * (1.0 - f) + self.zenith[i] as f64 * f
            } else {
                self.ground[i] as f64
            };
        }
        let sun = self.sun_direction.normalize_or(DVec3::Y);
        let cs = d.dot(sun);
        let disk = (self.sun_radius_deg as f64).to_radians().cos();
        for (i, v) in c.iter_mut().enumerate() {
            let s = self.sun_color[i] as f64;
            if cs >= disk {
                *v += s;
            }
            *v += s * self.sun_halo as f64 * cs.max(0.0).powi(256);
        }
        c
    }
}

/// Where an environment's radiance comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentSource {
    Sky(Sky),
    /// Equirectangular (latitude–longitude) image, `width = 2 · height`, rows top (+Y) to
    /// bottom (−Y); the centre column looks along −Z and longitude grows toward +X (the
    /// left quarter looks along −X). Linear RGB radiance.
    Equirect {
        width: u32,
        height: u32,
        texels: Vec<[f32; 3]>,
    },
    /// Six square faces of `size × size` texels, in the order +X, −X, +Y, −Y, +Z, −Z, rows
    /// top to bottom, oriented as Vulkan/OpenGL cube maps ([`cube_direction`]).
    Cube {
        size: u32,
        faces: Vec<Vec<[f32; 3]>>,
    },
}

/// The light arriving from every direction, with its placement in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub source: EnvironmentSource,
    /// Radiance multiplier.
    pub intensity: f32,
    /// The world direction that is up (+Y) in the environment.
    pub up: DVec3,
    /// Rotation of the environment about `up`, degrees.
    pub azimuth: f64,
    /// Edge of the environment cube's faces in texels. `None`: 256 for a sky, a quarter of
    /// an equirectangular image's width (a power of two, 16 to 1024), a cube's own size.
    /// Cube sources keep their size.
    pub resolution: Option<u32>,
    /// Cosine-weighted directions per texel of the irradiance cube (default 2048: the
    /// default sky's small bright sun is then within 2% everywhere).
    pub irradiance_samples: u32,
}

impl Default for Environment {
    /// The procedural sky ([`Sky::default`]).
    fn default() -> Self {
        Environment::sky(Sky::default())
    }
}

fn finite_rgb(what: &str, c: [f32; 3]) -> Result<()> {
    if c.iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(())
    } else {
        Err(Error::InvalidParameter(format!(
            "{what} {c:?}: radiance must be finite and non-negative"
        )))
    }
}

impl Environment {
    fn with_source(source: EnvironmentSource) -> Environment {
        Environment {
            source,
            intensity: 1.0,
            up: DVec3::Y,
            azimuth: 0.0,
            resolution: None,
            irradiance_samples: 2048,
        }
    }

    pub fn sky(sky: Sky) -> Environment {
        Environment::with_source(EnvironmentSource::Sky(sky))
    }

    /// Radiance `c` from every direction.
    pub fn constant(c: [f32; 3]) -> Environment {
        Environment::sky(Sky::constant(c))
    }

    /// `above` over the upper hemisphere, `below` under it.
    pub fn hemisphere(above: [f32; 3], below: [f32; 3]) -> Environment {
        Environment::sky(Sky::hemisphere(above, below))
    }

    /// An equirectangular image already in memory ([`EnvironmentSource::Equirect`]).
    pub fn from_equirect(width: u32, height: u32, texels: Vec<[f32; 3]>) -> Result<Environment> {
        let e = Environment::with_source(EnvironmentSource::Equirect {
            width,
            height,
            texels,
        });
        e.validate()?;
        Ok(e)
    }

    /// Six cube faces already in memory ([`EnvironmentSource::Cube`]).
    pub fn from_cube(size: u32, faces: Vec<Vec<[f32; 3]>>) -> Result<Environment> {
        let e = Environment::with_source(EnvironmentSource::Cube { size, faces });
        e.validate()?;
        Ok(e)
    }

    /// Checks the source and settings; every constructor calls it, the renderer again.
    pub fn validate(&self) -> Result<()> {
        match &self.source {
            EnvironmentSource::Sky(s) => {
                finite_rgb("sky zenith", s.zenith)?;
                finite_rgb("sky horizon", s.horizon)?;
                finite_rgb("sky ground", s.ground)?;
                finite_rgb("sun colour", s.sun_color)?;
                let sun_ok = s.sun_radius_deg.is_finite()
                    && (0.0..=90.0).contains(&s.sun_radius_deg)
                    && s.sun_halo.is_finite()
                    && s.sun_halo >= 0.0
                    && s.sun_direction.is_finite()
                    && s.sun_direction.length() >= 1e-12;
                if !sun_ok {
                    return Err(Error::InvalidParameter(format!(
                        "sun: direction {:?} must be finite and non-zero, radius {}° in [0, 90], \
                         halo {} non-negative",
                        s.sun_direction, s.sun_radius_deg, s.sun_halo
                    )));
                }
            }
            EnvironmentSource::Equirect {
                width,
                height,
                texels,
            } => {
                if *width == 0 || *height == 0 || *width != 2 * *height {
                    return Err(Error::InvalidParameter(format!(
                        "equirectangular map {width}x{height}: it must be non-empty and exactly \
                         twice as wide as high"
                    )));
                }
                if texels.len() != (*width as usize) * (*height as usize) {
                    return Err(Error::InvalidParameter(format!(
                        "equirectangular map {width}x{height} needs {} texels, got {}",
                        (*width as usize) * (*height as usize),
                        texels.len()
                    )));
                }
            }
            EnvironmentSource::Cube { size, faces } => {
                if *size == 0 || *size > MAX_CUBE_SIZE || faces.len() != 6 {
                    return Err(Error::InvalidParameter(format!(
                        "cube map: {} faces of {size}x{size}; give six faces of 1 to \
                         {MAX_CUBE_SIZE} texels square",
                        faces.len()
                    )));
                }
                let n = (*size as usize) * (*size as usize);
                if let Some(i) = faces.iter().position(|f| f.len() != n) {
                    return Err(Error::InvalidParameter(format!(
                        "cube face {} has {} texels; {size}x{size} = {n} expected",
                        FACE_NAMES[i],
                        faces[i].len()
                    )));
                }
            }
        }
        if !(self.intensity.is_finite() && self.intensity >= 0.0) {
            return Err(Error::InvalidParameter(format!(
                "environment intensity {} must be finite and non-negative",
                self.intensity
            )));
        }
        if !self.up.is_finite() || self.up.length() < 1e-12 || !self.azimuth.is_finite() {
            return Err(Error::InvalidParameter(format!(
                "environment up {:?} must be a finite non-zero vector and azimuth {} finite",
                self.up, self.azimuth
            )));
        }
        if let Some(r) = self.resolution {
            if !(4..=MAX_CUBE_SIZE).contains(&r) {
                return Err(Error::InvalidParameter(format!(
                    "environment resolution {r}: give 4 to {MAX_CUBE_SIZE} texels per cube face \
                     edge"
                )));
            }
        }
        if !(1..=MAX_IRRADIANCE_SAMPLES).contains(&self.irradiance_samples) {
            return Err(Error::InvalidParameter(format!(
                "{} irradiance samples: give 1 to {MAX_IRRADIANCE_SAMPLES}",
                self.irradiance_samples
            )));
        }
        Ok(())
    }

    /// World direction → environment direction (+Y = [`Environment::up`]).
    pub fn rotation(&self) -> DMat3 {
        let up = self.up.normalize_or(DVec3::Y);
        DMat3::from_rotation_y(-self.azimuth.to_radians())
            * DMat3::from_quat(DQuat::from_rotation_arc(up, DVec3::Y))
    }

    /// Edge of the environment cube's faces for this source.
    pub fn cube_size(&self) -> u32 {
        match &self.source {
            EnvironmentSource::Cube { size, .. } => *size,
            EnvironmentSource::Equirect { width, .. } => self
                .resolution
                .unwrap_or_else(|| (width / 4).max(1).next_power_of_two().clamp(16, 1024)),
            EnvironmentSource::Sky(_) => self.resolution.unwrap_or(256),
        }
    }
}

/// Cube face names in layer order.
pub const FACE_NAMES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// Unit direction through the point (s, t) ∈ [0, 1]² of cube face `face` (layer order +X,
/// −X, +Y, −Y, +Z, −Z; s to the right, t down the face image), Vulkan's cube-map convention
/// (`cube_direction` in shaders/lib/envmap.wgsl).
pub fn cube_direction(face: usize, s: f64, t: f64) -> DVec3 {
    let sc = 2.0 * s - 1.0;
    let tc = 2.0 * t - 1.0;
    let d = match face {
        0 => DVec3::new(1.0, -tc, -sc),
        1 => DVec3::new(-1.0, -tc, sc),
        2 => DVec3::new(sc, 1.0, tc),
        3 => DVec3::new(sc, -1.0, -tc),
        4 => DVec3::new(sc, -tc, 1.0),
        _ => DVec3::new(-sc, -tc, -1.0),
    };
    d.normalize()
}

/// The face and (s, t) ∈ [0, 1]² a direction falls on (the inverse of [`cube_direction`]).
pub fn cube_face_coords(d: DVec3) -> (usize, f64, f64) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

/// A cube map read back from the GPU: six faces of `size²` RGBA texels (layer order +X, −X,
/// +Y, −Y, +Z, −Z, rows top to bottom), in the environment's frame.
#[derive(Clone, Debug)]
pub struct CubeImage {
    pub size: u32,
    pub faces: Vec<Vec<[f32; 4]>>,
}

impl CubeImage {
    /// Unit direction through the centre of texel (x, y) of `face`.
    pub fn texel_direction(&self, face: usize, x: u32, y: u32) -> DVec3 {
        let n = self.size as f64;
        cube_direction(face, (x as f64 + 0.5) / n, (y as f64 + 0.5) / n)
    }

    /// The texel a direction falls in (nearest, no filtering).
    pub fn lookup(&self, d: DVec3) -> [f32; 4] {
        let (face, s, t) = cube_face_coords(d);
        let n = self.size;
        let x = ((s * n as f64) as u32).min(n - 1);
        let y = ((t * n as f64) as u32).min(n - 1);
        self.faces[face][(y * n + x) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_coords_invert_cube_direction() {
        for face in 0..6 {
            for &(s, t) in &[(0.5, 0.5), (0.1, 0.8), (0.9, 0.2), (0.3, 0.35)] {
                let d = cube_direction(face, s, t);
                let (f2, s2, t2) = cube_face_coords(d);
                assert_eq!(f2, face, "face of {d:?}");
                assert!((s - s2).abs() < 1e-12 && (t - t2).abs() < 1e-12);
            }
        }
        // face centres along the axes, in layer order
        let axes = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        for (f, a) in axes.iter().enumerate() {
            assert!((cube_direction(f, 0.5, 0.5) - *a).length() < 1e-12);
        }
    }

    #[test]
    fn rotation_puts_up_on_y() {
        let mut e = Environment::default();
        for up in [DVec3::Z, DVec3::NEG_Z, DVec3::X, DVec3::new(1.0, 2.0, 3.0)] {
            e.up = up;
            e.azimuth = 30.0;
            let r = e.rotation();
            assert!((r * up.normalize() - DVec3::Y).length() < 1e-12, "{up:?}");
        }
    }

    #[test]
    fn bad_environments_are_errors() {
        assert!(Environment::from_equirect(3, 2, vec![[0.0; 3]; 6]).is_err());
        assert!(Environment::from_equirect(4, 2, vec![[0.0; 3]; 7]).is_err());
        assert!(Environment::from_cube(2, vec![vec![[0.0; 3]; 4]; 5]).is_err());
        let mut e = Environment::constant([1.0; 3]);
        e.intensity = f32::NAN;
        assert!(e.validate().is_err());
        let mut e = Environment::constant([-1.0, 0.0, 0.0]);
        assert!(e.validate().is_err());
        e = Environment::default();
        e.up = DVec3::ZERO;
        assert!(e.validate().is_err());
    }
}
