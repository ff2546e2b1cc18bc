//! GPU device selection: a hardware adapter first, Mesa's lavapipe (a real Vulkan device on
//! the CPU) otherwise. `FERROVOL_BACKEND` (vulkan, gl, metal, dx12) restricts the backends,
//! `FERROVOL_ADAPTER` picks the first adapter whose name contains the given text
//! (case-insensitive, e.g. `llvmpipe` or `nvidia`).

use super::disk_cache::DiskCache;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Mutex, MutexGuard};

/// What the renderer needs to know about the device it runs on.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
    pub vendor: u32,
    pub device: u32,
    pub limits: wgpu::Limits,
    /// R32Float is filterable (linear sampling of float32 volumes without conversion).
    pub float32_filterable: bool,
    /// R16Unorm / R16Snorm textures (16-bit volumes stored losslessly).
    pub norm16: bool,
    /// GPU timestamp queries inside passes.
    pub timestamps: bool,
}

/// What lives on the device now, from wgpu's own counters (every renderer of the context
/// together): buffers, texture views and bind groups, and the device memory bound to
/// buffers and textures (not counting images exported to a host, whose memory the host
/// owns). Textures are counted by their views and bytes: wgpu's texture count is not kept
/// for textures it creates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceMemory {
    pub buffers: u64,
    pub texture_views: u64,
    pub bind_groups: u64,
    pub buffer_bytes: u64,
    pub texture_bytes: u64,
}

impl DeviceMemory {
    /// Device memory bound to buffers and textures, in bytes.
    pub fn bytes(&self) -> u64 {
        self.buffer_bytes + self.texture_bytes
    }
}

/// The compiled shaders of one device, shared by every renderer on it (a [`Context`] and its
/// clones hold one; the pipeline module fills it): parsed pass files by name, compute
/// pipelines by file, entry point and override constants, and the persistent pipeline
/// cache the driver compiles through ([`DiskCache`]). Compiling is most of a new
/// renderer's first frame, so a renderer made on a device that already drew (another volume
/// in the window, or the same one after its graphics resources were released) compiles only
/// what is new to the device. A cached pipeline keeps the layout of the renderer that
/// compiled it; another renderer's bind groups fit it because a pass builds its bind group
/// layouts from the context alone, and wgpu gives layouts of equal entries one identity on
/// a device.
pub(crate) struct ShaderStore {
    pub(crate) parsed: Mutex<HashMap<&'static str, std::sync::Arc<super::specialise::Parsed>>>,
    pub(crate) pipelines: Mutex<HashMap<PipelineKey, wgpu::ComputePipeline>>,
    pub(crate) disk: Option<DiskCache>,
}

