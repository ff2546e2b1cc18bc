//! High-quality isosurfaces: first hit with interval bisection, deferred shading with
//! environment maps, ambient occlusion.
//!
//! With [`BlendMode::Isosurface`](crate::BlendMode::Isosurface) a frame is two passes:
//!
//! 1. **First hit** (shaders/firsthit.wgsl): each pixel's ray is marched as the DVR pass
//!    marches it (bricks, clipping planes, cropping, the host's depth, the sample lattice,
//!    empty-space skipping against the iso-values); between two samples on opposite sides of
//!    an iso-value the crossing is refined by interval bisection on the field interpolated
//!    in f32 from the texels (not through the sampler, whose filter weights have 8 bits) and
//!    written to a layered G-buffer: position, normal (central differences at the refined
//!    hit), gradient magnitude, iso index, window depth and ambient accessibility. Marching
//!    goes on behind translucent surfaces until the accumulated opacity reaches the
//!    termination threshold or [`IsoParams::max_layers`] layers are filled, so nested
//!    translucent isosurfaces (skin over bone) keep every layer.
//! 2. **Deferred shading** (shaders/deferred.wgsl): every layer is lit (Blinn–Phong with the
//!    view's lights, irradiance-cube diffuse, environment specular on the Phong lobe,
//!    Fresnel, AO) and the layers are composited front to back with their opacities.
//!
//! Ambient occlusion is computed in the first pass, where the volume is bound, and stored
//! per layer. The environment's maps are built once by
//! [`Renderer::set_environment`](crate::Renderer::set_environment)
//! (see [`crate::environment`]).

use crate::binding::{
    bind, buffer_entry, sampled_texture_entry, sampler_entry, storage_texture_entry, texture_entry,
};
use crate::environment::{CubeImage, EnvPipelines, Environment, GpuEnvironment};
use crate::error::{Error, Result};
use crate::gpu::*;
use crate::params::{BlendMode, RenderParams, Shading, MAX_LIGHTS};
use crate::readback::{read_buffer, read_texture_layer};
use crate::renderer::{block_grid, DepthSource, Renderer, Tables, View};
use crate::Context;
use bytemuck::Zeroable;
use glam::{DMat4, DVec3};
use std::collections::HashMap;

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

