//! Whether the host's depth input changed between path-traced frames
//! (shaders/depth_changed.wgsl): opaque geometry that stays put must not restart the
//! accumulation, geometry that moves must.

use super::frame::groups;
use crate::error::Result;
use crate::gpu::binding::{bind, bind_view, buffer_entry, texture_entry};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::{encode_single_group, single_group_pipeline};
use crate::gpu::readback::read_buffer;
use crate::gpu::uniforms::{DepthCompareUniforms, UNIFORM_STRIDE};
use crate::gpu::Context;

/// The comparison's pipeline, the depth last seen and the flag it raises.
pub(crate) struct DepthCheck {
    bgl: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    uniforms: wgpu::Buffer,
    flag: wgpu::Buffer,
    /// (width, height, the depth last seen per pixel)
    seen: Option<(u32, u32, wgpu::Buffer)>,
}

impl DepthCheck {
    /// The depth comparison's bind group (depth_changed.wgsl).
    pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 4] {
        use wgpu::BufferBindingType as B;
        [
            buffer_entry(0, B::Uniform),
            texture_entry(1, false, wgpu::TextureViewDimension::D2),
            buffer_entry(2, B::Storage { read_only: false }),
            buffer_entry(3, B::Storage { read_only: false }),
        ]
    }

    pub fn new(ctx: &Context) -> Result<DepthCheck> {
        let (bgl, pipeline) = single_group_pipeline(
            ctx,
            "depth_changed.wgsl",
            "depth comparison",
            &Self::layout_entries(),
        )?;
        Ok(DepthCheck {
            bgl,
            pipeline,
            uniforms: uniform_buffer(ctx, "depth comparison uniforms", UNIFORM_STRIDE),
            flag: buffer(
                ctx,
                "depth changed",
                4,
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
            ),
            seen: None,
        })
    }

    /// Compares `depth_in` (width × height) with the depth seen last time and keeps it;
    /// true when any pixel differs, or nothing was seen at this size yet. Waits for the
    /// device: the one wait inside a frame, since the accumulation must restart in the
    /// frame whose depth changed (paths against the new depth added to sums against the old
    /// would show a wrong image), and the restart decides on the host what the frame
    /// traces.
    pub fn changed(&mut self, ctx: &Context, depth_in: &wgpu::Texture) -> Result<bool> {
        let (width, height) = (depth_in.width(), depth_in.height());
        let fresh = !self
            .seen
            .as_ref()
            .is_some_and(|(w, h, _)| *w == width && *h == height);
        if fresh {
            let seen = ctx.checked("allocating the depth comparison", || {
                buffer(
                    ctx,
                    "depth seen",
                    4 * width as u64 * height as u64,
                    wgpu::BufferUsages::STORAGE,
                )
            })?;
            self.seen = Some((width, height, seen));
        }
        let (_, _, seen) = self.seen.as_ref().expect("allocated above");
        let u = DepthCompareUniforms {
            size: [width, height, 0, 0],
        };
        ctx.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let view = depth_in.create_view(&Default::default());
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("depth comparison"),
            });
        enc.clear_buffer(&self.flag, 0, None);
        let [gx, gy] = groups([0, 0, width, height]);
        encode_single_group(
            ctx,
            &mut enc,
            "depth comparison",
            (&self.bgl, &self.pipeline),
            &[
                bind(0, self.uniforms.as_entire_binding()),
                bind_view(1, &view),
                bind(2, seen.as_entire_binding()),
                bind(3, self.flag.as_entire_binding()),
            ],
            [gx, gy, 1],
        );
        ctx.checked("comparing the depth input", || {
            ctx.submit([enc.finish()]);
        })?;
        let flag = read_buffer(ctx, &self.flag)?;
        Ok(fresh || flag != [0; 4])
    }
}
