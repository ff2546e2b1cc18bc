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
//! importance sampling with the phase function) and the view's lights (directional, or
//! positional with VTK's attenuation and spot cone; ratio-tracking transmittance), and end
//! by Russian roulette or after [`PathTraceParams::max_bounces`] scattering events. VTK's
//! cropping regions empty the medium where they crop.
//!
//! Frames accumulate: each [`Renderer::render`](crate::Renderer::render) adds
//! [`PathTraceParams::samples_per_frame`] paths per pixel to the sums of the frames before
//! (or, with a [`PathTraceParams::time_budget`], as many sixteenths of a path per pixel as
//! the budget holds at the rate an earlier frame's paths took on the device: the pixels in
//! 16 interleaved subsets, one submission a frame, timed without waiting), until anything
//! that changes the image changes (camera, lights, size, render or path tracing parameters
//! but the paths per frame, the budget and the preview, volume, transfer function,
//! environment), or until [`PathTraceParams::max_samples`]; the count is
//! [`Renderer::accumulated_samples`], the estimated error [`Renderer::convergence`]. The
//! frame shows each pixel's mean (pathtrace_show.wgsl), through the denoiser when asked. The environment is the one
//! [`Renderer::set_environment`](crate::Renderer::set_environment) built (the procedural sky
//! by default).
//!
//! The volume is the medium: one-component volumes (others are refused, naming the count).

use super::denoise::{DenoiseOutputs, DenoisePass};
use super::depth_check::DepthCheck;
use super::frame::{self, groups, FrameInput, Purpose};
use super::medium;
use super::pathtrace_variant::{self, PathTraceFacts, PathTraceVariant};
use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, bind_block, bind_view, buffer_entry, dynamic_uniform_entry, group_layout,
    sampled_texture_entry, sampler_entry, storage_texture_entry, texture_entry,
};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::{encode_single_group, single_group_pipeline, PipelineCache};
use crate::gpu::readback::read_buffer;
use crate::gpu::slots;
use crate::gpu::texture::block_grid;
use crate::gpu::timing::GpuTimer;
use crate::gpu::uniforms::{
    flag_bits, PathTraceUniforms, ShowUniforms, PT_FLAG_ATTENUATION, PT_FLAG_BACKGROUND,
    PT_FLAG_GUIDE, UNIFORM_STRIDE,
};
use crate::gpu::Context;
use crate::params::pathtrace::MAX_SAMPLES_PER_FRAME;
use crate::params::{
    BlendMode, Convergence, PathTraceParams, RenderParams, ScatterRegions, Shading,
    TransferFunction, View,
};
use crate::resources::intermix::IntermixBinding;
use crate::resources::tables::{empty_distances, tables_2d_layout_entry, Tables};
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::volume::Needed;
use crate::resources::volume::{blanking_layout_entry, grid_lookup_layout_entry, no_grid_lookup};
use crate::resources::Resources;
use bytemuck::Zeroable;
use glam::DMat4;

mod mesh;
use mesh::MeshTracer;

/// Subsets of a pass: the pixels of each 4×4 cell in Bayer order (every 4th pixel first,
/// then the rest of every 2nd, ...), as (x, y) offsets in the cell.
const SUBSETS: [(u32, u32); 16] = [
    (0, 0),
    (2, 2),
    (2, 0),
    (0, 2),
    (1, 1),
    (3, 3),
    (3, 1),
    (1, 3),
    (1, 0),
    (3, 2),
    (3, 0),
    (1, 2),
    (0, 1),
    (2, 3),
    (2, 1),
    (0, 3),
];
/// Sixteenths of a path per pixel in one pass.
const UNITS: u64 = SUBSETS.len() as u64;
/// Most dispatches one submission holds (one uniform block each): whole passes, and the
/// subsets before and after them.
const MAX_DISPATCHES: u64 = MAX_SAMPLES_PER_FRAME as u64 + 2 * UNITS;

/// Four floats per pixel, rows top to bottom.
type Pixels = Vec<[f32; 4]>;

/// The per-pixel buffers of an accumulation, all of one size.
struct Accumulation {
    width: u32,
    height: u32,
    /// Sums of radiance (rgb) and coverage (a) over the paths.
    sums: wgpu::Buffer,
    /// Paths, sum of squared luminances, depth (pathtrace.wgsl: moments).
    moments: wgpu::Buffer,
    /// The denoiser's guide sums.
    guide: wgpu::Buffer,
    /// The shown means, then the denoiser's other ping-pong image.
    images: [wgpu::Buffer; 2],
}

