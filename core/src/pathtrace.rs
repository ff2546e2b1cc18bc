//! Progressive Monte Carlo path tracing of the volume as a participating medium
//! ([`BlendMode::PathTrace`](crate::BlendMode::PathTrace), shaders/pathtrace.wgsl).
//!
//! The medium is the transfer function read physically: extinction
//! σ = −ln(1 − α) / unit distance from the opacity α as given (a slab one
//! ScalarOpacityUnitDistance thick lets 1 − α through, VTK's meaning), the colour as the
//! single-scattering albedo, and a Henyey–Greenstein phase function. Paths fly by delta
//! tracking against the majorant of each 8³-cell block they cross (from the block's
//! scalar range, so empty space is crossed block by block), take next-event estimates
//! toward the environment (directions drawn from its luminance on a 32² cube, multiple
//! importance sampling with the phase function) and the view's directional lights
//! (ratio-tracking transmittance), and end by Russian roulette or after
//! [`PathTraceParams::max_bounces`] scattering events.
//!
//! Frames accumulate: each [`Renderer::render`](crate::Renderer::render) adds
//! [`PathTraceParams::samples_per_frame`] paths per pixel to the sums of the frames before,
//! until anything that changes the image changes (camera, lights, size, render or path
//! tracing parameters but the paths per frame and the budget, volume, transfer function,
//! environment), or until [`PathTraceParams::max_samples`]; the count is
//! [`Renderer::accumulated_samples`]. The environment is the one
//! [`Renderer::set_environment`](crate::Renderer::set_environment) built (the procedural sky
//! by default).
//!
//! Limits of this version: the volume must fit in one brick; the first component is the
//! medium; cropping and positional lights are refused.

use crate::binding::{
    bind, buffer_entry, entry, sampled_texture_entry, sampler_entry, storage_texture_entry,
    texture_entry,
};
use crate::error::{Error, Result};
use crate::gpu::{
    DenoiseUniforms, PathTraceUniforms, PhaseTestUniforms, DENOISE_FROM_SUMS, DENOISE_LAST,
    PT_FLAG_ATTENUATION, PT_FLAG_BACKGROUND, PT_FLAG_GUIDE,
};
use crate::iso::{shader_module, single_group_pipeline};
use crate::params::{BlendMode, GradientMethod, Interpolation, RenderParams, Shading, MAX_LIGHTS};
use crate::readback::read_buffer;
use crate::renderer::{block_grid, DepthSource, Renderer, View};
use crate::transfer::TABLE_SIZE;
use crate::Context;
use bytemuck::Zeroable;
use glam::DMat4;

