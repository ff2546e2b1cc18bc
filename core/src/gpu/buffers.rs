//! Buffer creation.

use super::Context;

/// A buffer of `size` bytes for `usage`, not mapped.
pub(crate) fn buffer(
    ctx: &Context,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    })
}

/// A uniform buffer of `size` bytes that the queue writes.
pub(crate) fn uniform_buffer(ctx: &Context, label: &str, size: u64) -> wgpu::Buffer {
    buffer(
        ctx,
        label,
        size,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    )
}
