//! The renderer: long-lived pipelines, the uploaded volume and tables; one call per frame.

use crate::binding::{
    bind, buffer_entry, entry, sampled_texture_entry, storage_texture_entry, texture_entry,
};
use crate::camera::Camera;
use crate::device::Context;
use crate::error::{Error, Result};
use crate::gpu::*;
use crate::interop::{self, ExportableMemory, OutputPath, SharedOutput};
use crate::light::{Light, LightSpace};
use crate::params::{BlendMode, GradientMethod, Interpolation, RenderParams, MAX_LIGHTS};
use crate::readback::read_texture_layer;
use crate::transfer::{build_tables, TransferFunction, TABLE_SIZE};
use crate::upload::{self, BrickExtent, Layout, MinMaxGrid, BLOCK_SIZE};
use crate::volume::VolumeData;
use bytemuck::Zeroable;
use glam::{DMat4, DVec3};

/// What the frame is seen through: camera, lights and image size.
#[derive(Clone, Debug)]
pub struct View {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub width: u32,
    pub height: u32,
}

impl View {
    /// A view of `width × height` with a reset camera on `bounds` and VTK's headlight.
    pub fn fit(bounds: [f64; 6], width: u32, height: u32) -> View {
        let mut camera = Camera::default();
        camera.reset(bounds);
        View {
            camera,
            lights: vec![Light::headlight()],
            width,
            height,
        }
    }
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }
}

/// Options for uploading a volume.
#[derive(Clone, Copy, Debug, Default)]
pub struct UploadOptions {
    /// Largest brick edge in points (overlap included); `None` = the device limit.
    pub max_brick_points: Option<u32>,
    /// Largest brick texture in bytes; `None` = the device's buffer limit, at most 1 GiB.
    pub max_brick_bytes: Option<u64>,
    /// Store the first component's central-difference gradients in a texture beside each
    /// brick (8 bytes per point), so that shading reads one fetch instead of six (the same
    /// gradients: see shaders/gradient.wgsl); single-component volumes only. `None`: off
    /// (measured slower on lavapipe, the one device this was measured on; a GPU's texture
    /// units may well reverse that).
    pub precompute_gradients: Option<bool>,
}

/// Counters that show what a frame re-uploaded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    pub volume_uploads: u32,
    pub table_uploads: u32,
    pub occupancy_updates: u32,
    pub frames: u32,
}

/// A finished frame read back to the CPU.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Premultiplied RGBA8, rows top to bottom.
    pub rgba: Vec<u8>,
    /// Window depth per pixel (0 near … 1 far; 1 where no sample passed the threshold).
    pub depth: Vec<f32>,
}