/// One isosurface: where the field equals `value` (first component), drawn in `color`
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
    fn code(self) -> u32 {
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

/// Everything an isosurface frame needs beyond [`RenderParams`] (set with
/// [`Renderer::set_isosurface`]). The material's ambient, diffuse and specular
/// coefficients come from [`RenderParams::shading`] (lighting is always on in this mode,
/// whatever `shading.enabled` says); its termination threshold ends marching behind
/// translucent surfaces; its depth threshold picks the layer whose depth is written. The
/// field is always interpolated trilinearly (`interpolation` is for the DVR modes), and
/// the isosurfaces are those of the first component.
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
/// [`IsoParams::environment_light`]); the volume must fit in one brick.
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
        if self.values.is_empty() || self.values.len() > MAX_ISO_VALUES {
            return bad(format!(
                "{} iso-values: give 1 to {MAX_ISO_VALUES}",
                self.values.len()
            ));
        }
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
        if !(1..=MAX_LAYERS).contains(&self.max_layers) {
            return bad(format!(
                "{} layers: give 1 to {MAX_LAYERS}",
                self.max_layers
            ));
        }
        if !(1..=MAX_SPECULAR_SAMPLES).contains(&self.specular_samples) {
            return bad(format!(
                "{} specular samples: give 1 to {MAX_SPECULAR_SAMPLES}",
                self.specular_samples
            ));
        }
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
            if !(0.0..=1.0).contains(&f) {
                return bad(format!(
                    "Fresnel reflectance at normal incidence {f} must be in [0, 1]"
                ));
            }
        }
        if let Some(ao) = &self.ambient_occlusion {
            if !(1..=MAX_AO_SAMPLES).contains(&ao.samples) {
                return bad(format!(
                    "{} ambient-occlusion directions: give 1 to {MAX_AO_SAMPLES}",
                    ao.samples
                ));
            }
            if !(1..=MAX_AO_STEPS).contains(&ao.steps) {
                return bad(format!(
                    "{} ambient-occlusion steps: give 1 to {MAX_AO_STEPS}",
                    ao.steps
                ));
            }
            if let Some(r) = ao.radius {
                if !(r.is_finite() && r > 0.0) {
                    return bad(format!("ambient-occlusion radius {r} must be positive"));
                }
            }
        }
        if !(self.environment_light.is_finite() && self.environment_light >= 0.0) {
            return bad(format!(
                "environment light weight {} must be finite and non-negative",
                self.environment_light
            ));
        }
        if let Some(sc) = &self.scattering {
            if !(1..=MAX_SCATTER_SAMPLES).contains(&sc.samples) {
                return bad(format!(
                    "{} scattering directions: give 1 to {MAX_SCATTER_SAMPLES}",
                    sc.samples
                ));
            }
            if !(sc.absorption.is_finite() && sc.absorption >= 0.0) {
                return bad(format!(
                    "scattering absorption scale {} must be finite and non-negative",
                    sc.absorption
                ));
            }
            if !(0.0..=1.0).contains(&sc.fresnel) {
                return bad(format!(
                    "scattering Fresnel reflectance {} must be in [0, 1]",
                    sc.fresnel
                ));
            }
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

/// The G-buffer of the last isosurface frame, read back by [`Renderer::read_gbuffer`].
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

/// The pipeline constants of one specialisation of the first-hit pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct FirstHitVariant {
    skip: bool,
    crop: bool,
    single_brick: bool,
}

/// The pipeline constants of one specialisation of the deferred pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct DeferredVariant {
    lights: u32,
    positional_lights: bool,
    /// 0 none, 1 preview, 2 traced (IsoScattering).
    scatter: u32,
}

struct GBufferTargets {
    width: u32,
    height: u32,
    layers: u32,
    position: wgpu::Texture,
    normal: wgpu::Texture,
    extra: wgpu::Texture,
}

/// The occupancy of the min–max blocks for a set of iso-values: a block is occupied when
/// one of the values lies within its range.
#[derive(PartialEq)]
struct OccupancyKey {
    values: Vec<u64>,
    volume_upload: u32,
}

/// The isosurface passes' GPU state, created on first use.
pub(crate) struct IsoGpu {
    firsthit_module: wgpu::ShaderModule,
    firsthit_layout: wgpu::PipelineLayout,
    firsthit_bgl: wgpu::BindGroupLayout,
    deferred_module: wgpu::ShaderModule,
    deferred_layout: wgpu::PipelineLayout,
    deferred_bgl: wgpu::BindGroupLayout,
    firsthit: HashMap<FirstHitVariant, wgpu::ComputePipeline>,
    deferred: HashMap<DeferredVariant, wgpu::ComputePipeline>,
    pub(crate) env_pipelines: EnvPipelines,
    pub(crate) environment: Option<GpuEnvironment>,
    iso_buf: wgpu::Buffer,
    lobe_dirs: wgpu::Buffer,
    // fills the tables' slot when no transfer function is needed (scattering off)
    no_tables: Tables,
    gbuffer: Option<GBufferTargets>,
    occupancy: Option<(OccupancyKey, wgpu::TextureView, f64)>,
    /// The pixels the last frame's first-hit pass covered.
    last_rect: [u32; 4],
}

