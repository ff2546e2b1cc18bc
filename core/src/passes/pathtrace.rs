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
//! [`PathTraceParams::samples_per_frame`] paths per pixel to the sums of the frames before,
//! until anything that changes the image changes (camera, lights, size, render or path
//! tracing parameters but the paths per frame and the budget, volume, transfer function,
//! environment), or until [`PathTraceParams::max_samples`]; the count is
//! [`Renderer::accumulated_samples`]. The environment is the one
//! [`Renderer::set_environment`](crate::Renderer::set_environment) built (the procedural sky
//! by default).
//!
//! The first component is the medium (other components are not read).

use super::denoise::{DenoiseOutputs, DenoisePass};
use super::frame::{self, groups, FrameInput};
use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, bind_block, buffer_entry, dynamic_uniform_entry, sampled_texture_entry, sampler_entry,
    storage_texture_entry, texture_entry,
};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::{pipeline_variant, PipelineCache};
use crate::gpu::readback::read_buffer;
use crate::gpu::texture::block_grid;
use crate::gpu::uniforms::{
    flag_bits, PathTraceUniforms, PT_FLAG_ATTENUATION, PT_FLAG_BACKGROUND, PT_FLAG_GUIDE,
    PT_MAX_OPACITY, TABLE_SIZE, UNIFORM_STRIDE,
};
use crate::gpu::Context;
use crate::params::pathtrace::MAX_SAMPLES_PER_FRAME;
use crate::params::{
    BlendMode, CubeImage, GradientMethod, Interpolation, PathTraceParams, RenderParams,
    ScatterRegions, Shading,
};
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::volume::Needed;
use crate::resources::Resources;
use bytemuck::Zeroable;
use glam::DMat4;

const _: () = assert!(std::mem::size_of::<PathTraceUniforms>() as u64 <= UNIFORM_STRIDE);

/// The path tracer with its accumulation, created on first use.
pub(crate) struct PathTracePass {
    bgl: wgpu::BindGroupLayout,
    pipelines: PipelineCache<PathTraceVariant>,
    uniforms: wgpu::Buffer,
    /// Per pixel: sums of radiance and coverage over the accumulated paths.
    accum: Option<(u32, u32, wgpu::Buffer)>,
    /// Per pixel, the same size: the denoiser's guide sums, then its two ping-pong images.
    denoise_buffers: Option<[wgpu::Buffer; 3]>,
    denoise: Option<DenoisePass>,
    /// The environment's sampling distribution: (environment generation, texels per face
    /// edge, cumulative probabilities).
    env_dist: Option<(u64, u32, wgpu::Buffer)>,
    /// The block majorants: (the volume and table upload counts they were computed at,
    /// buffer, the largest).
    majorants: Option<((u32, u32), wgpu::TextureView, f32)>,
    /// What the accumulated paths were traced with; a different key starts over.
    key: String,
    pub samples: u32,
}