/// Largest opacity the medium takes (σ stays finite: 9.2 per unit distance); the same
/// clamp as PT_MAX_OPACITY in pathtrace.wgsl.
const MAX_OPACITY: f64 = 0.9999;
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
    pub fn code(self) -> u32 {
        match self {
            ScatterRegions::Nowhere => 0,
            ScatterRegions::Surfaces => 1,
            ScatterRegions::Between => 2,
            ScatterRegions::Everywhere => 3,
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
        if !(0.01..=1.0).contains(&self.roughness) {
            return bad(format!(
                "BSDF roughness {} must be in [0.01, 1]",
                self.roughness
            ));
        }
        if !(0.0..=1.0).contains(&self.fresnel) {
            return bad(format!(
                "BSDF Fresnel reflectance {} must be in [0, 1]",
                self.fresnel
            ));
        }
        if !(0.0..=1.0).contains(&self.transmission) {
            return bad(format!(
                "BSDF transmission {} must be in [0, 1]",
                self.transmission
            ));
        }
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

/// How the path tracer samples (set with [`Renderer::set_path_tracing`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceParams {
    /// Paths per pixel each frame adds (1 to [`MAX_SAMPLES_PER_FRAME`]).
    pub samples_per_frame: u32,
    /// Paths per pixel after which frames stop adding any and show the converged image
    /// again (a still render's budget); 0: no limit.
    pub max_samples: u32,
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
    /// collision. The accumulation ([`Renderer::read_accumulation`]) stays unfiltered.
    pub denoise: bool,
    /// Seed of the random streams (a different seed gives an independent image).
    pub seed: u32,
}

impl Default for PathTraceParams {
    fn default() -> Self {
        PathTraceParams {
            samples_per_frame: 4,
            max_samples: 0,
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
            seed: 0,
        }
    }
}

impl PathTraceParams {
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if !(1..=MAX_SAMPLES_PER_FRAME).contains(&self.samples_per_frame) {
            return bad(format!(
                "{} paths per pixel and frame: give 1 to {MAX_SAMPLES_PER_FRAME}",
                self.samples_per_frame
            ));
        }
        if !(1..=MAX_SAMPLES_PER_FRAME).contains(&self.secondary_rays) {
            return bad(format!(
                "{} secondary rays per primary ray: give 1 to {MAX_SAMPLES_PER_FRAME}",
                self.secondary_rays
            ));
        }
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

/// Bytes between the uniforms of consecutive dispatches of a frame (one path per pixel
/// each; 256 is the largest dynamic-offset alignment a device may ask for).
const UNIFORM_STRIDE: u64 = 256;
const _: () = assert!(std::mem::size_of::<PathTraceUniforms>() as u64 <= UNIFORM_STRIDE);

/// The path tracer's GPU state, created on first use.
pub(crate) struct PathTraceGpu {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    bgl: wgpu::BindGroupLayout,
    /// One pipeline per table interpolation (NEAREST).
    pipelines: std::collections::HashMap<PathTraceVariant, wgpu::ComputePipeline>,
    uniforms: wgpu::Buffer,
    /// Per pixel: sums of radiance and coverage over the accumulated paths.
    accum: Option<(u32, u32, wgpu::Buffer)>,
    /// Per pixel, the same size: the denoiser's guide sums, then its two ping-pong images.
    denoise_buffers: Option<[wgpu::Buffer; 3]>,
    denoise: Option<(wgpu::BindGroupLayout, wgpu::ComputePipeline, wgpu::Buffer)>,
    /// The environment's sampling distribution: (environment generation, texels per face
    /// edge, cumulative probabilities).
    env_dist: Option<(u64, u32, wgpu::Buffer)>,
    /// The block majorants: (the volume and table upload counts they were computed at,
    /// buffer, the largest).
    majorants: Option<((u32, u32), wgpu::TextureView, f32)>,
    /// What the accumulated paths were traced with; a different key starts over.
    key: String,
    samples: u32,
}

impl PathTraceGpu {
    fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<PathTraceGpu> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        let d = &ctx.device;
        let bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("path tracing"),
            entries: &[
                buffer_entry(0, B::Uniform),
                texture_entry(1, false, V::D2),
                buffer_entry(2, B::Storage { read_only: false }),
                texture_entry(4, false, V::D2),
                storage_texture_entry(5, wgpu::TextureFormat::Rgba8Unorm, V::D2),
                storage_texture_entry(6, wgpu::TextureFormat::R32Float, V::D2),
                entry(
                    7,
                    wgpu::BindingType::Buffer {
                        ty: B::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: std::num::NonZeroU64::new(std::mem::size_of::<
                            PathTraceUniforms,
                        >()
                            as u64),
                    },
                ),
                texture_entry(11, true, V::Cube),
                sampler_entry(13),
                buffer_entry(14, B::Storage { read_only: true }),
                sampled_texture_entry(
                    15,
                    wgpu::TextureSampleType::Float { filterable: false },
                    V::D3,
                ),
                buffer_entry(16, B::Storage { read_only: false }),
            ],
        });
        let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pathtrace.wgsl"),
            bind_group_layouts: &[Some(&bgl), Some(brick_bgl)],
            immediate_size: 0,
        });
        let module = shader_module(ctx, "pathtrace.wgsl")?;
        let uniforms = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("path tracing uniforms"),
            size: UNIFORM_STRIDE * MAX_SAMPLES_PER_FRAME as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(PathTraceGpu {
            module,
            layout,
            bgl,
            pipelines: Default::default(),
            uniforms,
            accum: None,
            denoise_buffers: None,
            denoise: None,
            env_dist: None,
            majorants: None,
            key: String::new(),
            samples: 0,
        })
    }

    fn pipeline(&mut self, ctx: &Context, v: PathTraceVariant) -> Result<wgpu::ComputePipeline> {
        if let Some(p) = self.pipelines.get(&v) {
            return Ok(p.clone());
        }
        let b = |x: bool| if x { 1.0 } else { 0.0 };
        let constants = [
            ("NEAREST", b(v.nearest)),
            ("HYBRID", b(v.hybrid)),
            ("GUIDE", b(v.guide)),
            ("FORWARD_DIFF", b(v.forward_diff)),
        ];
        let p = ctx.checked("creating the path tracing pipeline", || {
            ctx.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("path tracing"),
                    layout: Some(&self.layout),
                    module: &self.module,
                    entry_point: Some("main"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        zero_initialize_workgroup_memory: false,
                    },
                    cache: None,
                })
        })?;
        self.pipelines.insert(v, p.clone());
        Ok(p)
    }

    fn ensure_accum(&mut self, ctx: &Context, width: u32, height: u32) -> Result<()> {
        if self
            .accum
            .as_ref()
            .is_some_and(|(w, h, _)| *w == width && *h == height)
        {
            return Ok(());
        }
        self.accum = None;
        self.denoise_buffers = None;
        let buffer = |label| {
            ctx.checked("allocating the path tracing accumulation", || {
                ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: 16 * width as u64 * height as u64,
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_SRC
                        | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            })
        };
        let buf = buffer("path tracing accumulation")?;
        self.denoise_buffers = Some([
            buffer("denoiser guide")?,
            buffer("denoiser image A")?,
            buffer("denoiser image B")?,
        ]);
        self.accum = Some((width, height, buf));
        self.samples = 0;
        Ok(())
    }
}

