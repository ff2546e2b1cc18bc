//! The isosurface and path tracing render modes through the C ABI: iso-values, deferred
//! shading and ambient-occlusion settings ([`FvIsoParams`]), path tracing settings
//! ([`FvPathTraceParams`]) and the environment map both are lit by.

use crate::status::{FfiError, FfiResult};
use crate::types::ToCore;
use ferrovol_core::iso::MAX_ISO_VALUES;
use ferrovol_core::{
    AmbientOcclusion, BsdfParams, IsoParams, IsoScatterMode, IsoScattering, IsoValue,
    PathTraceParams, ScatterRegions, Shininess, SpecularMode,
};

/// Most iso-values in one FvIsoParams.
pub const FV_MAX_ISO_VALUES: usize = 8;
const _: () = assert!(FV_MAX_ISO_VALUES == MAX_ISO_VALUES);

/// How the environment's specular light is sampled on the Phong lobe.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvSpecularMode {
    /// Random unit vectors in a cone blended with the reflection vector (simple, noisy).
    Cone = 0,
    /// Importance sampling of the lobe, each sample from the mip level its pdf calls for.
    Importance = 1,
}

/// One isosurface: where the first component equals `value`, drawn in `color` (RGB in
/// [0, 1]) with `opacity` in (0, 1]. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvIsoValue {
    pub value: f64,
    pub color: [f32; 3],
    pub opacity: f32,
}

/// Isosurfaces and their shading for frames with FV_BLEND_MODE_ISOSURFACE. Fill with
/// fv_iso_params_default() and change what you need. The material's ambient, diffuse and
/// specular weights come from FvRenderParams (lighting is always on in this mode).
/// Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvIsoParams {
    /// sizeof(this struct) as the caller's header declares it, written by
    /// fv_iso_params_default; fields added in later minor versions take their defaults
    /// when it is smaller.
    pub size: usize,
    /// 1 to FV_MAX_ISO_VALUES entries of `values` are used.
    pub value_count: u32,
    pub values: [FvIsoValue; FV_MAX_ISO_VALUES],
    /// Halvings of each crossing interval (0 to 32; default 8: hits within 2·10⁻⁵ voxel).
    pub bisection_steps: u32,
    /// Translucent surface layers kept per pixel (1 to 8).
    pub max_layers: u32,
    /// One of FvSpecularMode.
    pub specular_mode: u32,
    /// Environment samples on the specular lobe per shaded point (1 to 1024).
    pub specular_samples: u32,
    /// Specular exponent at weak and at strong gradient magnitude (equal values: a constant
    /// exponent).
    pub shininess: [f32; 2],
    /// Gradient magnitudes (scalar units per world unit) that `shininess` spans; [0, 0]:
    /// 0 to a quarter of the data range per smallest voxel spacing.
    pub shininess_range: [f64; 2],
    /// Schlick Fresnel reflectance at normal incidence in [0, 1]; negative: no Fresnel term.
    pub fresnel: f32,
    /// Ambient-occlusion directions per hit (0: no ambient occlusion; at most 1024).
    pub ao_samples: u32,
    /// Steps along each ambient-occlusion ray (1 to 256).
    pub ao_steps: u32,
    /// Ambient-occlusion ray length in world units; 0: 8 smallest voxel spacings.
    pub ao_radius: f64,
    /// Weight of the environment's light (0: the lights only).
    pub environment_light: f32,
    /// Show the environment behind the surfaces (the frame becomes opaque).
    pub background: bool,
    /// Light scattered between the surfaces: 0 none (the default), 1 the preview
    /// (transmittance squared, the irradiance cube), 2 traced (`scatter_samples` directions
    /// from the inner surface out of the volume).
    pub scatter_mode: u32,
    /// Directions traced per pixel (scatter_mode 2), 1 to 256.
    pub scatter_samples: u32,
    /// Multiplies the medium's extinction between the surfaces (0: no absorption).
    pub scatter_absorption: f32,
    /// Fresnel reflectance at normal incidence of the first surface when scattering.
    pub scatter_fresnel: f32,
}

crate::sized::sized_params!(FvIsoParams, "FvIsoParams", scatter_fresnel: f32, 296);

