//! Ray casting (shaders/dvr.wgsl) in the blend modes of VTK's mappers (composite with early
//! ray termination, maximum, minimum, average, additive): one dispatch, each ray marching
//! through the bricks it crosses. Composite, additive and average skip blocks the transfer
//! function makes empty (occupancy), MIP and MinIP blocks whose scalar range cannot change the
//! ray's extremum.

use super::dvr_variant::{select, DvrFacts, DvrVariant};
use super::frame::{self, bricks_in_view, groups, visibility_order, FrameInput, Purpose};

use crate::error::Result;
use crate::gpu::binding::{
    bind, bind_view, buffer_entry, group_layout, sampled_texture_entry, storage_texture_entry,
    texture_entry,
};
use crate::gpu::pipeline::PipelineCache;
use crate::gpu::slots;
use crate::gpu::texture::block_grid;
use crate::gpu::uniforms::{FLAG_DEPTH_RANGE, PIXEL_STATE_BYTES};
use crate::gpu::Context;
use crate::params::downsample::Reduction;
use crate::params::BlendMode;
use crate::resources::intermix::IntermixBinding;
use crate::resources::tables::{tables_2d_layout_entry, Tables, PREINTEGRATION_FORMAT};
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::volume::Needed;
use crate::resources::volume::{blanking_layout_entry, grid_lookup_layout_entry, no_grid_lookup};

/// The ray-casting pass: its pipelines (one per variant).
pub(crate) struct DvrPass {
    bgl: wgpu::BindGroupLayout,
    pipelines: PipelineCache<DvrVariant>,
    /// The blanking mask bound when the volume has none (one point, not blanked); the
    /// mask's place takes it too.
    no_blanking: wgpu::TextureView,
    /// Bound in place of the pre-integration tables when a frame does not use them.
    no_preintegration: Tables,
    /// Bound in place of the 2D tables when no component has one.
    no_tables_2d: Tables,
    /// Bound in place of a rectilinear grid's lookup for a uniform grid.
    no_grid_lookup: wgpu::TextureView,
    /// Bound in place of the per-pixel ray state by frames that do not stream (one pixel's).
    no_ray_state: wgpu::Buffer,
    /// The intermixed volumes' bindings.
    intermix_binding: IntermixBinding,
}

