//! The path tracer's parameters ([`PathTraceParams`], [`BsdfParams`], [`ScatterRegions`]);
//! the pass is described in crate::passes::pathtrace.

use super::check::{count, within};
use crate::error::{Error, Result};
use crate::gpu::uniforms::{
    PT_SCATTER_BETWEEN, PT_SCATTER_EVERYWHERE, PT_SCATTER_NONE, PT_SCATTER_SURFACES,
};

/// Most paths per pixel and frame.
pub const MAX_SAMPLES_PER_FRAME: u32 = 4096;
/// Most scattering events per path.
pub const MAX_BOUNCES: u32 = 100_000;

/// Where collisions with the medium scatter light (the lecture's scattering regions). The
/// surfaces are where the hybrid model scatters by the BSDF (the gradient magnitude above
/// [`PathTraceParams::gradient_threshold`], or by chance with the stochastic blend); the
/// other collisions absorb the path or, without [`PathTraceParams::attenuation`], do not
/// happen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ScatterRegions {
    /// No collision scatters: the medium only absorbs (or, without attenuation, vanishes).
    Nowhere,
    /// Only at surfaces, by the BSDF.
    Surfaces,
    /// Only between surfaces, by Henyey–Greenstein.
    Between,
    /// At every collision, by the hybrid model.
    #[default]
    Everywhere,
}

impl ScatterRegions {
    /// The code pathtrace.wgsl knows it by (PT_SCATTER_*).
    pub(crate) fn code(self) -> u32 {
        match self {
            ScatterRegions::Nowhere => PT_SCATTER_NONE,
            ScatterRegions::Surfaces => PT_SCATTER_SURFACES,
            ScatterRegions::Between => PT_SCATTER_BETWEEN,
            ScatterRegions::Everywhere => PT_SCATTER_EVERYWHERE,
        }
    }
}

/// The surface-like scattering of the hybrid model (shaders/lib/bsdf.wgsl): GGX specular
/// reflection weighted by Schlick's Fresnel term, the rest split between Lambertian
/// reflection and an "inward-looking" Phong lobe transmitted through the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfParams {
    /// GGX roughness α, 0.01 to 1.
    pub roughness: f32,
    /// Fresnel reflectance at normal incidence, 0 to 1 (0.04: water, plastics, tissue).
    pub fresnel: f32,
    /// Share of the non-specular part that is transmitted, 0 to 1.
    pub transmission: f32,
    /// Half the transmitted lobe's directions lie within this angle of the continued
    /// propagation direction, degrees, 0.5 to 60 (60: uniform over the hemisphere).
    pub cone_angle: f32,
}

impl Default for BsdfParams {
    fn default() -> Self {
        BsdfParams {
            roughness: 0.4,
            fresnel: 0.04,
            transmission: 0.0,
            cone_angle: 30.0,
        }
    }
}

impl BsdfParams {
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        within("BSDF roughness", self.roughness, 0.01, 1.0)?;
        within("BSDF Fresnel reflectance", self.fresnel, 0.0, 1.0)?;
        within("BSDF transmission", self.transmission, 0.0, 1.0)?;
        if !(0.5..=60.0).contains(&self.cone_angle) {
            return bad(format!(
                "transmission cone angle {}° must be in [0.5°, 60°]",
                self.cone_angle
            ));
        }
        Ok(())
    }

    /// The exponent m of the transmitted Phong lobe cos^m: half its directions lie within
    /// the cone angle (P(θ < c) = 1 − cos^(m+1) c).
    pub fn lobe_exponent(&self) -> f32 {
        let c = (self.cone_angle as f64).to_radians().cos();
        ((0.5f64.ln() / c.ln()) - 1.0).max(0.0) as f32
    }
}

/// How far the path tracer's accumulation has come ([`Renderer::convergence`](crate::Renderer::convergence)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Convergence {
    /// Paths every pixel has (the passes completed).
    pub paths_per_pixel: u32,
    /// Paths per pixel on average, counting the pixels of the pass under way.
    pub mean_paths_per_pixel: f32,
    /// The shown image's estimated relative error: each covered pixel's standard error of
    /// its mean luminance (from the paths' second moment), RMS over the pixels the medium
    /// covers, over their mean luminance; `None` before every pixel has two paths.
    pub relative_error: Option<f32>,
}

