//! Ray casting (shaders/dvr.wgsl) in the blend modes of VTK's mappers (composite with early
//! ray termination, maximum, minimum, average, additive): one dispatch, each ray marching
//! through the bricks it crosses. Composite, additive and average skip blocks the transfer
//! function makes empty (occupancy), MIP and MinIP blocks whose scalar range cannot change the
//! ray's extremum.

use super::frame::{
    self, bricks_in_view, groups, visibility_order, FrameInput, SKIP_MAX_OCCUPANCY,
};

use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, buffer_entry, sampled_texture_entry, storage_texture_entry, texture_entry,
};
use crate::gpu::pipeline::{pipeline_variant, PipelineCache};
use crate::gpu::texture::block_grid;
use crate::gpu::uniforms::{FLAG_DEPTH_RANGE, MASK_BINARY, MASK_LABELS, MASK_NONE};
use crate::gpu::Context;
use crate::params::downsample::Reduction;
use crate::params::{BlendMode, GradientMethod, Interpolation, MaskKind, Quadrature};
use crate::resources::intermix::IntermixBinding;
use crate::resources::tables::{tables_2d_layout_entry, Tables, PREINTEGRATION_FORMAT};
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::volume::Needed;
use crate::resources::volume::{blanking_layout_entry, grid_lookup_layout_entry, no_grid_lookup};

/// The least share of the occupied blocks' samples an adaptive frame must save for its rays
/// to read their blocks' step multipliers; below it they take every step (the midpoint
/// rule). On lavapipe the reads cost about what half the samples do (docs/PERFORMANCE.md).
const ADAPTIVE_MIN_SAVING: f64 = 0.5;

pipeline_variant! {
    /// The pipeline constants of one specialisation of the DVR pass (overrides in dvr.wgsl).
    struct DvrVariant {
        blend: u32 => "BLEND",
        components: u32 => "NCOMP",
        independent: bool => "INDEPENDENT",
        shade: bool => "SHADE",
        gradient_opacity: bool => "GRAD_OPACITY",
        skip: bool => "SKIP",
        range_skip: bool => "RANGE_SKIP",
        crop: bool => "CROP",
        nearest: bool => "NEAREST",
        cubic: bool => "CUBIC",
        single_brick: bool => "SINGLE_BRICK",
        positional_lights: bool => "POSITIONAL_LIGHTS",
        lights: u32 => "NUM_LIGHTS",
        volumetric: bool => "VOLUMETRIC",
        opacity_normal: bool => "OPACITY_NORMAL",
        clipped_voxel: bool => "CLIPPED_VOXEL",
        blanking: bool => "BLANKING",
        mask: u32 => "MASK",
        /// Bit c: component c is classified by its 2D table.
        tables_2d: u32 => "TF2D",
        precomputed_gradient: bool => "PRECOMPUTED_GRADIENT",
        forward_diff: bool => "FORWARD_DIFF",
        streaming: bool => "STREAMING",
        preintegration: bool => "PREINT",
        midpoint: bool => "MIDPOINT",
        adaptive: bool => "ADAPTIVE",
        rectilinear: bool => "RECTILINEAR",
        /// Number of volumes intermixed with the main one.
        intermix: u32 => "INTERMIX",
        /// The intermixed volumes' atlas is read through a linear sampler (r32float is
        /// filterable on this device).
        intermix_filtered: bool => "INTERMIX_FILTERED",
    }
}

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
    /// The intermixed volumes' bindings.
    intermix_binding: IntermixBinding,
}