impl Image {
    /// Composites over an opaque background colour and writes a PNG.
    pub fn save_png(&self, path: &std::path::Path, background: [f32; 3]) -> Result<()> {
        let mut out = image::RgbImage::new(self.width, self.height);
        for (i, px) in out.pixels_mut().enumerate() {
            let p = &self.rgba[4 * i..4 * i + 4];
            let a = p[3] as f32 / 255.0;
            for c in 0..3 {
                let v = p[c] as f32 + (1.0 - a) * background[c] * 255.0;
                px.0[c] = v.round().clamp(0.0, 255.0) as u8;
            }
        }
        out.save(path).map_err(|e| Error::ImageWrite {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Pixel (x, y) as premultiplied RGBA in [0, 1].
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let i = 4 * (y * self.width + x) as usize;
        [0, 1, 2, 3].map(|c| self.rgba[i + c] as f32 / 255.0)
    }
}

pub(crate) struct GpuBrick {
    extent: BrickExtent,
    _texture: wgpu::Texture,
    _gradient: Option<wgpu::Texture>,
    _uniform: wgpu::Buffer,
    pub(crate) bind_linear: wgpu::BindGroup,
    pub(crate) bind_nearest: wgpu::BindGroup,
}

pub(crate) struct GpuVolume {
    data_dims: [u32; 3],
    pub(crate) components: u32,
    index_to_data: DMat4,
    layout: Layout,
    pub(crate) bricks: Vec<GpuBrick>,
    pub(crate) minmax: MinMaxGrid,
    /// The bricks carry precomputed gradients (binding 3).
    pub(crate) gradients: bool,
}

pub(crate) struct Targets {
    width: u32,
    height: u32,
    pub(crate) state: wgpu::Buffer,
    pub(crate) color: wgpu::Texture,
    pub(crate) depth: wgpu::Texture,
    pub(crate) depth_in: wgpu::Texture,
    /// The exportable memory of `color`, `depth` and `depth_in` (owned by those textures)
    /// when they were allocated for [`OutputPath::Shared`].
    exported: Option<[ExportableMemory; 3]>,
    /// [`Renderer::output_generation`] of this allocation.
    generation: u64,
}

impl Targets {
    fn path(&self) -> OutputPath {
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
}

/// Everything that decides the tables' contents; tables are rebuilt only when it changes.
#[derive(PartialEq)]
pub(crate) struct TableKey {
    tf: TransferFunction,
    step_bits: u64,
}

/// The pixels the volume's box can cover: the bounding rectangle of its projected corners
/// widened by a pixel, as [x0, y0, x1, y1) — or the whole image when a corner lies behind
/// the camera (the camera is inside or beside the volume).
fn screen_rect(
    vp: DMat4,
    index_to_world: DMat4,
    dims: [u32; 3],
    width: u32,
    height: u32,
) -> [u32; 4] {
    let full = [0, 0, width, height];
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for c in 0..8u32 {
        let ijk = DVec3::new(
            if c & 1 != 0 {
                (dims[0] - 1) as f64
            } else {
                0.0
            },
            if c & 2 != 0 {
                (dims[1] - 1) as f64
            } else {
                0.0
            },
            if c & 4 != 0 {
                (dims[2] - 1) as f64
            } else {
                0.0
            },
        );
        let clip = vp * index_to_world.transform_point3(ijk).extend(1.0);
        if clip.w <= 1e-9 || !clip.is_finite() {
            return full;
        }
        let x = (clip.x / clip.w + 1.0) * 0.5 * width as f64;
        let y = (1.0 - clip.y / clip.w) * 0.5 * height as f64;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let clamp = |v: f64, hi: u32| v.clamp(0.0, hi as f64) as u32;
    let r = [
        clamp(x0.floor() - 1.0, width),
        clamp(y0.floor() - 1.0, height),
        clamp(x1.ceil() + 1.0, width),
        clamp(y1.ceil() + 1.0, height),
    ];
    if r[0] >= r[2] || r[1] >= r[3] {
        return [0, 0, 0, 0];
    }
    r
}

/// Edge of the square compute workgroups (`@workgroup_size` in dvr.wgsl and resolve.wgsl).
/// 8×8 keeps rays in a workgroup coherent; 16×16 measured slower on lavapipe.
pub(crate) const WORKGROUP: u32 = 8;

/// Empty-space skipping is used only when fewer blocks than this fraction are occupied.
pub(crate) const SKIP_MAX_OCCUPANCY: f64 = 0.9;

/// A value per min–max block (occupancy flags, majorants) as a 3D texture of `dims` that
/// the passes read with textureLoad (lib/march.wgsl, block_coord): u32 values go to an
/// r32uint texture, f32 values to r32float. A texture for the same reason as [`Tables`].
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

/// The transfer-function tables as the shaders read them (lib/common.wgsl): one row of
/// `TABLE_SIZE` texels per table, two tables per component. A texture, not a storage
/// buffer: lavapipe reads a storage buffer at per-lane indices one lane at a time, a
/// texture with one gather (the benchmark frame took 1.5× as long with the buffer).
pub(crate) struct Tables {
    texture: wgpu::Texture,
    pub(crate) view: wgpu::TextureView,
}

impl Tables {
    pub(crate) fn new(d: &wgpu::Device, size: wgpu::Extent3d) -> Tables {
        let texture = d.create_texture(&wgpu::TextureDescriptor {
            label: Some("transfer tables"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        Tables { texture, view }
    }
}

/// The pipeline constants of one specialisation of the DVR pass (overrides in dvr.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct DvrVariant {
    blend: u32,
    components: u32,
    independent: bool,
    shade: bool,
    gradient_opacity: bool,
    skip: bool,
    crop: bool,
    nearest: bool,
    single_brick: bool,
    positional_lights: bool,
    lights: u32,
    volumetric: bool,
    precomputed_gradient: bool,
    forward_diff: bool,
}

impl DvrVariant {
    fn constants(&self) -> [(&'static str, f64); 14] {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        [
            ("BLEND", self.blend as f64),
            ("NCOMP", self.components as f64),
            ("INDEPENDENT", b(self.independent)),
            ("SHADE", b(self.shade)),
            ("GRAD_OPACITY", b(self.gradient_opacity)),
            ("SKIP", b(self.skip)),
            ("CROP", b(self.crop)),
            ("NEAREST", b(self.nearest)),
            ("SINGLE_BRICK", b(self.single_brick)),
            ("POSITIONAL_LIGHTS", b(self.positional_lights)),
            ("NUM_LIGHTS", self.lights as f64),
            ("VOLUMETRIC", b(self.volumetric)),
            ("PRECOMPUTED_GRADIENT", b(self.precomputed_gradient)),
            ("FORWARD_DIFF", b(self.forward_diff)),
        ]
    }
}

pub struct Renderer {
    pub(crate) ctx: Context,
    dvr_module: wgpu::ShaderModule,
    dvr_layout: wgpu::PipelineLayout,
    dvr_variants: std::collections::HashMap<DvrVariant, wgpu::ComputePipeline>,
    resolve: wgpu::ComputePipeline,
    dvr_bgl: wgpu::BindGroupLayout,
    pub(crate) brick_bgl: wgpu::BindGroupLayout,
    resolve_bgl: wgpu::BindGroupLayout,
    linear: wgpu::Sampler,
    pub(crate) nearest: wgpu::Sampler,
    pub(crate) frame_buf: wgpu::Buffer,
    pub(crate) volume: Option<GpuVolume>,
    pub(crate) tf: Option<TransferFunction>,
    pub(crate) tables: Option<(TableKey, Tables)>,
    occupancy: Option<(TableKey, wgpu::TextureView, f64)>,
    pub(crate) targets: Option<Targets>,
    output_path: OutputPath,
    /// Counts allocations of the output images.
    pub(crate) generation: u64,
    pub(crate) stats: Stats,
    /// The isosurface passes (crate::iso), created on first use.
    pub(crate) iso: Option<Box<crate::iso::IsoGpu>>,
    pub(crate) iso_params: Option<crate::iso::IsoParams>,
    /// Counts set_environment calls (path tracing restarts its accumulation on a change).
    pub(crate) environment_generation: u64,
    /// The path tracer (crate::pathtrace), created on first use, and its accumulation.
    pub(crate) pt: Option<Box<crate::pathtrace::PathTraceGpu>>,
    pub(crate) pt_params: crate::pathtrace::PathTraceParams,
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

impl Renderer {
    /// Creates the pipelines on a device (picks one with [`Context::new`] if you have none).
    pub fn new(ctx: Context) -> Result<Renderer> {
        let d = &ctx.device;
        let output_entries = [
            entry(
                5,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            ),
            entry(
                6,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: wgpu::TextureFormat::R32Float,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
            ),
        ];
        let dvr_bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dvr frame"),
            entries: &[
                buffer_entry(0, wgpu::BufferBindingType::Uniform),
                texture_entry(1, false, wgpu::TextureViewDimension::D2),
                buffer_entry(2, wgpu::BufferBindingType::Storage { read_only: false }),
                sampled_texture_entry(
                    3,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D3,
                ),
                texture_entry(4, false, wgpu::TextureViewDimension::D2),
                output_entries[0],
                output_entries[1],
            ],
        });
        let brick_bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("brick"),
            entries: &[
                buffer_entry(0, wgpu::BufferBindingType::Uniform),
                texture_entry(1, true, wgpu::TextureViewDimension::D3),
                entry(
                    2,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
                texture_entry(3, true, wgpu::TextureViewDimension::D3),
            ],
        });
        let resolve_bgl = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                buffer_entry(0, wgpu::BufferBindingType::Uniform),
                texture_entry(1, false, wgpu::TextureViewDimension::D2),
                buffer_entry(2, wgpu::BufferBindingType::Storage { read_only: true }),
                output_entries[0],
                output_entries[1],
            ],
        });
        let module = |name: &str| -> Result<wgpu::ShaderModule> {
            ctx.checked(&format!("compiling shader {name}"), || {
                let desc = wgpu::ShaderModuleDescriptor {
                    label: Some(name),
                    source: wgpu::ShaderSource::Wgsl(crate::shaders::compose(name).into()),
                };
                // SAFETY: our shaders index only within bounds they establish themselves
                // (pixel indices behind the viewport test, table indices from a clamped
                // coordinate, occupancy and texel coordinates clamped to their grids), and
                // every loop advances toward a bound (ray steps, lights, components).
                // wgpu's injected checks cost a clamp per access and a counter per loop
                // iteration, a fifth of the frame time on lavapipe.
                unsafe {
                    d.create_shader_module_trusted(desc, wgpu::ShaderRuntimeChecks::unchecked())
                }
            })
        };
        let layout = |name: &str, bgls: &[Option<&wgpu::BindGroupLayout>]| {
            d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(name),
                bind_group_layouts: bgls,
                immediate_size: 0,
            })
        };
        let dvr_module = module("dvr.wgsl")?;
        let dvr_layout = layout("dvr.wgsl", &[Some(&dvr_bgl), Some(&brick_bgl)]);
        let resolve_module = module("resolve.wgsl")?;
        let resolve_layout = layout("resolve.wgsl", &[Some(&resolve_bgl)]);
        let resolve = ctx.checked("creating the resolve pipeline", || {
            d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("resolve"),
                layout: Some(&resolve_layout),
                module: &resolve_module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        })?;
        let sampler = |f: wgpu::FilterMode| {
            d.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("volume"),
                address_mode_u: wgpu::AddressMode::ClampToEdge,
                address_mode_v: wgpu::AddressMode::ClampToEdge,
                address_mode_w: wgpu::AddressMode::ClampToEdge,
                mag_filter: f,
                min_filter: f,
                ..Default::default()
            })
        };
        let linear = sampler(wgpu::FilterMode::Linear);
        let nearest = sampler(wgpu::FilterMode::Nearest);
        let frame_buf = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Renderer {
            ctx,
            dvr_module,
            dvr_layout,
            dvr_variants: Default::default(),
            resolve,
            dvr_bgl,
            brick_bgl,
            resolve_bgl,
            linear,
            nearest,
            frame_buf,
            volume: None,
            tf: None,
            tables: None,
            occupancy: None,
            targets: None,
            output_path: OutputPath::Readback,
            generation: 0,
            stats: Stats::default(),
            iso: None,
            iso_params: None,
            environment_generation: 0,
            pt: None,
            pt_params: Default::default(),
        })
    }

    pub fn context(&self) -> &Context {
        &self.ctx
    }

    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Number of bricks the current volume is split into (0 without a volume).
    pub fn brick_count(&self) -> usize {
        self.volume.as_ref().map_or(0, |v| v.bricks.len())
    }

    /// The texture format the current volume is stored in.
    pub fn volume_format(&self) -> Option<wgpu::TextureFormat> {
        self.volume.as_ref().map(|v| v.layout.format)
    }

    /// Uploads a volume (replacing any previous one).
    pub fn set_volume(&mut self, v: &VolumeData) -> Result<()> {
        self.set_volume_with(v, UploadOptions::default())
    }

    pub fn set_volume_with(&mut self, v: &VolumeData, opts: UploadOptions) -> Result<()> {
        v.validate()?;
        let info = &self.ctx.info;
        let (storage, format, texel_bytes, scale, shift) = upload::choose_storage(v, info);
        let max_points = opts
            .max_brick_points
            .unwrap_or(info.limits.max_texture_dimension_3d)
            .min(info.limits.max_texture_dimension_3d);
        if max_points < 2 * upload::BRICK_OVERLAP + 2 {
            return Err(Error::InvalidParameter(format!(
                "brick edge {max_points} is too small (at least {})",
                2 * upload::BRICK_OVERLAP + 2
            )));
        }
        let max_bytes = opts
            .max_brick_bytes
            .unwrap_or(info.limits.max_buffer_size.min(1 << 30));
        let (brick_cells, extents) =
            upload::plan_bricks(v.dims, texel_bytes, max_points, max_bytes);
        let layout = Layout {
            storage,
            format,
            texel_bytes,
            channels: upload::channels_for(v.components),
            scale,
            shift,
            brick_cells,
        };
        // Off unless asked for: on lavapipe one rgba16float fetch costs more than the six
        // single-channel fetches it replaces (wavelet 256³ shaded, 900×900: 136–142 ms
        // against 126 ms). And 8-bit storage is filtered to 8-bit precision, which VTK's
        // on-the-fly gradients share: exact gradients cost 5 dB against VTK on the uint8 MRI.
        let gradients = v.components == 1 && opts.precompute_gradients.unwrap_or(false);
        let gradient_pipeline = if gradients {
            Some(self.gradient_pipeline()?)
        } else {
            None
        };
        let d = &self.ctx.device;
        let mut bricks = Vec::with_capacity(extents.len());
        for e in &extents {
            let size = wgpu::Extent3d {
                width: e.tex_size[0],
                height: e.tex_size[1],
                depth_or_array_layers: e.tex_size[2],
            };
            let texels = upload::brick_texels(v, &layout, e);
            let (texture, uniform) = self.ctx.checked("uploading the volume", || {
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
                upload_texture(&self.ctx.queue, &texture, &texels, texel_bytes);
                let v4 = |v: [u32; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
                let tex_size = v4(e.tex_size);
                let bu = BrickUniforms {
                    core_lo: v4(e.core_lo),
                    core_hi: v4(e.core_hi),
                    tex_lo: v4(e.tex_lo),
                    tex_inv_size: [1.0 / tex_size[0], 1.0 / tex_size[1], 1.0 / tex_size[2], 0.0],
                };
                let uniform = d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("brick uniforms"),
                    size: std::mem::size_of::<BrickUniforms>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                self.ctx
                    .queue
                    .write_buffer(&uniform, 0, bytemuck::bytes_of(&bu));
                (texture, uniform)
            })?;
            let view = texture.create_view(&Default::default());
            let gradient = match &gradient_pipeline {
                Some(p) => Some(self.build_gradients(p, &view, size, &layout)?),
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
            gradients,
        });
        self.occupancy = None;
        self.stats.volume_uploads += 1;
        Ok(())
    }

    /// The gradient build pass (shaders/gradient.wgsl): its bind group layout and pipeline.
    fn gradient_pipeline(&self) -> Result<(wgpu::BindGroupLayout, wgpu::ComputePipeline)> {
        crate::iso::single_group_pipeline(
            &self.ctx,
            "gradient.wgsl",
            "gradient build",
            &[
                buffer_entry(0, wgpu::BufferBindingType::Uniform),
                texture_entry(1, false, wgpu::TextureViewDimension::D3),
                storage_texture_entry(
                    2,
                    wgpu::TextureFormat::Rgba16Float,
                    wgpu::TextureViewDimension::D3,
                ),
            ],
        )
    }

    /// A brick's gradient texture, computed from its volume texture on the GPU.
    fn build_gradients(
        &self,
        (bgl, pipeline): &(wgpu::BindGroupLayout, wgpu::ComputePipeline),
        volume: &wgpu::TextureView,
        size: wgpu::Extent3d,
        layout: &Layout,
    ) -> Result<wgpu::Texture> {
        let d = &self.ctx.device;
        let texture = self.ctx.checked("allocating the gradient texture", || {
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
        let uniforms = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gradient build uniforms"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let scale = [layout.scale[0], layout.shift[0], 0.0f32, 0.0];
        self.ctx
            .queue
            .write_buffer(&uniforms, 0, bytemuck::bytes_of(&scale));
        let out = texture.create_view(&Default::default());
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gradient build"),
            layout: bgl,
            entries: &[
                bind(0, uniforms.as_entire_binding()),
                bind(1, wgpu::BindingResource::TextureView(volume)),
                bind(2, wgpu::BindingResource::TextureView(&out)),
            ],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(
                size.width.div_ceil(4),
                size.height.div_ceil(4),
                size.depth_or_array_layers.div_ceil(4),
            );
        }
        self.ctx.checked("computing the gradients", || {
            self.ctx.queue.submit([enc.finish()]);
        })?;
        Ok(texture)
    }

    /// Sets the transfer function; its tables are (re)built at the next frame if it changed.
    pub fn set_transfer_function(&mut self, tf: &TransferFunction) -> Result<()> {
        let comps = self
            .volume
            .as_ref()
            .map_or(tf.components.len() as u32, |v| v.components);
        tf.validate(comps)?;
        self.tf = Some(tf.clone());
        Ok(())
    }

    /// The world distance between samples these parameters give for the current volume.
    pub fn sample_distance(&self, params: &RenderParams) -> Result<f64> {
        let vol = self
            .volume
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no volume has been set".into()))?;
        Ok(match params.sample_distance {
            Some(d) => d,
            None => {
                let m = params.volume_matrix * vol.index_to_data;
                let s = [
                    m.x_axis.truncate().length(),
                    m.y_axis.truncate().length(),
                    m.z_axis.truncate().length(),
                ];
                s.iter().cloned().fold(f64::INFINITY, f64::min)
            }
        })
    }

    pub(crate) fn ensure_tables(&mut self, step: f64) -> Result<()> {
        let tf = self
            .tf
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no transfer function has been set".into()))?;
        let key = TableKey {
            tf: tf.clone(),
            step_bits: step.to_bits(),
        };
        if self.tables.as_ref().is_some_and(|(k, _)| *k == key) {
            return Ok(());
        }
        let comps = self.volume.as_ref().map_or(1, |v| v.components) as usize;
        let mut data: Vec<[f32; 4]> = Vec::with_capacity(comps * 2 * TABLE_SIZE);
        for c in 0..comps {
            data.extend(build_tables(tf.component(c), step));
        }
        let size = wgpu::Extent3d {
            width: TABLE_SIZE as u32,
            height: 2 * comps as u32,
            depth_or_array_layers: 1,
        };
        let tables = match self.tables.take() {
            Some((_, t)) if t.texture.size() == size => t,
            _ => Tables::new(&self.ctx.device, size),
        };
        upload_texture(
            &self.ctx.queue,
            &tables.texture,
            bytemuck::cast_slice(&data),
            16,
        );
        self.tables = Some((key, tables));
        self.stats.table_uploads += 1;
        Ok(())
    }

    /// Classifies the min–max grid against the transfer function: 1 for blocks where some
    /// value in the block's range has non-zero opacity.
    fn ensure_occupancy(&mut self, step: f64) -> Result<()> {
        let (Some(tf), Some(vol)) = (self.tf.as_ref(), self.volume.as_ref()) else {
            return Err(Error::InvalidParameter(
                "a volume and a transfer function are needed".into(),
            ));
        };
        let key = TableKey {
            tf: tf.clone(),
            step_bits: step.to_bits(),
        };
        if self.occupancy.as_ref().is_some_and(|(k, _, _)| *k == key) {
            return Ok(());
        }
        let nc = vol.components as usize;
        // Which components drive opacity, and prefix counts of non-zero table entries.
        let opacity_comps: Vec<usize> = if tf.independent {
            (0..nc).collect()
        } else {
            vec![nc - 1]
        };
        let prefix: Vec<(usize, [f64; 2], Vec<u32>)> = opacity_comps
            .iter()
            .map(|&c| {
                let ct = tf.component(if tf.independent { c } else { 0 });
                let tables = build_tables(ct, step);
                let mut p = vec![0u32; TABLE_SIZE + 1];
                for i in 0..TABLE_SIZE {
                    let nz = tables[i][3] > 0.0 && (!tf.independent || ct.weight > 0.0);
                    p[i + 1] = p[i] + nz as u32;
                }
                (c, ct.table_range(), p)
            })
            .collect();
        let nblocks = vol.minmax.ranges.len() / nc;
        let mut occ = vec![0u32; nblocks];
        let last = (TABLE_SIZE - 1) as f64;
        for (b, o) in occ.iter_mut().enumerate() {
            for (c, [lo, hi], p) in &prefix {
                let [mn, mx] = vol.minmax.ranges[b * nc + c];
                let x0 = ((mn as f64 - lo) / (hi - lo) * last)
                    .floor()
                    .clamp(0.0, last) as usize;
                let x1 = ((mx as f64 - lo) / (hi - lo) * last)
                    .ceil()
                    .clamp(0.0, last) as usize;
                if p[x1 + 1] > p[x0] {
                    *o = 1;
                    break;
                }
            }
        }
        let grid = block_grid(&self.ctx, "occupancy", vol.minmax.dims, &occ);
        let fraction = occ.iter().filter(|&&o| o != 0).count() as f64 / occ.len().max(1) as f64;
        self.occupancy = Some((key, grid, fraction));
        self.stats.occupancy_updates += 1;
        Ok(())
    }

    /// Fraction of occupancy blocks the last frame's transfer function left non-empty.
    pub fn occupied_fraction(&self) -> Option<f64> {
        self.occupancy.as_ref().map(|o| o.2)
    }

    pub(crate) fn ensure_targets(&mut self, width: u32, height: u32) -> Result<()> {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| t.width == width && t.height == height && t.path() == self.output_path)
        {
            return Ok(());
        }
        let max = self.ctx.info.limits.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::InvalidParameter(format!(
                "image size {width}x{height}: each side must be 1 to {max}"
            )));
        }
        let shared = self.output_path == OutputPath::Shared;
        let ctx = &self.ctx;
        let d = &ctx.device;
        let tex = |label, format, usage| -> Result<(wgpu::Texture, Option<ExportableMemory>)> {
            let desc = wgpu::TextureDescriptor {
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
            };
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
                ctx.queue.submit([enc.finish()]);
                // Wait: the host may write the depth input through its own API right after
                // this returns, and a clear landing later would wipe it.
                ctx.wait_idle()?;
            }
            Ok(Targets {
                width,
                height,
                state: d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("ray state"),
                    size: PIXEL_STATE_BYTES * width as u64 * height as u64,
                    // (COPY_SRC: Renderer::read_gbuffer reads the isosurface layer counts)
                    usage: wgpu::BufferUsages::STORAGE
                        | wgpu::BufferUsages::COPY_DST
                        | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                color,
                depth,
                depth_in,
                exported,
                generation: self.generation + 1,
            })
        })??;
        self.generation = targets.generation;
        self.targets = Some(targets);
        Ok(())
    }

    pub(crate) fn frame_uniforms(
        &self,
        view: &View,
        params: &RenderParams,
        step: f64,
        depth_input: bool,
        skip: bool,
    ) -> Result<(FrameUniforms, DvrVariant)> {
        let vol = self
            .volume
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no volume has been set".into()))?;
        // Isosurfaces need no transfer function: a placeholder fills its uniforms.
        let placeholder;
        let tf = match self.tf.as_ref() {
            Some(tf) => tf,
            None if params.blend == BlendMode::Isosurface => {
                placeholder = TransferFunction::ramp([0.0, 1.0], 1.0);
                &placeholder
            }
            None => {
                return Err(Error::InvalidParameter(
                    "no transfer function has been set".into(),
                ))
            }
        };
        let aspect = view.aspect();
        let vp = view.camera.view_projection(aspect);
        if !vp.is_finite() || vp.determinant().abs() < 1e-300 {
            return Err(Error::InvalidParameter("the camera gives a singular projection (check position, focal point, view up and clipping range)".into()));
        }
        let index_to_world = params.volume_matrix * vol.index_to_data;
        let world_to_index = index_to_world.inverse();
        let mut u = FrameUniforms::zeroed();
        u.camera = [mat(vp.inverse()), mat(vp)];
        u.world_to_index = mat(world_to_index);
        u.index_to_data = mat(vol.index_to_data);
        u.gradient_to_world = mat(world_to_index.transpose());
        let dd = vol.data_dims;
        u.dims = [
            dd[0] as f32,
            dd[1] as f32,
            dd[2] as f32,
            vol.components as f32,
        ];
        u.scalar_scale = vol.layout.scale;
        u.scalar_shift = vol.layout.shift;
        let mut any_go = false;
        for c in 0..4 {
            let ct = tf.component(c);
            let [lo, hi] = ct.table_range();
            u.tf_lo[c] = lo as f32;
            u.tf_inv_width[c] = (1.0 / (hi - lo)) as f32;
            let [glo, ghi] = ct.gradient_range();
            u.go_lo[c] = glo as f32;
            u.go_inv_width[c] = (1.0 / (ghi - glo)) as f32;
            u.weights[c] = ct.weight;
            u.additive_scale[c] = (step / ct.unit_distance) as f32;
            any_go |= ct.gradient_opacity.is_some() && (c as u32) < vol.components;
        }
        let s = &params.shading;
        u.material = [s.ambient, s.diffuse, s.specular, s.specular_power];
        let mut flags = 0;
        if let Some(c) = &params.cropping {
            u.crop_lo = [
                c.planes[0] as f32,
                c.planes[2] as f32,
                c.planes[4] as f32,
                0.0,
            ];
            u.crop_hi = [
                c.planes[1] as f32,
                c.planes[3] as f32,
                c.planes[5] as f32,
                0.0,
            ];
            u.mode[2] = c.regions;
        }
        u.misc = [
            step as f32,
            params.termination_threshold,
            params.depth_threshold,
            0.0,
        ];
        if let Some(r) = params.average_range {
            flags |= FLAG_AVERAGE_RANGE;
            u.average_range = [r[0] as f32, r[1] as f32, 0.0, 0.0];
        }
        // clipping planes, world → index space: keep dot(n_i, p) + w >= 0
        for (i, p) in params.clip_planes.iter().enumerate() {
            let n = p.normal.normalize();
            let ni = index_to_world.transpose().transform_vector3(n);
            let w = n.dot(index_to_world.transform_point3(DVec3::ZERO) - p.origin);
            u.clip[i] = [ni.x as f32, ni.y as f32, ni.z as f32, w as f32];
        }
        let mut nl = 0;
        if s.enabled {
            for l in view.lights.iter().take(MAX_LIGHTS) {
                let (pos, focal) = l.world_placement(&view.camera);
                let k = l.intensity;
                let g = &mut u.lights[nl];
                if l.positional {
                    g.position = [pos.x as f32, pos.y as f32, pos.z as f32, 1.0];
                    let axis = (focal - pos).try_normalize().unwrap_or(DVec3::NEG_Z);
                    let cone = if l.cone_angle < 90.0 {
                        (l.cone_angle as f64).to_radians().cos() as f32
                    } else {
                        -2.0
                    };
                    g.spot = [axis.x as f32, axis.y as f32, axis.z as f32, cone];
                } else {
                    let dir = (pos - focal).try_normalize().unwrap_or(DVec3::Z);
                    // A headlight shines along each ray (w = 2), as VTK's headlight path
                    // lights every sample from the camera.
                    let w = if l.space == LightSpace::Headlight {
                        2.0
                    } else {
                        0.0
                    };
                    g.position = [dir.x as f32, dir.y as f32, dir.z as f32, w];
                    g.spot = [0.0, 0.0, 0.0, -2.0];
                }
                g.diffuse = [
                    l.diffuse[0] * k,
                    l.diffuse[1] * k,
                    l.diffuse[2] * k,
                    l.exponent,
                ];
                g.specular = [l.specular[0] * k, l.specular[1] * k, l.specular[2] * k, 0.0];
                g.ambient = [l.ambient[0] * k, l.ambient[1] * k, l.ambient[2] * k, 0.0];
                g.attenuation = [l.attenuation[0], l.attenuation[1], l.attenuation[2], 0.0];
                nl += 1;
            }
            if s.two_sided {
                flags |= FLAG_TWO_SIDED;
            }
        }
        if params.jitter {
            flags |= FLAG_JITTER;
        }
        if tf.independent {
            flags |= FLAG_INDEPENDENT;
        }
        if depth_input {
            flags |= FLAG_DEPTH_INPUT;
        }
        // VTK's volumetric shadows: composite, shaded, lit; one component in one brick (the
        // shadow rays read the whole volume from one texture).
        let volumetric = s.enabled
            && s.volumetric_blending > 0.0
            && nl > 0
            && params.blend == BlendMode::Composite;
        if volumetric {
            if vol.bricks.len() != 1 || vol.components != 1 {
                return Err(Error::Unsupported(format!(
                    "volumetric scattering needs a one-component volume in one brick (this one \
                     has {} component(s) in {} brick(s)): turn the scattering blending off",
                    vol.components,
                    vol.bricks.len()
                )));
            }
            let extent = [DVec3::X, DVec3::Y, DVec3::Z]
                .iter()
                .zip(vol.data_dims)
                .map(|(axis, n)| {
                    index_to_world.transform_vector3(*axis).length() * (n.max(2) - 1) as f64
                })
                .fold(0.0, f64::max);
            // VTK: reach = √3 + (m − √3)(1 − R)^0.33 texture units, m the sample distance
            // over the largest extent
            let m = step / extent;
            let root3 = 3f64.sqrt();
            let reach = root3 + (m - root3) * (1.0 - s.global_illumination_reach as f64).powf(0.33);
            let (lo, hi) = vol
                .minmax
                .ranges
                .iter()
                .step_by(vol.components as usize)
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), r| {
                    (lo.min(r[0]), hi.max(r[1]))
                });
            let range = if hi > lo { (hi - lo) as f64 } else { 1.0 };
            u.scatter = [
                s.volumetric_blending,
                s.scattering_anisotropy,
                reach as f32,
                (2.0 / range) as f32,
            ];
        }
        u.viewport = [view.width, view.height, 0, 0x9e37_79b9];
        u.rect = screen_rect(vp, index_to_world, vol.data_dims, view.width, view.height);
        u.mode[0] = params.blend.code();
        u.mode[1] = flags;
        u.counts = [
            params.clip_planes.len() as u32,
            nl as u32,
            BLOCK_SIZE,
            vol.components,
        ];
        u.occupancy_dims = [
            vol.minmax.dims[0],
            vol.minmax.dims[1],
            vol.minmax.dims[2],
            0,
        ];
        let variant = DvrVariant {
            blend: params.blend.code(),
            components: vol.components,
            independent: tf.independent,
            shade: s.enabled,
            gradient_opacity: any_go,
            skip,
            crop: params.cropping.is_some(),
            nearest: params.interpolation == Interpolation::Nearest,
            single_brick: vol.bricks.len() == 1,
            positional_lights: u.lights[..nl].iter().any(|l| l.position[3] == 1.0),
            lights: nl as u32,
            volumetric,
            precomputed_gradient: vol.gradients,
            forward_diff: params.gradient == GradientMethod::Forward,
        };
        Ok((u, variant))
    }

    /// Bricks in front-to-back order for this camera: along each axis, bricks on the
    /// camera's side of a brick boundary come first. For a grid of boxes this order is a
    /// valid visibility order for perspective and parallel projection alike.
    pub(crate) fn brick_order(&self, view: &View, params: &RenderParams) -> Vec<usize> {
        let Some(vol) = self.volume.as_ref() else {
            return vec![];
        };
        let world_to_index = (params.volume_matrix * vol.index_to_data).inverse();
        let cam = world_to_index.transform_point3(view.camera.position);
        let dir = world_to_index.transform_vector3(view.camera.direction());
        let bc = vol.layout.brick_cells as f64;
        let mut order: Vec<usize> = (0..vol.bricks.len()).collect();
        // Per axis, how many brick steps separate a brick from the camera's brick (perspective:
        // a ray's successive bricks have non-decreasing steps on every axis and a strictly
        // larger sum) or how far it lies along the view direction (parallel).
        let key = |e: &BrickExtent| -> [i64; 3] {
            [0, 1, 2].map(|a| {
                let cell = e.cell[a] as i64;
                if view.camera.parallel {
                    if dir[a] >= 0.0 {
                        cell
                    } else {
                        -cell
                    }
                } else {
                    (cell - (cam[a] / bc).floor() as i64).abs()
                }
            })
        };
        order.sort_by_key(|&i| {
            let k = key(&vol.bricks[i].extent);
            k[0] + k[1] + k[2]
        });
        order
    }

    /// Renders one frame and returns once it is submitted; read it with [`Renderer::read_image`]
    /// or, with [`OutputPath::Shared`], wait with [`Renderer::finish`] and sample the shared
    /// images. `depth` (window depth per pixel, rows top to bottom) terminates rays at opaque
    /// geometry.
    pub fn render(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: Option<&[f32]>,
    ) -> Result<()> {
        let source = match depth {
            Some(d) => DepthSource::Cpu(d),
            None => DepthSource::None,
        };
        self.render_from(view, params, source)
    }

    /// Like [`Renderer::render`] with a depth input, but the depth is what the host wrote into
    /// the shared depth-input image ([`SharedOutput::depth_in`], window depth, rows top to
    /// bottom) instead of an upload. Needs [`OutputPath::Shared`] and output images of the
    /// view's size already allocated ([`Renderer::prepare_output`] or an earlier frame); the
    /// host must have finished writing (`glFinish`) before this call.
    pub fn render_with_shared_depth(&mut self, view: &View, params: &RenderParams) -> Result<()> {
        match &self.targets {
            Some(t)
                if t.path() == OutputPath::Shared
                    && self.output_path == OutputPath::Shared
                    && t.width == view.width
                    && t.height == view.height => {}
            Some(t) if t.path() == OutputPath::Shared && self.output_path == OutputPath::Shared => {
                return Err(Error::InvalidParameter(format!(
                    "the shared depth input is {}x{}, the view {}x{}: call \
                     Renderer::prepare_output({}, {}), import the new images and write the \
                     depth into the new depth input first",
                    t.width, t.height, view.width, view.height, view.width, view.height
                )))
            }
            _ => {
                return Err(Error::InvalidParameter(
                    "no shared depth input: switch to OutputPath::Shared and call \
                     Renderer::prepare_output, import SharedOutput::depth_in and write the depth \
                     into it first"
                        .into(),
                ))
            }
        }
        self.render_from(view, params, DepthSource::Shared)
    }

    fn render_from(
        &mut self,
        view: &View,
        params: &RenderParams,
        depth: DepthSource<'_>,
    ) -> Result<()> {
        if params.blend == BlendMode::Isosurface {
            return self.render_isosurface(view, params, depth);
        }
        if params.blend == BlendMode::PathTrace {
            return self.render_pathtrace(view, params, depth);
        }
        params.validate()?;
        if view.lights.len() > MAX_LIGHTS && params.shading.enabled {
            return Err(Error::InvalidParameter(format!(
                "{} lights; at most {MAX_LIGHTS} are supported",
                view.lights.len()
            )));
        }
        let step = self.sample_distance(params)?;
        self.ensure_tables(step)?;
        self.ensure_occupancy(step)?;
        // Skipping costs a block lookup per sample; where nearly every block is occupied
        // (the wavelet under its benchmark transfer function) it cannot pay for itself.
        let occupied = self.occupancy.as_ref().map_or(1.0, |o| o.2);
        let skip = params.empty_space_skipping
            && params.blend == BlendMode::Composite
            && occupied < SKIP_MAX_OCCUPANCY;
        self.ensure_targets(view.width, view.height)?;
        self.write_depth_input(view, depth)?;
        let depth_input = !matches!(depth, DepthSource::None);
        let (u, variant) = self.frame_uniforms(view, params, step, depth_input, skip)?;
        if !self.dvr_variants.contains_key(&variant) {
            let constants = variant.constants();
            let p = self.ctx.checked("creating a ray-casting pipeline", || {
                self.ctx
                    .device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some("dvr"),
                        layout: Some(&self.dvr_layout),
                        module: &self.dvr_module,
                        entry_point: Some("main"),
                        compilation_options: wgpu::PipelineCompilationOptions {
                            constants: &constants,
                            zero_initialize_workgroup_memory: false,
                        },
                        cache: None,
                    })
            })?;
            self.dvr_variants.insert(variant, p);
        }
        let dvr = &self.dvr_variants[&variant];
        let order = self.brick_order(view, params);
        let t = self.targets.as_ref().expect("targets allocated above");
        let vol = self.volume.as_ref().expect("checked in frame_uniforms");
        let (_, tables) = self.tables.as_ref().expect("tables built above");
        let (_, occupancy, _) = self.occupancy.as_ref().expect("occupancy built above");
        let q = &self.ctx.queue;
        let d = &self.ctx.device;
        q.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&u));
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let common = [
            bind(0, self.frame_buf.as_entire_binding()),
            bind(1, wgpu::BindingResource::TextureView(&tables.view)),
            bind(2, t.state.as_entire_binding()),
            bind(5, wgpu::BindingResource::TextureView(&color_view)),
            bind(6, wgpu::BindingResource::TextureView(&depth_view)),
        ];
        let mut dvr_entries = common.to_vec();
        dvr_entries.push(bind(3, wgpu::BindingResource::TextureView(occupancy)));
        dvr_entries.push(bind(4, wgpu::BindingResource::TextureView(&depth_in_view)));
        let dvr_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("dvr frame"),
            layout: &self.dvr_bgl,
            entries: &dvr_entries,
        });
        let resolve_bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.resolve_bgl,
            entries: &common,
        });
        let rect = u.rect;
        let groups = [
            (rect[2] - rect[0]).div_ceil(WORKGROUP),
            (rect[3] - rect[1]).div_ceil(WORKGROUP),
        ];
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        if rect != [0, 0, view.width, view.height] {
            clear_outputs(&mut enc, &color_view, &depth_view);
        }
        if !variant.single_brick {
            enc.clear_buffer(&t.state, 0, None);
        }
        for i in order {
            let b = &vol.bricks[i];
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("dvr"),
                timestamp_writes: None,
            });
            pass.set_pipeline(dvr);
            pass.set_bind_group(0, &dvr_bg, &[]);
            let bg = if params.interpolation == Interpolation::Nearest {
                &b.bind_nearest
            } else {
                &b.bind_linear
            };
            pass.set_bind_group(1, bg, &[]);
            pass.dispatch_workgroups(groups[0], groups[1], 1);
        }
        if !variant.single_brick {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("resolve"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.resolve);
            pass.set_bind_group(0, &resolve_bg, &[]);
            pass.dispatch_workgroups(groups[0], groups[1], 1);
        }
        q.submit([enc.finish()]);
        self.stats.frames += 1;
        Ok(())
    }

    /// The output texture (premultiplied RGBA8) of the last frame.
    pub fn output_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.color)
    }

    /// Chooses where frames go. [`OutputPath::Shared`] needs a device that can export memory
    /// ([`Context::external_memory_support`]); without one this returns that error
    /// ([`Error::Unsupported`], saying why) and the renderer stays on the path it had. The
    /// output images are reallocated at the next frame or [`Renderer::prepare_output`].
    pub fn set_output_path(&mut self, path: OutputPath) -> Result<()> {
        if path == OutputPath::Shared {
            self.ctx.external_memory_support()?;
        }
        self.output_path = path;
        Ok(())
    }

    /// [`Renderer::set_output_path`] with [`OutputPath::Shared`] (`true`) or
    /// [`OutputPath::Readback`] (`false`).
    pub fn set_output_sharing(&mut self, on: bool) -> Result<()> {
        self.set_output_path(if on {
            OutputPath::Shared
        } else {
            OutputPath::Readback
        })
    }

    /// The path chosen with [`Renderer::set_output_path`] (the default is
    /// [`OutputPath::Readback`]).
    pub fn output_path(&self) -> OutputPath {
        self.output_path
    }

    /// Allocates the output images for frames of `width × height` on the current path now
    /// rather than at the next frame, so the host can import them (and write the depth input)
    /// before rendering. Does nothing when they already fit.
    pub fn prepare_output(&mut self, width: u32, height: u32) -> Result<()> {
        self.ensure_targets(width, height)
    }

    /// Counts allocations of the output images: it changes exactly when they are replaced
    /// (a new size, a path switch), i.e. when a host must import them again. 0 before the
    /// first allocation.
    pub fn output_generation(&self) -> u64 {
        self.targets.as_ref().map_or(0, |t| t.generation)
    }

    /// Exports the output images: new file descriptors (the caller owns them) with what
    /// OpenGL needs to import them; see [`crate::interop`] for the protocol. Needs
    /// [`OutputPath::Shared`] and images allocated on it (a frame rendered or
    /// [`Renderer::prepare_output`] called after switching).
    pub fn shared_output(&self) -> Result<SharedOutput> {
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
                 call Renderer::prepare_output(width, height) first"
                    .into(),
            ));
        };
        Ok(SharedOutput {
            generation: t.generation,
            width: t.width,
            height: t.height,
            color: color.export(&self.ctx, &t.color)?,
            depth: depth.export(&self.ctx, &t.depth)?,
            depth_in: depth_in.export(&self.ctx, &t.depth_in)?,
        })
    }

    /// Blocks until the GPU has finished every frame submitted so far. With
    /// [`OutputPath::Shared`] this is the synchronisation with the host: call it after
    /// [`Renderer::render`] and before the host samples the shared images (no semaphores are
    /// shared; Mesa's llvmpipe has no `GL_EXT_semaphore_fd`).
    pub fn finish(&self) -> Result<()> {
        self.ctx.wait_idle()
    }

    /// Checks a CPU depth input (window depth per pixel) against the frame's size and copies
    /// it into the depth-input image; nothing to do for the other sources. The output images
    /// must be allocated for the frame.
    pub(crate) fn write_depth_input(&self, view: &View, depth: DepthSource<'_>) -> Result<()> {
        let DepthSource::Cpu(d) = depth else {
            return Ok(());
        };
        let n = (view.width * view.height) as usize;
        if d.len() != n {
            return Err(Error::InvalidParameter(format!(
                "depth image has {} values for a {}x{} frame ({n} expected)",
                d.len(),
                view.width,
                view.height
            )));
        }
        let t = self
            .targets
            .as_ref()
            .expect("output images allocated for the frame");
        upload_texture(&self.ctx.queue, &t.depth_in, bytemuck::cast_slice(d), 4);
        Ok(())
    }

    /// Waits for the last frame and copies its colour and depth to the CPU.
    pub fn read_image(&self) -> Result<Image> {
        let t = self
            .targets
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("nothing has been rendered yet".into()))?;
        let rgba = read_texture_layer(&self.ctx, &t.color, 0, 0, 4)?;
        let depth_bytes = read_texture_layer(&self.ctx, &t.depth, 0, 0, 4)?;
        let depth = bytemuck::cast_slice::<u8, f32>(&depth_bytes).to_vec();
        Ok(Image {
            width: t.width,
            height: t.height,
            rgba,
            depth,
        })
    }

    /// Renders and reads back in one call.
    pub fn render_image(&mut self, view: &View, params: &RenderParams) -> Result<Image> {
        self.render(view, params, None)?;
        self.read_image()
    }
}
