//! The path tracer's denoiser.

use super::frame::groups;
use crate::error::Result;
use crate::gpu::binding::{
    bind, bind_block, bind_view, buffer_entry, dynamic_uniform_entry, storage_texture_entry,
};
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::pipeline::single_group_pipeline;
use crate::gpu::uniforms::{DenoiseUniforms, UNIFORM_STRIDE};
use crate::gpu::Context;

/// Iterations of the à-trous denoiser (taps 1, 2 and 4 pixels apart).
const DENOISE_ITERATIONS: u32 = 3;
/// Edge-stopping scales of the denoiser: colour (radiance units, shrinking by √2 each
/// iteration), the power of the normals' cosine (low: a medium's first-collision normals are
/// noisy), depth (sample distances per pixel of tap spacing).
const DENOISE_COLOR_SIGMA: f32 = 1.0;
const DENOISE_NORMAL_POWER: f32 = 1.0;
const DENOISE_DEPTH_SIGMA: f32 = 16.0;

/// What the denoiser reads and writes.
pub(crate) struct DenoiseOutputs<'a> {
    /// The accumulation (its coverage sums turn the guide's depth sums into means).
    pub accum: &'a wgpu::Buffer,
    pub guide: &'a wgpu::Buffer,
    pub images: [&'a wgpu::Buffer; 2],
    pub color: &'a wgpu::TextureView,
}

/// The denoiser (shaders/denoise.wgsl): an edge-avoiding à-trous filter of the path
/// tracer's shown means guided by the first collisions' normals and depths.
pub(crate) struct DenoisePass {
    bgl: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    uniforms: wgpu::Buffer,
}

impl DenoisePass {
    /// The denoiser's bind group (denoise.wgsl).
    pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 6] {
        use wgpu::BufferBindingType as B;
        [
            dynamic_uniform_entry::<DenoiseUniforms>(0),
            buffer_entry(1, B::Storage { read_only: true }),
            buffer_entry(2, B::Storage { read_only: false }),
            buffer_entry(3, B::Storage { read_only: true }),
            buffer_entry(4, B::Storage { read_only: true }),
            storage_texture_entry(
                5,
                wgpu::TextureFormat::Rgba8Unorm,
                wgpu::TextureViewDimension::D2,
            ),
        ]
    }

    pub fn new(ctx: &Context) -> Result<DenoisePass> {
        let (bgl, pipeline) =
            single_group_pipeline(ctx, "denoise.wgsl", "denoise", &Self::layout_entries())?;
        let uniforms = uniform_buffer(
            ctx,
            "denoiser uniforms",
            UNIFORM_STRIDE * DENOISE_ITERATIONS as u64,
        );
        Ok(DenoisePass {
            bgl,
            pipeline,
            uniforms,
        })
    }

    /// Records the denoiser's iterations over `rect`: the means in `images[0]` filtered back
    /// and forth between the two images, the last iteration also into the output colour. The
    /// colour edge-stopping scale shrinks each iteration (Dammertz et al. halve it); depths
    /// are compared per `step` (the sample distance) times the tap spacing.
    pub fn encode(
        &self,
        ctx: &Context,
        enc: &mut wgpu::CommandEncoder,
        out: &DenoiseOutputs<'_>,
        rect: [u32; 4],
        width: u32,
        step: f32,
    ) {
        let mut blocks = vec![0u8; (UNIFORM_STRIDE * DENOISE_ITERATIONS as u64) as usize];
        for i in 0..DENOISE_ITERATIONS {
            let last = u32::from(i + 1 == DENOISE_ITERATIONS);
            let u = DenoiseUniforms {
                rect,
                size: [width, 0, 1 << i, last],
                params: [
                    0.0,
                    DENOISE_COLOR_SIGMA * 0.5f32.powf(i as f32 * 0.5),
                    DENOISE_NORMAL_POWER,
                    DENOISE_DEPTH_SIGMA * step,
                ],
            };
            let at = (UNIFORM_STRIDE * i as u64) as usize;
            blocks[at..at + std::mem::size_of::<DenoiseUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        ctx.queue.write_buffer(&self.uniforms, 0, &blocks);
        let bind = |src: &wgpu::Buffer, dst: &wgpu::Buffer| {
            ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("denoise"),
                layout: &self.bgl,
                entries: &[
                    bind_block::<DenoiseUniforms>(0, &self.uniforms),
                    bind(1, src.as_entire_binding()),
                    bind(2, dst.as_entire_binding()),
                    bind(3, out.guide.as_entire_binding()),
                    bind(4, out.accum.as_entire_binding()),
                    bind_view(5, out.color),
                ],
            })
        };
        let [a, b] = out.images;
        let gr = groups(rect);
        let bind_groups = [bind(a, b), bind(b, a)];
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("denoise"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        for i in 0..DENOISE_ITERATIONS {
            pass.set_bind_group(
                0,
                &bind_groups[i as usize % 2],
                &[(UNIFORM_STRIDE * i as u64) as u32],
            );
            pass.dispatch_workgroups(gr[0], gr[1], 1);
        }
    }
}