impl DvrPass {
    pub fn new(ctx: &Context, brick_bgl: &wgpu::BindGroupLayout) -> Result<DvrPass> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        let bgl = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("dvr frame"),
                entries: &[
                    buffer_entry(0, B::Uniform),
                    texture_entry(1, false, V::D2),
                    texture_entry(2, false, V::D3),
                    sampled_texture_entry(3, wgpu::TextureSampleType::Uint, V::D3),
                    texture_entry(4, false, V::D2),
                    texture_entry(25, false, V::D2),
                    storage_texture_entry(5, wgpu::TextureFormat::Rgba8Unorm, V::D2),
                    storage_texture_entry(6, wgpu::TextureFormat::R32Float, V::D2),
                    buffer_entry(7, B::Storage { read_only: false }),
                    blanking_layout_entry(),
                    texture_entry(9, true, V::D2),
                    sampled_texture_entry(10, wgpu::TextureSampleType::Uint, V::D3),
                    tables_2d_layout_entry(),
                    grid_lookup_layout_entry(),
                ]
                .into_iter()
                .chain(IntermixBinding::layout_entries(ctx))
                .collect::<Vec<_>>(),
            });
        let pipelines = PipelineCache::new(ctx, "dvr.wgsl", "dvr", &[&bgl, brick_bgl])?;
        let no_blanking = block_grid(ctx, "no blanking", [1; 3], &[0u8]);
        Ok(DvrPass {
            bgl,
            pipelines,
            no_blanking,
            no_preintegration: Tables::with_format(&ctx.device, [1, 1], PREINTEGRATION_FORMAT),
            no_tables_2d: Tables::new(&ctx.device, [1, 1]),
            no_grid_lookup: no_grid_lookup(ctx),
            intermix_binding: IntermixBinding::new(ctx),
        })
    }

    /// One ray-cast frame.
    pub fn render(&mut self, input: FrameInput<'_>) -> Result<()> {
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
            f.uniforms.mode[1] |= FLAG_DEPTH_RANGE;
        }
        if plan.is_some() && f.volumetric {
            return Err(Error::Unsupported(
                "volumetric shadows need every visible brick resident, and the visible bricks \
                 exceed the volume's memory budget: raise the budget or turn the scattering \
                 blending off"
                    .into(),
            ));
        }
        let streaming = plan.is_some();
        if streaming && params.interpolation == Interpolation::Cubic {
            return Err(Error::Unsupported(
                "cubic interpolation reads two points around each sample, beyond what a \
                 streamed brick keeps around it, and the bricks in view exceed the volume's \
                 memory budget: raise the budget or interpolate linearly"
                    .into(),
            ));
        }
        if streaming && params.blend == BlendMode::Slice {
            return Err(Error::Unsupported(
                "the slice blend mode needs every brick in view resident, and they exceed \
                 the volume's memory budget: raise the budget"
                    .into(),
            ));
        }
        if params.quadrature.midpoints() && res.intermix.is_some() {
            return Err(Error::Unsupported(format!(
                "the {} quadrature draws one volume: clear the intermixed volumes or use \
                 Quadrature::Vtk",
                params.quadrature.name()
            )));
        }
        let vol = res.volume()?;
        let rectilinear = vol.grid_lookup.is_some();
        if rectilinear && f.volumetric {
            return Err(Error::Unsupported(
                "volumetric shadows march uniform grids, and this volume is rectilinear \
                 (per-axis coordinates): turn the scattering blending off"
                    .into(),
            ));
        }
        let clipped_voxel = params.clipped_voxel_value.is_some()
            && !params.clip_planes.is_empty()
            && params.blend == BlendMode::Composite
            && (params.shading.enabled || f.gradient_opacity);
        if rectilinear && clipped_voxel {
            return Err(Error::Unsupported(
                "the clipped voxel value applies to uniform grids, and this volume is \
                 rectilinear (per-axis coordinates): leave the clipped voxel value unset"
                    .into(),
            ));
        }
        let tf = res.transfer_function()?;
        let tables_2d = (0..vol.components as usize)
            .filter(|&c| tf.component(c).table_2d.is_some())
            .fold(0u32, |bits, c| bits | 1 << c);
        if tables_2d != 0 && params.blend != BlendMode::Composite {
            return Err(Error::Unsupported(format!(
                "2D transfer functions classify composite ray casting, not the {:?} blend \
                 mode: use 1D functions or the composite mode",
                params.blend
            )));
        }
        if tables_2d != 0 && !f.independent && vol.components > 1 {
            return Err(Error::Unsupported(
                "2D transfer functions classify one or independent components: these are \
                 dependent"
                    .into(),
            ));
        }
        // Additive and average skip empty blocks too, counting the skipped samples (their
        // terms are 0), as long as every sample counts (no cropping, blanking or average
        // range) and the occupancy is of the components they sum (one or independent).
        let mask = match res.mask_kind() {
            Some(MaskKind::Binary) => MASK_BINARY,
            // label maps: composite ray casting of one component, as VTK's
            Some(MaskKind::LabelMap)
                if params.blend == BlendMode::Composite
                    && vol.components == 1
                    && params.mask_blend > 0.0
                    && res.transfer_function()?.max_label() > 0 =>
            {
                MASK_LABELS
            }
            _ => MASK_NONE,
        };
        let counts_all = params.cropping.is_none()
            && res.blanking.is_none()
            && mask != MASK_BINARY
            && (vol.components == 1 || f.independent)
            && (params.blend == BlendMode::Additive
                || (params.blend == BlendMode::Average && params.average_range.is_none()));
        // (the occupancy is the 1D tables': blocks are not skipped under 2D tables)
        // (blocks and their exits are in the grid's index space, which rays on a
        // rectilinear grid do not march)
        let skip = params.empty_space_skipping
            && !rectilinear
            && tables_2d == 0
            && (params.blend == BlendMode::Composite || counts_all)
            && occupied < SKIP_MAX_OCCUPANCY;
        // MIP and MinIP skip blocks whose range cannot move the ray's extremum, on
        // one-component volumes (the range grid holds the first component).
        let range_skip = params.empty_space_skipping
            && !rectilinear
            && matches!(params.blend, BlendMode::Maximum | BlendMode::Minimum)
            && vol.components == 1
            && !streaming;
        // ComputeNormalFromOpacity: composite and shaded; one or independent components.
        let opacity_normal = params.shading.enabled
            && params.shading.normal_from_opacity
            && params.blend == BlendMode::Composite;
        if opacity_normal && vol.components > 1 && !f.independent {
            return Err(Error::Unsupported(format!(
                "shading normals from the opacity gradient need one or independent components \
                 (this volume has {} dependent ones): turn normal_from_opacity off",
                vol.components
            )));
        }
        if opacity_normal && f.gradient_opacity && !vol.single_brick() {
            return Err(Error::Unsupported(
                "shading normals from the opacity gradient with gradient opacity read two \
                 voxels around each sample, beyond a brick's apron, and this volume is \
                 bricked (larger than one texture or than the memory budget): turn gradient \
                 opacity or normal_from_opacity off"
                    .into(),
            ));
        }
        // Pre-integration: composite, one or independent components, no volumetric shadows
        // and no label map (a labelled sample is classified alone).
        let preintegration = params.preintegration
            && params.blend == BlendMode::Composite
            && (vol.components == 1 || f.independent)
            && !f.volumetric
            && mask != MASK_LABELS
            && tables_2d == 0;
        // Adaptive steps: composite and unshaded (lighting turns with the gradient's
        // direction, which a block's values do not bound), classified by the 1D tables the
        // occupancy grid's step multipliers come from, on a uniform grid whose blocks rays
        // march, with nothing that cuts samples out inside a block (cropping, blanking,
        // masks); and only where the coarse steps save enough samples to pay for reading
        // the blocks.
        let saving = res.occupancy.as_ref().map_or(0.0, |o| o.saving);
        let adaptive = params.quadrature == Quadrature::Adaptive
            && !params.shading.enabled
            && saving >= ADAPTIVE_MIN_SAVING
            && params.blend == BlendMode::Composite
            && !preintegration
            && !f.gradient_opacity
            && tables_2d == 0
            && mask == MASK_NONE
            && (vol.components == 1 || f.independent)
            && !rectilinear
            && params.cropping.is_none()
            && res.blanking.is_none();
        let intermix = res.intermix.as_ref().map_or(0, |m| m.volumes.len() as u32);
        if intermix > 0 {
            let refused = [
                (
                    streaming,
                    "the bricks in view exceed the volume's memory budget",
                ),
                (params.cropping.is_some(), "cropping is on"),
                (res.blanking.is_some(), "the main volume has blanking"),
                (mask != MASK_NONE, "the main volume has a mask"),
                (rectilinear, "the main volume is rectilinear"),
                (f.volumetric, "volumetric shadows are on"),
                (params.preintegration, "pre-integration is on"),
                (vol.components > 1, "the main volume has several components"),
                (tables_2d != 0, "the main volume has a 2D transfer function"),
                (
                    params.interpolation == Interpolation::Cubic,
                    "the interpolation is cubic",
                ),
                (
                    params.whole_box.is_some(),
                    "the volume is a piece of a whole",
                ),
            ];
            if let Some((_, why)) = refused.iter().find(|(on, _)| *on) {
                return Err(Error::Unsupported(format!(
                    "intermixed volumes are ray cast with one-component main volumes, \
                     linear or nearest interpolation and no cropping, blanking, masks, \
                     pre-integration, volumetric shadows or streaming, and {why}: clear the \
                     intermixed volumes or turn that off"
                )));
            }
        }
        let variant = DvrVariant {
            blend: params.blend.code(),
            components: vol.components,
            independent: f.independent,
            shade: params.shading.enabled,
            gradient_opacity: f.gradient_opacity,
            skip: skip && intermix == 0,
            range_skip,
            crop: params.cropping.is_some(),
            nearest: params.interpolation == Interpolation::Nearest,
            cubic: params.interpolation == Interpolation::Cubic,
            single_brick: vol.single_brick(),
            positional_lights: f.positional_lights(),
            lights: f.lights(),
            volumetric: f.volumetric,
            opacity_normal,
            blanking: res.blanking.is_some(),
            mask,
            tables_2d,
            clipped_voxel,
            precomputed_gradient: vol.gradients,
            forward_diff: params.gradient == GradientMethod::Forward,
            streaming,
            preintegration,
            midpoint: params.quadrature.midpoints(),
            adaptive,
            rectilinear,
            intermix,
            intermix_filtered: intermix > 0 && ctx.info.float32_filterable,
        };
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
                bind(0, res.frame_buf.as_entire_binding()),
                bind(1, wgpu::BindingResource::TextureView(&tables.view)),
                bind(2, wgpu::BindingResource::TextureView(&vol.ranges)),
                bind(3, wgpu::BindingResource::TextureView(occupancy)),
                bind(4, wgpu::BindingResource::TextureView(&depth_in_view)),
                bind(25, wgpu::BindingResource::TextureView(&depth_near_view)),
                bind(5, wgpu::BindingResource::TextureView(&color_view)),
                bind(6, wgpu::BindingResource::TextureView(&depth_view)),
                bind(7, t.state.as_entire_binding()),
                res.blanking_entry(&self.no_blanking),
                bind(9, wgpu::BindingResource::TextureView(&preintegrated.view)),
                bind(
                    10,
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
                q.submit([enc.finish()]);
            }
            Some(plan) => {
                // One pass per group of bricks, front to back: each ray marches what is
                // resident and stops where its next brick waits, its state in `t.state`.
                enc.clear_buffer(&t.state, 0, None);
                q.submit([enc.finish()]);
                for g in 0..plan.groups.len() {
                    res.load_stream_group(ctx, &plan, g)?;
                    let vol = res.volume()?;
                    let mut enc = d.create_command_encoder(&Default::default());
                    dispatch(&mut enc, vol.bind_group(variant.nearest));
                    q.submit([enc.finish()]);
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
