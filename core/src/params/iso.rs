//! The isosurface parameters ([`IsoParams`]) and what the first-hit pass leaves behind
//! ([`GBuffer`]); the passes are described in crate::passes::iso.

use super::check::{count, non_negative, within};
use crate::error::{Error, Result};
use crate::gpu::uniforms::{ISO_MAX_VALUES, SPECULAR_CONE, SPECULAR_IMPORTANCE};
use glam::DVec3;

/// Most iso-values per frame.
pub const MAX_ISO_VALUES: usize = ISO_MAX_VALUES;
/// Most G-buffer layers (surfaces kept per pixel).
pub const MAX_LAYERS: u32 = 8;
/// Most bisection steps.
pub const MAX_BISECTION_STEPS: u32 = 32;
/// Most specular samples per shaded point (also the number of precomputed cone vectors).
pub const MAX_SPECULAR_SAMPLES: u32 = 1024;
/// Most ambient-occlusion directions per hit.
pub const MAX_AO_SAMPLES: u32 = 1024;
/// Most steps per ambient-occlusion ray.
pub const MAX_AO_STEPS: u32 = 256;

/// One isosurface: where the field equals `value` (of the component the isosurfaces are of,
/// see [`IsoParams`]), drawn in `color`
/// with `opacity` (1: opaque; less: the surfaces behind show through).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoValue {
    pub value: f64,
    pub color: [f32; 3],
    pub opacity: f32,
}

impl IsoValue {
    pub fn new(value: f64, color: [f32; 3], opacity: f32) -> IsoValue {
        IsoValue {
            value,
            color,
            opacity,
        }
    }
}

/// How the environment's specular light is sampled on the Phong lobe cos^s around the
/// reflection vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SpecularMode {
    /// The simple scheme: precomputed random unit vectors p (flipped when r·p < 0) blended
    /// with the reflection vector r by a weight from the shininess, normalised, weighted by
    /// the lobe; the full-resolution map is read. Noisy, aliased at low sample counts.
    Cone,
    /// Importance sampling of the lobe (Hammersley directions with the lobe's distribution),
    /// each sample read from the mip level whose texels cover the solid angle its pdf gives
    /// it (Colbert & Křivánek, GPU Gems 3 ch. 20): smooth even at a few samples.
    #[default]
    Importance,
}

impl SpecularMode {
    pub(crate) fn code(self) -> u32 {
        match self {
            SpecularMode::Cone => SPECULAR_CONE,
            SpecularMode::Importance => SPECULAR_IMPORTANCE,
        }
    }
}

/// The specular exponent s of a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shininess {
    Constant(f32),
    /// From the gradient magnitude |∇f| (scalar units per world unit) at the hit, linearly:
    /// `exponents[0]` at or below `range[0]`, `exponents[1]` at or above `range[1]`, so
    /// shininess shows how sharp the boundary is. `range: None` spans 0 to a quarter of the
    /// data range per smallest voxel spacing.
    GradientMagnitude {
        range: Option<[f64; 2]>,
        exponents: [f32; 2],
    },
}

impl Default for Shininess {
    fn default() -> Self {
        Shininess::GradientMagnitude {
            range: None,
            exponents: [8.0, 64.0],
        }
    }
}

/// Ambient occlusion: per hit, `samples` directions (Hammersley, uniform over the
/// hemisphere around the normal), each a short ray of `steps` samples over `radius`; the
/// fraction that never reaches the other side of the hit's iso-value scales ambient and
/// environment light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    pub samples: u32,
    pub steps: u32,
    /// Ray length in world units; `None`: 8 smallest voxel spacings.
    pub radius: Option<f64>,
}

impl Default for AmbientOcclusion {
    fn default() -> Self {
        AmbientOcclusion {
            samples: 16,
            steps: 8,
            radius: None,
        }
    }
}

