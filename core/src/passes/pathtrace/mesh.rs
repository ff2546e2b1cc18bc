//! The path tracer's mesh medium: pathtrace_mesh.wgsl's layout, pipelines and uniforms, and
//! a mesh frame's preparation (the accumulation, show pass and denoiser are the parent's).

use super::{accumulation_key, lit, Medium, PathTracePass, Setup};
use crate::error::{Error, Result};
use crate::gpu::binding::{bind_view, group_layout, texture_entry};
use crate::gpu::pipeline::PipelineCache;
use crate::gpu::slots;
use crate::gpu::Context;
use crate::params::{BlendMode, ScalarLocation};
use crate::passes::frame::Purpose;
use crate::passes::unstructured::{self, MeshTransfer};
use crate::passes::unstructured_variant::{self, MeshPathTraceVariant, UnstructuredFacts};
use crate::resources::targets::DepthSource;
use crate::resources::Resources;

/// The mesh's path tracer: its layout, pipelines and mesh uniforms.
pub(super) struct MeshTracer {
    bgl: wgpu::BindGroupLayout,
    pipelines: PipelineCache<MeshPathTraceVariant>,
    transfer: MeshTransfer,
}

impl MeshTracer {
    fn new(ctx: &Context) -> Result<MeshTracer> {
        let bgl = group_layout(
            &ctx.device,
            "path tracing a mesh",
            &PathTracePass::mesh_layout_entries(),
        );
        let pipelines =
            PipelineCache::new(ctx, "pathtrace_mesh.wgsl", "path tracing a mesh", &[&bgl])?;
        Ok(MeshTracer {
            bgl,
            pipelines,
            transfer: MeshTransfer::new(ctx),
        })
    }
}

impl PathTracePass {
    /// The mesh's path tracer's bind group (pathtrace_mesh.wgsl, its only group).
    pub fn mesh_layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        Self::shared_layout_entries()
            .into_iter()
            .chain([texture_entry(
                slots::DEPTH_IN,
                false,
                wgpu::TextureViewDimension::D2,
            )])
            .chain(MeshTransfer::layout_entries())
            .collect()
    }

    /// A mesh's frame (pathtrace_mesh.wgsl), None when only preparing.
    pub(super) fn prepare_mesh(
        &mut self,
        f: &Setup<'_>,
        res: &mut Resources,
        purpose: Purpose,
    ) -> Result<Option<Medium>> {
        let (ctx, view, params) = (f.ctx, f.view, f.params);
        let tf = res.transfer_function()?.clone();
        let ct = tf.component(0);
        let mesh = res.mesh.as_ref().ok_or_else(crate::resources::no_volume)?;
        let facts = UnstructuredFacts {
            blend: BlendMode::PathTrace,
            components: mesh.components,
            cell_scalars: mesh.location == ScalarLocation::Cells,
            shade: false,
            lights: 0,
            positional_lights: false,
            gradient_opacity: ct.gradient_opacity.is_some(),
            tables_2d: ct.table_2d.is_some(),
            cropping: params.cropping.is_some(),
            average_range: false,
            whole_box: params.whole_box.is_some(),
            volumetric: false,
            depth_range: matches!(f.depth, DepthSource::Range(..)),
            intermix: res.intermix.is_some(),
            hybrid: f.hybrid,
            iso_scattering: false,
        };
        let variant = MeshPathTraceVariant {
            cell_scalars: unstructured_variant::select(&facts)
                .map_err(Error::from)?
                .cell_scalars,
            guide: f.guided,
        };
        res.ensure_tables(ctx, 1.0)?;
        self.prepare_common(f, res)?;
        let depth_input = !matches!(f.depth, DepthSource::None);
        let frame = unstructured::frame_uniforms(res, view, &lit(params), depth_input)?;
        let key = accumulation_key(f, res);
        let tracer = match &mut self.mesh {
            Some(t) => t,
            None => self.mesh.insert(MeshTracer::new(ctx)?),
        };
        let pipeline = tracer.pipelines.get(ctx, variant)?;
        if purpose == Purpose::Prepare {
            return Ok(None);
        }
        let mesh = res.mesh.as_ref().expect("checked above");
        tracer.transfer.write(ctx, mesh, ct);
        ctx.queue
            .write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&frame));
        let tracer = self.mesh.as_ref().expect("created above");
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("path tracing a mesh"),
            layout: &tracer.bgl,
            entries: &self
                .shared_entries(res)?
                .into_iter()
                .chain([bind_view(
                    slots::DEPTH_IN,
                    &res.targets
                        .as_ref()
                        .expect("allocated in prepare_common")
                        .depth_in
                        .create_view(&Default::default()),
                )])
                .chain(tracer.transfer.entries(mesh))
                .collect::<Vec<_>>(),
        });
        let u = self.base_uniforms(f, res, ct.unit_distance)?;
        // (the denoiser compares depths per cell)
        let cell = mesh.cell_size();
        Ok(Some(Medium {
            key,
            pipeline,
            groups: vec![group],
            u,
            rect: frame.rect,
            scale: cell as f32,
        }))
    }
}
