//! The frame's output images: colour, depth, the depth input and the per-pixel ray state,
//! in memory OpenGL can import when the output is shared.

use super::Resources;
use crate::error::{Error, Result};
use crate::gpu::interop::{self, ExportableMemory, OutputPath, SharedTargets};
use crate::gpu::readback::read_texture_layer;
use crate::gpu::texture::{texture_2d, upload_texture};
use crate::gpu::uniforms::PIXEL_STATE_BYTES;
use crate::gpu::Context;
use crate::params::{Image, View};
use std::sync::OnceLock;

pub(crate) struct Targets {
    pub width: u32,
    pub height: u32,
    /// The per-pixel ray state, allocated by the first frame that keeps one
    /// ([`Targets::state`]): streamed ray casting and isosurfaces.
    state: OnceLock<wgpu::Buffer>,
    pub(crate) color: wgpu::Texture,
    pub(crate) depth: wgpu::Texture,
    pub(crate) depth_in: wgpu::Texture,
    /// Where rays start, for [`DepthSource::Range`] (window depth; never shared).
    pub(crate) depth_near: wgpu::Texture,
    /// The exportable memory of `color`, `depth` and `depth_in` (owned by those textures)
    /// when they were allocated for [`OutputPath::Shared`].
    exported: Option<[ExportableMemory; 3]>,
    /// [`crate::Renderer::output_generation`] of this allocation.
    pub generation: u64,
}

impl Targets {
    /// The per-pixel ray state ([`PIXEL_STATE_BYTES`] a pixel), allocated on first use: most
    /// frames keep none, and it is the largest of the images (48 bytes a pixel).
    pub(crate) fn state(&self, ctx: &Context) -> &wgpu::Buffer {
        self.state.get_or_init(|| {
            ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("ray state"),
                size: PIXEL_STATE_BYTES * self.width as u64 * self.height as u64,
                // (COPY_SRC: Renderer::read_gbuffer reads the isosurface layer counts)
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        })
    }

    pub fn path(&self) -> OutputPath {
        if self.exported.is_some() {
            OutputPath::Shared
        } else {
            OutputPath::Readback
        }
    }
}

/// Where the ray caster's depth input comes from.
#[derive(Clone, Copy)]
pub(crate) enum DepthSource<'a> {
    /// None: rays run to the far side of the volume.
    None,
    /// Uploaded from the CPU with the frame.
    Cpu(&'a [f32]),
    /// Already in the shared depth-input image, written by the host.
    Shared,
    /// Uploaded from the CPU: each pixel's ray samples only between a near and a far window
    /// depth (half-open, nothing where near ≥ far).
    Range(&'a [f32], &'a [f32]),
}

/// Clears the frame's colour (transparent) and depth (far) images; the passes that cover only
/// the volume's projected rectangle call it first, since pixels outside get no ray.
pub(crate) fn clear_outputs(
    enc: &mut wgpu::CommandEncoder,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear outside the volume"),
        color_attachments: &[clear_attachment(color, 0.0), clear_attachment(depth, 1.0)],
        ..Default::default()
    });
}

/// A colour attachment that clears its first channel to `value` and the rest to zero.
fn clear_attachment(
    view: &wgpu::TextureView,
    value: f64,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color {
                r: value,
                g: 0.0,
                b: 0.0,
                a: 0.0,
            }),
            store: wgpu::StoreOp::Store,
        },
    })
}

