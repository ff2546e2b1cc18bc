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
//! (see [`crate::params::environment`]).

mod mesh;

use super::frame::{self, bricks_in_view, groups, visibility_order, FrameInput, Purpose};
use super::iso_variant::{self, DeferredVariant, FirstHitVariant, IsoFacts};
use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, bind_view, buffer_entry, group_layout, sampled_texture_entry, sampler_entry,
    storage_texture_entry, texture_entry,
};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::PipelineCache;
use crate::gpu::readback::{read_buffer, read_texture_layer};
use crate::gpu::slots;
use crate::gpu::texture::block_grid;
use crate::gpu::uniforms::{mat, IsoUniforms, ISO_FLAG_BACKGROUND};
use crate::gpu::Context;
use crate::params::downsample::Reduction;
use crate::params::iso::MAX_SPECULAR_SAMPLES;
use crate::params::{
    BlendMode, GBuffer, IsoParams, RenderParams, Shading, Shininess, TransferFunction,
};
use crate::resources::environment::texel_solid_angle;
use crate::resources::levels::LevelDemand;
use crate::resources::tables::{Occupancy, Tables};
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::volume::Needed;
use crate::resources::volume::{blanking_layout_entry, grid_lookup_layout_entry, no_grid_lookup};
use crate::resources::Resources;
use bytemuck::Zeroable;
use glam::DMat4;

/// The component whose isosurfaces are drawn, as vtkGPUVolumeRayCastMapper chooses it:
/// with independent components the one of the largest weight (the first of equal ones),
/// else (one or dependent components) the first.
fn iso_component(tf: Option<&TransferFunction>, components: u32) -> u32 {
    match tf {
        Some(tf) if tf.independent && components > 1 => {
            let mut best = 0;
            for c in 1..components as usize {
                if tf.component(c).weight > tf.component(best).weight {
                    best = c;
                }
            }
            best as u32
        }
        _ => 0,
    }
}

struct GBufferTargets {
    width: u32,
    height: u32,
    layers: u32,
    position: wgpu::Texture,
    normal: wgpu::Texture,
    extra: wgpu::Texture,
}

/// The G-buffer's textures as the passes bind them (all layers).
struct GBufferViews {
    position: wgpu::TextureView,
    normal: wgpu::TextureView,
    extra: wgpu::TextureView,
}