/// A shader module created as the renderer creates its own: without wgpu's injected
/// bounds checks and loop counters. SAFETY of that, for the isosurface passes: iso indices
/// are clamped to MAX_ISO in the shaders, G-buffer layers stay below the layer count the
/// textures were made with (iso.counts.z, the same value), the cone table is indexed modulo
/// its length, pixel indices sit behind the rectangle test, and every loop advances toward
/// a bound (ray steps, bisection steps, samples, lights).
pub(crate) fn shader_module(ctx: &Context, name: &str) -> Result<wgpu::ShaderModule> {
    ctx.checked(&format!("compiling shader {name}"), || {
        let desc = wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::compose(name).into()),
        };
        // SAFETY: see the function's documentation.
        unsafe {
            ctx.device
                .create_shader_module_trusted(desc, wgpu::ShaderRuntimeChecks::unchecked())
        }
    })
}

/// A pass of one bind group (`entries`) running `file`'s `main`: its bind group layout and
/// compute pipeline (the small passes: gradient build, denoiser, scattering checks).
pub(crate) fn single_group_pipeline(
    ctx: &Context,
    file: &str,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> Result<(wgpu::BindGroupLayout, wgpu::ComputePipeline)> {
    let d = &ctx.device;
    let bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    });
    let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(file),
        bind_group_layouts: &[Some(&bgl)],
        immediate_size: 0,
    });
    let module = shader_module(ctx, file)?;
    let pipeline = ctx.checked(&format!("creating the {label} pipeline"), || {
        d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        })
    })?;
    Ok((bgl, pipeline))
}

/// `n` unit vectors uniform over the sphere from a fixed seed (PCG), as vec4s.
fn random_unit_vectors(n: usize) -> Vec<[f32; 4]> {
    let mut state: u64 = 0x853c_49e6_748f_ea9b;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let x = (((state >> 18) ^ state) >> 27) as u32;
        let r = (state >> 59) as u32;
        x.rotate_right(r) as f64 / 4_294_967_296.0
    };
    (0..n)
        .map(|_| {
            let z = 1.0 - 2.0 * next();
            let phi = 2.0 * std::f64::consts::PI * next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            [
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
                0.0,
            ]
        })
        .collect()
}

const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