impl FvIsoParams {
    pub fn defaults() -> Self {
        let d = IsoParams::default();
        let (shininess, shininess_range) = match d.shininess {
            Shininess::Constant(s) => ([s, s], [0.0, 0.0]),
            Shininess::GradientMagnitude { range, exponents } => {
                (exponents, range.unwrap_or([0.0, 0.0]))
            }
        };
        let ao = AmbientOcclusion::default();
        FvIsoParams {
            size: std::mem::size_of::<FvIsoParams>(),
            value_count: 0,
            values: [FvIsoValue::default(); FV_MAX_ISO_VALUES],
            bisection_steps: d.bisection_steps,
            max_layers: d.max_layers,
            specular_mode: match d.specular {
                SpecularMode::Cone => FvSpecularMode::Cone as u32,
                SpecularMode::Importance => FvSpecularMode::Importance as u32,
            },
            specular_samples: d.specular_samples,
            shininess,
            shininess_range,
            fresnel: d.fresnel.unwrap_or(-1.0),
            ao_samples: 0,
            ao_steps: ao.steps,
            ao_radius: 0.0,
            environment_light: d.environment_light,
            background: d.background,
            scatter_mode: 0,
            scatter_samples: IsoScattering::default().samples,
            scatter_absorption: IsoScattering::default().absorption,
            scatter_fresnel: IsoScattering::default().fresnel,
        }
    }
}

impl ToCore for FvIsoParams {
    type Core = IsoParams;
    fn to_core(&self) -> FfiResult<IsoParams> {
        let n = self.value_count as usize;
        if n == 0 || n > FV_MAX_ISO_VALUES {
            return Err(FfiError::invalid(format!(
                "value_count {n}: give 1 to {FV_MAX_ISO_VALUES} iso-values"
            )));
        }
        let specular = match self.specular_mode {
            0 => SpecularMode::Cone,
            1 => SpecularMode::Importance,
            m => {
                return Err(FfiError::invalid(format!(
                    "specular_mode {m} is not an FvSpecularMode (0 cone, 1 importance)"
                )))
            }
        };
        let [s0, s1] = self.shininess;
        let shininess = if s0 == s1 {
            Shininess::Constant(s0)
        } else {
            Shininess::GradientMagnitude {
                range: (self.shininess_range != [0.0, 0.0]).then_some(self.shininess_range),
                exponents: self.shininess,
            }
        };
        if !(self.ao_radius.is_finite() && self.ao_radius >= 0.0) {
            return Err(FfiError::invalid(format!(
                "ao_radius {} must be 0 (automatic) or positive",
                self.ao_radius
            )));
        }
        if self.fresnel.is_nan() {
            return Err(FfiError::invalid(
                "fresnel is NaN: give a reflectance in [0, 1] or a negative value for none",
            ));
        }
        let p = IsoParams {
            values: self.values[..n]
                .iter()
                .map(|v| IsoValue::new(v.value, v.color, v.opacity))
                .collect(),
            bisection_steps: self.bisection_steps,
            max_layers: self.max_layers,
            specular,
            specular_samples: self.specular_samples,
            shininess,
            fresnel: (self.fresnel >= 0.0).then_some(self.fresnel),
            ambient_occlusion: (self.ao_samples > 0).then_some(AmbientOcclusion {
                samples: self.ao_samples,
                steps: self.ao_steps,
                radius: (self.ao_radius > 0.0).then_some(self.ao_radius),
            }),
            environment_light: self.environment_light,
            background: self.background,
            scattering: match self.scatter_mode {
                0 => None,
                m @ (1 | 2) => Some(IsoScattering {
                    mode: if m == 1 {
                        IsoScatterMode::Preview
                    } else {
                        IsoScatterMode::Traced
                    },
                    samples: self.scatter_samples,
                    absorption: self.scatter_absorption,
                    fresnel: self.scatter_fresnel,
                }),
                m => {
                    return Err(FfiError::invalid(format!(
                        "scatter_mode {m}: 0 none, 1 preview, 2 traced"
                    )))
                }
            },
        };
        p.validate()?;
        Ok(p)
    }
}

/// Where collisions with the medium scatter light (FvPathTraceParams::scatter_regions).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvScatterRegions {
    /// No collision scatters: the medium only absorbs (or, without attenuation, vanishes).
    Nowhere = 0,
    /// Only at surfaces (where the hybrid model chooses the BSDF).
    Surfaces = 1,
    /// Only between surfaces (by Henyey–Greenstein).
    Between = 2,
    /// At every collision, by the hybrid model.
    Everywhere = 3,
}