/// The pipeline constants of one specialisation of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct PathTraceVariant {
    /// Nearest table lookups.
    nearest: bool,
    /// The BSDF and the scattering regions (anything but Henyey–Greenstein everywhere).
    hybrid: bool,
    /// The denoiser's guide.
    guide: bool,
    /// Forward-difference gradients (FORWARD_DIFF in lib/volume.wgsl).
    forward_diff: bool,
}

/// Texels per face edge of the cube the environment is importance-sampled on (at most).
const ENV_DIST_SIZE: u32 = 32;
/// Share of the environment's sampling probability spread uniformly over the sphere, so
/// every direction keeps some (the distribution is built from a coarse mip level).
const ENV_DIST_UNIFORM: f64 = 0.1;

/// The cumulative sampling probabilities of the texels of a cube image: luminance × solid
/// angle, mixed with a uniform share (pathtrace.wgsl: env_sample, env_pdf).
fn environment_cdf(cube: &crate::environment::CubeImage) -> Vec<f32> {
    let n = cube.size as usize;
    let mut weights = Vec::with_capacity(6 * n * n);
    let mut solid = Vec::with_capacity(6 * n * n);
    for face in &cube.faces {
        for (i, t) in face.iter().enumerate() {
            let sc = 2.0 * ((i % n) as f64 + 0.5) / n as f64 - 1.0;
            let tc = 2.0 * ((i / n) as f64 + 0.5) / n as f64 - 1.0;
            let q = 1.0 + sc * sc + tc * tc;
            let omega = 4.0 / (n * n) as f64 / (q * q.sqrt());
            let lum = 0.2126 * t[0] as f64 + 0.7152 * t[1] as f64 + 0.0722 * t[2] as f64;
            weights.push(lum.max(0.0) * omega);
            solid.push(omega);
        }
    }
    let total: f64 = weights.iter().sum();
    let total_solid: f64 = solid.iter().sum();
    let mut acc = 0.0;
    let mut cdf: Vec<f32> = weights
        .iter()
        .zip(&solid)
        .map(|(w, o)| {
            let lum_share = if total > 0.0 {
                w / total
            } else {
                o / total_solid
            };
            acc += (1.0 - ENV_DIST_UNIFORM) * lum_share + ENV_DIST_UNIFORM * o / total_solid;
            acc as f32
        })
        .collect();
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    cdf
}

/// Iterations of the à-trous denoiser (taps 1, 2, 4, 8 and 16 pixels apart).
const DENOISE_ITERATIONS: u32 = 3;
/// Edge-stopping scales of the denoiser: colour (radiance units, shrinking by √2 each
/// iteration), the power of the normals' cosine (low: a medium's first-collision normals are
/// noisy), depth (sample distances per pixel of tap spacing).
const DENOISE_COLOR_SIGMA: f32 = 1.0;
const DENOISE_NORMAL_POWER: f32 = 1.0;
const DENOISE_DEPTH_SIGMA: f32 = 16.0;

