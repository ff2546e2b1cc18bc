//! The gradient build (shaders/gradient.wgsl): central-difference gradients of the pool's
//! first component into an rgba16float texture beside it, for
//! [`UploadOptions::precompute_gradients`](crate::UploadOptions::precompute_gradients).

use crate::error::Result;
use crate::gpu::binding::{bind, bind_view, buffer_entry, storage_texture_entry, texture_entry};
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::pipeline::{encode_single_group, single_group_pipeline};
use crate::gpu::Context;
use crate::resources::bricks::Layout;

pub(crate) struct GradientPass {
    bgl: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl GradientPass {
    /// The gradient build's bind group (gradient.wgsl).
    pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 3] {
        [
            buffer_entry(0, wgpu::BufferBindingType::Uniform),
            texture_entry(1, false, wgpu::TextureViewDimension::D3),
            storage_texture_entry(
                2,
                wgpu::TextureFormat::Rgba16Float,
                wgpu::TextureViewDimension::D3,
            ),
        ]
    }

    pub fn new(ctx: &Context) -> Result<GradientPass> {
        let (bgl, pipeline) = single_group_pipeline(
            ctx,
            "gradient.wgsl",
            "gradient build",
            &Self::layout_entries(),
        )?;
        Ok(GradientPass { bgl, pipeline })
    }

    /// The gradient texture of a volume texture (one brick or the pool), computed on the GPU.
    pub fn build(
        &self,
        ctx: &Context,
        volume: &wgpu::TextureView,
        size: wgpu::Extent3d,
        layout: &Layout,
    ) -> Result<wgpu::Texture> {
        let d = &ctx.device;
        let texture = ctx.checked("allocating the gradient texture", || {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some("gradients"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
                view_formats: &[],
            })
        })?;
        let uniforms = uniform_buffer(ctx, "gradient build uniforms", 16);
        let scale = [layout.scale[0], layout.shift[0], 0.0f32, 0.0];
        ctx.queue
            .write_buffer(&uniforms, 0, bytemuck::bytes_of(&scale));
        let out = texture.create_view(&Default::default());
        let mut enc = d.create_command_encoder(&Default::default());
        encode_single_group(
            ctx,
            &mut enc,
            "gradient build",
            (&self.bgl, &self.pipeline),
            &[
                bind(0, uniforms.as_entire_binding()),
                bind_view(1, volume),
                bind_view(2, &out),
            ],
            [
                size.width.div_ceil(4),
                size.height.div_ceil(4),
                size.depth_or_array_layers.div_ceil(4),
            ],
        );
        ctx.checked("computing the gradients", || {
            ctx.submit([enc.finish()]);
        })?;
        Ok(texture)
    }
}