const _: () = assert!(std::mem::size_of::<PathTraceUniforms>() as u64 <= UNIFORM_STRIDE);

/// The path tracer with its accumulation, created on first use.
/// What the block majorants are built from: volume and table uploads, the mask, the level.
type MajorantKey = (u32, u32, u64, u32);

pub(crate) struct PathTracePass {
    bgl: wgpu::BindGroupLayout,
    pipelines: PipelineCache<PathTraceVariant>,
    uniforms: wgpu::Buffer,
    accum: Option<Accumulation>,
    /// What shows the accumulation (pathtrace_show.wgsl): layout, pipeline, uniforms.
    show: (wgpu::BindGroupLayout, wgpu::ComputePipeline, wgpu::Buffer),
    denoise: Option<DenoisePass>,
    /// Whether the host's depth input changed (created with the first frame that has one).
    depth_check: Option<DepthCheck>,
    /// The environment's sampling distribution: (environment generation, texels per face
    /// edge, cumulative probabilities).
    env_dist: Option<(u64, u32, wgpu::Buffer)>,
    /// The block majorants: (the volume and table upload counts they were computed at,
    /// buffer, the largest).
    majorants: Option<(MajorantKey, wgpu::TextureView, f32)>,
    /// Bound in place of the mask when the volume has none.
    no_mask: wgpu::TextureView,
    /// Bound in place of a rectilinear grid's lookup for a uniform grid.
    no_grid_lookup: wgpu::TextureView,
    /// Bound in place of the 2D tables without any.
    no_tables_2d: Tables,
    /// The intermixed volumes' bindings.
    intermix_binding: IntermixBinding,
    /// What the accumulated paths were traced with; a different key starts over.
    key: String,
    /// Sixteenths of a path per pixel accumulated (passes × 16 + subsets of the next).
    units: u64,
    /// The device time of the frames' paths, per sixteenth (read a frame or more later).
    timer: GpuTimer,
    /// The pixels the accumulation covers (x0, y0, x1, y1).
    rect: [u32; 4],
    /// The mesh's path tracer, created with the first mesh traced.
    mesh: Option<MeshTracer>,
}

/// What a frame's path tracing is given.
struct Setup<'a> {
    ctx: &'a Context,
    view: &'a View,
    params: &'a RenderParams,
    depth: DepthSource<'a>,
    pp: PathTraceParams,
    /// The denoiser runs (now or until a number of paths).
    guided: bool,
    /// The surface model or scattering regions are asked for (not Henyey–Greenstein
    /// everywhere).
    hybrid: bool,
}

/// One medium's frame, ready to trace: what its accumulation converges to (a different
/// key starts over), its pipeline and bind groups (the first with the uniform blocks),
/// uniforms, pixels, and the distance the denoiser compares depths per.
struct Medium {
    key: String,
    pipeline: wgpu::ComputePipeline,
    groups: Vec<wgpu::BindGroup>,
    u: PathTraceUniforms,
    rect: [u32; 4],
    scale: f32,
}

/// The render parameters a path tracer's frame uniforms are built with: the view's lights
/// light the medium whatever `shading.enabled` says.
fn lit(params: &RenderParams) -> RenderParams {
    RenderParams {
        blend: BlendMode::PathTrace,
        shading: Shading {
            enabled: true,
            ..params.shading
        },
        ..params.clone()
    }
}

/// What the accumulated paths converge to: the view, the parameters (but the paths per
/// frame, the budget and the preview), the volume or mesh, its tables, level, environment,
/// mask, intermixed volumes and the host's depth.
fn accumulation_key(f: &Setup<'_>, res: &Resources) -> String {
    let converges_to = PathTraceParams {
        samples_per_frame: 0,
        max_samples: 0,
        time_budget: 0.0,
        denoise_until: 0,
        ..f.pp
    };
    format!(
        "{:?}|{:?}|{converges_to:?}|{:?}|{}|{}|{:?}|{}",
        f.view,
        f.params,
        (
            res.stats.volume_uploads,
            res.stats.table_uploads,
            res.drawn_level,
        ),
        res.environment.generation,
        res.generation,
        (res.mask_generation, res.intermix_generation),
        !matches!(f.depth, DepthSource::None)
    )
}