impl Resources {
    pub fn ensure_targets(&mut self, ctx: &Context, width: u32, height: u32) -> Result<()> {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| t.width == width && t.height == height && t.path() == self.output_path)
        {
            return Ok(());
        }
        let max = ctx.info.limits.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::InvalidParameter(format!(
                "image size {width}x{height}: each side must be 1 to {max}"
            )));
        }
        let shared = self.output_path == OutputPath::Shared;
        let d = &ctx.device;
        let tex = |label, format, usage| -> Result<(wgpu::Texture, Option<ExportableMemory>)> {
            let desc = texture_2d(label, [width, height], format, usage);
            if shared {
                let (t, m) = interop::create_exportable_texture(ctx, &desc)?;
                Ok((t, Some(m)))
            } else {
                Ok((d.create_texture(&desc), None))
            }
        };
        let out_usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::RENDER_ATTACHMENT;
        let targets = ctx.checked("allocating the frame", || -> Result<Targets> {
            let (color, color_mem) = tex("color", wgpu::TextureFormat::Rgba8Unorm, out_usage)?;
            let (depth, depth_mem) = tex("depth", wgpu::TextureFormat::R32Float, out_usage)?;
            let (depth_in, depth_in_mem) = tex(
                "depth in",
                wgpu::TextureFormat::R32Float,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            )?;
            let depth_near = d.create_texture(&texture_2d(
                "depth near",
                [width, height],
                wgpu::TextureFormat::R32Float,
                wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            ));
            let exported = match (color_mem, depth_mem, depth_in_mem) {
                (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                _ => None,
            };
            if exported.is_some() {
                // wgpu zero-fills the textures it allocates before their first use; it
                // leaves imported ones alone, so clear these the same way.
                let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("clear the shared output"),
                });
                let cv = color.create_view(&Default::default());
                let dv = depth.create_view(&Default::default());
                enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("clear the shared output"),
                    color_attachments: &[clear_attachment(&cv, 0.0), clear_attachment(&dv, 0.0)],
                    ..Default::default()
                });
                // The depth input starts at the far plane: nothing occludes until the host
                // writes its depth.
                let far: Vec<f32> = vec![1.0; width as usize * height as usize];
                upload_texture(&ctx.queue, &depth_in, bytemuck::cast_slice(&far), 4);
                ctx.submit([enc.finish()]);
                // Wait: the host may write the depth input through its own API right after
                // this returns, and a clear landing later would wipe it.
                ctx.wait_idle()?;
            }
            Ok(Targets {
                width,
                height,
                state: OnceLock::new(),
                color,
                depth,
                depth_in,
                depth_near,
                exported,
                generation: self.generation + 1,
            })
        })??;
        self.generation = targets.generation;
        self.targets = Some(targets);
        Ok(())
    }

    /// Exports the output images: new file descriptors (the caller owns them) with what
    /// OpenGL needs to import them; see [`crate::interop`] for the protocol. Needs
    /// [`OutputPath::Shared`] and images allocated on it (a frame rendered or
    /// [`Renderer::prepare_targets`] called after switching).
    pub fn shared_targets(&self, ctx: &Context) -> Result<SharedTargets> {
        if self.output_path != OutputPath::Shared {
            return Err(Error::Unsupported(
                "the output is not shared: call Renderer::set_output_path(OutputPath::Shared) \
                 first (or read frames with Renderer::read_image)"
                    .into(),
            ));
        }
        let Some((t, [color, depth, depth_in])) = self
            .targets
            .as_ref()
            .and_then(|t| t.exported.as_ref().map(|e| (t, e)))
        else {
            return Err(Error::InvalidParameter(
                "the output images are not allocated in shared memory yet: render a frame or \
                 call Renderer::prepare_targets(width, height) first"
                    .into(),
            ));
        };
        Ok(SharedTargets {
            generation: t.generation,
            width: t.width,
            height: t.height,
            color: color.export(ctx, &t.color)?,
            depth: depth.export(ctx, &t.depth)?,
            depth_in: depth_in.export(ctx, &t.depth_in)?,
        })
    }

    /// Checks a CPU depth input (window depth per pixel) against the frame's size and copies
    /// it into the depth-input image (a range's near depths into the near image); nothing to
    /// do for the other sources. The output images must be allocated for the frame.
    pub fn write_depth_input(
        &self,
        ctx: &Context,
        view: &View,
        depth: DepthSource<'_>,
    ) -> Result<()> {
        let (far, near) = match depth {
            DepthSource::Cpu(d) => (d, None),
            DepthSource::Range(near, far) => (far, Some(near)),
            DepthSource::None | DepthSource::Shared => return Ok(()),
        };
        let n = (view.width * view.height) as usize;
        for (what, d) in [("depth image", Some(far)), ("near depth image", near)] {
            match d {
                Some(d) if d.len() != n => {
                    return Err(Error::InvalidParameter(format!(
                        "{what} has {} values for a {}x{} frame ({n} expected)",
                        d.len(),
                        view.width,
                        view.height
                    )))
                }
                _ => {}
            }
        }
        let t = self
            .targets
            .as_ref()
            .expect("output images allocated for the frame");
        upload_texture(&ctx.queue, &t.depth_in, bytemuck::cast_slice(far), 4);
        if let Some(near) = near {
            upload_texture(&ctx.queue, &t.depth_near, bytemuck::cast_slice(near), 4);
        }
        Ok(())
    }

    /// Waits for the last frame and copies its colour and depth to the CPU.
    pub fn read_image(&self, ctx: &Context) -> Result<Image> {
        let t = self
            .targets
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("nothing has been rendered yet".into()))?;
        let rgba = read_texture_layer(ctx, &t.color, 0, 0, 4)?;
        let depth_bytes = read_texture_layer(ctx, &t.depth, 0, 0, 4)?;
        let depth = bytemuck::cast_slice::<u8, f32>(&depth_bytes).to_vec();
        Ok(Image {
            width: t.width,
            height: t.height,
            rgba,
            depth,
        })
    }
}