impl DvrPass {
    /// The frame's bind group (group 0 of dvr.wgsl; the volume's is group 1).
    pub fn layout_entries(filterable: bool) -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        [
            buffer_entry(slots::FRAME, B::Uniform),
            texture_entry(slots::TABLES, false, V::D2),
            texture_entry(slots::BLOCK_RANGE, false, V::D3),
            sampled_texture_entry(slots::OCCUPANCY, wgpu::TextureSampleType::Uint, V::D3),
            texture_entry(slots::DEPTH_IN, false, V::D2),
            texture_entry(slots::DEPTH_NEAR, false, V::D2),
            storage_texture_entry(slots::OUT_COLOR, wgpu::TextureFormat::Rgba8Unorm, V::D2),
            storage_texture_entry(slots::OUT_DEPTH, wgpu::TextureFormat::R32Float, V::D2),
            buffer_entry(slots::RAY_STATE, B::Storage { read_only: false }),
            blanking_layout_entry(),
            texture_entry(slots::PREINT_TABLES, true, V::D2),
            sampled_texture_entry(slots::MASK, wgpu::TextureSampleType::Uint, V::D3),
            tables_2d_layout_entry(),
            grid_lookup_layout_entry(),
        ]
        .into_iter()
        .chain(IntermixBinding::layout_entries(filterable))
        .collect()
    }

    pub fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<DvrPass> {
        let entries = Self::layout_entries(ctx.info.float32_filterable);
        let bgl = group_layout(&ctx.device, "dvr frame", &entries);
        let pipelines = PipelineCache::new(ctx, "dvr.wgsl", "dvr", &[&bgl, brick_bgl])?;
        let no_blanking = block_grid(ctx, "no blanking", [1; 3], &[0u8]);
        Ok(DvrPass {
            bgl,
            pipelines,
            no_blanking,
            no_preintegration: Tables::with_format(&ctx.device, [1, 1], PREINTEGRATION_FORMAT),
            no_tables_2d: Tables::new(&ctx.device, [1, 1]),
            no_grid_lookup: no_grid_lookup(ctx),
            no_ray_state: ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("no ray state"),
                size: PIXEL_STATE_BYTES,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
            intermix_binding: IntermixBinding::new(ctx),
        })
    }

    /// One ray-cast frame.
    pub fn render(&mut self, input: FrameInput<'_>) -> Result<()> {
        let purpose = input.purpose;
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        if params.shading.enabled {
            frame::check_light_count(view)?;
        }
        let step = res.sample_distance(params)?;
        res.ensure_tables(ctx, step)?;
        res.ensure_occupancy(ctx, step)?;
        let needed = if params.blend == BlendMode::Composite {
            Needed::Occupied
        } else {
            Needed::All
        };
        // Volumetric shadows' rays leave the pixels' lines: every needed brick, in view or
        // not.
        let in_view = if frame::casts_shadows(view, params) {
            None
        } else {
            Some(bricks_in_view(res, view, params)?)
        };
        let front = visibility_order(res, view, params)?;
        // A preview past the budget draws coarser bricks where fine ones are missing (masks,
        // blanking and intermixed volumes have no coarser levels: such a preview streams).
        let lod = match in_view.as_deref() {
            Some(in_view)
                if params.preview_level
                    && params.blend != BlendMode::Slice
                    && res.mask.is_none()
                    && res.blanking.is_none()
                    && res.intermix.is_none() =>
            {
                // (MIP and MinIP stand-ins keep the extremes a mean would lose)
                let reduction = match params.blend {
                    BlendMode::Maximum => Reduction::Max,
                    BlendMode::Minimum => Reduction::Min,
                    _ => Reduction::Mean,
                };
                res.enter_lod(ctx, needed, &front, in_view, reduction)?
            }
            _ => false,
        };
        let plan = match lod {
            true => None,
            false => res.plan_streaming(ctx, needed, &front, in_view.as_deref())?,
        };
        let occupied = res.occupancy.as_ref().map_or(1.0, |o| o.fraction);
        res.ensure_targets(ctx, view.width, view.height)?;
        res.write_depth_input(ctx, view, depth)?;
        let depth_input = !matches!(depth, DepthSource::None);
        let mut f = frame::frame(res, view, params, step, depth_input)?;
        if matches!(depth, DepthSource::Range(..)) {
            f.uniforms.flags |= FLAG_DEPTH_RANGE;
        }
        let streaming = plan.is_some();
        let vol = res.volume()?;
        let tf = res.transfer_function()?;
        let variant = select(&DvrFacts {
            blend: params.blend,
            interpolation: params.interpolation,
            quadrature: params.quadrature,
            gradient: params.gradient,
            shade: params.shading.enabled,
            normal_from_opacity: params.shading.normal_from_opacity,
            empty_space_skipping: params.empty_space_skipping,
            preintegration: params.preintegration,
            cropping: params.cropping.is_some(),
            clipped_voxel_value: params.clipped_voxel_value.is_some()
                && !params.clip_planes.is_empty(),
            average_range: params.average_range.is_some(),
            whole_box: params.whole_box.is_some(),
            mask_blend: params.mask_blend > 0.0,
            volumetric: f.volumetric,
            independent: f.independent,
            gradient_opacity: f.gradient_opacity,
            lights: f.lights(),
            positional_lights: f.positional_lights(),
            components: vol.components,
            single_brick: vol.single_brick(),
            rectilinear: vol.grid_lookup.is_some(),
            precomputed_gradient: vol.gradients,
            blanking: res.blanking.is_some(),
            mask: res.mask_kind(),
            labels: tf.max_label() > 0,
            tables_2d: (0..vol.components as usize)
                .filter(|&c| tf.component(c).table_2d.is_some())
                .fold(0u32, |bits, c| bits | 1 << c),
            occupied,
            saving: res.occupancy.as_ref().map_or(0.0, |o| o.saving),
            intermix: res.intermix.as_ref().map_or(0, |m| m.volumes.len() as u32),
            float32_filterable: ctx.info.float32_filterable,
            streaming,
        })?;
        let (preintegration, tables_2d) = (variant.preintegration, variant.tables_2d);
        if preintegration {
            res.ensure_preintegration(ctx, step)?;
        }
        if tables_2d != 0 {
            res.ensure_tables_2d(ctx)?;
        }
        let mut u = f.uniforms;
        u.rect = frame::prepare_intermix(ctx, res, params, view, step, u.rect)?;
        let vol = res.volume()?;
        let dvr = self.pipelines.get(ctx, variant)?;
        if purpose == Purpose::Prepare {
            return Ok(());
        }
        let t = res.targets.as_ref().expect("targets allocated above");
        let (_, tables) = res.tables.as_ref().expect("tables built above");
        let occupancy = &res.occupancy.as_ref().expect("occupancy built above").grid;
        let preintegrated = match &res.preintegration {
            Some((_, t)) if preintegration => t,
            _ => &self.no_preintegration,
        };
        let q = &ctx.queue;
        let d = &ctx.device;
        q.write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&u));
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let depth_near_view = t.depth_near.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let dvr_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dvr frame"),
            layout: &self.bgl,
            entries: &[
                bind(slots::FRAME, res.frame_buf.as_entire_binding()),
                bind_view(slots::TABLES, &tables.view),
                bind_view(slots::BLOCK_RANGE, &vol.ranges),
                bind_view(slots::OCCUPANCY, occupancy),
                bind_view(slots::DEPTH_IN, &depth_in_view),
                bind_view(slots::DEPTH_NEAR, &depth_near_view),
                bind_view(slots::OUT_COLOR, &color_view),
                bind_view(slots::OUT_DEPTH, &depth_view),
                bind(
                    slots::RAY_STATE,
                    match variant.streaming {
                        true => t.state(ctx),
                        false => &self.no_ray_state,
                    }
                    .as_entire_binding(),
                ),
                res.blanking_entry(&self.no_blanking),
                bind_view(slots::PREINT_TABLES, &preintegrated.view),
                bind(
                    slots::MASK,
                    wgpu::BindingResource::TextureView(
                        res.mask.as_ref().map_or(&self.no_blanking, |(m, _)| m),
                    ),
                ),
                res.tables_2d_entry(tables_2d != 0, &self.no_tables_2d),
                res.grid_lookup_entry(&self.no_grid_lookup)?,
            ]
            .into_iter()
            .chain(self.intermix_binding.entries(res.intermix.as_ref()))
            .collect::<Vec<_>>(),
        });
        let rect = u.rect;
        let gr = groups(rect);
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        if rect != [0, 0, view.width, view.height] {
            clear_outputs(&mut enc, &color_view, &depth_view);
        }
        let dispatch = |enc: &mut wgpu::CommandEncoder, volume: &wgpu::BindGroup| {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("dvr"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&dvr);
            pass.set_bind_group(0, &dvr_bg, &[]);
            pass.set_bind_group(1, volume, &[]);
            pass.dispatch_workgroups(gr[0], gr[1], 1);
        };
        match plan {
            None => {
                dispatch(&mut enc, vol.bind_group(variant.nearest));
                ctx.submit([enc.finish()]);
            }
            Some(plan) => {
                // One pass per group of bricks, front to back: each ray marches what is
                // resident and stops where its next brick waits, its state in `t.state`.
                enc.clear_buffer(t.state(ctx), 0, None);
                ctx.submit([enc.finish()]);
                for g in 0..plan.groups.len() {
                    res.load_stream_group(ctx, &plan, g)?;
                    let vol = res.volume()?;
                    let mut enc = d.create_command_encoder(&Default::default());
                    dispatch(&mut enc, vol.bind_group(variant.nearest));
                    ctx.submit([enc.finish()]);
                    res.streamed_pass(&plan, g);
                }
            }
        }
        if lod {
            res.read_lod_requests(ctx)?;
        }
        res.stats.frames += 1;
        Ok(())
    }
}