fn denoise_pipeline(
    ctx: &Context,
) -> Result<(wgpu::BindGroupLayout, wgpu::ComputePipeline, wgpu::Buffer)> {
    use wgpu::BufferBindingType as B;
    let (bgl, pipeline) = single_group_pipeline(
        ctx,
        "denoise.wgsl",
        "denoise",
        &[
            entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: B::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: std::num::NonZeroU64::new(
                        std::mem::size_of::<DenoiseUniforms>() as u64,
                    ),
                },
            ),
            buffer_entry(1, B::Storage { read_only: true }),
            buffer_entry(2, B::Storage { read_only: false }),
            buffer_entry(3, B::Storage { read_only: true }),
            buffer_entry(4, B::Storage { read_only: true }),
            storage_texture_entry(
                5,
                wgpu::TextureFormat::Rgba8Unorm,
                wgpu::TextureViewDimension::D2,
            ),
        ],
    )?;
    let d = &ctx.device;
    let uniforms = d.create_buffer(&wgpu::BufferDescriptor {
        label: Some("denoiser uniforms"),
        size: UNIFORM_STRIDE * DENOISE_ITERATIONS as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    Ok((bgl, pipeline, uniforms))
}

/// What the denoiser reads and writes.
struct DenoiseOutputs<'a> {
    accum: &'a wgpu::Buffer,
    guide: &'a wgpu::Buffer,
    images: [&'a wgpu::Buffer; 2],
    color: &'a wgpu::TextureView,
}

/// Records the denoiser's iterations over `rect`: the accumulation's means (scale[0] = 1 /
/// paths) filtered into the ping-pong images, the last also into the output colour. The
/// colour edge-stopping scale shrinks each iteration (Dammertz et al. halve it); depths are
/// compared per `scale[1]` (the sample distance) times the tap spacing.
#[allow(clippy::too_many_arguments)]
fn encode_denoise(
    ctx: &Context,
    enc: &mut wgpu::CommandEncoder,
    bgl: &wgpu::BindGroupLayout,
    pipeline: &wgpu::ComputePipeline,
    uniforms: &wgpu::Buffer,
    out: &DenoiseOutputs<'_>,
    rect: [u32; 4],
    width: u32,
    scale: [f32; 2],
) {
    let mut blocks = vec![0u8; (UNIFORM_STRIDE * DENOISE_ITERATIONS as u64) as usize];
    for i in 0..DENOISE_ITERATIONS {
        let mut flags = 0;
        if i == 0 {
            flags |= DENOISE_FROM_SUMS;
        }
        if i + 1 == DENOISE_ITERATIONS {
            flags |= DENOISE_LAST;
        }
        let u = DenoiseUniforms {
            rect,
            size: [width, 0, 1 << i, flags],
            params: [
                scale[0],
                DENOISE_COLOR_SIGMA * 0.5f32.powf(i as f32 * 0.5),
                DENOISE_NORMAL_POWER,
                DENOISE_DEPTH_SIGMA * scale[1],
            ],
        };
        let at = (UNIFORM_STRIDE * i as u64) as usize;
        blocks[at..at + std::mem::size_of::<DenoiseUniforms>()]
            .copy_from_slice(bytemuck::bytes_of(&u));
    }
    ctx.queue.write_buffer(uniforms, 0, &blocks);
    let bind = |src: &wgpu::Buffer, dst: &wgpu::Buffer| {
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("denoise"),
            layout: bgl,
            entries: &[
                bind(
                    0,
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: uniforms,
                        offset: 0,
                        size: std::num::NonZeroU64::new(
                            std::mem::size_of::<DenoiseUniforms>() as u64
                        ),
                    }),
                ),
                bind(1, src.as_entire_binding()),
                bind(2, dst.as_entire_binding()),
                bind(3, out.guide.as_entire_binding()),
                bind(4, out.accum.as_entire_binding()),
                bind(5, wgpu::BindingResource::TextureView(out.color)),
            ],
        })
    };
    let [a, b] = out.images;
    let groups = [bind(out.accum, a), bind(a, b), bind(b, a)];
    let wg = crate::renderer::WORKGROUP;
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("denoise"),
        timestamp_writes: None,
    });
    pass.set_pipeline(pipeline);
    for i in 0..DENOISE_ITERATIONS {
        let g = if i == 0 {
            &groups[0]
        } else {
            &groups[1 + (i as usize + 1) % 2]
        };
        pass.set_bind_group(0, g, &[(UNIFORM_STRIDE * i as u64) as u32]);
        pass.dispatch_workgroups(
            (rect[2] - rect[0]).div_ceil(wg),
            (rect[3] - rect[1]).div_ceil(wg),
            1,
        );
    }
}