impl GBufferTargets {
    fn views(&self) -> GBufferViews {
        let array_view = |tex: &wgpu::Texture| {
            tex.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        GBufferViews {
            position: array_view(&self.position),
            normal: array_view(&self.normal),
            extra: array_view(&self.extra),
        }
    }
}

/// The bricks a frame of the isosurfaces `iso` needs when its rays leave the pixels' lines
/// (ambient occlusion, scattering between the surfaces), so that past the budget it draws a
/// coarser level (`levels.rs`); none for a frame that streams.
pub(crate) fn level_demand(iso: &IsoParams, res: &Resources) -> Result<Option<LevelDemand>> {
    let ao = iso.ambient_occlusion.is_some_and(|a| a.samples > 0);
    if !ao && iso.scattering.is_none() {
        return Ok(None);
    }
    surfaces_demand(iso, res, iso.scattering.is_some()).map(Some)
}

/// The bricks the surfaces of `iso` lie in, and the visible ones too where `visible`.
pub(crate) fn surfaces_demand(
    iso: &IsoParams,
    res: &Resources,
    visible: bool,
) -> Result<LevelDemand> {
    Ok(LevelDemand::Surfaces {
        values: iso.values.iter().map(|v| v.value as f32).collect(),
        component: iso_component(res.tf.as_ref(), res.volume()?.components),
        visible,
    })
}

/// The occupancy of the min–max blocks for a set of iso-values: a block is occupied when
/// one of the values lies within its range.
#[derive(PartialEq)]
struct OccupancyKey {
    values: Vec<u64>,
    component: u32,
    volume_upload: u32,
    /// The level of the volume drawn (`Resources::drawn_level`): its blocks are its own.
    level: u32,
}

/// The isosurface passes (first hit, deferred shading) with their state, created on first
/// use.
pub(crate) struct IsoPass {
    firsthit_bgl: wgpu::BindGroupLayout,
    deferred_bgl: wgpu::BindGroupLayout,
    firsthit: PipelineCache<FirstHitVariant>,
    deferred: PipelineCache<DeferredVariant>,
    iso_buf: wgpu::Buffer,
    lobe_dirs: wgpu::Buffer,
    // fills the tables' slot when no transfer function is needed (scattering off)
    no_tables: Tables,
    gbuffer: Option<GBufferTargets>,
    occupancy: Option<Occupancy<OccupancyKey>>,
    /// The pixels the last frame's first-hit pass covered.
    last_rect: [u32; 4],
    /// Bound in place of the mask when the volume has none.
    no_mask: wgpu::TextureView,
    /// Bound in place of a rectilinear grid's lookup for a uniform grid.
    no_grid_lookup: wgpu::TextureView,
    /// The passes of a mesh's surfaces, created on first use.
    mesh: Option<mesh::MeshSurfaces>,
}

/// The iso-values a frame draws: an error without them.
fn required(iso: Option<&IsoParams>) -> Result<&IsoParams> {
    let iso = iso.ok_or_else(|| {
        Error::InvalidParameter(
            "BlendMode::Isosurface needs iso-values: call Renderer::set_isosurface first".into(),
        )
    })?;
    iso.validate()?;
    Ok(iso)
}

/// The frame's settings lit: lighting is the point of this mode, so the material applies
/// whatever `enabled` says.
fn lit(params: &RenderParams) -> RenderParams {
    RenderParams {
        blend: BlendMode::Isosurface,
        shading: Shading {
            enabled: true,
            ..params.shading
        },
        ..params.clone()
    }
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

impl IsoPass {
    /// The first-hit pass's bind group (group 0 of firsthit.wgsl; the volume's is group 1).
    pub fn firsthit_layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        let gb_write = |b| storage_texture_entry(b, GBUFFER_FORMAT, V::D2Array);
        vec![
            buffer_entry(slots::FRAME, B::Uniform),
            buffer_entry(2, B::Storage { read_only: false }),
            sampled_texture_entry(slots::OCCUPANCY, wgpu::TextureSampleType::Uint, V::D3),
            texture_entry(slots::DEPTH_IN, false, V::D2),
            buffer_entry(slots::ISO, B::Uniform),
            gb_write(8),
            gb_write(9),
            gb_write(10),
            sampler_entry(11),
            sampled_texture_entry(12, wgpu::TextureSampleType::Uint, V::D3),
            blanking_layout_entry(),
            grid_lookup_layout_entry(),
        ]
    }

    /// The deferred shading pass's bind group (group 0 of deferred.wgsl; the volume's is
    /// group 1).
    pub fn deferred_layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        vec![
            buffer_entry(slots::FRAME, B::Uniform),
            buffer_entry(2, B::Storage { read_only: true }),
            storage_texture_entry(slots::OUT_COLOR, wgpu::TextureFormat::Rgba8Unorm, V::D2),
            storage_texture_entry(slots::OUT_DEPTH, wgpu::TextureFormat::R32Float, V::D2),
            buffer_entry(slots::ISO, B::Uniform),
            texture_entry(8, false, V::D2Array),
            texture_entry(9, false, V::D2Array),
            texture_entry(10, false, V::D2Array),
            texture_entry(11, true, V::Cube),
            texture_entry(12, true, V::Cube),
            sampler_entry(13),
            buffer_entry(14, B::Storage { read_only: true }),
            sampled_texture_entry(15, wgpu::TextureSampleType::Uint, V::D3),
            texture_entry(slots::TABLES, false, V::D2),
            blanking_layout_entry(),
            grid_lookup_layout_entry(),
        ]
    }

