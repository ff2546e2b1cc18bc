//! What the passes read and write, owned by the renderer and borrowed by each pass for a
//! frame: the volume (bricks, min–max grid, optional gradients), the transfer tables and the
//! occupancy they give, the output images (with their interop export) and the environment.

pub(crate) mod bricks;
pub(crate) mod environment;
pub(crate) mod gradients;
pub(crate) mod intermix;
pub(crate) mod levels;
pub(crate) mod lod;
pub(crate) mod mesh;
pub(crate) mod residency;
pub(crate) mod tables;
pub(crate) mod targets;
pub(crate) mod volume;

use crate::error::{Error, Result};
use crate::gpu::binding::{
    buffer_entry, entry, group_layout, sampled_texture_entry, texture_entry,
};
use crate::gpu::buffers::uniform_buffer;
use crate::gpu::interop::OutputPath;
use crate::gpu::slots;
use crate::gpu::uniforms::FrameUniforms;
use crate::gpu::Context;
use crate::params::{MaskKind, RenderParams, Stats, StreamProgress, TransferFunction};
use environment::EnvironmentState;
use gradients::GradientPass;
use tables::{Occupancy, TableKey, Tables};
use targets::Targets;
use volume::GpuVolume;

/// The renderer's resources. Passes get `&mut Resources` for a frame; each resource is built
/// or rebuilt on demand by its `ensure_*` function when what decides its contents changed.
pub(crate) struct Resources {
    /// Layout of the volume's bind group (group 1 of every pass that samples the volume):
    /// pool uniforms, pool texture, sampler, gradient pool, page table, empty bricks' values,
    /// the bricks a preview frame read from a coarser level (lod.rs).
    pub brick_bgl: wgpu::BindGroupLayout,
    pub nearest: wgpu::Sampler,
    linear: wgpu::Sampler,
    /// The frame uniforms (lib/common.wgsl's Frame), written by each pass.
    pub frame_buf: wgpu::Buffer,
    pub volume: Option<GpuVolume>,
    /// An unstructured volume, drawn instead of `volume` while it is set.
    pub mesh: Option<mesh::gpu::GpuMesh>,
    /// A coarser level of a bricked volume, built when a path-traced frame's bricks exceed
    /// the memory budget (levels.rs).
    pub level: Option<levels::Level>,
    /// Fine points per point of the level the last frame drew (1: the volume itself).
    pub drawn_level: u32,
    /// Per point of the volume's grid, non-zero where it is blanked (r8uint), or none.
    pub blanking: Option<wgpu::TextureView>,
    /// The mask of the current volume (r8uint, one value per point) and what it means.
    pub mask: Option<(wgpu::TextureView, MaskKind)>,
    /// Counts the masks set (and cleared).
    pub mask_generation: u64,
    pub tf: Option<TransferFunction>,
    pub tables: Option<(TableKey, Tables)>,
    /// The 2D tables (Table2D) of the components that have one, built when a frame needs them.
    pub tables_2d: Option<(TableKey, Tables)>,
    /// The pre-integration tables, built when a frame asks for pre-integration.
    pub preintegration: Option<(TableKey, Tables)>,
    /// Occupancy of the min–max blocks under the transfer function.
    pub occupancy: Option<Occupancy<TableKey>>,
    pub targets: Option<Targets>,
    pub output_path: OutputPath,
    /// Counts allocations of the output images.
    pub generation: u64,
    pub environment: EnvironmentState,
    pub stats: Stats,
    /// The gradient build, created when a volume first asks for precomputed gradients.
    gradient_pass: Option<GradientPass>,
    /// Told of each pass of a streamed frame.
    pub progress: Option<StreamProgress>,
    /// Volumes drawn with the main one, intermixed per sample.
    pub intermix: Option<intermix::Intermix>,
    /// Counts the sets of intermixed volumes set (and cleared).
    pub intermix_generation: u64,
}

/// The error of a frame without a volume.
pub(super) fn no_volume() -> Error {
    Error::InvalidParameter("no volume has been set".into())
}

/// The volume's bind group (group 1 of the passes that march it; lib/volume.wgsl).
pub(crate) fn brick_layout_entries() -> [wgpu::BindGroupLayoutEntry; 7] {
    use wgpu::TextureViewDimension as V;
    [
        buffer_entry(slots::POOL, wgpu::BufferBindingType::Uniform),
        texture_entry(slots::VOLUME, true, V::D3),
        entry(
            slots::VOLUME_SAMPLER,
            wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        ),
        texture_entry(slots::GRADIENTS, true, V::D3),
        sampled_texture_entry(slots::PAGE_TABLE, wgpu::TextureSampleType::Uint, V::D3),
        texture_entry(slots::BRICK_CONSTANTS, false, V::D3),
        buffer_entry(
            slots::BRICK_REQUESTS,
            wgpu::BufferBindingType::Storage { read_only: false },
        ),
    ]
}

impl Resources {
    pub fn new(ctx: &Context) -> Resources {
        let d = &ctx.device;
        let brick_bgl = group_layout(d, "brick", &brick_layout_entries());
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
        let frame_buf = uniform_buffer(
            ctx,
            "frame uniforms",
            std::mem::size_of::<FrameUniforms>() as u64,
        );
        Resources {
            brick_bgl,
            linear: sampler(wgpu::FilterMode::Linear),
            nearest: sampler(wgpu::FilterMode::Nearest),
            frame_buf,
            volume: None,
            mesh: None,
            level: None,
            drawn_level: 1,
            tf: None,
            tables: None,
            preintegration: None,
            tables_2d: None,
            blanking: None,
            mask: None,
            mask_generation: 0,
            occupancy: None,
            targets: None,
            output_path: OutputPath::Readback,
            generation: 0,
            environment: EnvironmentState::default(),
            stats: Stats::default(),
            gradient_pass: None,
            progress: None,
            intermix: None,
            intermix_generation: 0,
        }
    }

    /// Forgets what belonged to the volume before a new one (image or mesh): its coarser
    /// level, occupancy, blanking and mask; counts the upload.
    pub fn new_volume_state(&mut self) {
        self.level = None;
        self.occupancy = None;
        self.blanking = None;
        self.mask = None;
        self.mask_generation += 1;
        self.stats.volume_uploads += 1;
    }

    /// The volume, or the error every pass gives without one.
    pub fn volume(&self) -> Result<&GpuVolume> {
        self.volume.as_ref().ok_or_else(no_volume)
    }

    /// The transfer function, or the error every pass that classifies gives without one.
    pub fn transfer_function(&self) -> Result<&TransferFunction> {
        self.tf
            .as_ref()
            .ok_or_else(|| Error::InvalidParameter("no transfer function has been set".into()))
    }

    /// The mask's kind, where one is set.
    pub fn mask_kind(&self) -> Option<MaskKind> {
        self.mask.as_ref().map(|(_, k)| *k)
    }

    /// The world distance between samples these parameters give for the current volume (the
    /// volume itself while a coarser level is drawn).
    pub fn sample_distance(&self, params: &RenderParams) -> Result<f64> {
        let vol = self.fine_volume()?;
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
}
