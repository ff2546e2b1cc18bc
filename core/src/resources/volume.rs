//! The volume on the device: its bricks (texture, uniforms, bind groups) and min–max grid.

use super::bricks::{self, BrickExtent, Layout, MinMaxGrid};
use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::binding::bind;
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::texture::upload_texture;
use crate::gpu::uniforms::BrickUniforms;
use crate::gpu::Context;
use crate::params::{UploadOptions, VolumeData};
use glam::DMat4;

/// Computes a brick's gradient texture from its volume texture (the gradient build pass).
pub(crate) type GradientBuilder<'a> =
    dyn Fn(&Context, &wgpu::TextureView, wgpu::Extent3d, &Layout) -> Result<wgpu::Texture> + 'a;

/// Whether an upload of `v` with `opts` stores precomputed gradients: one-component volumes,
/// when asked for. Off by default: on lavapipe one rgba16float fetch costs more than the six
/// single-channel fetches it replaces, and 8-bit storage is filtered to 8-bit precision,
/// which VTK's on-the-fly gradients share (exact gradients differ from VTK's on uint8 data).
pub(crate) fn wants_gradients(v: &VolumeData, opts: &UploadOptions) -> bool {
    v.components == 1 && opts.precompute_gradients.unwrap_or(false)
}

pub(crate) struct GpuBrick {
    pub extent: BrickExtent,
    _texture: wgpu::Texture,
    _gradient: Option<wgpu::Texture>,
    _uniform: wgpu::Buffer,
    pub bind_linear: wgpu::BindGroup,
    pub bind_nearest: wgpu::BindGroup,
}

pub(crate) struct GpuVolume {
    pub data_dims: [u32; 3],
    pub components: u32,
    pub index_to_data: DMat4,
    pub layout: Layout,
    pub bricks: Vec<GpuBrick>,
    pub minmax: MinMaxGrid,
    /// The bricks carry precomputed gradients (binding 3).
    pub gradients: bool,
}

impl Resources {
    /// Uploads a volume (replacing any previous one). With precomputed gradients (one
    /// component and [`UploadOptions::precompute_gradients`]), `gradients` computes each
    /// brick's gradient texture from its volume texture.
    pub fn set_volume(
        &mut self,
        ctx: &Context,
        v: &VolumeData,
        opts: UploadOptions,
        gradients: Option<&GradientBuilder<'_>>,
    ) -> Result<()> {
        v.validate()?;
        let info = &ctx.info;
        let (storage, format, texel_bytes, scale, shift) = bricks::choose_storage(v, info);
        let max_points = opts
            .max_brick_points
            .unwrap_or(info.limits.max_texture_dimension_3d)
            .min(info.limits.max_texture_dimension_3d);
        if max_points < 2 * bricks::BRICK_OVERLAP + 2 {
            return Err(Error::InvalidParameter(format!(
                "brick edge {max_points} is too small (at least {})",
                2 * bricks::BRICK_OVERLAP + 2
            )));
        }
        let max_bytes = opts
            .max_brick_bytes
            .unwrap_or(info.limits.max_buffer_size.min(1 << 30));
        let (brick_cells, extents) =
            bricks::plan_bricks(v.dims, texel_bytes, max_points, max_bytes);
        let layout = Layout {
            storage,
            format,
            texel_bytes,
            channels: bricks::channels_for(v.components),
            scale,
            shift,
            brick_cells,
        };
        let build_gradients = gradients.filter(|_| wants_gradients(v, &opts));
        let d = &ctx.device;
        let mut bricks = Vec::with_capacity(extents.len());
        for e in &extents {
            let size = wgpu::Extent3d {
                width: e.tex_size[0],
                height: e.tex_size[1],
                depth_or_array_layers: e.tex_size[2],
            };
            let texels = bricks::brick_texels(v, &layout, e);
            let (texture, uniform) = ctx.checked("uploading the volume", || {
                let texture = d.create_texture(&wgpu::TextureDescriptor {
                    label: Some("volume brick"),
                    size,
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D3,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                });
                upload_texture(&ctx.queue, &texture, &texels, texel_bytes);
                let v4 = |v: [u32; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
                let tex_size = v4(e.tex_size);
                let bu = BrickUniforms {
                    core_lo: v4(e.core_lo),
                    core_hi: v4(e.core_hi),
                    tex_lo: v4(e.tex_lo),
                    tex_inv_size: [1.0 / tex_size[0], 1.0 / tex_size[1], 1.0 / tex_size[2], 0.0],
                };
                let uniform = uniform_buffer(
                    ctx,
                    "brick uniforms",
                    std::mem::size_of::<BrickUniforms>() as u64,
                );
                ctx.queue.write_buffer(&uniform, 0, bytemuck::bytes_of(&bu));
                (texture, uniform)
            })?;
            let view = texture.create_view(&Default::default());
            let gradient = match build_gradients {
                Some(build) => Some(build(ctx, &view, size, &layout)?),
                None => None,
            };
            let gradient_view = gradient
                .as_ref()
                .map(|t| t.create_view(&Default::default()));
            let brick_group = |s: &wgpu::Sampler| {
                d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("brick"),
                    layout: &self.brick_bgl,
                    entries: &[
                        bind(0, uniform.as_entire_binding()),
                        bind(1, wgpu::BindingResource::TextureView(&view)),
                        bind(2, wgpu::BindingResource::Sampler(s)),
                        bind(
                            3,
                            wgpu::BindingResource::TextureView(
                                gradient_view.as_ref().unwrap_or(&view),
                            ),
                        ),
                    ],
                })
            };
            let bind_linear = brick_group(&self.linear);
            let bind_nearest = brick_group(&self.nearest);
            bricks.push(GpuBrick {
                extent: *e,
                _texture: texture,
                _gradient: gradient,
                _uniform: uniform,
                bind_linear,
                bind_nearest,
            });
        }
        self.volume = Some(GpuVolume {
            data_dims: v.dims,
            components: v.components,
            index_to_data: v.index_to_data(),
            layout,
            bricks,
            minmax: MinMaxGrid::new(v),
            gradients: build_gradients.is_some(),
        });
        self.occupancy = None;
        self.stats.volume_uploads += 1;
        Ok(())
    }
}
