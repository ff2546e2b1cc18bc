//! Sharing the output with another graphics API without a copy: the renderer allocates its
//! output images in Vulkan external memory (`VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD`) and
//! hands out file descriptors that OpenGL imports with `GL_EXT_memory_object_fd`.
//!
//! What the host does (OpenGL, once per [`SharedTargets::generation`]):
//!
//! 1. compare [`Context::device_uuids`] with GL's device UUIDs
//!    (`glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, i)` for i below `GL_NUM_DEVICE_UUIDS_EXT`)
//!    and `glGetUnsignedBytevEXT(GL_DRIVER_UUID_EXT)`; import only when the device is one of
//!    GL's and the drivers are equal, whether the device is a GPU or a CPU;
//! 2. per image of [`Renderer::shared_targets`](crate::Renderer::shared_targets):
//!    `glCreateMemoryObjectsEXT`, `glMemoryObjectParameterivEXT(GL_DEDICATED_MEMORY_OBJECT_EXT,
//!    GL_TRUE)` (the allocations are dedicated), `glImportMemoryFdEXT(mem, size,
//!    GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd)`, then on a new texture
//!    `glTexParameteri(GL_TEXTURE_TILING_EXT, GL_OPTIMAL_TILING_EXT)` and
//!    `glTexStorageMem2DEXT(GL_TEXTURE_2D, 1, gl_internal_format, width, height, mem, 0)`.
//!
//! Per frame: [`Renderer::render`](crate::Renderer::render), then
//! [`Renderer::finish`](crate::Renderer::finish) before GL samples the colour and depth. That
//! CPU wait is the synchronisation: no semaphores are exported (docs/ARCHITECTURE.md says what
//! wgpu 30 lacks for that and why it stays so). Likewise, GL must be done with the images
//! (`glFinish`) before the next `render`, and done writing the depth input before
//! [`Renderer::render_with_shared_depth`](crate::Renderer::render_with_shared_depth).
//!
//! No image layout transitions or queue family transfers are made for the other API: the
//! images stay in whatever layout wgpu last used. That changes nothing where layouts do not
//! change the memory (lavapipe/llvmpipe, where this is tested); on a GPU the host relies on
//! its GL reading the images as they are, which comparing them with
//! [`Renderer::read_image`](crate::Renderer::read_image) checks there.
//!
//! Row 0 of every image is the top row of the frame (wgpu's convention); GL's texture row 0
//! is its bottom row, so the host flips when it draws.
//!
//! Ownership: each call of `shared_targets` makes new file descriptors (`vkGetMemoryFdKHR`),
//! owned by the caller as [`OwnedFd`](std::os::fd::OwnedFd). `glImportMemoryFdEXT` takes an
//! fd over when it succeeds (pass `fd.into_raw_fd()` and do not close it); an fd that is not
//! imported is closed when dropped. The renderer keeps its own reference to the memory and
//! frees it when the images are replaced (a new size, sharing switched) or the renderer is
//! dropped; memory imported elsewhere stays alive until that side deletes its memory object,
//! so after a generation change the host deletes its old textures and memory objects.

use crate::error::{Error, Result};
use crate::gpu::Context;

/// Identifies a device across APIs: `VkPhysicalDeviceIDProperties::deviceUUID` and
/// `driverUUID`, to compare with OpenGL's `GL_DEVICE_UUID_EXT` and `GL_DRIVER_UUID_EXT`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DeviceUuids {
    pub device: [u8; 16],
    pub driver: [u8; 16],
}

/// Where frames go.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum OutputPath {
    /// Ordinary GPU memory; the host reads frames with
    /// [`Renderer::read_image`](crate::Renderer::read_image).
    #[default]
    Readback,
    /// Exportable memory another API imports
    /// ([`Renderer::shared_targets`](crate::Renderer::shared_targets)); `read_image` still works.
    Shared,
}

