//! Copies of GPU textures and buffers to the CPU (tests, G-buffer and environment
//! inspection, the output image), each waiting for the device.

use super::buffers::buffer;
use super::Context;
use crate::error::{Error, Result};

/// Copies one mip level / array layer of a texture to the CPU (rows tightly packed).
pub(crate) fn read_texture_layer(
    ctx: &Context,
    tex: &wgpu::Texture,
    mip: u32,
    layer: u32,
    bytes_per_texel: u32,
) -> Result<Vec<u8>> {
    let w = (tex.width() >> mip).max(1);
    let h = (tex.height() >> mip).max(1);
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buf = buffer(
        ctx,
        "readback",
        padded as u64 * h as u64,
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: tex,
            mip_level: mip,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    ctx.submit([enc.finish()]);
    let bytes = map_read(ctx, &buf)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for y in 0..h as usize {
        out.extend_from_slice(&bytes[y * padded as usize..y * padded as usize + row as usize]);
    }
    Ok(out)
}

/// Copies a storage buffer to the CPU.
pub(crate) fn read_buffer(ctx: &Context, src: &wgpu::Buffer) -> Result<Vec<u8>> {
    let buf = buffer(
        ctx,
        "readback",
        src.size(),
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(src, 0, &buf, 0, src.size());
    ctx.submit([enc.finish()]);
    map_read(ctx, &buf)
}

fn map_read(ctx: &Context, buf: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buf.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle()?;
    rx.recv()
        .map_err(|_| Error::Gpu("readback never completed".into()))?
        .map_err(|e| Error::Gpu(format!("mapping the readback buffer: {e}")))?;
    let out = buf
        .slice(..)
        .get_mapped_range()
        .map_err(|e| Error::Gpu(format!("{e:?}")))?
        .to_vec();
    buf.unmap();
    Ok(out)
}