impl PathTracePass {
    pub fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<PathTracePass> {
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
                dynamic_uniform_entry::<PathTraceUniforms>(7),
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
        let pipelines =
            PipelineCache::new(ctx, "pathtrace.wgsl", "path tracing", &[&bgl, brick_bgl])?;
        let uniforms = uniform_buffer(
            ctx,
            "path tracing uniforms",
            UNIFORM_STRIDE * MAX_SAMPLES_PER_FRAME as u64,
        );
        Ok(PathTracePass {
            bgl,
            pipelines,
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
        let buf = pixel_buffer("path tracing accumulation")?;
        self.denoise_buffers = Some([
            pixel_buffer("denoiser guide")?,
            pixel_buffer("denoiser image A")?,
            pixel_buffer("denoiser image B")?,
        ]);
        self.accum = Some((width, height, buf));
        self.samples = 0;
        Ok(())
    }
}

pipeline_variant! {
    /// The pipeline constants of one specialisation of the path tracer.
    struct PathTraceVariant {
        /// Nearest table lookups.
        nearest: bool => "NEAREST",
        /// The BSDF and the scattering regions (anything but Henyey–Greenstein everywhere).
        hybrid: bool => "HYBRID",
        /// The denoiser's guide.
        guide: bool => "GUIDE",
        /// Forward-difference gradients (FORWARD_DIFF in lib/volume.wgsl).
        forward_diff: bool => "FORWARD_DIFF",
        /// The volume is one brick (lib/volume.wgsl).
        single_brick: bool => "SINGLE_BRICK",
        /// Cropping regions.
        crop: bool => "CROP",
    }
}

/// Texels per face edge of the cube the environment is importance-sampled on (at most).
const ENV_DIST_SIZE: u32 = 32;
/// Share of the environment's sampling probability spread uniformly over the sphere, so
/// every direction keeps some (the distribution is built from a coarse mip level).
const ENV_DIST_UNIFORM: f64 = 0.1;

/// The cumulative sampling probabilities of the texels of a cube image: luminance × solid
/// angle, mixed with a uniform share (pathtrace.wgsl: env_sample, env_pdf).
fn environment_cdf(cube: &CubeImage) -> Vec<f32> {
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

impl PathTracePass {
    /// Builds the environment's sampling distribution when the environment changed.
    fn ensure_environment_distribution(&mut self, ctx: &Context, res: &Resources) -> Result<()> {
        let generation = res.environment.generation;
        if self
            .env_dist
            .as_ref()
            .is_some_and(|(gen, _, _)| *gen == generation)
        {
            return Ok(());
        }
        let (size, mips) = {
            let env = res.current_environment()?;
            (env.size, env.mips)
        };
        let mut level = 0;
        while level + 1 < mips && (size >> level) > ENV_DIST_SIZE {
            level += 1;
        }
        let cube = res.read_environment(ctx, level)?;
        let cdf = environment_cdf(&cube);
        let buf = buffer(
            ctx,
            "environment sampling distribution",
            (4 * cdf.len()) as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        ctx.queue.write_buffer(&buf, 0, bytemuck::cast_slice(&cdf));
        self.env_dist = Some((generation, cube.size, buf));
        Ok(())
    }

    /// Starts the accumulation over at the next path-traced frame.
    pub fn reset_accumulation(&mut self) {
        self.samples = 0;
        self.key.clear();
    }

    /// The medium's majorant per min–max block: the largest extinction (per world unit) the
    /// first component's transfer function gives on the table entries the block's scalar
    /// range touches (the table is linear between entries, so its maximum over the range is
    /// at one of them).
    fn block_majorants(res: &Resources) -> Result<Vec<f32>> {
        let tf = res.transfer_function()?;
        let vol = res.volume()?;
        let c = tf.component(0);
        let [lo, hi] = c.table_range();
        let last = (TABLE_SIZE - 1) as f64;
        let sigma: Vec<f64> = (0..TABLE_SIZE)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / last;
                let a = (c.opacity.eval(x)[0].clamp(0.0, 1.0) as f64).min(PT_MAX_OPACITY);
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
    fn ensure_majorants(&mut self, ctx: &Context, res: &Resources) -> Result<f32> {
        let key = (res.stats.volume_uploads, res.stats.table_uploads);
        if let Some((k, _, max)) = self.majorants.as_ref() {
            if *k == key {
                return Ok(*max);
            }
        }
        let m = Self::block_majorants(res)?;
        let max = m.iter().copied().fold(0.0f32, f32::max);
        let dims = res.volume()?.minmax.dims;
        let grid = block_grid(ctx, "path tracing block majorants", dims, &m);
        self.majorants = Some((key, grid, max));
        Ok(max)
    }

    /// One path-traced frame: `samples_per_frame` more paths per pixel.
    pub fn render(&mut self, input: FrameInput<'_>, pp: &PathTraceParams) -> Result<()> {
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        let pp = *pp;
        pp.validate()?;
        let single_brick = res.volume()?.single_brick();
        frame::check_light_count(view)?;
        let unit = res
            .tf
            .as_ref()
            .map_or(1.0, |tf| tf.component(0).unit_distance);
        let step = res.sample_distance(params)?;
        res.ensure_tables(ctx, step)?;
        res.ensure_occupancy(ctx, step)?;
        res.ensure_resident(ctx, Needed::Occupied)?;
        res.ensure_environment(ctx)?;
        res.ensure_targets(ctx, view.width, view.height)?;
        res.write_depth_input(ctx, view, depth)?;
        self.ensure_environment_distribution(ctx, res)?;
        let majorant = self.ensure_majorants(ctx, res)?;
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
        let frame = frame::frame(res, view, &lit, step, depth_input)?.uniforms;
        // (the paths per frame are not part of what the image converges to)
        let converges_to = PathTraceParams {
            samples_per_frame: 0,
            max_samples: 0,
            ..pp
        };
        let key = format!(
            "{view:?}|{params:?}|{converges_to:?}|{:?}|{}|{}|{depth_input}",
            (res.stats.volume_uploads, res.stats.table_uploads),
            res.environment.generation,
            res.generation
        );
        let nearest = params.interpolation == Interpolation::Nearest;
        let variant = PathTraceVariant {
            nearest,
            hybrid: pp.gradient_threshold.is_finite()
                || pp.stochastic_blend > 0.0
                || pp.scatter != ScatterRegions::Everywhere,
            guide: pp.denoise,
            forward_diff: params.gradient == GradientMethod::Forward,
            single_brick,
            crop: params.cropping.is_some(),
        };
        let pipeline = self.pipelines.get(ctx, variant)?;
        self.ensure_accum(ctx, view.width, view.height)?;
        if pp.denoise && self.denoise.is_none() {
            self.denoise = Some(DenoisePass::new(ctx)?);
        }
        if self.key != key || depth_input {
            // (a host's depth may change from frame to frame without telling)
            self.key = key;
            self.samples = 0;
        }
        let before = self.samples;
        let add = if pp.max_samples > 0 {
            pp.samples_per_frame
                .min(pp.max_samples.saturating_sub(before))
        } else {
            pp.samples_per_frame
        };
        if add == 0 {
            // The budget is reached: the output images hold the converged frame.
            res.stats.frames += 1;
            return Ok(());
        }
        let full = [0, 0, view.width, view.height];
        let rect = if pp.background { full } else { frame.rect };
        let env = res.current_environment()?;
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
        let (_, dist_size, dist) = self.env_dist.as_ref().expect("built above");
        let (_, majorant_buf, _) = self.majorants.as_ref().expect("built above");
        let flags = flag_bits(&[
            (pp.background, PT_FLAG_BACKGROUND),
            (pp.attenuation, PT_FLAG_ATTENUATION),
            (pp.denoise, PT_FLAG_GUIDE),
        ]);
        u.options = [flags, *dist_size, pp.scatter.code(), 0];
        u.rect = rect;
        let q = &ctx.queue;
        q.write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&frame));
        // One path per pixel per dispatch, each with its own uniforms (the path index).
        let mut blocks = vec![0u8; (UNIFORM_STRIDE * add as u64) as usize];
        for i in 0..add {
            u.counts[1] = before + i;
            let at = (UNIFORM_STRIDE * i as u64) as usize;
            blocks[at..at + std::mem::size_of::<PathTraceUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        q.write_buffer(&self.uniforms, 0, &blocks);
        let t = res.targets.as_ref().expect("allocated above");
        let (_, tables) = res.tables.as_ref().expect("built above");
        let (_, _, accum) = self.accum.as_ref().expect("allocated above");
        let [guide, ping, pong] = self.denoise_buffers.as_ref().expect("allocated above");
        let cube_sampler = res.cube_sampler()?;
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let bg = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("path tracing"),
            layout: &self.bgl,
            entries: &[
                bind(0, res.frame_buf.as_entire_binding()),
                bind(1, wgpu::BindingResource::TextureView(&tables.view)),
                bind(2, accum.as_entire_binding()),
                bind(4, wgpu::BindingResource::TextureView(&depth_in_view)),
                bind(5, wgpu::BindingResource::TextureView(&color_view)),
                bind(6, wgpu::BindingResource::TextureView(&depth_view)),
                bind_block::<PathTraceUniforms>(7, &self.uniforms),
                bind(11, wgpu::BindingResource::TextureView(&env.cube_view)),
                bind(13, wgpu::BindingResource::Sampler(cube_sampler)),
                bind(14, dist.as_entire_binding()),
                bind(15, wgpu::BindingResource::TextureView(majorant_buf)),
                bind(16, guide.as_entire_binding()),
            ],
        });
        let brick = res.volume()?.bind_group(nearest);
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("path-traced frame"),
            });
        if rect != full {
            clear_outputs(&mut enc, &color_view, &depth_view);
            if before == 0 {
                // (pixels outside the rectangle keep no sums of an earlier accumulation)
                enc.clear_buffer(accum, 0, None);
                enc.clear_buffer(guide, 0, None);
            }
        }
        if rect[2] > rect[0] && rect[3] > rect[1] {
            let gr = groups(rect);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("path tracing"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(1, brick, &[]);
            for i in 0..add {
                pass.set_bind_group(0, &bg, &[(UNIFORM_STRIDE * i as u64) as u32]);
                pass.dispatch_workgroups(gr[0], gr[1], 1);
            }
        }
        if pp.denoise && rect[2] > rect[0] && rect[3] > rect[1] {
            let out = DenoiseOutputs {
                accum,
                guide,
                images: [ping, pong],
                color: &color_view,
            };
            let n = (before + add) as f32;
            self.denoise.as_ref().expect("created above").encode(
                ctx,
                &mut enc,
                &out,
                rect,
                view.width,
                [1.0 / n, step as f32],
            );
        }
        ctx.checked("rendering the path-traced frame", || {
            q.submit([enc.finish()]);
        })?;
        self.samples = before + add;
        res.stats.frames += 1;
        Ok(())
    }

    /// Waits for the last path-traced frame and returns its per-pixel mean over the
    /// accumulated paths, rows top to bottom: radiance (rgb, linear, not clipped) and the
    /// fraction of paths that met the medium (a; 1 everywhere with the background on).
    pub fn read_accumulation(&self, ctx: &Context) -> Result<Vec<[f32; 4]>> {
        if self.samples == 0 {
            return Err(Error::InvalidParameter(
                "no path-traced frame has been rendered yet".into(),
            ));
        }
        let (_, _, buf) = self.accum.as_ref().expect("allocated with the first frame");
        let bytes = read_buffer(ctx, buf)?;
        let n = self.samples as f32;
        Ok(bytemuck::cast_slice::<u8, [f32; 4]>(&bytes)
            .iter()
            .map(|v| v.map(|c| c / n))
            .collect())
    }
}
