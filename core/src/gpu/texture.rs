//! Texture helpers: whole-texture uploads and the per-block grids the passes read.

use super::Context;

/// A value per min–max block or brick (occupancy flags, majorants, scalar ranges, the page
/// table) as a 3D texture of `dims` that the passes read with textureLoad (lib/march.wgsl,
/// block_coord): u32 values go to an r32uint texture, f32 values to r32float, [f32; 2] to
/// rg32float, [f32; 4] to rgba32float. A texture for the same reason as the transfer tables
/// (resources::tables).
pub(crate) fn block_grid<T: GridValue>(
    ctx: &Context,
    label: &str,
    dims: [u32; 3],
    values: &[T],
) -> wgpu::TextureView {
    block_grid_texture(ctx, label, dims, values).create_view(&Default::default())
}

/// [`block_grid`]'s texture, for grids rewritten later (with [`upload_texture`]).
pub(crate) fn block_grid_texture<T: GridValue>(
    ctx: &Context,
    label: &str,
    dims: [u32; 3],
    values: &[T],
) -> wgpu::Texture {
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
    upload_texture(
        &ctx.queue,
        &texture,
        bytemuck::cast_slice(&data),
        std::mem::size_of::<T>() as u32,
    );
    texture
}

/// Writes tightly packed texels (`texel_bytes` each, rows then images) over the whole of
/// `texture`'s first mip level.
pub(crate) fn upload_texture(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes: &[u8],
    texel_bytes: u32,
) {
    let s = texture.size();
    let size = [s.width, s.height, s.depth_or_array_layers];
    upload_region(queue, texture, [0; 3], size, bytes, texel_bytes);
}

/// Most bytes one texture write stages: larger regions go in slabs of whole images.
const MAX_WRITE_BYTES: usize = 64 << 20;

/// Writes tightly packed texels (`texel_bytes` each, rows then images) over the box of
/// `size` texels at `origin` in `texture`'s first mip level.
pub(crate) fn upload_region(
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    origin: [u32; 3],
    size: [u32; 3],
    bytes: &[u8],
    texel_bytes: u32,
) {
    let row = size[0] * texel_bytes;
    let image = row as usize * size[1] as usize;
    let slab = (MAX_WRITE_BYTES / image.max(1)).clamp(1, size[2].max(1) as usize) as u32;
    let mut z = 0;
    while z < size[2] {
        let n = slab.min(size[2] - z);
        let at = z as usize * image;
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: origin[0],
                    y: origin[1],
                    z: origin[2] + z,
                },
                aspect: wgpu::TextureAspect::All,
            },
            &bytes[at..at + n as usize * image],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size[1]),
            },
            wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: n,
            },
        );
        z += n;
    }
}

/// The value types of [`block_grid`] textures.
pub(crate) trait GridValue: bytemuck::Pod + Default {
    const FORMAT: wgpu::TextureFormat;
}

impl GridValue for u32 {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
}

impl GridValue for [u32; 2] {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
}

impl GridValue for u8 {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;
}

impl GridValue for f32 {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
}

impl GridValue for [f32; 2] {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;
}

impl GridValue for [f32; 4] {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
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