impl PathTracePass {
    /// The path tracer's bind group (group 0 of pathtrace.wgsl; the volume's is group 1).
    pub fn layout_entries(filterable: bool) -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::TextureViewDimension as V;
        Self::shared_layout_entries()
            .into_iter()
            .chain([
                texture_entry(slots::DEPTH_IN, false, V::D2),
                sampled_texture_entry(
                    15,
                    wgpu::TextureSampleType::Float { filterable: false },
                    V::D3,
                ),
                sampled_texture_entry(17, wgpu::TextureSampleType::Uint, V::D3),
                blanking_layout_entry(),
                grid_lookup_layout_entry(),
                tables_2d_layout_entry(),
            ])
            .chain(IntermixBinding::layout_entries(filterable))
            .collect()
    }

    /// The bind group of pathtrace_show.wgsl, which turns the accumulation into the image.
    pub fn show_layout_entries() -> [wgpu::BindGroupLayoutEntry; 6] {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        [
            buffer_entry(0, B::Uniform),
            buffer_entry(1, B::Storage { read_only: true }),
            buffer_entry(2, B::Storage { read_only: true }),
            buffer_entry(3, B::Storage { read_only: false }),
            storage_texture_entry(4, wgpu::TextureFormat::Rgba8Unorm, V::D2),
            storage_texture_entry(5, wgpu::TextureFormat::R32Float, V::D2),
        ]
    }

    pub fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<PathTracePass> {
        let entries = Self::layout_entries(ctx.info.float32_filterable);
        let bgl = group_layout(&ctx.device, "path tracing", &entries);
        let pipelines =
            PipelineCache::new(ctx, "pathtrace.wgsl", "path tracing", &[&bgl, brick_bgl])?;
        let uniforms = uniform_buffer(
            ctx,
            "path tracing uniforms",
            UNIFORM_STRIDE * MAX_DISPATCHES,
        );
        let (show_bgl, show_pipeline) = single_group_pipeline(
            ctx,
            "pathtrace_show.wgsl",
            "path tracing image",
            &Self::show_layout_entries(),
        )?;
        let show_uniforms = uniform_buffer(ctx, "path tracing image uniforms", UNIFORM_STRIDE);
        Ok(PathTracePass {
            bgl,
            pipelines,
            uniforms,
            accum: None,
            show: (show_bgl, show_pipeline, show_uniforms),
            denoise: None,
            depth_check: None,
            env_dist: None,
            majorants: None,
            no_mask: block_grid(ctx, "no mask", [1; 3], &[1u8]),
            no_grid_lookup: no_grid_lookup(ctx),
            no_tables_2d: Tables::new(&ctx.device, [1, 1]),
            intermix_binding: IntermixBinding::new(ctx),
            key: String::new(),
            units: 0,
            timer: GpuTimer::new(ctx, ctx.info.timestamps),
            rect: [0; 4],
            mesh: None,
        })
    }

    /// Paths every pixel has (the passes completed).
    pub fn samples(&self) -> u32 {
        (self.units / UNITS) as u32
    }

    fn ensure_accum(&mut self, ctx: &Context, width: u32, height: u32) -> Result<()> {
        if self
            .accum
            .as_ref()
            .is_some_and(|a| a.width == width && a.height == height)
        {
            return Ok(());
        }
        self.accum = None;
        let pixel_buffer = |label| {
            ctx.checked("allocating the path tracing accumulation", || {
                buffer(
                    ctx,
                    label,
                    16 * width as u64 * height as u64,
                    wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_SRC
                        | wgpu::BufferUsages::COPY_DST,
                )
            })
        };
        self.accum = Some(Accumulation {
            width,
            height,
            sums: pixel_buffer("path tracing accumulation")?,
            moments: pixel_buffer("path tracing moments")?,
            guide: pixel_buffer("denoiser guide")?,
            images: [
                pixel_buffer("path tracing image")?,
                pixel_buffer("denoiser image")?,
            ],
        });
        self.units = 0;
        Ok(())
    }
}

impl PathTracePass {
    /// Starts the accumulation over at the next path-traced frame.
    pub fn reset_accumulation(&mut self) {
        self.units = 0;
        self.key.clear();
    }