impl IsoGpu {
    fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<IsoGpu> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        let d = &ctx.device;
        let gb_write = |b| storage_texture_entry(b, GBUFFER_FORMAT, V::D2Array);
        let firsthit_bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("first hit"),
            entries: &[
                buffer_entry(0, B::Uniform),
                buffer_entry(2, B::Storage { read_only: false }),
                sampled_texture_entry(3, wgpu::TextureSampleType::Uint, V::D3),
                texture_entry(4, false, V::D2),
                buffer_entry(7, B::Uniform),
                gb_write(8),
                gb_write(9),
                gb_write(10),
                sampler_entry(11),
            ],
        });
        let deferred_bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred"),
            entries: &[
                buffer_entry(0, B::Uniform),
                buffer_entry(2, B::Storage { read_only: true }),
                storage_texture_entry(5, wgpu::TextureFormat::Rgba8Unorm, V::D2),
                storage_texture_entry(6, wgpu::TextureFormat::R32Float, V::D2),
                buffer_entry(7, B::Uniform),
                texture_entry(8, false, V::D2Array),
                texture_entry(9, false, V::D2Array),
                texture_entry(10, false, V::D2Array),
                texture_entry(11, true, V::Cube),
                texture_entry(12, true, V::Cube),
                sampler_entry(13),
                buffer_entry(14, B::Storage { read_only: true }),
                texture_entry(1, false, V::D2),
            ],
        });
        let layout = |name: &str, bgls: &[Option<&wgpu::BindGroupLayout>]| {
            d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(name),
                bind_group_layouts: bgls,
                immediate_size: 0,
            })
        };
        let firsthit_layout = layout("firsthit.wgsl", &[Some(&firsthit_bgl), Some(brick_bgl)]);
        let deferred_layout = layout("deferred.wgsl", &[Some(&deferred_bgl), Some(brick_bgl)]);
        let firsthit_module = shader_module(ctx, "firsthit.wgsl")?;
        let deferred_module = shader_module(ctx, "deferred.wgsl")?;
        let env_pipelines = EnvPipelines::new(ctx)?;
        let iso_buf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("iso uniforms"),
            size: std::mem::size_of::<IsoUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let dirs = random_unit_vectors(MAX_SPECULAR_SAMPLES as usize);
        let lobe_dirs = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("specular cone directions"),
            size: (dirs.len() * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ctx.queue
            .write_buffer(&lobe_dirs, 0, bytemuck::cast_slice(&dirs));
        Ok(IsoGpu {
            firsthit_module,
            firsthit_layout,
            firsthit_bgl,
            deferred_module,
            deferred_layout,
            deferred_bgl,
            firsthit: HashMap::new(),
            deferred: HashMap::new(),
            env_pipelines,
            environment: None,
            iso_buf,
            lobe_dirs,
            no_tables: Tables::new(
                d,
                wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
            ),
            gbuffer: None,
            occupancy: None,
            last_rect: [0; 4],
        })
    }

    fn ensure_gbuffer(
        &mut self,
        ctx: &Context,
        width: u32,
        height: u32,
        layers: u32,
    ) -> Result<()> {
        if self
            .gbuffer
            .as_ref()
            .is_some_and(|g| g.width == width && g.height == height && g.layers == layers)
        {
            return Ok(());
        }
        self.gbuffer = None;
        let tex = |label| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: GBUFFER_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let g = ctx.checked("allocating the G-buffer", || GBufferTargets {
            width,
            height,
            layers,
            position: tex("g-buffer position"),
            normal: tex("g-buffer normal"),
            extra: tex("g-buffer extra"),
        })?;
        self.gbuffer = Some(g);
        Ok(())
    }

    fn pipeline(
        &mut self,
        ctx: &Context,
        fh: FirstHitVariant,
        df: DeferredVariant,
    ) -> Result<(&wgpu::ComputePipeline, &wgpu::ComputePipeline)> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let create = |label, layout, module, constants: &[(&str, f64)]| {
            ctx.checked(&format!("creating the {label} pipeline"), || {
                ctx.device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(label),
                        layout: Some(layout),
                        module,
                        entry_point: Some("main"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants,
                            zero_initialize_workgroup_memory: false,
                        },
                        cache: None,
                    })
            })
        };
        if !self.firsthit.contains_key(&fh) {
            let c = [
                ("SKIP", b(fh.skip)),
                ("CROP", b(fh.crop)),
                ("SINGLE_BRICK", b(fh.single_brick)),
            ];
            let p = create(
                "first hit",
                &self.firsthit_layout,
                &self.firsthit_module,
                &c,
            )?;
            self.firsthit.insert(fh, p);
        }
        if !self.deferred.contains_key(&df) {
            let c = [
                ("NUM_LIGHTS", df.lights as f64),
                ("POSITIONAL_LIGHTS", b(df.positional_lights)),
                ("SCATTER", df.scatter as f64),
            ];
            let p = create(
                "deferred shading",
                &self.deferred_layout,
                &self.deferred_module,
                &c,
            )?;
            self.deferred.insert(df, p);
        }
        Ok((&self.firsthit[&fh], &self.deferred[&df]))
    }
}

fn read_cube(ctx: &Context, tex: &wgpu::Texture, mip: u32) -> Result<CubeImage> {
    let size = (tex.width() >> mip).max(1);
    let mut faces = Vec::with_capacity(6);
    for f in 0..6 {
        let bytes = read_texture_layer(ctx, tex, mip, f, 8)?;
        let halves: &[half::f16] = bytemuck::cast_slice(&bytes);
        faces.push(
            halves
                .chunks(4)
                .map(|c| [c[0].to_f32(), c[1].to_f32(), c[2].to_f32(), c[3].to_f32()])
                .collect(),
        );
    }
    Ok(CubeImage { size, faces })
}