/// One output image in exportable memory.
#[derive(Debug)]
pub struct SharedImage {
    /// A new descriptor of the image's memory, `VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD`
    /// (`GL_HANDLE_TYPE_OPAQUE_FD_EXT`). Yours: give it to `glImportMemoryFdEXT` with
    /// `into_raw_fd()` (GL closes it), or drop it (closes it).
    #[cfg(unix)]
    pub fd: std::os::fd::OwnedFd,
    /// Size of the allocation in bytes: the `size` argument of `glImportMemoryFdEXT`.
    pub size: u64,
    pub width: u32,
    pub height: u32,
    pub format: wgpu::TextureFormat,
    /// The `internalFormat` for `glTexStorageMem2DEXT` (`GL_RGBA8` or `GL_R32F`).
    pub gl_internal_format: u32,
    /// The image has its own allocation (`VkMemoryDedicatedAllocateInfo`); set
    /// `GL_DEDICATED_MEMORY_OBJECT_EXT` to `GL_TRUE` before importing. Always true.
    pub dedicated: bool,
}

/// The renderer's output images, exported.
#[derive(Debug)]
pub struct SharedTargets {
    /// Changes whenever the images are reallocated (size changed, sharing switched on);
    /// when it differs from the one imported, delete the old GL objects and import again.
    pub generation: u64,
    pub width: u32,
    pub height: u32,
    /// Premultiplied RGBA8 (`Rgba8Unorm`, `GL_RGBA8`), rows top to bottom.
    pub color: SharedImage,
    /// Window depth of the volume per pixel (`R32Float`, `GL_R32F`; 1 where nothing was hit).
    pub depth: SharedImage,
    /// Depth of opaque geometry the rays stop at (`R32Float`, `GL_R32F`), written by the host
    /// and used by [`Renderer::render_with_shared_depth`](crate::Renderer::render_with_shared_depth).
    pub depth_in: SharedImage,
}

/// `GL_RGBA8`
pub const GL_RGBA8: u32 = 0x8058;
/// `GL_R32F`
pub const GL_R32F: u32 = 0x822E;

/// The GL internal format with the same texel layout as `format`, for the formats the
/// renderer shares.
pub fn gl_internal_format(format: wgpu::TextureFormat) -> Option<u32> {
    match format {
        wgpu::TextureFormat::Rgba8Unorm => Some(GL_RGBA8),
        wgpu::TextureFormat::R32Float => Some(GL_R32F),
        _ => None,
    }
}

impl Context {
    /// `Ok` when the renderer can put its output in memory other APIs import (Vulkan backend,
    /// Vulkan 1.1 or later, `VK_KHR_external_memory_fd` enabled on the device); otherwise
    /// [`Error::Unsupported`] saying what is missing.
    pub fn external_memory_support(&self) -> Result<()> {
        imp::support(self)
    }

    /// Whether [`Context::external_memory_support`] is `Ok`.
    pub fn can_export_memory(&self) -> bool {
        self.external_memory_support().is_ok()
    }

    /// The device and driver UUIDs (Vulkan only; [`Error::Unsupported`] elsewhere).
    pub fn device_uuids(&self) -> Result<DeviceUuids> {
        imp::device_uuids(self)
    }
}

/// The exportable memory behind a texture made by [`create_exportable_texture`]. Only valid
/// while that texture lives: the texture owns the memory and wgpu frees it with the texture.
pub(crate) struct ExportableMemory {
    /// The `VkDeviceMemory` handle.
    #[cfg_attr(not(target_os = "linux"), allow(dead_code))]
    memory: u64,
    /// Allocation size in bytes.
    size: u64,
}

impl ExportableMemory {
    /// Exports the memory of `texture` (the one it was made with) as a fresh fd.
    pub fn export(&self, ctx: &Context, texture: &wgpu::Texture) -> Result<SharedImage> {
        let format = texture.format();
        Ok(SharedImage {
            #[cfg(unix)]
            fd: imp::memory_fd(ctx, self.memory)?,
            size: self.size,
            width: texture.width(),
            height: texture.height(),
            format,
            gl_internal_format: gl_internal_format(format).unwrap_or(0),
            dedicated: true,
        })
    }
}