    /// Uploads the block majorants when the volume or the transfer function changed (the
    /// upload counters say so: the tables are built for this frame before this is called).
    fn ensure_majorants(&mut self, ctx: &Context, res: &Resources) -> Result<f32> {
        let key = (
            res.stats.volume_uploads,
            res.stats.table_uploads,
            res.mask_generation,
            res.drawn_level,
        );
        if let Some((k, _, max)) = self.majorants.as_ref() {
            if *k == key {
                return Ok(*max);
            }
        }
        let m = medium::block_majorants(res)?;
        let max = m.iter().copied().fold(0.0f32, f32::max);
        let dims = res.volume()?.minmax.dims;
        // (a block without extinction holds −its leap distance: pathtrace.wgsl, block_span)
        let medium: Vec<bool> = m.iter().map(|&x| x > 0.0).collect();
        let texels: Vec<f32> = m
            .iter()
            .zip(empty_distances(dims, &medium))
            .map(|(&x, d)| if d == 0 { x } else { -(d as f32) })
            .collect();
        let grid = block_grid(ctx, "path tracing block majorants", dims, &texels);
        self.majorants = Some((key, grid, max));
        Ok(max)
    }

    /// One path-traced frame: `samples_per_frame` more paths per pixel, through the image
    /// volume or the mesh the resources hold.
    pub fn render(&mut self, input: FrameInput<'_>, pp: &PathTraceParams) -> Result<()> {
        let purpose = input.purpose;
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        pp.validate()?;
        frame::check_light_count(view)?;
        let f = Setup {
            ctx,
            view,
            params,
            depth,
            pp: *pp,
            guided: pp.denoise || pp.denoise_until > 0,
            hybrid: pp.gradient_threshold.is_finite()
                || pp.stochastic_blend > 0.0
                || pp.scatter != ScatterRegions::Everywhere,
        };
        let medium = if res.mesh.is_some() {
            self.prepare_mesh(&f, res, purpose)?
        } else {
            self.prepare_image(&f, res, purpose)?
        };
        match medium {
            Some(m) => self.trace(&f, res, m),
            None => Ok(()),
        }
    }

    /// What every medium's frame needs before its own: the environment and its sampling
    /// distribution, the output images, the host's depth, the accumulation, the denoiser.
    fn prepare_common(&mut self, f: &Setup<'_>, res: &mut Resources) -> Result<()> {
        let ctx = f.ctx;
        res.ensure_environment(ctx)?;
        res.ensure_targets(ctx, f.view.width, f.view.height)?;
        res.write_depth_input(ctx, f.view, f.depth)?;
        let generation = res.environment.generation;
        if self.env_dist.as_ref().map(|d| d.0) != Some(generation) {
            let (size, buf) = medium::environment_distribution(ctx, res)?;
            self.env_dist = Some((generation, size, buf));
        }
        self.ensure_accum(ctx, f.view.width, f.view.height)?;
        if f.guided && self.denoise.is_none() {
            self.denoise = Some(DenoisePass::new(ctx)?);
        }
        Ok(())
    }

    /// The bindings both path tracers declare (lib/pathtrace.wgsl).
    fn shared_layout_entries() -> [wgpu::BindGroupLayoutEntry; 9] {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        [
            buffer_entry(slots::FRAME, B::Uniform),
            texture_entry(slots::TABLES, false, V::D2),
            buffer_entry(slots::PT_ACCUM, B::Storage { read_only: false }),
            buffer_entry(slots::PT_MOMENTS, B::Storage { read_only: false }),
            dynamic_uniform_entry::<PathTraceUniforms>(slots::PT_UNIFORMS),
            texture_entry(slots::PT_ENV_CUBE, true, V::Cube),
            sampler_entry(slots::PT_ENV_SAMPLER),
            buffer_entry(slots::PT_ENV_CDF, B::Storage { read_only: true }),
            buffer_entry(slots::PT_GUIDE, B::Storage { read_only: false }),
        ]
    }