/// Everything an isosurface frame needs beyond [`RenderParams`](crate::RenderParams) (set with
/// [`Renderer::set_isosurface`](crate::Renderer::set_isosurface)). The material's ambient, diffuse and specular
/// coefficients come from [`RenderParams::shading`](crate::RenderParams::shading) (lighting is always on in this mode,
/// whatever `shading.enabled` says); its termination threshold ends marching behind
/// translucent surfaces; its depth threshold picks the layer whose depth is written. The
/// field is always interpolated trilinearly (`interpolation` is for the DVR modes), and
/// the isosurfaces are those of one component, as vtkGPUVolumeRayCastMapper chooses it: with
/// independent components the one of the largest weight (the first of equal ones), else the
/// first.
#[derive(Clone, Debug, PartialEq)]
pub struct IsoParams {
    /// 1 to [`MAX_ISO_VALUES`] isosurfaces.
    pub values: Vec<IsoValue>,
    /// Halvings of the crossing interval, then one linear interpolation inside the last
    /// one. The default, 8, brackets a one-voxel step to 1/256 voxel and puts hits within
    /// 2·10⁻⁵ voxel of the interpolated field's isosurface (measured on a sphere: 4 steps
    /// give 4.5·10⁻⁴, 0 steps, interpolation alone, 5.5·10⁻³).
    pub bisection_steps: u32,
    /// Surface layers kept per pixel (1 to [`MAX_LAYERS`]).
    pub max_layers: u32,
    pub specular: SpecularMode,
    /// Environment samples on the specular lobe (1 to [`MAX_SPECULAR_SAMPLES`]).
    pub specular_samples: u32,
    pub shininess: Shininess,
    /// Schlick's Fresnel weighting of specular light with this reflectance at normal
    /// incidence (e.g. 0.04); `None`: no Fresnel term.
    pub fresnel: Option<f32>,
    pub ambient_occlusion: Option<AmbientOcclusion>,
    /// Weight of the environment's light (0: the view's lights only). The default, 0.6,
    /// leaves room for VTK's headlight; give 1 for environment light alone.
    pub environment_light: f32,
    /// Show the environment behind the surfaces (the frame becomes opaque).
    pub background: bool,
    /// Light scattered between the surfaces (the fast path of multiple scattering):
    /// `None` (the default) shades the layers as surfaces only.
    pub scattering: Option<IsoScattering>,
}

/// How [`IsoScattering`] follows the light inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IsoScatterMode {
    /// The real-time preview: the way out absorbs as much as the way in (transmittance
    /// squared), the environment's light from the irradiance cube.
    Preview,
    /// The final version: directions traced from the inner surface out of the volume.
    Traced,
}

/// Scattering restricted to the isosurfaces (shaders/deferred.wgsl): light enters at the
/// first surface, is absorbed on its way inward to the next surface (extinction from the
/// first component's transfer function, as the path tracer reads it, times `absorption`),
/// scatters there (Lambertian, albedo the inner surface's colour), and leaves toward the
/// environment; the result and the first surface's own shading are blended by Schlick's
/// Fresnel term, and the first surface is opaque. Lit by the environment (weight
/// [`IsoParams::environment_light`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsoScattering {
    pub mode: IsoScatterMode,
    /// Directions traced per pixel (Traced), 1 to [`MAX_SCATTER_SAMPLES`].
    pub samples: u32,
    /// Multiplies the medium's extinction (0: nothing is absorbed).
    pub absorption: f32,
    /// Fresnel reflectance at normal incidence of the first surface (0 to 1).
    pub fresnel: f32,
}

impl Default for IsoScattering {
    fn default() -> Self {
        IsoScattering {
            mode: IsoScatterMode::Preview,
            samples: 16,
            absorption: 1.0,
            fresnel: 0.04,
        }
    }
}

/// Most directions [`IsoScattering`] traces per pixel.
pub const MAX_SCATTER_SAMPLES: u32 = 256;

impl Default for IsoParams {
    fn default() -> Self {
        IsoParams {
            values: Vec::new(),
            bisection_steps: 8,
            max_layers: 4,
            specular: SpecularMode::Importance,
            specular_samples: 16,
            shininess: Shininess::default(),
            fresnel: None,
            ambient_occlusion: None,
            environment_light: 0.6,
            background: false,
            scattering: None,
        }
    }
}

