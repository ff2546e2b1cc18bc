//! Bind group layout entries and bind group entries for the compute passes, one set of
//! helpers for every pass (ray casting, isosurfaces, environment maps, path tracing).

/// A layout entry visible to compute shaders.
pub(crate) fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A uniform or storage buffer, bound whole.
pub(crate) fn buffer_entry(
    binding: u32,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// A uniform block of type `T` bound at a dynamic offset (one block per dispatch, see
/// [`super::uniforms::UNIFORM_STRIDE`]).
pub(crate) fn dynamic_uniform_entry<T>(binding: u32) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: std::num::NonZeroU64::new(std::mem::size_of::<T>() as u64),
        },
    )
}

/// The `T`-sized block at the start of `buffer`, for a [`dynamic_uniform_entry`].
pub(crate) fn bind_block<T>(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    bind(
        binding,
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: 0,
            size: std::num::NonZeroU64::new(std::mem::size_of::<T>() as u64),
        }),
    )
}

/// A sampled texture of any sample type (float, uint, …).
pub(crate) fn sampled_texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Texture {
            sample_type,
            view_dimension: dim,
            multisampled: false,
        },
    )
}

/// A sampled float texture.
pub(crate) fn texture_entry(
    binding: u32,
    filterable: bool,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    sampled_texture_entry(binding, wgpu::TextureSampleType::Float { filterable }, dim)
}

/// A write-only storage texture.
pub(crate) fn storage_texture_entry(
    binding: u32,
    format: wgpu::TextureFormat,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: dim,
        },
    )
}

/// A filtering sampler.
pub(crate) fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    entry(
        binding,
        wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
    )
}

pub(crate) fn bind(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

/// A bind group layout of `entries` on `device`.
pub(crate) fn group_layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

/// A bind group entry of a texture view.
pub(crate) fn bind_view(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
    bind(binding, wgpu::BindingResource::TextureView(view))
}