    /// What they bind (after prepare_common).
    fn shared_entries<'a>(&'a self, res: &'a Resources) -> Result<Vec<wgpu::BindGroupEntry<'a>>> {
        let (_, tables) = res.tables.as_ref().expect("tables built before binding");
        let acc = self.accum.as_ref().expect("allocated in prepare_common");
        let (_, _, dist) = self.env_dist.as_ref().expect("built in prepare_common");
        let env = res.current_environment()?;
        Ok(vec![
            bind(slots::FRAME, res.frame_buf.as_entire_binding()),
            bind_view(slots::TABLES, &tables.view),
            bind(slots::PT_ACCUM, acc.sums.as_entire_binding()),
            bind(slots::PT_MOMENTS, acc.moments.as_entire_binding()),
            bind_block::<PathTraceUniforms>(slots::PT_UNIFORMS, &self.uniforms),
            bind_view(slots::PT_ENV_CUBE, &env.cube_view),
            bind(
                slots::PT_ENV_SAMPLER,
                wgpu::BindingResource::Sampler(res.cube_sampler()?),
            ),
            bind(slots::PT_ENV_CDF, dist.as_entire_binding()),
            bind(slots::PT_GUIDE, acc.guide.as_entire_binding()),
        ])
    }

    /// The uniforms both path tracers read, but the image's majorants and surface model.
    fn base_uniforms(
        &self,
        f: &Setup<'_>,
        res: &Resources,
        unit: f64,
    ) -> Result<PathTraceUniforms> {
        let pp = &f.pp;
        let env = res.current_environment()?;
        let mut u = PathTraceUniforms::zeroed();
        u.env_rotation = DMat4::from_mat3(env.rotation).as_mat4().to_cols_array();
        u.medium = [
            0.0,
            pp.anisotropy,
            (1.0 / unit) as f32,
            pp.environment_light,
        ];
        u.counts = [pp.secondary_rays, 0, pp.max_bounces, pp.seed];
        let (_, dist_size, _) = self.env_dist.as_ref().expect("built in prepare_common");
        let flags = flag_bits(&[
            (pp.background, PT_FLAG_BACKGROUND),
            (pp.attenuation, PT_FLAG_ATTENUATION),
            (f.guided, PT_FLAG_GUIDE),
        ]);
        u.options = [flags, *dist_size, pp.scatter.code(), 0];
        Ok(u)
    }