impl Renderer {
    /// Builds the environment's sampling distribution when the environment changed.
    fn ensure_environment_distribution(&mut self) -> Result<()> {
        let generation = self.environment_generation;
        if self
            .pt
            .as_ref()
            .and_then(|g| g.env_dist.as_ref())
            .is_some_and(|(gen, _, _)| *gen == generation)
        {
            return Ok(());
        }
        let (size, mips) = {
            let env = self
                .iso
                .as_ref()
                .and_then(|i| i.environment.as_ref())
                .ok_or_else(|| Error::InvalidParameter("no environment yet".into()))?;
            (env.size, env.mips)
        };
        let mut level = 0;
        while level + 1 < mips && (size >> level) > ENV_DIST_SIZE {
            level += 1;
        }
        let cube = self.read_environment(level)?;
        let cdf = environment_cdf(&cube);
        let buf = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("environment sampling distribution"),
            size: (4 * cdf.len()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.ctx
            .queue
            .write_buffer(&buf, 0, bytemuck::cast_slice(&cdf));
        let g = self.pt.as_mut().expect("created before");
        g.env_dist = Some((generation, cube.size, buf));
        Ok(())
    }

    /// Sets how frames with [`BlendMode::PathTrace`](crate::BlendMode::PathTrace) sample
    /// (a change other than of the paths per frame starts the accumulation over).
    pub fn set_path_tracing(&mut self, p: &PathTraceParams) -> Result<()> {
        p.validate()?;
        self.pt_params = *p;
        Ok(())
    }

    /// The path tracing settings set last (the defaults before any call).
    pub fn path_tracing(&self) -> &PathTraceParams {
        &self.pt_params
    }

    /// Paths per pixel the last path-traced frame shows (0 before the first).
    pub fn accumulated_samples(&self) -> u32 {
        self.pt.as_ref().map_or(0, |g| g.samples)
    }

    /// Starts the accumulation over at the next path-traced frame.
    pub fn reset_accumulation(&mut self) {
        if let Some(g) = self.pt.as_mut() {
            g.samples = 0;
            g.key.clear();
        }
    }

    /// The medium's majorant per min–max block: the largest extinction (per world unit) the
    /// first component's transfer function gives on the table entries the block's scalar
    /// range touches (the table is linear between entries, so its maximum over the range is
    /// at one of them).
    fn block_majorants(&self) -> Result<Vec<f32>> {
        let tf = self
            .tf
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no transfer function has been set".into()))?;
        let vol = self
            .volume
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no volume has been set".into()))?;
        let c = tf.component(0);
        let [lo, hi] = c.table_range();
        let last = (TABLE_SIZE - 1) as f64;
        let sigma: Vec<f64> = (0..TABLE_SIZE)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / last;
                let a = (c.opacity.eval(x)[0].clamp(0.0, 1.0) as f64).min(MAX_OPACITY);
                -(1.0 - a).ln() / c.unit_distance
            })
            .collect();
        let nc = vol.components as usize;
        Ok(vol
            .minmax
            .ranges
            .chunks(nc)
            .map(|r| {
                let [mn, mx] = r[0];
                if mn > mx {
                    return 0.0;
                }
                let at = |v: f32| (v as f64 - lo) / (hi - lo) * last;
                let i0 = at(mn).floor().clamp(0.0, last) as usize;
                let i1 = at(mx).ceil().clamp(0.0, last) as usize;
                sigma[i0..=i1].iter().copied().fold(0.0, f64::max) as f32
            })
            .collect())
    }

    /// Uploads the block majorants when the volume or the transfer function changed (the
    /// upload counters say so: the tables are built for this frame before this is called).
    fn ensure_majorants(&mut self) -> Result<f32> {
        let key = (self.stats.volume_uploads, self.stats.table_uploads);
        if let Some((k, _, max)) = self.pt.as_ref().and_then(|g| g.majorants.as_ref()) {
            if *k == key {
                return Ok(*max);
            }
        }
        let m = self.block_majorants()?;
        let max = m.iter().copied().fold(0.0f32, f32::max);
        let dims = self
            .volume
            .as_ref()
            .expect("block_majorants needs the volume")
            .minmax
            .dims;
        let grid = block_grid(&self.ctx, "path tracing block majorants", dims, &m);
        let g = self.pt.as_mut().expect("created before");
        g.majorants = Some((key, grid, max));
        Ok(max)
    }

    /// One path-traced frame: `samples_per_frame` more paths per pixel.
    pub(crate) fn render_pathtrace(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: DepthSource<'_>,
    ) -> Result<()> {
        params.validate()?;
        let pp = self.pt_params;
        pp.validate()?;
        let vol = self
            .volume
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no volume has been set".into()))?;
        if vol.bricks.len() != 1 {
            return Err(Error::Unsupported(format!(
                "path tracing needs the volume in one brick; it is split into {} (it exceeds \
                 the device's 3D texture or allocation limits)",
                vol.bricks.len()
            )));
        }
        if params.cropping.is_some() {
            return Err(Error::Unsupported(
                "path tracing does not crop yet: turn cropping off (clipping planes work)".into(),
            ));
        }
        if view.lights.len() > MAX_LIGHTS {
            return Err(Error::InvalidParameter(format!(
                "{} lights; at most {MAX_LIGHTS} are supported",
                view.lights.len()
            )));
        }
        if let Some(i) = view.lights.iter().position(|l| l.positional) {
            return Err(Error::Unsupported(format!(
                "light {i} is positional: path tracing lights with directional lights, the \
                 headlight and the environment"
            )));
        }
        let unit = self
            .tf
            .as_ref()
            .map_or(1.0, |tf| tf.component(0).unit_distance);
        let step = self.sample_distance(params)?;
        self.ensure_tables(step)?;
        self.ensure_environment()?;
        self.ensure_targets(view.width, view.height)?;
        self.write_depth_input(view, depth)?;
        if self.pt.is_none() {
            self.pt = Some(Box::new(PathTraceGpu::new(&self.ctx, &self.brick_bgl)?));
        }
        self.ensure_environment_distribution()?;
        let majorant = self.ensure_majorants()?;
        // The view's directional lights light the medium whatever `shading.enabled` says.
        let lit = RenderParams {
            blend: BlendMode::PathTrace,
            shading: Shading {
                enabled: true,
                ..params.shading
            },
            ..params.clone()
        };
        let depth_input = !matches!(depth, DepthSource::None);
        let (frame, _) = self.frame_uniforms(view, &lit, step, depth_input, false)?;
        // (the paths per frame are not part of what the image converges to)
        let converges_to = PathTraceParams {
            samples_per_frame: 0,
            max_samples: 0,
            ..pp
        };
        let key = format!(
            "{view:?}|{params:?}|{converges_to:?}|{:?}|{}|{}|{depth_input}",
            (self.stats.volume_uploads, self.stats.table_uploads),
            self.environment_generation,
            self.generation
        );
        let ctx = self.ctx.clone();
        let nearest = params.interpolation == Interpolation::Nearest;
        let g = self.pt.as_mut().expect("created above");
        let variant = PathTraceVariant {
            nearest,
            hybrid: pp.gradient_threshold.is_finite()
                || pp.stochastic_blend > 0.0
                || pp.scatter != ScatterRegions::Everywhere,
            guide: pp.denoise,
            forward_diff: params.gradient == GradientMethod::Forward,
        };
        let pipeline = g.pipeline(&ctx, variant)?;
        g.ensure_accum(&ctx, view.width, view.height)?;
        if pp.denoise && g.denoise.is_none() {
            g.denoise = Some(denoise_pipeline(&ctx)?);
        }
        if g.key != key || depth_input {
            // (a host's depth may change from frame to frame without telling)
            g.key = key;
            g.samples = 0;
        }
        let before = g.samples;
        let add = if pp.max_samples > 0 {
            pp.samples_per_frame
                .min(pp.max_samples.saturating_sub(before))
        } else {
            pp.samples_per_frame
        };
        if add == 0 {
            // The budget is reached: the output images hold the converged frame.
            self.stats.frames += 1;
            return Ok(());
        }
        let full = [0, 0, view.width, view.height];
        let rect = if pp.background { full } else { frame.rect };
        let env = self
            .iso
            .as_ref()
            .and_then(|i| i.environment.as_ref())
            .expect("built above");
        let mut u = PathTraceUniforms::zeroed();
        u.env_rotation = DMat4::from_mat3(env.rotation).as_mat4().to_cols_array();
        // Nothing scatters and nothing absorbs: no collisions at all.
        let transparent = pp.scatter == ScatterRegions::Nowhere && !pp.attenuation;
        u.medium = [
            if transparent { 0.0 } else { majorant },
            pp.anisotropy,
            (1.0 / unit) as f32,
            pp.environment_light,
        ];
        u.surface = [
            pp.gradient_threshold.min(f32::MAX),
            pp.stochastic_blend,
            pp.bsdf.roughness,
            pp.bsdf.fresnel,
        ];
        u.lobe = [pp.bsdf.transmission, pp.bsdf.lobe_exponent(), 0.0, 0.0];
        u.counts = [pp.secondary_rays, before, pp.max_bounces, pp.seed];
        let (_, dist_size, dist) = g.env_dist.as_ref().expect("built above");
        let (_, majorant_buf, _) = g.majorants.as_ref().expect("built above");
        let mut flags = 0;
        if pp.background {
            flags |= PT_FLAG_BACKGROUND;
        }
        if pp.attenuation {
            flags |= PT_FLAG_ATTENUATION;
        }
        if pp.denoise {
            flags |= PT_FLAG_GUIDE;
        }
        u.options = [flags, *dist_size, pp.scatter.code(), 0];
        u.rect = rect;
        let q = &ctx.queue;
        q.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        // One path per pixel per dispatch, each with its own uniforms (the path index).
        let mut blocks = vec![0u8; (UNIFORM_STRIDE * add as u64) as usize];
        for i in 0..add {
            u.counts[1] = before + i;
            let at = (UNIFORM_STRIDE * i as u64) as usize;
            blocks[at..at + std::mem::size_of::<PathTraceUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        q.write_buffer(&g.uniforms, 0, &blocks);
        let t = self.targets.as_ref().expect("allocated above");
        let (_, tables) = self.tables.as_ref().expect("built above");
        let (_, _, accum) = g.accum.as_ref().expect("allocated above");
        let [guide, ping, pong] = g.denoise_buffers.as_ref().expect("allocated above");
        let iso = self.iso.as_ref().expect("created above");
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let bg = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("path tracing"),
            layout: &g.bgl,
            entries: &[
                bind(0, self.frame_buf.as_entire_binding()),
                bind(1, wgpu::BindingResource::TextureView(&tables.view)),
                bind(2, accum.as_entire_binding()),
                bind(4, wgpu::BindingResource::TextureView(&depth_in_view)),
                bind(5, wgpu::BindingResource::TextureView(&color_view)),
                bind(6, wgpu::BindingResource::TextureView(&depth_view)),
                bind(
                    7,
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &g.uniforms,
                        offset: 0,
                        size: std::num::NonZeroU64::new(
                            std::mem::size_of::<PathTraceUniforms>() as u64
                        ),
                    }),
                ),
                bind(11, wgpu::BindingResource::TextureView(&env.cube_view)),
                bind(
                    13,
                    wgpu::BindingResource::Sampler(&iso.env_pipelines.cube_sampler),
                ),
                bind(14, dist.as_entire_binding()),
                bind(15, wgpu::BindingResource::TextureView(majorant_buf)),
                bind(16, guide.as_entire_binding()),
            ],
        });
        let vol = self.volume.as_ref().expect("checked above");
        let brick = if nearest {
            &vol.bricks[0].bind_nearest
        } else {
            &vol.bricks[0].bind_linear
        };
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("path-traced frame"),
            });
        if rect != full {
            crate::renderer::clear_outputs(&mut enc, &color_view, &depth_view);
            if before == 0 {
                // (pixels outside the rectangle keep no sums of an earlier accumulation)
                enc.clear_buffer(accum, 0, None);
                enc.clear_buffer(guide, 0, None);
            }
        }
        if rect[2] > rect[0] && rect[3] > rect[1] {
            let wg = crate::renderer::WORKGROUP;
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("path tracing"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(1, brick, &[]);
            for i in 0..add {
                pass.set_bind_group(0, &bg, &[(UNIFORM_STRIDE * i as u64) as u32]);
                pass.dispatch_workgroups(
                    (rect[2] - rect[0]).div_ceil(wg),
                    (rect[3] - rect[1]).div_ceil(wg),
                    1,
                );
            }
        }
        if pp.denoise && rect[2] > rect[0] && rect[3] > rect[1] {
            let (dbgl, dpipe, dubuf) = g.denoise.as_ref().expect("created above");
            let out = DenoiseOutputs {
                accum,
                guide,
                images: [ping, pong],
                color: &color_view,
            };
            encode_denoise(
                &ctx,
                &mut enc,
                dbgl,
                dpipe,
                dubuf,
                &out,
                rect,
                view.width,
                {
                    let n = (before + add) as f32;
                    [1.0 / n, step as f32]
                },
            );
        }
        ctx.checked("rendering the path-traced frame", || {
            q.submit([enc.finish()]);
        })?;
        let g = self.pt.as_mut().expect("created above");
        g.samples = before + add;
        self.stats.frames += 1;
        Ok(())
    }

    /// Waits for the last path-traced frame and returns its per-pixel mean over the
    /// accumulated paths, rows top to bottom: radiance (rgb, linear, not clipped) and the
    /// fraction of paths that met the medium (a; 1 everywhere with the background on).
    pub fn read_accumulation(&self) -> Result<Vec<[f32; 4]>> {
        let g = self.pt.as_ref().filter(|g| g.samples > 0).ok_or_else(|| {
            Error::InvalidParameter("no path-traced frame has been rendered yet".into())
        })?;
        let (_, _, buf) = g.accum.as_ref().expect("allocated with the first frame");
        let bytes = read_buffer(&self.ctx, buf)?;
        let n = g.samples as f32;
        Ok(bytemuck::cast_slice::<u8, [f32; 4]>(&bytes)
            .iter()
            .map(|v| v.map(|c| c / n))
            .collect())
    }

    /// Draws `n` Henyey–Greenstein scattering directions with anisotropy `g` by the path
    /// tracer's own sampling code (shaders/lib/phase.wgsl) and returns the cosine of each
    /// to the propagation direction: for checking the sampler against the density.
    pub fn sample_phase_cosines(&self, g: f32, n: u32, seed: u32) -> Result<Vec<f32>> {
        if g.is_nan() || g.abs() >= 1.0 {
            return Err(Error::InvalidParameter(format!(
                "phase sampling check: anisotropy {g} must be in (−1, 1)"
            )));
        }
        let dir = glam::Vec3::new(0.3, -0.5, 0.8).normalize();
        let u = PhaseTestUniforms {
            params: [g, dir.x, dir.y, dir.z],
            counts: [n, seed, 0, 0],
            ..Default::default()
        };
        Ok(self.run_phase_check(&u)?.iter().map(|v| v[0]).collect())
    }

    /// Checks the path tracer's BSDF (shaders/lib/bsdf.wgsl, colour 1) at a surface with
    /// gradient direction `normal` for a path arriving along `dir` (both unit vectors):
    /// per sample, [value / density of a direction drawn by its sampler, 4π × value and 4π ×
    /// density of a uniformly drawn direction]. The means of the first two estimate the
    /// albedo (≤ 1 when energy is conserved; equal when sampler and density agree), the
    /// mean of the third is 1 when the density is normalised.
    pub fn sample_bsdf(
        &self,
        bsdf: &BsdfParams,
        normal: [f32; 3],
        dir: [f32; 3],
        n: u32,
        seed: u32,
    ) -> Result<Vec<[f32; 3]>> {
        bsdf.validate()?;
        let unit = |v: [f32; 3]| (glam::Vec3::from(v).length() - 1.0).abs() < 1e-3;
        if !unit(normal) || !unit(dir) {
            return Err(Error::InvalidParameter(format!(
                "BSDF check: normal {normal:?} and direction {dir:?} must be unit vectors"
            )));
        }
        let u = PhaseTestUniforms {
            params: [0.0, dir[0], dir[1], dir[2]],
            bsdf: [
                bsdf.roughness,
                bsdf.fresnel,
                bsdf.transmission,
                bsdf.lobe_exponent(),
            ],
            normal: [normal[0], normal[1], normal[2], 0.0],
            counts: [n, seed, 1, 0],
        };
        Ok(self
            .run_phase_check(&u)?
            .iter()
            .map(|v| [v[0], v[1], v[2]])
            .collect())
    }

    /// Runs shaders/phase_test.wgsl: `u.counts[0]` samples.
    fn run_phase_check(&self, u: &PhaseTestUniforms) -> Result<Vec<[f32; 4]>> {
        let n = u.counts[0];
        if n == 0 || n > 1 << 24 {
            return Err(Error::InvalidParameter(format!(
                "scattering check: the sample count {n} must be in 1 to 2^24"
            )));
        }
        use wgpu::BufferBindingType as B;
        let ctx = &self.ctx;
        let d = &ctx.device;
        let (bgl, pipeline) = single_group_pipeline(
            ctx,
            "phase_test.wgsl",
            "phase test",
            &[
                buffer_entry(0, B::Uniform),
                buffer_entry(1, B::Storage { read_only: false }),
            ],
        )?;
        let ubuf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("phase test uniforms"),
            size: std::mem::size_of::<PhaseTestUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&ubuf, 0, bytemuck::bytes_of(u));
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("phase test results"),
            size: 16 * n as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("phase test"),
            layout: &bgl,
            entries: &[
                bind(0, ubuf.as_entire_binding()),
                bind(1, out.as_entire_binding()),
            ],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(n.div_ceil(64), 1, 1);
        }
        ctx.checked("running the scattering check", || {
            ctx.queue.submit([enc.finish()]);
        })?;
        let bytes = read_buffer(ctx, &out)?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }
}