/// Creates a 2D, single-sample, single-mip texture in exportable memory: a `VkImage` with
/// `VkExternalMemoryImageCreateInfo(OPAQUE_FD)` and optimal tiling, bound to a dedicated
/// allocation made with `VkExportMemoryAllocateInfo`, wrapped into a wgpu texture that owns
/// both. Its contents are undefined: clear it before use.
pub(crate) fn create_exportable_texture(
    ctx: &Context,
    desc: &wgpu::TextureDescriptor,
) -> Result<(wgpu::Texture, ExportableMemory)> {
    if desc.dimension != wgpu::TextureDimension::D2
        || desc.mip_level_count != 1
        || desc.sample_count != 1
        || desc.size.depth_or_array_layers != 1
        || !desc.view_formats.is_empty()
        || gl_internal_format(desc.format).is_none()
    {
        return Err(Error::InvalidParameter(format!(
            "exportable textures are 2D, one mip level, one sample, one layer and Rgba8Unorm \
             or R32Float ({:?} asked for)",
            desc
        )));
    }
    imp::create(ctx, desc)
}

#[cfg(target_os = "linux")]
mod imp {
    use super::{DeviceUuids, ExportableMemory};
    use crate::error::{Error, Result};
    use crate::gpu::Context;
    use ash::vk;
    use std::os::fd::{FromRawFd, OwnedFd};
    use wgpu::hal::api::Vulkan;
    use wgpu::hal::vulkan;

    const HANDLE: vk::ExternalMemoryHandleTypeFlags = vk::ExternalMemoryHandleTypeFlags::OPAQUE_FD;

    fn unsupported(what: impl Into<String>) -> Error {
        Error::Unsupported(format!(
            "{}; the output can only be read back (Renderer::read_image)",
            what.into()
        ))
    }

    /// Runs `f` on wgpu-hal's Vulkan device, or says the backend is not Vulkan.
    fn with_device<T>(ctx: &Context, f: impl FnOnce(&vulkan::Device) -> Result<T>) -> Result<T> {
        // SAFETY: the guard is only used to read handles and call Vulkan functions that
        // create, query and export objects of our own; nothing wgpu tracks is destroyed.
        let hal = unsafe { ctx.device.as_hal::<Vulkan>() };
        match hal {
            Some(d) => f(&d),
            None => Err(unsupported(format!(
                "external memory needs the Vulkan backend, the device runs on {} \
                 (unset FERROVOL_BACKEND or set it to vulkan)",
                ctx.info.backend
            ))),
        }
    }

    /// The Vulkan version both the instance and the physical device support.
    fn api_version(d: &vulkan::Device) -> u32 {
        let inst = d.shared_instance();
        // SAFETY: the physical device belongs to this instance, which outlives the call.
        let props = unsafe {
            inst.raw_instance()
                .get_physical_device_properties(d.raw_physical_device())
        };
        props.api_version.min(inst.instance_api_version())
    }

    fn check(d: &vulkan::Device) -> Result<()> {
        let v = api_version(d);
        if v < vk::API_VERSION_1_1 {
            return Err(unsupported(format!(
                "external memory needs Vulkan 1.1 (VK_KHR_external_memory, dedicated \
                 allocations), the device offers {}.{}",
                vk::api_version_major(v),
                vk::api_version_minor(v)
            )));
        }
        if !d
            .enabled_device_extensions()
            .contains(&ash::khr::external_memory_fd::NAME)
        {
            return Err(unsupported(
                "the Vulkan driver lacks VK_KHR_external_memory_fd (not enabled on the device)",
            ));
        }
        Ok(())
    }