impl IsoParams {
    /// Defaults with these iso-values.
    pub fn with_values(values: Vec<IsoValue>) -> IsoParams {
        IsoParams {
            values,
            ..IsoParams::default()
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        count(
            "iso-values",
            self.values.len().min(u32::MAX as usize) as u32,
            1,
            MAX_ISO_VALUES as u32,
        )?;
        for (i, v) in self.values.iter().enumerate() {
            if !v.value.is_finite() || v.value.abs() > f32::MAX as f64 {
                return bad(format!("iso-value {i} ({}) must be finite", v.value));
            }
            if !v.color.iter().all(|c| (0.0..=1.0).contains(c)) {
                return bad(format!(
                    "iso-value {i} ({}): colour {:?} must have components in [0, 1]",
                    v.value, v.color
                ));
            }
            if !(v.opacity > 0.0 && v.opacity <= 1.0) {
                return bad(format!(
                    "iso-value {i} ({}): opacity {} must be in (0, 1]",
                    v.value, v.opacity
                ));
            }
        }
        if self.bisection_steps > MAX_BISECTION_STEPS {
            return bad(format!(
                "{} bisection steps: at most {MAX_BISECTION_STEPS} (each halves the interval; \
                 f32 runs out long before)",
                self.bisection_steps
            ));
        }
        count("layers", self.max_layers, 1, MAX_LAYERS)?;
        count(
            "specular samples",
            self.specular_samples,
            1,
            MAX_SPECULAR_SAMPLES,
        )?;
        match self.shininess {
            Shininess::Constant(s) if !(s.is_finite() && s >= 0.0) => {
                return bad(format!("shininess {s} must be finite and non-negative"));
            }
            Shininess::GradientMagnitude { range, exponents } => {
                if !exponents.iter().all(|s| s.is_finite() && *s >= 0.0) {
                    return bad(format!(
                        "shininess exponents {exponents:?} must be finite and non-negative"
                    ));
                }
                if let Some([lo, hi]) = range {
                    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                        return bad(format!(
                            "shininess gradient range [{lo}, {hi}] must be finite with low < high"
                        ));
                    }
                }
            }
            _ => {}
        }
        if let Some(f) = self.fresnel {
            within("Fresnel reflectance at normal incidence", f, 0.0, 1.0)?;
        }
        if let Some(ao) = &self.ambient_occlusion {
            count(
                "ambient-occlusion directions",
                ao.samples,
                1,
                MAX_AO_SAMPLES,
            )?;
            count("ambient-occlusion steps", ao.steps, 1, MAX_AO_STEPS)?;
            if let Some(r) = ao.radius {
                if !(r.is_finite() && r > 0.0) {
                    return bad(format!("ambient-occlusion radius {r} must be positive"));
                }
            }
        }
        non_negative("environment light weight", self.environment_light)?;
        if let Some(sc) = &self.scattering {
            count("scattering directions", sc.samples, 1, MAX_SCATTER_SAMPLES)?;
            non_negative("scattering absorption scale", sc.absorption)?;
            within("scattering Fresnel reflectance", sc.fresnel, 0.0, 1.0)?;
        }
        Ok(())
    }
}

/// One surface layer of a pixel, from [`GBuffer::hits`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// World position of the refined crossing.
    pub position: DVec3,
    /// Unit world normal, facing the viewer.
    pub normal: DVec3,
    /// |∇f| in scalar units per world unit.
    pub gradient_magnitude: f64,
    /// Index into [`IsoParams::values`].
    pub iso_index: usize,
    /// Window depth (0 near … 1 far).
    pub depth: f32,
    /// Ambient accessibility (1: no occlusion; 1 without AO).
    pub ambient_access: f32,
    /// World distance along the ray from the near plane.
    pub distance: f64,
}

/// The G-buffer of the last isosurface frame, read back by [`Renderer::read_gbuffer`](crate::Renderer::read_gbuffer).
#[derive(Clone, Debug)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    /// Per pixel (rows top to bottom): how many layers hold a hit.
    pub counts: Vec<u32>,
    /// Per layer, then pixel: xyz world position, w iso index.
    pub position: Vec<[f32; 4]>,
    /// Per layer, then pixel: xyz unit normal, w gradient magnitude.
    pub normal: Vec<[f32; 4]>,
    /// Per layer, then pixel: window depth, ambient accessibility, ray distance, 0.
    pub extra: Vec<[f32; 4]>,
}

impl GBuffer {
    /// The surfaces of pixel (x, y), front to back.
    pub fn hits(&self, x: u32, y: u32) -> Vec<Hit> {
        let px = (y * self.width + x) as usize;
        let n = (self.width * self.height) as usize;
        (0..self.counts[px] as usize)
            .map(|l| {
                let i = l * n + px;
                let (p, nn, e) = (self.position[i], self.normal[i], self.extra[i]);
                Hit {
                    position: DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64),
                    normal: DVec3::new(nn[0] as f64, nn[1] as f64, nn[2] as f64),
                    gradient_magnitude: nn[3] as f64,
                    iso_index: p[3] as usize,
                    depth: e[0],
                    ambient_access: e[1],
                    distance: e[2] as f64,
                }
            })
            .collect()
    }
}
