//! What a frame is seen through ([`View`]), how a volume is uploaded ([`UploadOptions`]),
//! and what comes back ([`Image`], [`Stats`]).

use super::camera::Camera;
use super::light::Light;

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
    /// Largest brick edge in points (apron included); `None` = the device's 3D texture
    /// limit. A volume larger than this along some axis is cut into bricks stored in a
    /// pool texture that every pass samples through a page table.
    pub max_brick_points: Option<u32>,
    /// Most bytes the volume may take on the device (its texture, or the brick pool with
    /// any precomputed gradients); `None` = the device's single-allocation limit. A volume
    /// larger than this is bricked and only the bricks a frame needs are resident; when
    /// even they do not fit, ray casting and isosurfaces stream them through the pool, front
    /// to back, in several passes of one frame; path tracing, volumetric shadows, ambient
    /// occlusion and scattering between isosurfaces, whose rays go anywhere, draw the finest
    /// coarser level that fits ([`VolumeData::downsampled`](crate::VolumeData::downsampled), reported by
    /// [`Residency::level`]).
    pub memory_budget: Option<u64>,
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
    /// Bricks read into the pool of a bricked volume.
    pub brick_uploads: u32,
    /// Passes of streamed frames (frames whose bricks exceed the memory budget take one
    /// pass per group of bricks the pool holds).
    pub streamed_passes: u32,
    /// Times the path tracer's accumulation started over (anything it converges to
    /// changed, or the first frame).
    pub accumulation_restarts: u32,
    /// Builds of the pre-integration tables (when the transfer function or the step
    /// changed under pre-integration).
    pub preintegration_builds: u32,
}

/// Called after each pass of a streamed frame is submitted: (passes so far, passes in the
/// frame).
pub type StreamProgress = Box<dyn FnMut(u32, u32) + Send>;

/// How much of the volume is on the device: bricks resident against all bricks, and the
/// pool's bytes (volume texture and precomputed gradients) against what the whole volume
/// would take. A volume that fits one texture is one brick, always resident.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Residency {
    pub bricks: u32,
    pub resident: u32,
    /// Bytes of the pools on the device: the volume's and a coarser level's.
    pub pool_bytes: u64,
    pub dense_bytes: u64,
    /// Fine points per point, along each axis, of the level the last frame drew: 1 for the
    /// volume itself; 2, 4, … when the bricks of a frame whose rays go anywhere (path
    /// tracing, volumetric shadows, ambient occlusion, scattering between isosurfaces)
    /// exceed the memory budget and it drew a level downsampled that much (the finest that
    /// fits).
    pub level: u32,
    /// That level's points per axis.
    pub level_dims: [u32; 3],
    /// Bricks the last frame's rays read from a coarser level standing in for them: a
    /// preview frame ([`super::RenderParams::preview_level`]) of ray casting past the budget
    /// draws the fine bricks it has and a coarser level's where they are missing, and brings
    /// some of those for the next; 0 when every sample came from the volume itself.
    pub stand_ins: u32,
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
    /// Pixel (x, y) as premultiplied RGBA in [0, 1].
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let i = 4 * (y * self.width + x) as usize;
        [0, 1, 2, 3].map(|c| self.rgba[i + c] as f32 / 255.0)
    }
}