    /// An image volume's frame (pathtrace.wgsl), None when only preparing.
    fn prepare_image(
        &mut self,
        f: &Setup<'_>,
        res: &mut Resources,
        purpose: Purpose,
    ) -> Result<Option<Medium>> {
        let (ctx, view, params, pp) = (f.ctx, f.view, f.params, &f.pp);
        let vol = res.volume()?;
        let intermix = res.intermix.as_ref().map_or(0, |m| m.volumes.len() as u32);
        let table_2d = res.tf.as_ref().is_some_and(TransferFunction::has_2d);
        let variant = pathtrace_variant::select(&PathTraceFacts {
            interpolation: params.interpolation,
            gradient: params.gradient,
            components: vol.components,
            single_brick: vol.single_brick(),
            rectilinear: vol.grid_lookup.is_some(),
            cropping: params.cropping.is_some(),
            mask: res.mask_kind(),
            labels_apply: params.mask_blend > 0.0
                && res.tf.as_ref().is_some_and(|tf| tf.max_label() > 0),
            blanking: res.blanking.is_some(),
            tables_2d: table_2d,
            hybrid: f.hybrid,
            guided: f.guided,
            intermix,
            float32_filterable: ctx.info.float32_filterable,
        })?;
        let unit = res
            .tf
            .as_ref()
            .map_or(1.0, |tf| tf.component(0).unit_distance);
        let step = res.sample_distance(params)?;
        res.ensure_tables(ctx, step)?;
        if table_2d {
            res.ensure_tables_2d(ctx)?;
        }
        res.ensure_occupancy(ctx, step)?;
        res.ensure_resident(ctx, Needed::Occupied)?;
        self.prepare_common(f, res)?;
        let majorant = self.ensure_majorants(ctx, res)?;
        let depth_input = !matches!(f.depth, DepthSource::None);
        let frame = frame::frame(res, view, &lit(params), step, depth_input)?.uniforms;
        let key = accumulation_key(f, res);
        let pipeline = self.pipelines.get(ctx, variant)?;
        if purpose == Purpose::Prepare {
            return Ok(None);
        }
        let rect = frame::prepare_intermix(ctx, res, params, view, step, frame.rect)?;
        let others = res.intermix.as_ref().map_or(0.0, |m| m.majorant());
        let mut u = self.base_uniforms(f, res, unit)?;
        // Nothing scatters and nothing absorbs: no collisions at all.
        let transparent = pp.scatter == ScatterRegions::Nowhere && !pp.attenuation;
        u.medium[0] = if transparent { 0.0 } else { majorant + others };
        u.surface = [
            pp.gradient_threshold.min(f32::MAX),
            pp.stochastic_blend,
            pp.bsdf.roughness,
            pp.bsdf.fresnel,
        ];
        u.lobe = [pp.bsdf.transmission, pp.bsdf.lobe_exponent(), others, 0.0];
        ctx.queue
            .write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&frame));
        let (_, majorant_buf, _) = self.majorants.as_ref().expect("built above");
        let depth_in_view = res
            .targets
            .as_ref()
            .expect("allocated in prepare_common")
            .depth_in
            .create_view(&Default::default());
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("path tracing"),
            layout: &self.bgl,
            entries: &self
                .shared_entries(res)?
                .into_iter()
                .chain([
                    bind_view(slots::DEPTH_IN, &depth_in_view),
                    bind_view(15, majorant_buf),
                    bind(
                        17,
                        wgpu::BindingResource::TextureView(
                            res.mask.as_ref().map_or(&self.no_mask, |(m, _)| m),
                        ),
                    ),
                    res.blanking_entry(&self.no_mask),
                    res.grid_lookup_entry(&self.no_grid_lookup)?,
                    res.tables_2d_entry(table_2d, &self.no_tables_2d),
                ])
                .chain(self.intermix_binding.entries(res.intermix.as_ref()))
                .collect::<Vec<_>>(),
        });
        let brick = res.volume()?.bind_group(variant.nearest).clone();
        Ok(Some(Medium {
            key,
            pipeline,
            groups: vec![group, brick],
            u,
            rect,
            scale: step as f32,
        }))
    }

    /// Traces the frame's paths into the accumulation and shows it.
    fn trace(&mut self, f: &Setup<'_>, res: &mut Resources, m: Medium) -> Result<()> {
        let (ctx, view, pp) = (f.ctx, f.view, &f.pp);
        let depth_input = !matches!(f.depth, DepthSource::None);
        // (a host's depth may change from frame to frame without telling: compare it)
        let depth_changed = if depth_input {
            if self.depth_check.is_none() {
                self.depth_check = Some(DepthCheck::new(ctx)?);
            }
            let t = res.targets.as_ref().expect("allocated in prepare_common");
            self.depth_check
                .as_mut()
                .expect("created above")
                .changed(ctx, &t.depth_in)?
        } else {
            false
        };
        if self.key != m.key || depth_changed {
            self.key = m.key;
            self.units = 0;
            res.stats.accumulation_restarts += 1;
        }
        let before = self.units;
        let limit = if pp.max_samples > 0 {
            pp.max_samples as u64 * UNITS
        } else {
            u64::MAX
        };
        let wanted = (pp.samples_per_frame as u64 * UNITS).min(limit.saturating_sub(before));
        if wanted == 0 {
            // The budget is reached: the output images hold the converged frame.
            res.stats.frames += 1;
            return Ok(());
        }
        let full = [0, 0, view.width, view.height];
        let rect = if pp.background { full } else { m.rect };
        let mut u = m.u;
        u.rect = rect;
        let q = &ctx.queue;
        let t = res.targets.as_ref().expect("allocated in prepare_common");
        let acc = self.accum.as_ref().expect("allocated in prepare_common");
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        // Sixteenths this frame traces: all that are wanted without a budget, else as many
        // as the budget holds at the rate measured on the device at an earlier frame (read
        // without waiting; at most twice the sixteenths measured), one before any
        // measurement came back, at least one. (Every frame is timed and takes what came
        // back, so the rate is fresh when a budget comes.)
        let rate = self.timer.seconds_per_unit(ctx)?;
        let n = if pp.time_budget > 0.0 {
            budget_units(pp.time_budget as f64, rate, wanted)
        } else {
            wanted
        };
        // One submission: the paths, then the image shown.
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("path-traced frame"),
            });
        if before == 0 {
            // A new accumulation: no pixel has paths (the shown image reads the counts).
            enc.clear_buffer(&acc.moments, 0, None);
            if f.guided {
                enc.clear_buffer(&acc.guide, 0, None);
            }
        }
        let dispatches = plan_dispatches(before, n);
        let mut blocks = vec![0u8; UNIFORM_STRIDE as usize * dispatches.len()];
        for (i, d) in dispatches.iter().enumerate() {
            u.counts[1] = d.pass;
            u.options[3] = d.lattice();
            let at = UNIFORM_STRIDE as usize * i;
            blocks[at..at + std::mem::size_of::<PathTraceUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        q.write_buffer(&self.uniforms, 0, &blocks);
        let traced = rect[2] > rect[0] && rect[3] > rect[1];
        if traced {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("path tracing"),
                timestamp_writes: self.timer.pass_writes(),
            });
            pass.set_pipeline(&m.pipeline);
            for (i, g) in m.groups.iter().enumerate().skip(1) {
                pass.set_bind_group(i as u32, g, &[]);
            }
            for (i, d) in dispatches.iter().enumerate() {
                pass.set_bind_group(0, &m.groups[0], &[(UNIFORM_STRIDE * i as u64) as u32]);
                let gr = d.groups(rect);
                pass.dispatch_workgroups(gr[0], gr[1], 1);
            }
            drop(pass);
            self.timer.resolve(&mut enc);
        }
        self.units = before + n;
        self.rect = rect;
        if rect != full {
            clear_outputs(&mut enc, &color_view, &depth_view);
        }
        if traced {
            let (show_bgl, show_pipeline, show_uniforms) = &self.show;
            let su = ShowUniforms {
                rect,
                size: [view.width, 0, 0, 0],
            };
            q.write_buffer(show_uniforms, 0, bytemuck::bytes_of(&su));
            encode_single_group(
                ctx,
                &mut enc,
                "path tracing image",
                (show_bgl, show_pipeline),
                &[
                    bind(0, show_uniforms.as_entire_binding()),
                    bind(1, acc.sums.as_entire_binding()),
                    bind(2, acc.moments.as_entire_binding()),
                    bind(3, acc.images[0].as_entire_binding()),
                    bind_view(4, &color_view),
                    bind_view(5, &depth_view),
                ],
                {
                    let [x, y] = groups(rect);
                    [x, y, 1]
                },
            );
            if pp.denoise || self.samples() < pp.denoise_until {
                let out = DenoiseOutputs {
                    accum: &acc.sums,
                    guide: &acc.guide,
                    images: [&acc.images[0], &acc.images[1]],
                    color: &color_view,
                };
                self.denoise
                    .as_ref()
                    .expect("created above")
                    .encode(ctx, &mut enc, &out, rect, view.width, m.scale);
            }
        }
        ctx.checked("rendering the path-traced frame", || {
            ctx.submit([enc.finish()]);
        })?;
        if traced {
            self.timer.submitted(ctx, n);
        }
        res.stats.frames += 1;
        Ok(())
    }

    /// Waits for the last path-traced frame and reads its sums and moments back.
    fn read_sums(&self, ctx: &Context) -> Result<(Pixels, Pixels)> {
        let acc = match &self.accum {
            Some(acc) if self.units > 0 => acc,
            _ => {
                return Err(Error::InvalidParameter(
                    "no path-traced frame has been rendered yet".into(),
                ))
            }
        };
        let sums = read_buffer(ctx, &acc.sums)?;
        let moments = read_buffer(ctx, &acc.moments)?;
        Ok((
            bytemuck::cast_slice::<u8, [f32; 4]>(&sums).to_vec(),
            bytemuck::cast_slice::<u8, [f32; 4]>(&moments).to_vec(),
        ))
    }

    /// Waits for the last path-traced frame and returns its per-pixel mean over the
    /// accumulated paths, rows top to bottom: radiance (rgb, linear, not clipped) and the
    /// fraction of paths that met the medium (a; 1 everywhere with the background on);
    /// zero where no path was traced.
    pub fn read_accumulation(&self, ctx: &Context) -> Result<Vec<[f32; 4]>> {
        let (sums, moments) = self.read_sums(ctx)?;
        Ok(sums
            .iter()
            .zip(&moments)
            .map(|(s, m)| {
                if m[0] > 0.0 {
                    s.map(|c| c / m[0])
                } else {
                    [0.0; 4]
                }
            })
            .collect())
    }

    /// Waits for the last path-traced frame and estimates how far it has converged.
    pub fn convergence(&self, ctx: &Context) -> Result<Convergence> {
        if self.units == 0 {
            return Ok(Convergence::default());
        }
        let (sums, moments) = self.read_sums(ctx)?;
        let traced: f64 = moments.iter().map(|m| m[0] as f64).sum();
        let passes = self.samples();
        let [x0, y0, x1, y1] = self.rect;
        let in_rect = ((x1 - x0) as f64 * (y1 - y0) as f64).max(1.0);
        let mut variance = 0.0;
        let mut luminance = 0.0;
        let mut covered = 0usize;
        for (s, m) in sums.iter().zip(&moments) {
            let n = m[0] as f64;
            if n < 2.0 || s[3] <= 0.0 {
                continue;
            }
            let mean = (0.2126 * s[0] as f64 + 0.7152 * s[1] as f64 + 0.0722 * s[2] as f64) / n;
            let spread = (m[1] as f64 / n - mean * mean).max(0.0) * n / (n - 1.0);
            variance += spread / n;
            luminance += mean;
            covered += 1;
        }
        let relative_error = (passes >= 2 && covered > 0 && luminance > 0.0).then(|| {
            let c = covered as f64;
            ((variance / c).sqrt() / (luminance / c)) as f32
        });
        Ok(Convergence {
            paths_per_pixel: passes,
            mean_paths_per_pixel: (traced / in_rect) as f32,
            relative_error,
        })
    }
}