impl Renderer {
    pub(crate) fn iso_gpu(&mut self) -> Result<&mut IsoGpu> {
        if self.iso.is_none() {
            self.iso = Some(Box::new(IsoGpu::new(&self.ctx, &self.brick_bgl)?));
        }
        Ok(self.iso.as_mut().expect("created above"))
    }

    /// Sets the isosurfaces and their shading for frames with
    /// [`BlendMode::Isosurface`](crate::BlendMode::Isosurface).
    pub fn set_isosurface(&mut self, iso: &IsoParams) -> Result<()> {
        iso.validate()?;
        self.iso_params = Some(iso.clone());
        Ok(())
    }

    /// The isosurface parameters set last.
    pub fn isosurface(&self) -> Option<&IsoParams> {
        self.iso_params.as_ref()
    }

    /// Builds the environment's GPU maps (environment cube with mips, irradiance cube) now;
    /// isosurface frames use them until the next call. Without a call, the first isosurface
    /// frame builds the default procedural sky.
    pub fn set_environment(&mut self, env: &Environment) -> Result<()> {
        env.validate()?;
        let ctx = self.ctx.clone();
        let g = self.iso_gpu()?;
        g.environment = None;
        g.environment = Some(GpuEnvironment::build(&ctx, &g.env_pipelines, env)?);
        self.environment_generation += 1;
        Ok(())
    }

    /// Builds the default environment (the procedural sky) unless one is set: isosurfaces
    /// and path tracing are lit by it.
    pub(crate) fn ensure_environment(&mut self) -> Result<()> {
        if self.iso_gpu()?.environment.is_none() {
            self.set_environment(&Environment::default())?;
        }
        Ok(())
    }

    /// The irradiance cube of the current environment (π-normalised: E/π), for inspection
    /// and tests.
    pub fn read_irradiance(&self) -> Result<CubeImage> {
        let e = self.current_environment()?;
        read_cube(&self.ctx, &e.irradiance, 0)
    }

    /// Mip level `level` of the current environment cube.
    pub fn read_environment(&self, level: u32) -> Result<CubeImage> {
        let e = self.current_environment()?;
        if level >= e.mips {
            return Err(Error::InvalidParameter(format!(
                "environment cube level {level}: it has levels 0 to {}",
                e.mips - 1
            )));
        }
        read_cube(&self.ctx, &e.cube, level)
    }

    fn current_environment(&self) -> Result<&GpuEnvironment> {
        self.iso
            .as_ref()
            .and_then(|g| g.environment.as_ref())
            .ok_or_else(|| {
                Error::InvalidParameter(
                    "no environment yet: call Renderer::set_environment or render an \
                     isosurface frame first"
                        .into(),
                )
            })
    }

    /// Waits for the last isosurface frame and copies its G-buffer to the CPU.
    pub fn read_gbuffer(&self) -> Result<GBuffer> {
        let (Some(g), Some(t)) = (self.iso.as_ref(), self.targets.as_ref()) else {
            return Err(Error::InvalidParameter(
                "no isosurface frame has been rendered yet".into(),
            ));
        };
        let Some(gb) = g.gbuffer.as_ref() else {
            return Err(Error::InvalidParameter(
                "no isosurface frame has been rendered yet".into(),
            ));
        };
        let state = read_buffer(&self.ctx, &t.state)?;
        let states: &[[f32; 12]] = bytemuck::cast_slice(&state);
        let r = g.last_rect;
        let counts = (0..gb.width * gb.height)
            .map(|i| {
                let (x, y) = (i % gb.width, i / gb.width);
                if x >= r[0] && x < r[2] && y >= r[1] && y < r[3] {
                    (states[i as usize][0] as u32).min(gb.layers)
                } else {
                    0
                }
            })
            .collect();
        let read = |tex: &wgpu::Texture| -> Result<Vec<[f32; 4]>> {
            let mut out = Vec::new();
            for l in 0..gb.layers {
                let bytes = read_texture_layer(&self.ctx, tex, 0, l, 16)?;
                out.extend_from_slice(bytemuck::cast_slice::<u8, [f32; 4]>(&bytes));
            }
            Ok(out)
        };
        Ok(GBuffer {
            width: gb.width,
            height: gb.height,
            layers: gb.layers,
            counts,
            position: read(&gb.position)?,
            normal: read(&gb.normal)?,
            extra: read(&gb.extra)?,
        })
    }