    pub fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<IsoPass> {
        let d = &ctx.device;
        let firsthit_bgl = group_layout(d, "first hit", &Self::firsthit_layout_entries());
        let deferred_bgl = group_layout(d, "deferred", &Self::deferred_layout_entries());
        let firsthit = PipelineCache::new(
            ctx,
            "firsthit.wgsl",
            "first hit",
            &[&firsthit_bgl, brick_bgl],
        )?;
        let deferred = PipelineCache::new(
            ctx,
            "deferred.wgsl",
            "deferred shading",
            &[&deferred_bgl, brick_bgl],
        )?;
        let iso_buf = uniform_buffer(
            ctx,
            "iso uniforms",
            std::mem::size_of::<IsoUniforms>() as u64,
        );
        let dirs = random_unit_vectors(MAX_SPECULAR_SAMPLES as usize);
        let lobe_dirs = buffer(
            ctx,
            "specular cone directions",
            (dirs.len() * 16) as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        ctx.queue
            .write_buffer(&lobe_dirs, 0, bytemuck::cast_slice(&dirs));
        Ok(IsoPass {
            firsthit_bgl,
            deferred_bgl,
            firsthit,
            deferred,
            iso_buf,
            lobe_dirs,
            no_tables: Tables::new(d, [1, 1]),
            gbuffer: None,
            occupancy: None,
            last_rect: [0; 4],
            no_mask: block_grid(ctx, "no mask", [1; 3], &[1u8]),
            no_grid_lookup: no_grid_lookup(ctx),
            mesh: None,
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
}

impl IsoPass {
    /// Waits for the last isosurface frame and copies its G-buffer to the CPU.
    pub fn read_gbuffer(&self, ctx: &Context, res: &Resources) -> Result<GBuffer> {
        let (Some(gb), Some(t)) = (self.gbuffer.as_ref(), res.targets.as_ref()) else {
            return Err(Error::InvalidParameter(
                "no isosurface frame has been rendered yet".into(),
            ));
        };
        let state = read_buffer(ctx, t.state(ctx))?;
        let states: &[[f32; 12]] = bytemuck::cast_slice(&state);
        let r = self.last_rect;
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
                let bytes = read_texture_layer(ctx, tex, 0, l, 16)?;
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
    fn ensure_occupancy(
        &mut self,
        ctx: &Context,
        res: &Resources,
        values: &[f32],
        component: u32,
    ) -> Result<()> {
        let vol = res.volume()?;
        let key = OccupancyKey {
            values: values.iter().map(|v| v.to_bits() as u64).collect(),
            component,
            volume_upload: res.stats.volume_uploads,
            level: res.drawn_level,
        };
        if Occupancy::current(&self.occupancy, &key) {
            return Ok(());
        }
        let occ = vol
            .minmax
            .blocks_holding(values, component as usize, vol.components as usize);
        self.occupancy = Some(Occupancy::new(
            ctx,
            "iso occupancy",
            key,
            vol.minmax.dims,
            &occ,
        ));
        Ok(())
    }

    /// One isosurface frame of the iso-values `iso` (an error without them): first hit,
    /// then deferred shading.
    pub fn render(&mut self, input: FrameInput<'_>, iso: Option<&IsoParams>) -> Result<()> {
        let purpose = input.purpose;
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        let iso = required(iso)?;
        frame::check_light_count(view)?;
        let rectilinear = res.volume()?.grid_lookup.is_some();
        res.ensure_environment(ctx)?;
        let step = res.sample_distance(params)?;
        if iso.scattering.is_some() {
            if res.tf.is_none() {
                return Err(Error::InvalidParameter(
                    "scattering between isosurfaces reads the transfer function's opacity: \
                     set a transfer function"
                        .into(),
                ));
            }
            res.ensure_tables(ctx, step)?;
        }
        let spacing = res.sample_distance(&RenderParams {
            sample_distance: None,
            ..params.clone()
        })?;
        let values: Vec<f32> = iso.values.iter().map(|v| v.value as f32).collect();
        let component = iso_component(res.tf.as_ref(), res.volume()?.components);
        self.ensure_occupancy(ctx, res, &values, component)?;
        let surfaces = &self.occupancy.as_ref().expect("built above").flags;
        let mut lod = false;
        let plan = if iso.scattering.is_some() {
            // the scattering also reads the transfer function's opacity between the surfaces
            res.ensure_occupancy(ctx, step)?;
            let visible = &res.occupancy.as_ref().expect("built above").flags;
            let both: Vec<u32> = surfaces.iter().zip(visible).map(|(a, b)| a | b).collect();
            res.ensure_resident(ctx, Needed::Blocks(&both))?;
            None
        } else {
            // Ambient-occlusion rays leave the pixels' lines: every brick a surface lies in,
            // in view or not.
            let in_view = if iso.ambient_occlusion.is_some_and(|a| a.samples > 0) {
                None
            } else {
                Some(bricks_in_view(res, view, params)?)
            };
            let front = visibility_order(res, view, params)?;
            // A preview past the budget draws coarser bricks where fine ones are missing
            // (masks and blanking have no coarser levels: such a preview streams).
            lod = match in_view.as_deref() {
                Some(in_view)
                    if params.preview_level && res.mask.is_none() && res.blanking.is_none() =>
                {
                    res.enter_lod(
                        ctx,
                        Needed::Blocks(surfaces),
                        &front,
                        in_view,
                        Reduction::Mean,
                    )?
                }
                _ => false,
            };
            match lod {
                true => None,
                false => {
                    res.plan_streaming(ctx, Needed::Blocks(surfaces), &front, in_view.as_deref())?
                }
            }
        };
        res.ensure_targets(ctx, view.width, view.height)?;
        res.write_depth_input(ctx, view, depth)?;
        let depth_input = !matches!(depth, DepthSource::None);
        let f = frame::frame(res, view, &lit(params), step, depth_input)?;
        let vol = res.volume()?;
        let data_range = vol.minmax.ranges.chunks(vol.components as usize).fold(
            [f32::INFINITY, f32::NEG_INFINITY],
            |a, r| {
                let [lo, hi] = r[component as usize];
                [a[0].min(lo), a[1].max(hi)]
            },
        );
        let single_brick = vol.single_brick();
        let occupied = self.occupancy.as_ref().map_or(1.0, |o| o.fraction);
        let step_voxels = match plan {
            Some(_) => step_in_voxels(res, params, step)?,
            None => 0.0,
        };
        let (fh, df) = iso_variant::select(&IsoFacts {
            interpolation: params.interpolation,
            empty_space_skipping: params.empty_space_skipping,
            cropping: params.cropping.is_some(),
            single_brick,
            rectilinear,
            component,
            mask: res.mask_kind(),
            blanking: res.blanking.is_some(),
            occupied,
            lights: f.lights(),
            positional_lights: f.positional_lights(),
            scattering: iso.scattering.map(|s| s.mode),
            ambient_occlusion: iso.ambient_occlusion.is_some_and(|a| a.samples > 0),
            streaming: plan.is_some(),
            step_voxels,
        })?;
        let firsthit = self.firsthit.get(ctx, fh)?;
        let deferred = self.deferred.get(ctx, df)?;
        // With scattering the surfaces are interfaces: the first-hit pass keeps the first two
        // crossings whatever their opacities (the deferred pass makes the first opaque).
        let layers = if iso.scattering.is_some() {
            2
        } else {
            iso.max_layers
        };
        self.ensure_gbuffer(ctx, view.width, view.height, layers)?;
        if purpose == Purpose::Prepare {
            return Ok(());
        }
        let frame = f.uniforms;
        self.last_rect = frame.rect;
        let unit = res
            .tf
            .as_ref()
            .map_or(1.0, |tf| tf.component(component as usize).unit_distance);
        let full = [0, 0, view.width, view.height];
        let mut u = iso_uniforms(res, iso, layers, data_range, spacing, full, frame.rect)?;
        if let Some(sc) = &iso.scattering {
            u.scatter = [
                (sc.absorption as f64 / unit) as f32,
                sc.samples as f32,
                sc.fresnel,
                0.0,
            ];
        }
        let rect = frame.rect;
        let q = &ctx.queue;
        q.write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&frame));
        q.write_buffer(&self.iso_buf, 0, bytemuck::bytes_of(&u));
        let t = res.targets.as_ref().expect("allocated above");
        let occupancy = &self.occupancy.as_ref().expect("built above").grid;
        let gb = self.gbuffer.as_ref().expect("allocated above").views();
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let d = &ctx.device;
        let firsthit_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("first hit"),
            layout: &self.firsthit_bgl,
            entries: &[
                bind(slots::FRAME, res.frame_buf.as_entire_binding()),
                bind(2, t.state(ctx).as_entire_binding()),
                bind_view(slots::OCCUPANCY, occupancy),
                bind_view(slots::DEPTH_IN, &depth_in_view),
                bind(slots::ISO, self.iso_buf.as_entire_binding()),
                bind_view(8, &gb.position),
                bind_view(9, &gb.normal),
                bind_view(10, &gb.extra),
                bind(11, wgpu::BindingResource::Sampler(&res.nearest)),
                bind(
                    12,
                    wgpu::BindingResource::TextureView(
                        res.mask.as_ref().map_or(&self.no_mask, |(m, _)| m),
                    ),
                ),
                res.blanking_entry(&self.no_mask),
                res.grid_lookup_entry(&self.no_grid_lookup)?,
            ],
        });
        let shading =
            self.deferred_inputs(ctx, res, &gb, res.grid_lookup_entry(&self.no_grid_lookup)?)?;
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("isosurface frame"),
        });
        shading.clear_outside(&mut enc, u.shade_rect, full);
        let first_hit = |enc: &mut wgpu::CommandEncoder, volume: &wgpu::BindGroup| {
            let gr = groups(rect);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("first hit"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&firsthit);
            pass.set_bind_group(0, &firsthit_bg, &[]);
            pass.set_bind_group(1, volume, &[]);
            pass.dispatch_workgroups(gr[0], gr[1], 1);
        };
        match &plan {
            None => first_hit(&mut enc, vol.bind_group(false)),
            Some(plan) => {
                // One pass per group of bricks, front to back (as dvr.rs streams), then the
                // deferred shading of the layers they wrote.
                let state = t.state(ctx).clone();
                enc.clear_buffer(&state, 0, None);
                ctx.submit([enc.finish()]);
                for g in 0..plan.groups.len() {
                    res.load_stream_group(ctx, plan, g)?;
                    let mut enc = d.create_command_encoder(&Default::default());
                    first_hit(&mut enc, res.volume()?.bind_group(false));
                    ctx.submit([enc.finish()]);
                    res.streamed_pass(plan, g);
                }
                enc = d.create_command_encoder(&Default::default());
            }
        }
        shading.dispatch(
            &mut enc,
            &deferred,
            Some(res.volume()?.bind_group(false)),
            u.shade_rect,
        );
        ctx.checked("rendering the isosurface frame", || {
            ctx.submit([enc.finish()]);
        })?;
        if lod {
            res.read_lod_requests(ctx)?;
        }
        res.stats.frames += 1;
        Ok(())
    }

    /// The deferred pass's bind group, shading the G-buffer `gb` into the frame's colour and
    /// depth; `grid_lookup` binds the rectilinear grid's lookup (or its placeholder).
    fn deferred_inputs(
        &self,
        ctx: &Context,
        res: &Resources,
        gb: &GBufferViews,
        grid_lookup: wgpu::BindGroupEntry<'_>,
    ) -> Result<DeferredInputs> {
        let t = res.targets.as_ref().expect("allocated by the frame");
        let env = res.current_environment()?;
        // (the tables only matter with scattering; otherwise a one-texel table fills the slot)
        let tables = res.tables.as_ref().map_or(&self.no_tables, |(_, t)| t);
        let color = t.color.create_view(&Default::default());
        let depth = t.depth.create_view(&Default::default());
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred"),
            layout: &self.deferred_bgl,
            entries: &[
                bind(slots::FRAME, res.frame_buf.as_entire_binding()),
                bind(2, t.state(ctx).as_entire_binding()),
                bind_view(slots::OUT_COLOR, &color),
                bind_view(slots::OUT_DEPTH, &depth),
                bind(slots::ISO, self.iso_buf.as_entire_binding()),
                bind_view(8, &gb.position),
                bind_view(9, &gb.normal),
                bind_view(10, &gb.extra),
                bind_view(11, &env.cube_view),
                bind_view(12, &env.irradiance_view),
                bind(13, wgpu::BindingResource::Sampler(res.cube_sampler()?)),
                bind(14, self.lobe_dirs.as_entire_binding()),
                bind(
                    15,
                    wgpu::BindingResource::TextureView(
                        res.mask.as_ref().map_or(&self.no_mask, |(m, _)| m),
                    ),
                ),
                bind_view(slots::TABLES, &tables.view),
                res.blanking_entry(&self.no_mask),
                grid_lookup,
            ],
        });
        Ok(DeferredInputs {
            group,
            color,
            depth,
        })
    }
}

