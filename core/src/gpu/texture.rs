//! Texture helpers: whole-texture uploads and the per-block grids the passes read.

use super::Context;

/// A value per min–max block (occupancy flags, majorants) as a 3D texture of `dims` that
/// the passes read with textureLoad (lib/march.wgsl, block_coord): u32 values go to an
/// r32uint texture, f32 values to r32float. A texture for the same reason as the transfer
/// tables (resources::tables).
pub(crate) fn block_grid<T: GridValue>(
    ctx: &Context,
    label: &str,
    dims: [u32; 3],
    values: &[T],
) -> wgpu::TextureView {
    let size = wgpu::Extent3d {
        width: dims[0].max(1),
        height: dims[1].max(1),
        depth_or_array_layers: dims[2].max(1),
    };
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: T::FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let n = (size.width * size.height * size.depth_or_array_layers) as usize;
    let mut data = values.to_vec();
    data.resize(n, T::default());
    upload_texture(&ctx.queue, &texture, bytemuck::cast_slice(&data), 4);
    texture.create_view(&Default::default())
}

/// Writes tightly packed texels (`texel_bytes` each, rows then images) over the whole of
/// `texture`'s first mip level.
pub(crate) fn upload_texture(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes: &[u8],
    texel_bytes: u32,
) {
    let size = texture.size();
    queue.write_texture(
        texture.as_image_copy(),
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width * texel_bytes),
            rows_per_image: Some(size.height),
        },
        size,
    );
}

/// The value types of [`block_grid`] textures.
pub(crate) trait GridValue: bytemuck::Pod + Default {
    const FORMAT: wgpu::TextureFormat;
}

impl GridValue for u32 {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
}

impl GridValue for f32 {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
}

/// The descriptor of a 2D texture of one mip level and one layer.
pub(crate) fn texture_2d<'a>(
    label: &'a str,
    [width, height]: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::TextureDescriptor<'a> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    }
}
