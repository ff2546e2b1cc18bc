//! The isosurfaces of an unstructured volume: the first hit walks the tetrahedra
//! (shaders/firsthit_mesh.wgsl: exact crossings, the points' gradients interpolated for the
//! normal, ambient occlusion by walks through the mesh) and writes the G-buffer an image
//! volume's first hit writes, which the same deferred pass shades without an image volume
//! bound. Scattering between the surfaces is refused (unstructured_variant.rs).

use super::{iso_uniforms, lit, required, IsoPass, GBUFFER_FORMAT};
use crate::error::{Error, Result};
use crate::gpu::binding::texture_entry;
use crate::gpu::binding::{bind, bind_view, buffer_entry, group_layout, storage_texture_entry};
use crate::gpu::pipeline::{encode_single_group, PipelineCache};
use crate::gpu::slots;
use crate::gpu::Context;
use crate::params::{IsoParams, ScalarLocation};
use crate::passes::frame::{check_light_count, groups, positional_lights, FrameInput, Purpose};
use crate::passes::iso_variant::DeferredVariant;
use crate::passes::unstructured::{frame_uniforms, MeshTransfer};
use crate::passes::unstructured_variant::{select_iso, MeshFirstHitVariant, UnstructuredFacts};
use crate::resources::targets::DepthSource;

/// The mesh's first-hit pipelines, the deferred pipelines without an image volume's group,
/// and the mesh's uniforms.
pub(super) struct MeshSurfaces {
    bgl: wgpu::BindGroupLayout,
    firsthit: PipelineCache<MeshFirstHitVariant>,
    deferred: PipelineCache<DeferredVariant>,
    transfer: MeshTransfer,
}

impl MeshSurfaces {
    fn new(ctx: &Context, deferred_bgl: &wgpu::BindGroupLayout) -> Result<MeshSurfaces> {
        let bgl = group_layout(
            &ctx.device,
            "first hit (mesh)",
            &IsoPass::mesh_firsthit_layout_entries(),
        );
        Ok(MeshSurfaces {
            firsthit: PipelineCache::new(ctx, "firsthit_mesh.wgsl", "first hit (mesh)", &[&bgl])?,
            deferred: PipelineCache::new(
                ctx,
                "deferred.wgsl",
                "deferred shading (mesh)",
                &[deferred_bgl],
            )?,
            bgl,
            transfer: MeshTransfer::new(ctx),
        })
    }
}

impl IsoPass {
    /// The bind group of firsthit_mesh.wgsl.
    pub fn mesh_firsthit_layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        let gb_write = |b| storage_texture_entry(b, GBUFFER_FORMAT, V::D2Array);
        [
            buffer_entry(slots::FRAME, B::Uniform),
            buffer_entry(2, B::Storage { read_only: false }),
            texture_entry(slots::DEPTH_IN, false, V::D2),
            buffer_entry(slots::ISO, B::Uniform),
            gb_write(8),
            gb_write(9),
            gb_write(10),
        ]
        .into_iter()
        .chain(MeshTransfer::layout_entries())
        .collect()
    }

    /// One isosurface frame of the renderer's mesh (an error without iso-values).
    pub fn render_mesh(&mut self, input: FrameInput<'_>, iso: Option<&IsoParams>) -> Result<()> {
        let purpose = input.purpose;
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        let iso = required(iso)?;
        check_light_count(view)?;
        res.ensure_environment(ctx)?;
        let depth_input = !matches!(depth, DepthSource::None);
        let frame = frame_uniforms(res, view, &lit(params), depth_input)?;
        let mesh = res.mesh.as_ref().ok_or_else(crate::resources::no_volume)?;
        let (fh, df) = select_iso(&UnstructuredFacts {
            blend: params.blend,
            components: mesh.components,
            cell_scalars: mesh.location == ScalarLocation::Cells,
            shade: true,
            lights: frame.light_count,
            positional_lights: positional_lights(&frame),
            gradient_opacity: false,
            tables_2d: false,
            cropping: params.cropping.is_some(),
            average_range: false,
            whole_box: params.whole_box.is_some(),
            volumetric: false,
            depth_range: matches!(depth, DepthSource::Range(..)),
            intermix: res.intermix.is_some(),
            hybrid: false,
            iso_scattering: iso.scattering.is_some(),
        })
        .map_err(Error::from)?;
        res.ensure_targets(ctx, view.width, view.height)?;
        res.write_depth_input(ctx, view, depth)?;
        if self.mesh.is_none() {
            self.mesh = Some(MeshSurfaces::new(ctx, &self.deferred_bgl)?);
        }
        let surfaces = self.mesh.as_ref().expect("created above");
        let firsthit = surfaces.firsthit.get(ctx, fh)?;
        let deferred = surfaces.deferred.get(ctx, df)?;
        let layers = iso.max_layers;
        self.ensure_gbuffer(ctx, view.width, view.height, layers)?;
        if purpose == Purpose::Prepare {
            return Ok(());
        }
        self.last_rect = frame.rect;
        let mesh = res.mesh.as_ref().expect("checked above");
        let full = [0, 0, view.width, view.height];
        let u = iso_uniforms(
            res,
            iso,
            layers,
            mesh.range,
            mesh.cell_size(),
            full,
            frame.rect,
        )?;
        let q = &ctx.queue;
        q.write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&frame));
        q.write_buffer(&self.iso_buf, 0, bytemuck::bytes_of(&u));
        let surfaces = self.mesh.as_ref().expect("created above");
        surfaces.transfer.write_walk(ctx, mesh);
        let t = res.targets.as_ref().expect("allocated above");
        let gb = self.gbuffer.as_ref().expect("allocated above").views();
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let firsthit_entries: Vec<_> = [
            bind(slots::FRAME, res.frame_buf.as_entire_binding()),
            bind(2, t.state(ctx).as_entire_binding()),
            bind_view(slots::DEPTH_IN, &depth_in_view),
            bind(slots::ISO, self.iso_buf.as_entire_binding()),
            bind_view(8, &gb.position),
            bind_view(9, &gb.normal),
            bind_view(10, &gb.extra),
        ]
        .into_iter()
        .chain(surfaces.transfer.entries(mesh))
        .collect();
        let shading = self.deferred_inputs(
            ctx,
            res,
            &gb,
            bind_view(slots::GRID_LOOKUP, &self.no_grid_lookup),
        )?;
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("isosurface frame (mesh)"),
            });
        shading.clear_outside(&mut enc, u.shade_rect, full);
        let gr = groups(frame.rect);
        encode_single_group(
            ctx,
            &mut enc,
            "first hit (mesh)",
            (&surfaces.bgl, &firsthit),
            &firsthit_entries,
            [gr[0], gr[1], 1],
        );
        shading.dispatch(&mut enc, &deferred, None, u.shade_rect);
        ctx.checked("rendering the mesh's isosurfaces", || {
            ctx.submit([enc.finish()]);
        })?;
        res.stats.frames += 1;
        Ok(())
    }
}