/// The deferred pass's inputs for one frame: its bind group and the frame's outputs.
struct DeferredInputs {
    group: wgpu::BindGroup,
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
}

impl DeferredInputs {
    /// Clears the outputs when the pixels shaded (`shade_rect`) are not all of them.
    fn clear_outside(&self, enc: &mut wgpu::CommandEncoder, shade_rect: [u32; 4], full: [u32; 4]) {
        if shade_rect != full {
            clear_outputs(enc, &self.color, &self.depth);
        }
    }

    /// Shades `shade_rect`'s pixels with `pipeline` (and the image volume's group, where the
    /// surfaces are an image volume's).
    fn dispatch(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        volume: Option<&wgpu::BindGroup>,
        shade_rect: [u32; 4],
    ) {
        let gs = groups(shade_rect);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("deferred shading"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        if let Some(volume) = volume {
            pass.set_bind_group(1, volume, &[]);
        }
        pass.dispatch_workgroups(gs[0], gs[1], 1);
    }
}

/// The isosurface uniforms of `iso` drawn in `layers` layers (its scattering aside): the
/// shininess range by default from the scalars' `data_range` over four times the `spacing`
/// of the samples or cells, the occlusion radius 8 `spacing`; the deferred pass shades the
/// whole image (`full`) when the environment fills the background, else `rect`.
fn iso_uniforms(
    res: &Resources,
    iso: &IsoParams,
    layers: u32,
    data_range: [f32; 2],
    spacing: f64,
    full: [u32; 4],
    rect: [u32; 4],
) -> Result<IsoUniforms> {
    let env = res.current_environment()?;
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
        texel_solid_angle(env.size) as f32,
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
    u.shade_rect = if iso.background { full } else { rect };
    Ok(u)
}

/// The sample distance `step` in voxels along the direction the volume's grid is stretched
/// most (the spectral norm of world → index).
fn step_in_voxels(res: &Resources, params: &RenderParams, step: f64) -> Result<f64> {
    let vol = res.volume()?;
    let m = (params.volume_matrix * vol.index_to_data).inverse();
    let a = glam::DMat3::from_mat4(m);
    // the largest singular value of `a`, by power iteration on aᵀa
    let ata = a.transpose() * a;
    let mut v = glam::DVec3::new(1.0, 0.7, 0.3);
    for _ in 0..64 {
        v = (ata * v).normalize_or_zero();
    }
    Ok(step * (ata * v).length().sqrt())
}