    pub fn support(ctx: &Context) -> Result<()> {
        with_device(ctx, check)
    }

    pub fn device_uuids(ctx: &Context) -> Result<DeviceUuids> {
        with_device(ctx, |d| {
            let v = api_version(d);
            if v < vk::API_VERSION_1_1 {
                return Err(Error::Unsupported(
                    "device UUIDs need Vulkan 1.1 (VkPhysicalDeviceIDProperties)".into(),
                ));
            }
            let mut id = vk::PhysicalDeviceIDProperties::default();
            let mut props = vk::PhysicalDeviceProperties2::default().push_next(&mut id);
            // SAFETY: Vulkan 1.1 is supported by instance and device (checked above); the
            // chain holds one structure that outlives the call.
            unsafe {
                d.shared_instance()
                    .raw_instance()
                    .get_physical_device_properties2(d.raw_physical_device(), &mut props)
            };
            Ok(DeviceUuids {
                device: id.device_uuid,
                driver: id.driver_uuid,
            })
        })
    }

    /// The Vulkan usage flags wgpu gives an image with these usages (wgpu-hal's
    /// `conv::map_texture_usage` of wgpu-core's mapping), and the hal usage itself.
    fn usages(
        usage: wgpu::TextureUsages,
        format: wgpu::TextureFormat,
    ) -> (vk::ImageUsageFlags, wgpu::TextureUses) {
        use wgpu::TextureUsages as U;
        let mut vk_usage = vk::ImageUsageFlags::empty();
        let mut hal = wgpu::TextureUses::empty();
        use vk::ImageUsageFlags as Vk;
        use wgpu::TextureUses as Hal;
        for (wanted, vk_flag, hal_flag) in [
            (U::COPY_SRC, Vk::TRANSFER_SRC, Hal::COPY_SRC),
            (U::COPY_DST, Vk::TRANSFER_DST, Hal::COPY_DST),
            (U::TEXTURE_BINDING, Vk::SAMPLED, Hal::RESOURCE),
            (
                U::RENDER_ATTACHMENT,
                Vk::COLOR_ATTACHMENT,
                Hal::COLOR_TARGET,
            ),
        ] {
            if usage.contains(wanted) {
                vk_usage |= vk_flag;
                hal |= hal_flag;
            }
        }
        if usage.contains(U::STORAGE_BINDING) {
            vk_usage |= vk::ImageUsageFlags::STORAGE;
            hal |= wgpu::TextureUses::STORAGE_WRITE_ONLY;
            if format == wgpu::TextureFormat::R32Float {
                hal |= wgpu::TextureUses::STORAGE_READ_ONLY | wgpu::TextureUses::STORAGE_READ_WRITE;
            }
        }
        (vk_usage, hal)
    }

    fn vk_format(format: wgpu::TextureFormat) -> vk::Format {
        match format {
            wgpu::TextureFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
            _ => vk::Format::R32_SFLOAT,
        }
    }