/// One dispatch of the path tracer: one more path for the pixels of pass `pass`, all of the
/// rectangle's or one subset's.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Dispatch {
    pass: u32,
    subset: Option<usize>,
}

impl Dispatch {
    /// The pixels traced (PathTrace.options.w): stride | x offset << 8 | y offset << 16.
    fn lattice(&self) -> u32 {
        match self.subset {
            None => 1,
            Some(i) => {
                let (x, y) = SUBSETS[i];
                4 | x << 8 | y << 16
            }
        }
    }

    /// Workgroups (8 × 8) covering the pixels traced in `rect`.
    fn groups(&self, rect: [u32; 4]) -> [u32; 2] {
        match self.subset {
            None => groups(rect),
            Some(i) => {
                let (x, y) = SUBSETS[i];
                let along = |lo: u32, hi: u32, off: u32| (hi - lo).saturating_sub(off).div_ceil(4);
                groups([0, 0, along(rect[0], rect[2], x), along(rect[1], rect[3], y)])
            }
        }
    }
}

/// Sixteenths a frame with a time budget of `budget` seconds traces, of `wanted`: as many
/// as fit at the last measured `rate` (seconds per sixteenth, and the sixteenths it was
/// measured on), but at most twice as many as that measurement (a rate holds near the work
/// it was measured on: one too low would otherwise send several frames in flight far over
/// the budget before it is corrected); one while no rate is known, at least one.
fn budget_units(budget: f64, rate: Option<(f64, u64)>, wanted: u64) -> u64 {
    let fit = match rate {
        None => 1,
        Some((t, work)) if t > 0.0 => ((budget / t).floor() as u64).min(2 * work),
        Some((_, work)) => 2 * work,
    };
    fit.clamp(1, wanted.max(1))
}