/// A compiled pipeline's identity: its pass file, entry point and override constants (their
/// values' bits).
#[derive(PartialEq, Eq, Hash)]
pub(crate) struct PipelineKey {
    pub(crate) file: &'static str,
    pub(crate) entry: &'static str,
    pub(crate) constants: Vec<(&'static str, u64)>,
}

/// The map behind `m`, also after a thread panicked while holding it (what it held is whole:
/// entries are inserted complete).
pub(crate) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// An adapter, a device and its queue, and the shaders compiled on it. `Send + Sync`; clones
/// share the same device and the same compiled shaders.
#[derive(Clone)]
pub struct Context {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: DeviceInfo,
    /// Set (with the driver's message) when the device is lost.
    lost: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// The device memory (bytes) allocations may reach before they fail as out of memory;
    /// `u64::MAX` for no cap ([`Context::limit_device_memory`]).
    memory_cap: std::sync::Arc<std::sync::atomic::AtomicU64>,
    /// The bytes one storage binding may hold below the device's limit; `u64::MAX` for the
    /// device's own ([`Context::limit_binding_size`]).
    binding_cap: std::sync::Arc<std::sync::atomic::AtomicU64>,
    /// The shader modules and compute pipelines of every renderer on this device.
    pub(crate) shaders: std::sync::Arc<ShaderStore>,
    /// The latest submission to the queue ([`Context::submit`]).
    last_submission: std::sync::Arc<Mutex<Option<wgpu::SubmissionIndex>>>,
    /// Times the host waited for the device ([`Context::device_waits`]).
    waits: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

/// The backend sets to try, in order. Without FERROVOL_BACKEND: the native APIs first and
/// OpenGL only when none of them has an adapter, because initialising wgpu's GL backend
/// (EGL) releases whatever GL context the calling thread had current, which breaks a host
/// such as VTK that creates ferrovol inside its own GL rendering.
fn backends_from_env() -> Result<Vec<wgpu::Backends>> {
    match std::env::var("FERROVOL_BACKEND") {
        Err(_) => Ok(vec![
            wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12,
            wgpu::Backends::GL,
        ]),
        Ok(s) => {
            let mut b = wgpu::Backends::empty();
            for part in s.split(',').map(|p| p.trim().to_ascii_lowercase()) {
                b |= match part.as_str() {
                    "vulkan" | "vk" => wgpu::Backends::VULKAN,
                    "gl" | "gles" | "opengl" => wgpu::Backends::GL,
                    "metal" => wgpu::Backends::METAL,
                    "dx12" | "d3d12" => wgpu::Backends::DX12,
                    other => {
                        return Err(Error::InvalidParameter(format!(
                            "FERROVOL_BACKEND='{s}': unknown backend '{other}' (use vulkan, gl, metal or dx12)"
                        )))
                    }
                };
            }
            Ok(vec![b])
        }
    }
}

fn type_rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

impl Context {
    /// Picks an adapter (environment overrides honoured) and creates a device on it.
    pub fn new() -> Result<Context> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Context> {
        let wanted = std::env::var("FERROVOL_ADAPTER")
            .ok()
            .map(|s| s.to_lowercase());
        let sets = backends_from_env()?;
        let mut adapters = Vec::new();
        let mut backends = wgpu::Backends::empty();
        for set in sets {
            backends |= set;
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
            desc.backends = set;
            adapters = wgpu::Instance::new(desc).enumerate_adapters(set).await;
            if let Some(w) = &wanted {
                adapters.retain(|a| a.get_info().name.to_lowercase().contains(w.as_str()));
            }
            if !adapters.is_empty() {
                break;
            }
        }
        // Hardware first; among equals prefer Vulkan (the path shared with GL interop).
        adapters.sort_by_key(|a| {
            let i = a.get_info();
            (type_rank(i.device_type), i.backend != wgpu::Backend::Vulkan)
        });
        let Some(adapter) = adapters.into_iter().next() else {
            let mut why = format!(" for backends {backends:?}");
            if let Some(w) = wanted {
                why.push_str(&format!(" whose name contains '{w}'"));
            }
            return Err(Error::NoAdapter(why));
        };
        let ai = adapter.get_info();
        let feats = adapter.features();
        let mut required = wgpu::Features::empty();
        for f in [
            wgpu::Features::FLOAT32_FILTERABLE,
            wgpu::Features::TEXTURE_FORMAT_16BIT_NORM,
            wgpu::Features::TIMESTAMP_QUERY,
            wgpu::Features::PIPELINE_CACHE,
        ] {
            if feats.contains(f) {
                required |= f;
            }
        }
        // Ask for everything the adapter has: large volumes need large textures and buffers.
        let limits = adapter.limits();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("ferrovol"),
                required_features: required,
                required_limits: limits.clone(),
                ..Default::default()
            })
            .await
            .map_err(|e| Error::RequestDevice {
                adapter: ai.name.clone(),
                message: e.to_string(),
            })?;
        let info = DeviceInfo {
            name: ai.name.clone(),
            backend: format!("{:?}", ai.backend),
            device_type: format!("{:?}", ai.device_type),
            driver: ai.driver.clone(),
            driver_info: ai.driver_info.clone(),
            vendor: ai.vendor,
            device: ai.device,
            limits: device.limits(),
            float32_filterable: required.contains(wgpu::Features::FLOAT32_FILTERABLE),
            norm16: required.contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM),
            timestamps: required.contains(wgpu::Features::TIMESTAMP_QUERY),
        };
        let lost = std::sync::Arc::new(std::sync::Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if reason != wgpu::DeviceLostReason::Destroyed {
                if let Ok(mut l) = flag.lock() {
                    *l = Some(message);
                }
            }
        });
        let disk = DiskCache::open(&device, &ai);
        Ok(Context {
            adapter,
            device,
            queue,
            info,
            lost,
            memory_cap: std::sync::Arc::new(std::sync::atomic::AtomicU64::new(u64::MAX)),
            binding_cap: std::sync::Arc::new(std::sync::atomic::AtomicU64::new(u64::MAX)),
            shaders: std::sync::Arc::new(ShaderStore {
                parsed: Default::default(),
                pipelines: Default::default(),
                disk,
            }),
            last_submission: Default::default(),
            waits: Default::default(),
        })
    }

    /// Runs `f` and turns any wgpu validation or out-of-memory error it caused into an
    /// [`Error`]; so does an allocation by `f` that takes the context's device memory past the
    /// cap of [`Context::limit_device_memory`] (what `f` made is dropped, as the driver's
    /// failed allocation would be).
    pub fn checked<T>(&self, what: &str, f: impl FnOnce() -> T) -> Result<T> {
        let cap = self.memory_cap.load(std::sync::atomic::Ordering::Relaxed);
        let before = (cap != u64::MAX).then(|| self.device_memory().bytes());
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let val = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let v = pollster::block_on(val.pop());
        let o = pollster::block_on(oom.pop());
        self.check_lost(what)?;
        if let Some(e) = o {
            return Err(Error::OutOfMemory(format!("{what}: {e}")));
        }
        if let Some(before) = before {
            let after = self.device_memory().bytes();
            if after > before && after > cap {
                return Err(Error::OutOfMemory(format!(
                    "{what}: {} bytes more would hold {after} bytes on a device limited to \
                     {cap} bytes",
                    after - before
                )));
            }
        }
        if let Some(e) = v {
            return Err(Error::Gpu(format!("{what}: {e}")));
        }
        Ok(out)
    }

    /// Submits `commands` to the queue: the one way ferrovol submits, so that
    /// [`Context::last_submission`] knows where a frame's work ends.
    pub(crate) fn submit(
        &self,
        commands: impl IntoIterator<Item = wgpu::CommandBuffer>,
    ) -> wgpu::SubmissionIndex {
        let index = self.queue.submit(commands);
        *lock(&self.last_submission) = Some(index.clone());
        index
    }

    /// The latest submission to the queue, by any renderer on this device.
    pub(crate) fn last_submission(&self) -> Option<wgpu::SubmissionIndex> {
        lock(&self.last_submission).clone()
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait_idle(&self) -> Result<()> {
        self.wait_for(None, "waiting for the GPU")
    }

    /// Blocks until the GPU has finished `submission` (None: all submitted work); `what`
    /// names the wait in errors.
    pub(crate) fn wait_for(
        &self,
        submission: Option<wgpu::SubmissionIndex>,
        what: &str,
    ) -> Result<()> {
        self.waits
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let polled = self.device.poll(wgpu::PollType::Wait {
            submission_index: submission,
            timeout: None,
        });
        self.check_lost(what)?;
        polled
            .map(|_| ())
            .map_err(|e| Error::Gpu(format!("{what}: {e}")))
    }

    /// Runs the callbacks of the work the device has finished (mapped readbacks), without
    /// waiting for any; `what` names the poll in errors.
    pub(crate) fn poll(&self, what: &str) -> Result<()> {
        let polled = self.device.poll(wgpu::PollType::Poll);
        self.check_lost(what)?;
        polled
            .map(|_| ())
            .map_err(|e| Error::Gpu(format!("{what}: {e}")))
    }

    /// How many times the host has waited for the device on this context and its clones
    /// (every renderer on it together). Frames wait only where a caller asks for pixels or
    /// results ([`crate::Renderer::read_image`], [`crate::Renderer::finish`],
    /// [`crate::Renderer::wait_for_previous_frame`], the accumulation and its convergence),
    /// and a path-traced frame with a host's depth input (to restart in that frame); besides,
    /// building an environment and allocating the shared output wait once. The count lets
    /// a host or a test see that nothing else did.
    pub fn device_waits(&self) -> u64 {
        self.waits.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// How many compute pipelines (pass variants) have been compiled on this device, by every
    /// renderer on it together ([`crate::Renderer::prepare`] compiles a frame's ahead).
    pub fn compiled_pipelines(&self) -> usize {
        lock(&self.shaders.pipelines).len()
    }

    /// The buffers, textures and device memory the context holds now.
    pub fn device_memory(&self) -> DeviceMemory {
        let hal = self.device.get_internal_counters().hal;
        let read = |c: &wgpu::wgt::InternalCounter| c.read().max(0) as u64;
        DeviceMemory {
            buffers: read(&hal.buffers),
            texture_views: read(&hal.texture_views),
            bind_groups: read(&hal.bind_groups),
            buffer_bytes: read(&hal.buffer_memory),
            texture_bytes: read(&hal.texture_memory),
        }
    }

    /// Loses the device on purpose, as a driver reset or a removed GPU would, so that a host
    /// can test its recovery (the role of WebGL's `WEBGL_lose_context`): the device is
    /// destroyed and every later call on this context, its clones and their renderers fails
    /// with [`Error::DeviceLost`]. A new context works as before.
    pub fn lose_device(&self) {
        if let Ok(mut l) = self.lost.lock() {
            l.get_or_insert_with(|| "the device was lost on request (lose_device)".into());
        }
        self.device.destroy();
    }

    /// Caps the device memory this context (its clones and their renderers together) may
    /// hold, as a device with that much memory would: an allocation that goes past it fails
    /// with [`Error::OutOfMemory`] and leaves what was there before usable. For testing how a
    /// host handles out-of-memory on any device; `None` removes the cap. The renderers' memory
    /// budget for streaming bricks is set apart from this (`RenderParams`).
    pub fn limit_device_memory(&self, bytes: Option<u64>) {
        self.memory_cap.store(
            bytes.unwrap_or(u64::MAX),
            std::sync::atomic::Ordering::Relaxed,
        );
    }

    /// Caps the bytes one storage buffer binding holds, as a device with that limit would
    /// (lavapipe binds 128 MiB, many GPUs 2 or 4 GiB): a mesh whose tetrahedra exceed it
    /// splits them over two bindings, and one past two is refused. For testing how meshes
    /// are laid out on any device; `None` gives the device's own limit back. Applies to
    /// meshes uploaded after the call.
    pub fn limit_binding_size(&self, bytes: Option<u64>) {
        self.binding_cap.store(
            bytes.unwrap_or(u64::MAX),
            std::sync::atomic::Ordering::Relaxed,
        );
    }

    /// The bytes one storage buffer binding may hold: the device's limit, or less
    /// ([`Context::limit_binding_size`]).
    pub fn max_binding_size(&self) -> u64 {
        let cap = self.binding_cap.load(std::sync::atomic::Ordering::Relaxed);
        self.info.limits.max_storage_buffer_binding_size.min(cap)
    }

    /// [`Error::DeviceLost`] once the driver has reported the device lost.
    pub fn check_lost(&self, what: &str) -> Result<()> {
        match self.lost.lock().map(|l| l.clone()) {
            Ok(Some(message)) => Err(Error::DeviceLost(format!("{what}: {message}"))),
            Ok(None) => Ok(()),
            Err(_) => Err(Error::DeviceLost(format!(
                "{what}: the device-lost flag is poisoned"
            ))),
        }
    }
}

impl std::fmt::Display for DeviceInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "adapter:   {}", self.name)?;
        writeln!(f, "backend:   {}", self.backend)?;
        writeln!(f, "type:      {}", self.device_type)?;
        writeln!(f, "driver:    {} {}", self.driver, self.driver_info)?;
        writeln!(
            f,
            "ids:       vendor 0x{:04x} device 0x{:04x}",
            self.vendor, self.device
        )?;
        writeln!(
            f,
            "max 3D texture:     {}",
            self.limits.max_texture_dimension_3d
        )?;
        writeln!(f, "max buffer size:    {}", self.limits.max_buffer_size)?;
        writeln!(
            f,
            "max storage buffer: {}",
            self.limits.max_storage_buffer_binding_size
        )?;
        writeln!(f, "float32 filterable: {}", self.float32_filterable)?;
        writeln!(f, "16-bit norm:        {}", self.norm16)?;
        write!(f, "timestamps:         {}", self.timestamps)
    }
}