/// How frames with FV_BLEND_MODE_PATH_TRACE sample. Fill with fv_path_trace_params_default()
/// and change what you need. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvPathTraceParams {
    /// sizeof(this struct) as the caller's header declares it, written by
    /// fv_path_trace_params_default; fields added in later minor versions take their defaults
    /// when it is smaller.
    pub size: usize,
    /// Paths per pixel each frame adds (1 to 4096).
    pub samples_per_frame: u32,
    /// Paths per pixel after which frames add none and show the converged image again (a
    /// still render's budget); 0: no limit.
    pub max_samples: u32,
    /// Most scattering events per path.
    pub max_bounces: u32,
    /// Henyey–Greenstein anisotropy g in (−1, 1).
    pub anisotropy: f32,
    /// Weight of the environment's light (0: the directional lights only).
    pub environment_light: f32,
    /// Show the environment behind the medium (the frame becomes opaque).
    pub background: bool,
    /// Seed of the random streams.
    pub seed: u32,
    /// Secondary rays per primary ray, 1 to 4096 (the ray budget P × S: each S consecutive
    /// paths of a pixel share their camera ray and first collision).
    pub secondary_rays: u32,
    /// The hybrid model's gradient threshold ψ (scalar units per world unit): the BSDF
    /// where the gradient magnitude exceeds it; INFINITY: Henyey–Greenstein everywhere.
    pub gradient_threshold: f32,
    /// k > 0: the stochastic blend instead of the threshold, the BSDF with probability
    /// 1 − exp(−k·|∇s|); 0: the threshold.
    pub stochastic_blend: f32,
    /// The BSDF's GGX roughness in [0.01, 1].
    pub roughness: f32,
    /// The BSDF's Fresnel reflectance at normal incidence in [0, 1].
    pub fresnel: f32,
    /// Share of the BSDF's non-specular part transmitted through the surface, [0, 1].
    pub transmission: f32,
    /// Half the transmitted lobe lies within this angle, degrees in [0.5, 60].
    pub cone_angle: f32,
    /// One of FvScatterRegions.
    pub scatter_regions: u32,
    /// Collisions that do not scatter absorb (true) or are left out (false).
    pub attenuation: bool,
    /// Show the image through the edge-aware à-trous denoiser (the accumulation stays
    /// unfiltered).
    pub denoise: bool,
    /// Seconds a frame may spend tracing (0: no limit: samples_per_frame paths per pixel
    /// each frame). With a budget a frame adds as many sixteenths of a path per pixel as fit
    /// (16 interleaved pixel subsets; during the first pass untraced pixels show a traced
    /// neighbour), at least one sixteenth, at most samples_per_frame paths per pixel.
    pub time_budget: f32,
    /// Denoise the shown image while pixels have fewer than this many paths (a preview; 0:
    /// only as `denoise` says).
    pub denoise_until: u32,
}

crate::sized::sized_params!(FvPathTraceParams, "FvPathTraceParams", denoise_until: u32, 80);

impl FvPathTraceParams {
    pub fn defaults() -> Self {
        let d = PathTraceParams::default();
        FvPathTraceParams {
            size: std::mem::size_of::<FvPathTraceParams>(),
            samples_per_frame: d.samples_per_frame,
            max_samples: d.max_samples,
            max_bounces: d.max_bounces,
            anisotropy: d.anisotropy,
            environment_light: d.environment_light,
            background: d.background,
            seed: d.seed,
            secondary_rays: d.secondary_rays,
            gradient_threshold: d.gradient_threshold,
            stochastic_blend: d.stochastic_blend,
            roughness: d.bsdf.roughness,
            fresnel: d.bsdf.fresnel,
            transmission: d.bsdf.transmission,
            cone_angle: d.bsdf.cone_angle,
            scatter_regions: match d.scatter {
                ScatterRegions::Nowhere => FvScatterRegions::Nowhere,
                ScatterRegions::Surfaces => FvScatterRegions::Surfaces,
                ScatterRegions::Between => FvScatterRegions::Between,
                ScatterRegions::Everywhere => FvScatterRegions::Everywhere,
            } as u32,
            attenuation: d.attenuation,
            denoise: d.denoise,
            time_budget: d.time_budget,
            denoise_until: d.denoise_until,
        }
    }
}

impl ToCore for FvPathTraceParams {
    type Core = PathTraceParams;
    fn to_core(&self) -> FfiResult<PathTraceParams> {
        let scatter = match self.scatter_regions {
            0 => ScatterRegions::Nowhere,
            1 => ScatterRegions::Surfaces,
            2 => ScatterRegions::Between,
            3 => ScatterRegions::Everywhere,
            m => {
                return Err(FfiError::invalid(format!(
                    "scatter_regions {m} is not an FvScatterRegions (0 nowhere, 1 surfaces, \
                     2 between, 3 everywhere)"
                )))
            }
        };
        let p = PathTraceParams {
            samples_per_frame: self.samples_per_frame,
            max_samples: self.max_samples,
            time_budget: self.time_budget,
            secondary_rays: self.secondary_rays,
            max_bounces: self.max_bounces,
            anisotropy: self.anisotropy,
            gradient_threshold: self.gradient_threshold,
            stochastic_blend: self.stochastic_blend,
            bsdf: BsdfParams {
                roughness: self.roughness,
                fresnel: self.fresnel,
                transmission: self.transmission,
                cone_angle: self.cone_angle,
            },
            scatter,
            attenuation: self.attenuation,
            environment_light: self.environment_light,
            background: self.background,
            denoise: self.denoise,
            denoise_until: self.denoise_until,
            seed: self.seed,
        };
        p.validate()?;
        Ok(p)
    }
}