/// The dispatches that trace sixteenths `from .. from + n` of the accumulation: whole passes
/// where a pass starts and ends inside the range, single subsets elsewhere.
fn plan_dispatches(from: u64, n: u64) -> Vec<Dispatch> {
    let mut out = Vec::new();
    let mut at = from;
    let end = from + n;
    while at < end {
        let pass = (at / UNITS) as u32;
        if at.is_multiple_of(UNITS) && end - at >= UNITS {
            out.push(Dispatch { pass, subset: None });
            at += UNITS;
        } else {
            out.push(Dispatch {
                pass,
                subset: Some((at % UNITS) as usize),
            });
            at += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::budget_units;

    #[test]
    fn budgets_plan_from_the_last_rate() {
        // no rate yet: one sixteenth; then what fits, at least one, at most what is wanted
        // and twice the work the rate was measured on
        assert_eq!(budget_units(0.1, None, 48), 1);
        assert_eq!(budget_units(0.1, Some((0.01, 16)), 48), 10);
        assert_eq!(budget_units(0.1, Some((0.01, 2)), 48), 4);
        assert_eq!(budget_units(0.1, Some((0.3, 16)), 48), 1);
        assert_eq!(budget_units(100.0, Some((0.01, 32)), 48), 48);
        assert_eq!(budget_units(0.1, Some((0.0, 8)), 48), 16);
    }
}