    /// The occupancy grid (a texture) for these iso-values: blocks whose min–max range holds one.
    fn ensure_iso_occupancy(&mut self, values: &[f32]) -> Result<()> {
        let vol = self
            .volume
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no volume has been set".into()))?;
        let key = OccupancyKey {
            values: values.iter().map(|v| v.to_bits() as u64).collect(),
            volume_upload: self.stats.volume_uploads,
        };
        let g = self.iso.as_mut().expect("created before");
        if g.occupancy.as_ref().is_some_and(|(k, _, _)| *k == key) {
            return Ok(());
        }
        let nc = vol.components as usize;
        let occ: Vec<u32> = vol
            .minmax
            .ranges
            .chunks(nc)
            .map(|r| {
                let [lo, hi] = r[0];
                values.iter().any(|&v| v >= lo && v <= hi) as u32
            })
            .collect();
        let grid = block_grid(&self.ctx, "iso occupancy", vol.minmax.dims, &occ);
        let fraction = occ.iter().filter(|&&o| o != 0).count() as f64 / occ.len().max(1) as f64;
        g.occupancy = Some((key, grid, fraction));
        Ok(())
    }

    /// One isosurface frame: first hit per brick in visibility order, then deferred shading.
    pub(crate) fn render_isosurface(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: DepthSource<'_>,
    ) -> Result<()> {
        params.validate()?;
        let iso = self.iso_params.clone().ok_or_else(|| {
            Error::InvalidParameter(
                "BlendMode::Isosurface needs iso-values: call Renderer::set_isosurface first"
                    .into(),
            )
        })?;
        iso.validate()?;
        if view.lights.len() > MAX_LIGHTS {
            return Err(Error::InvalidParameter(format!(
                "{} lights; at most {MAX_LIGHTS} are supported",
                view.lights.len()
            )));
        }
        if self.volume.is_none() {
            return Err(Error::InvalidParameter("no volume has been set".into()));
        }
        self.ensure_environment()?;
        let step = self.sample_distance(params)?;
        if iso.scattering.is_some() {
            if self.tf.is_none() {
                return Err(Error::InvalidParameter(
                    "scattering between isosurfaces reads the transfer function's opacity: \
                     set a transfer function"
                        .into(),
                ));
            }
            self.ensure_tables(step)?;
        }
        let spacing = self.sample_distance(&RenderParams {
            sample_distance: None,
            ..params.clone()
        })?;
        let values: Vec<f32> = iso.values.iter().map(|v| v.value as f32).collect();
        self.ensure_iso_occupancy(&values)?;
        self.ensure_targets(view.width, view.height)?;
        self.write_depth_input(view, depth)?;
        let depth_input = !matches!(depth, DepthSource::None);
        // Lighting is the point of this mode: the material applies whatever `enabled` says.
        let lit = RenderParams {
            blend: BlendMode::Isosurface,
            shading: Shading {
                enabled: true,
                ..params.shading
            },
            ..params.clone()
        };
        let (frame, _) = self.frame_uniforms(view, &lit, step, depth_input, false)?;
        let order = self.brick_order(view, params);
        let vol = self.volume.as_ref().expect("checked above");
        let data_range = vol
            .minmax
            .ranges
            .chunks(vol.components as usize)
            .fold([f32::INFINITY, f32::NEG_INFINITY], |a, r| {
                [a[0].min(r[0][0]), a[1].max(r[0][1])]
            });
        let single_brick = vol.bricks.len() == 1;
        if iso.scattering.is_some() && !single_brick {
            return Err(Error::Unsupported(format!(
                "scattering between isosurfaces needs the volume in one brick; it is split \
                 into {} (it exceeds the device's 3D texture or allocation limits)",
                vol.bricks.len()
            )));
        }
        let unit = self
            .tf
            .as_ref()
            .map_or(1.0, |tf| tf.component(0).unit_distance);
        let full = [0, 0, view.width, view.height];
        let ctx = self.ctx.clone();
        let g = self.iso.as_mut().expect("created above");
        let occupied = g.occupancy.as_ref().map_or(1.0, |o| o.2);
        let fh = FirstHitVariant {
            skip: params.empty_space_skipping && occupied < crate::renderer::SKIP_MAX_OCCUPANCY,
            crop: params.cropping.is_some(),
            single_brick,
        };
        let df = DeferredVariant {
            lights: frame.counts[1],
            positional_lights: frame.lights[..frame.counts[1] as usize]
                .iter()
                .any(|l| l.position[3] == 1.0),
            scatter: match iso.scattering.map(|s| s.mode) {
                None => 0,
                Some(IsoScatterMode::Preview) => 1,
                Some(IsoScatterMode::Traced) => 2,
            },
        };
        let (firsthit, deferred) = {
            let (a, b) = g.pipeline(&ctx, fh, df)?;
            (a.clone(), b.clone())
        };
        // With scattering the surfaces are interfaces: the first-hit pass keeps the first two
        // crossings whatever their opacities (the deferred pass makes the first opaque).
        let layers = if iso.scattering.is_some() {
            2
        } else {
            iso.max_layers
        };
        g.ensure_gbuffer(&ctx, view.width, view.height, layers)?;
        g.last_rect = frame.rect;
        let g = self.iso.as_ref().expect("created above");
        let env = g.environment.as_ref().expect("built above");
        // The uniforms.
        let mut u = IsoUniforms::zeroed();
        u.env_rotation = mat(DMat4::from_mat3(env.rotation));
        for (i, v) in iso.values.iter().enumerate() {
            u.values[i / 4][i % 4] = v.value as f32;
            let opacity = if iso.scattering.is_some() {
                0.0
            } else {
                v.opacity
            };
            u.colors[i] = [v.color[0], v.color[1], v.color[2], opacity];
        }
        u.shininess = match iso.shininess {
            Shininess::Constant(s) => [0.0, 0.0, s, s],
            Shininess::GradientMagnitude { range, exponents } => {
                let [lo, hi] = range.unwrap_or_else(|| {
                    let w = (data_range[1] - data_range[0]).max(0.0) as f64;
                    [0.0, (w / (4.0 * spacing)).max(1e-30)]
                });
                [
                    lo as f32,
                    (1.0 / (hi - lo)) as f32,
                    exponents[0],
                    exponents[1],
                ]
            }
        };
        let ao = iso.ambient_occlusion;
        u.ao = [
            ao.map_or(0.0, |a| a.radius.unwrap_or(8.0 * spacing) as f32),
            0.0,
            0.0,
            0.0,
        ];
        u.env = [
            iso.environment_light,
            iso.fresnel.unwrap_or(-1.0),
            crate::environment::texel_solid_angle(env.size) as f32,
            (env.mips - 1) as f32,
        ];
        u.counts = [
            iso.values.len() as u32,
            iso.bisection_steps,
            layers,
            ao.map_or(0, |a| a.samples),
        ];
        u.options = [
            ao.map_or(1, |a| a.steps),
            iso.specular_samples,
            iso.specular.code(),
            if iso.background {
                ISO_FLAG_BACKGROUND
            } else {
                0
            },
        ];
        if let Some(sc) = &iso.scattering {
            u.scatter = [
                (sc.absorption as f64 / unit) as f32,
                sc.samples as f32,
                sc.fresnel,
                0.0,
            ];
        }
        let rect = frame.rect;
        u.shade_rect = if iso.background { full } else { rect };
        let shade_rect = u.shade_rect;
        let q = &ctx.queue;
        q.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        q.write_buffer(&g.iso_buf, 0, bytemuck::bytes_of(&u));
        let t = self.targets.as_ref().expect("allocated above");
        let (_, occupancy, _) = g.occupancy.as_ref().expect("built above");
        // (the tables only matter with scattering; otherwise a one-texel table fills the slot)
        let tables = self.tables.as_ref().map_or(&g.no_tables, |(_, t)| t);
        let gb = g.gbuffer.as_ref().expect("allocated above");
        let array_view = |tex: &wgpu::Texture| {
            tex.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let (gp, gn, ge) = (
            array_view(&gb.position),
            array_view(&gb.normal),
            array_view(&gb.extra),
        );
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let d = &ctx.device;
        let firsthit_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("first hit"),
            layout: &g.firsthit_bgl,
            entries: &[
                bind(0, self.frame_buf.as_entire_binding()),
                bind(2, t.state.as_entire_binding()),
                bind(3, wgpu::BindingResource::TextureView(occupancy)),
                bind(4, wgpu::BindingResource::TextureView(&depth_in_view)),
                bind(7, g.iso_buf.as_entire_binding()),
                bind(8, wgpu::BindingResource::TextureView(&gp)),
                bind(9, wgpu::BindingResource::TextureView(&gn)),
                bind(10, wgpu::BindingResource::TextureView(&ge)),
                bind(11, wgpu::BindingResource::Sampler(&self.nearest)),
            ],
        });
        let deferred_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred"),
            layout: &g.deferred_bgl,
            entries: &[
                bind(0, self.frame_buf.as_entire_binding()),
                bind(2, t.state.as_entire_binding()),
                bind(5, wgpu::BindingResource::TextureView(&color_view)),
                bind(6, wgpu::BindingResource::TextureView(&depth_view)),
                bind(7, g.iso_buf.as_entire_binding()),
                bind(8, wgpu::BindingResource::TextureView(&gp)),
                bind(9, wgpu::BindingResource::TextureView(&gn)),
                bind(10, wgpu::BindingResource::TextureView(&ge)),
                bind(11, wgpu::BindingResource::TextureView(&env.cube_view)),
                bind(12, wgpu::BindingResource::TextureView(&env.irradiance_view)),
                bind(
                    13,
                    wgpu::BindingResource::Sampler(&g.env_pipelines.cube_sampler),
                ),
                bind(14, g.lobe_dirs.as_entire_binding()),
                bind(1, wgpu::BindingResource::TextureView(&tables.view)),
            ],
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("isosurface frame"),
        });
        if shade_rect != full {
            crate::renderer::clear_outputs(&mut enc, &color_view, &depth_view);
        }
        if !single_brick {
            enc.clear_buffer(&t.state, 0, None);
        }
        let wg = crate::renderer::WORKGROUP;
        let groups = |r: [u32; 4]| [(r[2] - r[0]).div_ceil(wg), (r[3] - r[1]).div_ceil(wg)];
        let gr = groups(rect);
        for i in order {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("first hit"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&firsthit);
            pass.set_bind_group(0, &firsthit_bg, &[]);
            pass.set_bind_group(1, &vol.bricks[i].bind_linear, &[]);
            pass.dispatch_workgroups(gr[0], gr[1], 1);
        }
        {
            let gs = groups(shade_rect);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("deferred shading"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&deferred);
            pass.set_bind_group(0, &deferred_bg, &[]);
            // (the scattering pass samples the volume: one brick)
            pass.set_bind_group(1, &vol.bricks[0].bind_linear, &[]);
            pass.dispatch_workgroups(gs[0], gs[1], 1);
        }
        ctx.checked("rendering the isosurface frame", || {
            q.submit([enc.finish()]);
        })?;
        self.stats.frames += 1;
        Ok(())
    }
}