    fn vk_err(what: &str, e: vk::Result) -> Error {
        match e {
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
                Error::OutOfMemory(format!("{what}: {e}"))
            }
            vk::Result::ERROR_DEVICE_LOST => Error::DeviceLost(format!("{what}: {e}")),
            _ => Error::Gpu(format!("{what}: {e}")),
        }
    }

    pub fn create(
        ctx: &Context,
        desc: &wgpu::TextureDescriptor,
    ) -> Result<(wgpu::Texture, ExportableMemory)> {
        let (vk_usage, hal_usage) = usages(desc.usage, desc.format);
        let format = vk_format(desc.format);
        let extent = vk::Extent3D {
            width: desc.size.width,
            height: desc.size.height,
            depth: 1,
        };
        let label = desc.label.unwrap_or("exported");
        let (hal_texture, memory, size) = with_device(ctx, |d| {
            check(d)?;
            let raw = d.raw_device();
            let inst = d.shared_instance().raw_instance();
            let phd = d.raw_physical_device();

            // Can this format and usage be exported at all?
            let mut ext_info =
                vk::PhysicalDeviceExternalImageFormatInfo::default().handle_type(HANDLE);
            let info = vk::PhysicalDeviceImageFormatInfo2::default()
                .format(format)
                .ty(vk::ImageType::TYPE_2D)
                .tiling(vk::ImageTiling::OPTIMAL)
                .usage(vk_usage)
                .push_next(&mut ext_info);
            let mut ext_props = vk::ExternalImageFormatProperties::default();
            let mut props = vk::ImageFormatProperties2::default().push_next(&mut ext_props);
            // SAFETY: Vulkan 1.1 (checked); both chains are local and outlive the call.
            unsafe { inst.get_physical_device_image_format_properties2(phd, &info, &mut props) }
                .map_err(|e| {
                    unsupported(format!(
                        "{:?} images with {vk_usage:?} cannot be exported as opaque fds ({e})",
                        desc.format
                    ))
                })?;
            let features = ext_props
                .external_memory_properties
                .external_memory_features;
            if !features.contains(vk::ExternalMemoryFeatureFlags::EXPORTABLE) {
                return Err(unsupported(format!(
                    "the driver cannot export {:?} images as opaque fds (features {features:?})",
                    desc.format
                )));
            }

            let mut external = vk::ExternalMemoryImageCreateInfo::default().handle_types(HANDLE);
            let image_info = vk::ImageCreateInfo::default()
                .image_type(vk::ImageType::TYPE_2D)
                .format(format)
                .extent(extent)
                .mip_levels(1)
                .array_layers(1)
                .samples(vk::SampleCountFlags::TYPE_1)
                .tiling(vk::ImageTiling::OPTIMAL)
                .usage(vk_usage)
                .sharing_mode(vk::SharingMode::EXCLUSIVE)
                .initial_layout(vk::ImageLayout::UNDEFINED)
                .push_next(&mut external);
            // SAFETY: a valid create info on our device; the image is destroyed below on
            // every error path and otherwise owned by the wgpu texture.
            let image = unsafe { raw.create_image(&image_info, None) }
                .map_err(|e| vk_err("creating an exportable image", e))?;
            // SAFETY: `image` was just created on this device.
            let req = unsafe { raw.get_image_memory_requirements(image) };
            // SAFETY: the physical device belongs to this instance.
            let mem_props = unsafe { inst.get_physical_device_memory_properties(phd) };
            let allowed = |i: usize| req.memory_type_bits & (1 << i) != 0;
            let types = mem_props.memory_types_as_slice();
            let index = (0..types.len())
                .find(|&i| {
                    allowed(i)
                        && types[i]
                            .property_flags
                            .contains(vk::MemoryPropertyFlags::DEVICE_LOCAL)
                })
                .or_else(|| (0..types.len()).find(|&i| allowed(i)));
            let Some(index) = index else {
                // SAFETY: unused image of ours.
                unsafe { raw.destroy_image(image, None) };
                return Err(unsupported("no memory type can hold an exportable image"));
            };
            let mut export = vk::ExportMemoryAllocateInfo::default().handle_types(HANDLE);
            let mut dedicated = vk::MemoryDedicatedAllocateInfo::default().image(image);
            let alloc = vk::MemoryAllocateInfo::default()
                .allocation_size(req.size)
                .memory_type_index(index as u32)
                .push_next(&mut export)
                .push_next(&mut dedicated);
            // SAFETY: a valid allocate info naming our image; freed below on error, else
            // owned by the wgpu texture.
            let memory = match unsafe { raw.allocate_memory(&alloc, None) } {
                Ok(m) => m,
                Err(e) => {
                    // SAFETY: unused image of ours.
                    unsafe { raw.destroy_image(image, None) };
                    return Err(vk_err("allocating exportable memory", e));
                }
            };
            // SAFETY: the memory was allocated for this image (dedicated, its size and type).
            if let Err(e) = unsafe { raw.bind_image_memory(image, memory, 0) } {
                // SAFETY: unused objects of ours, the image first as it refers to the memory.
                unsafe {
                    raw.destroy_image(image, None);
                    raw.free_memory(memory, None);
                }
                return Err(vk_err("binding exportable memory", e));
            }
            let hal_desc = wgpu::hal::TextureDescriptor {
                label: Some(label),
                size: desc.size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: desc.format,
                usage: hal_usage,
                memory_flags: wgpu::hal::MemoryFlags::empty(),
                view_formats: vec![],
            };
            // SAFETY: the image was created from `hal_desc` (2D, one mip, one sample, the
            // format's Vulkan equivalent, the usages wgpu derives from `desc.usage`) without
            // MUTABLE_FORMAT and with no view formats. With no drop callback and dedicated
            // memory, wgpu-hal owns both and destroys the image and frees the memory when
            // the texture is destroyed.
            let texture = unsafe {
                d.texture_from_raw(
                    image,
                    &hal_desc,
                    None,
                    vulkan::TextureMemory::Dedicated(memory),
                )
            };
            Ok((texture, memory, req.size))
        })?;
        // SAFETY: the hal texture was created on this device from a descriptor equal to
        // `desc`. It is reported as initialized to wgpu; the renderer clears it before any
        // read. It starts in VK_IMAGE_LAYOUT_UNDEFINED, which UNINITIALIZED stands for.
        let texture = unsafe {
            ctx.device.create_texture_from_hal::<Vulkan>(
                hal_texture,
                desc,
                wgpu::TextureUses::UNINITIALIZED,
            )
        };
        let memory = ExportableMemory {
            memory: vk::Handle::as_raw(memory),
            size,
        };
        Ok((texture, memory))
    }

    pub fn memory_fd(ctx: &Context, memory: u64) -> Result<OwnedFd> {
        with_device(ctx, |d| {
            check(d)?;
            let ext = ash::khr::external_memory_fd::Device::new(
                d.shared_instance().raw_instance(),
                d.raw_device(),
            );
            let info = vk::MemoryGetFdInfoKHR::default()
                .memory(<vk::DeviceMemory as vk::Handle>::from_raw(memory))
                .handle_type(HANDLE);
            // SAFETY: the extension is enabled on this device (checked); the memory was
            // allocated on it with an export of this handle type and is alive (its texture
            // is held by the caller).
            let fd = unsafe { ext.get_memory_fd(&info) }
                .map_err(|e| vk_err("exporting memory (vkGetMemoryFdKHR)", e))?;
            if fd < 0 {
                return Err(Error::Gpu(format!("vkGetMemoryFdKHR returned fd {fd}")));
            }
            // SAFETY: vkGetMemoryFdKHR returns a new descriptor the application owns.
            Ok(unsafe { OwnedFd::from_raw_fd(fd) })
        })
    }
}

#[cfg(not(target_os = "linux"))]
mod imp {
    use super::{DeviceUuids, ExportableMemory};
    use crate::error::{Error, Result};
    use crate::gpu::Context;

    fn unsupported() -> Error {
        Error::Unsupported(
            "exporting the output as Vulkan external memory (opaque fd) is implemented on \
             Linux only; the output can only be read back (Renderer::read_image)"
                .into(),
        )
    }

    pub fn support(_: &Context) -> Result<()> {
        Err(unsupported())
    }

    pub fn device_uuids(_: &Context) -> Result<DeviceUuids> {
        Err(unsupported())
    }

    pub fn create(
        _: &Context,
        _: &wgpu::TextureDescriptor,
    ) -> Result<(wgpu::Texture, ExportableMemory)> {
        Err(unsupported())
    }

    #[cfg(unix)]
    pub fn memory_fd(_: &Context, _: u64) -> Result<std::os::fd::OwnedFd> {
        Err(unsupported())
    }
}
