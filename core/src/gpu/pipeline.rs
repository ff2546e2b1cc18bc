//! Shader modules and compute pipelines: the one way ferrovol creates them, kept per device
//! ([`super::context::ShaderStore`]) and specialised by pipeline-overridable constants.

use super::context::{lock, PipelineKey};
use super::specialise::{self, Parsed};
use super::Context;
use crate::error::Result;
use std::hash::Hash;
use std::sync::Arc;

/// Pass `file` composed ([`super::shaders::compose`]), parsed and validated, the first time
/// the device needs it ([`super::context::ShaderStore`]).
pub(crate) fn parsed_shader(ctx: &Context, file: &'static str) -> Result<Arc<Parsed>> {
    if let Some(p) = lock(&ctx.shaders.parsed).get(file) {
        return Ok(p.clone());
    }
    let parsed = Arc::new(specialise::parse(file, &super::shaders::compose(file))?);
    Ok(lock(&ctx.shaders.parsed)
        .entry(file)
        .or_insert(parsed)
        .clone())
}

/// The shader module of one variant of pass `file` ([`specialise::specialise`]), created
/// without wgpu's injected bounds checks and loop counters: those cost a clamp per access
/// and a counter per loop iteration, a large share of the frame time on lavapipe.
///
/// SAFETY of that, for every pass: the shaders index only within bounds they establish
/// themselves (pixel indices behind the viewport or rectangle test, table indices from a
/// clamped coordinate, occupancy and texel coordinates clamped to their grids, iso indices
/// clamped to MAX_ISO, G-buffer layers below the layer count the textures were made with,
/// the cone table indexed modulo its length), and every loop advances toward a bound (ray
/// steps, bisection steps, samples, lights, components, bounces).
fn variant_module(
    ctx: &Context,
    file: &'static str,
    entry: &str,
    constants: &[(&'static str, f64)],
) -> Result<wgpu::ShaderModule> {
    let module = specialise::specialise(file, &*parsed_shader(ctx, file)?, entry, constants)?;
    ctx.checked(&format!("compiling shader {file}"), || {
        let desc = wgpu::ShaderModuleDescriptor {
            label: Some(file),
            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module)),
        };
        // SAFETY: see the function's documentation.
        unsafe {
            ctx.device
                .create_shader_module_trusted(desc, wgpu::ShaderRuntimeChecks::unchecked())
        }
    })
}

/// A pipeline layout of `groups` bind group layouts.
pub(crate) fn pipeline_layout(
    ctx: &Context,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    ctx.device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &groups,
            immediate_size: 0,
        })
}

/// The compute pipeline of pass `file`'s `entry` with these override constants, compiled with
/// `layout` the first time the device needs it ([`super::context::ShaderStore`]).
pub(crate) fn compute_pipeline(
    ctx: &Context,
    label: &str,
    layout: &wgpu::PipelineLayout,
    file: &'static str,
    entry: &'static str,
    constants: &[(&'static str, f64)],
) -> Result<wgpu::ComputePipeline> {
    let key = PipelineKey {
        file,
        entry,
        constants: constants.iter().map(|&(n, v)| (n, v.to_bits())).collect(),
    };
    if let Some(p) = lock(&ctx.shaders.pipelines).get(&key) {
        return Ok(p.clone());
    }
    let module = variant_module(ctx, file, entry, constants)?;
    let pipeline = ctx.checked(&format!("creating the {label} pipeline"), || {
        ctx.device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[],
                    // no pass uses workgroup memory
                    zero_initialize_workgroup_memory: false,
                },
                cache: ctx.shaders.disk.as_ref().map(|d| &d.cache),
            })
    })?;
    if let Some(disk) = &ctx.shaders.disk {
        disk.save();
    }
    Ok(lock(&ctx.shaders.pipelines)
        .entry(key)
        .or_insert(pipeline)
        .clone())
}

/// The override constants of one specialisation of a pass (its `override` declarations).
pub(crate) trait Variant: Copy + Eq + Hash {
    fn constants(&self) -> Vec<(&'static str, f64)>;
}

/// A field's value as an override constant: booleans 1 or 0, counts as they are.
pub(crate) trait OverrideValue {
    fn value(self) -> f64;
}

impl OverrideValue for bool {
    fn value(self) -> f64 {
        if self {
            1.0
        } else {
            0.0
        }
    }
}

impl OverrideValue for u32 {
    fn value(self) -> f64 {
        self as f64
    }
}

/// Declares a pass's pipeline variant: a struct with one field per override constant
/// (`field: type => "WGSL_NAME"`) and its [`Variant`] implementation.
macro_rules! pipeline_variant {
    ($(#[$meta:meta])* $vis:vis struct $name:ident {
        $($(#[$fmeta:meta])* $field:ident: $ty:ty => $wgsl:literal,)*
    }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis struct $name {
            $($(#[$fmeta])* $vis $field: $ty,)*
        }

        impl $crate::gpu::pipeline::Variant for $name {
            fn constants(&self) -> Vec<(&'static str, f64)> {
                use $crate::gpu::pipeline::OverrideValue;
                vec![$(($wgsl, self.$field.value()),)*]
            }
        }
    };
}
pub(crate) use pipeline_variant;

/// A pass's pipelines, one per variant, compiled on the device's first use of each
/// ([`super::context::ShaderStore`]).
pub(crate) struct PipelineCache<K> {
    file: &'static str,
    label: &'static str,
    layout: wgpu::PipelineLayout,
    variant: std::marker::PhantomData<K>,
}

impl<K: Variant> PipelineCache<K> {
    pub fn new(
        ctx: &Context,
        file: &'static str,
        label: &'static str,
        groups: &[&wgpu::BindGroupLayout],
    ) -> Result<PipelineCache<K>> {
        // compiled here, so that a broken shader fails the pass's creation
        parsed_shader(ctx, file)?;
        Ok(PipelineCache {
            file,
            label,
            layout: pipeline_layout(ctx, file, groups),
            variant: std::marker::PhantomData,
        })
    }

    /// The pipeline of variant `v`.
    pub fn get(&self, ctx: &Context, v: K) -> Result<wgpu::ComputePipeline> {
        compute_pipeline(
            ctx,
            self.label,
            &self.layout,
            self.file,
            "main",
            &v.constants(),
        )
    }
}

/// A pass of one bind group (`entries`) running `file`'s `main`: its bind group layout and
/// compute pipeline (the small passes: resolve, gradient build, denoiser, sampling checks).
pub(crate) fn single_group_pipeline(
    ctx: &Context,
    file: &'static str,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> Result<(wgpu::BindGroupLayout, wgpu::ComputePipeline)> {
    let bgl = ctx
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries,
        });
    let layout = pipeline_layout(ctx, file, &[&bgl]);
    let pipeline = compute_pipeline(ctx, label, &layout, file, "main", &[])?;
    Ok((bgl, pipeline))
}

/// Records a compute pass of `pipeline` with one bind group (`entries` for `layout`) over
/// `groups` workgroups.
pub(crate) fn encode_single_group(
    ctx: &Context,
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    (layout, pipeline): (&wgpu::BindGroupLayout, &wgpu::ComputePipeline),
    entries: &[wgpu::BindGroupEntry<'_>],
    groups: [u32; 3],
) {
    let bg = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries,
    });
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, &bg, &[]);
    pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
}