/// How the path tracer samples (set with [`Renderer::set_path_tracing`](crate::Renderer::set_path_tracing)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceParams {
    /// Paths per pixel each frame adds (1 to [`MAX_SAMPLES_PER_FRAME`]).
    pub samples_per_frame: u32,
    /// Paths per pixel after which frames stop adding any and show the converged image
    /// again (a still render's budget); 0: no limit.
    pub max_samples: u32,
    /// Seconds a frame may spend tracing (0: no limit, each frame adds `samples_per_frame`
    /// paths per pixel). With a budget a frame adds as many sixteenths of a path per pixel
    /// as fit (16 interleaved subsets of the pixels; during the first pass the pixels not
    /// traced yet show a traced neighbour), at least one sixteenth and at most
    /// `samples_per_frame` paths per pixel. The time per sixteenth is measured on the
    /// device (GPU timestamps) and read back a frame or more later, so that no frame waits
    /// for it: a frame plans from an earlier frame's rate, at most twice the sixteenths that
    /// rate was measured on (one sixteenth before any came back), and the device time it
    /// takes follows the budget as the rate holds.
    pub time_budget: f32,
    /// Secondary rays per primary ray, 1 to [`MAX_SAMPLES_PER_FRAME`] (the lecture's ray
    /// budget P × S: each group of S consecutive paths of a pixel shares its jittered
    /// camera ray and first collision, and differs from there on; 1: independent paths).
    pub secondary_rays: u32,
    /// Most scattering events per path (0: single scattering is off too; the medium only
    /// attenuates what is behind it).
    pub max_bounces: u32,
    /// Henyey–Greenstein anisotropy g, |g| < 1 (0 isotropic, > 0 forward scattering).
    pub anisotropy: f32,
    /// The hybrid model's switch ψ: collisions where the gradient magnitude (scalar units
    /// per world unit) exceeds it scatter by the BSDF, the others by Henyey–Greenstein.
    /// Infinite (the default): Henyey–Greenstein everywhere.
    pub gradient_threshold: f32,
    /// The stochastic blend instead of the switch: a collision scatters by the BSDF with
    /// probability 1 − exp(−k·|∇s|) for this k > 0 (0: the hard switch at ψ).
    pub stochastic_blend: f32,
    /// The BSDF of the surfaces.
    pub bsdf: BsdfParams,
    /// Where collisions scatter.
    pub scatter: ScatterRegions,
    /// Collisions that do not scatter absorb the path (on) or do not happen (off).
    pub attenuation: bool,
    /// Weight of the environment's light (0: the view's directional lights only).
    pub environment_light: f32,
    /// Show the environment behind the medium (the frame becomes opaque).
    pub background: bool,
    /// Show the progressive image through the edge-aware à-trous denoiser
    /// (shaders/denoise.wgsl), guided by the normal and depth at the paths' first
    /// collision. The accumulation ([`Renderer::read_accumulation`](crate::Renderer::read_accumulation)) stays unfiltered.
    pub denoise: bool,
    /// Show the image through the denoiser while the pixels have fewer than this many paths
    /// (a preview that gives way to the unfiltered image; 0: only as `denoise` says).
    pub denoise_until: u32,
    /// Seed of the random streams (a different seed gives an independent image).
    pub seed: u32,
}

impl Default for PathTraceParams {
    fn default() -> Self {
        PathTraceParams {
            samples_per_frame: 4,
            max_samples: 0,
            time_budget: 0.0,
            secondary_rays: 1,
            max_bounces: 64,
            anisotropy: 0.0,
            gradient_threshold: f32::INFINITY,
            stochastic_blend: 0.0,
            bsdf: BsdfParams::default(),
            scatter: ScatterRegions::Everywhere,
            attenuation: true,
            environment_light: 1.0,
            background: false,
            denoise: false,
            denoise_until: 0,
            seed: 0,
        }
    }
}

impl PathTraceParams {
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        count(
            "paths per pixel and frame",
            self.samples_per_frame,
            1,
            MAX_SAMPLES_PER_FRAME,
        )?;
        count(
            "secondary rays per primary ray",
            self.secondary_rays,
            1,
            MAX_SAMPLES_PER_FRAME,
        )?;
        if self.max_bounces > MAX_BOUNCES {
            return bad(format!(
                "{} scattering events per path: at most {MAX_BOUNCES}",
                self.max_bounces
            ));
        }
        if self.anisotropy.is_nan() || self.anisotropy.abs() >= 1.0 {
            return bad(format!(
                "Henyey–Greenstein anisotropy {} must be in (−1, 1)",
                self.anisotropy
            ));
        }
        if self.gradient_threshold.is_nan() || self.gradient_threshold < 0.0 {
            return bad(format!(
                "gradient threshold ψ {} must be non-negative (infinite: no BSDF)",
                self.gradient_threshold
            ));
        }
        if !(self.stochastic_blend.is_finite() && self.stochastic_blend >= 0.0) {
            return bad(format!(
                "stochastic blend rate k {} must be finite and non-negative (0: the hard \
                 switch)",
                self.stochastic_blend
            ));
        }
        if !(self.time_budget.is_finite() && self.time_budget >= 0.0) {
            return bad(format!(
                "time budget {} s must be finite and non-negative (0: no budget)",
                self.time_budget
            ));
        }
        self.bsdf.validate()?;
        if !(self.environment_light.is_finite() && self.environment_light >= 0.0) {
            return bad(format!(
                "environment light weight {} must be finite and non-negative",
                self.environment_light
            ));
        }
        Ok(())
    }
}
