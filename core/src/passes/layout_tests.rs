//! Each pass's bind group layouts (Rust) against the bindings its WGSL declares (naga's
//! reflection of the composed module), without a device: every binding an entry point uses
//! is in the layout with the same kind, and every layout entry is declared by the shader.

use super::{
    denoise::DenoisePass, depth_check::DepthCheck, dvr::DvrPass, iso::IsoPass,
    pathtrace::PathTracePass, scatter_check, unstructured::UnstructuredPass,
};
use crate::gpu::shaders;
use crate::resources::{brick_layout_entries, environment::EnvPipelines, gradients::GradientPass};
use std::collections::BTreeMap;

/// What a binding is, as both sides can say it.
#[derive(Debug, PartialEq, Eq)]
enum Kind {
    Uniform,
    Storage {
        read_only: bool,
    },
    Texture {
        sample: &'static str,
        dim: wgpu::TextureViewDimension,
    },
    StorageTexture {
        format: wgpu::TextureFormat,
        dim: wgpu::TextureViewDimension,
    },
    Sampler,
}

fn rust_kind(ty: &wgpu::BindingType) -> Kind {
    use wgpu::BindingType as T;
    match *ty {
        T::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            ..
        } => Kind::Uniform,
        T::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            ..
        } => Kind::Storage { read_only },
        T::Texture {
            sample_type,
            view_dimension,
            ..
        } => Kind::Texture {
            sample: match sample_type {
                wgpu::TextureSampleType::Float { .. } => "float",
                wgpu::TextureSampleType::Uint => "uint",
                wgpu::TextureSampleType::Sint => "sint",
                wgpu::TextureSampleType::Depth => "depth",
            },
            dim: view_dimension,
        },
        T::StorageTexture {
            format,
            view_dimension,
            ..
        } => Kind::StorageTexture {
            format,
            dim: view_dimension,
        },
        T::Sampler(_) => Kind::Sampler,
        ref other => panic!("no pass binds {other:?}"),
    }
}

fn wgsl_kind(m: &naga::Module, var: &naga::GlobalVariable) -> Kind {
    use naga::{ImageClass, ImageDimension as D, TypeInner};
    use wgpu::TextureViewDimension as V;
    match var.space {
        naga::AddressSpace::Uniform => return Kind::Uniform,
        naga::AddressSpace::Storage { access } => {
            return Kind::Storage {
                read_only: !access.contains(naga::StorageAccess::STORE),
            }
        }
        _ => {}
    }
    match &m.types[var.ty].inner {
        TypeInner::Sampler { .. } => Kind::Sampler,
        TypeInner::Image {
            dim,
            arrayed,
            class,
        } => {
            let dim = match (dim, arrayed) {
                (D::D1, false) => V::D1,
                (D::D2, false) => V::D2,
                (D::D2, true) => V::D2Array,
                (D::D3, false) => V::D3,
                (D::Cube, false) => V::Cube,
                (D::Cube, true) => V::CubeArray,
                other => panic!("no pass declares an image of {other:?}"),
            };
            match class {
                ImageClass::Sampled { kind, .. } => Kind::Texture {
                    sample: match kind {
                        naga::ScalarKind::Float => "float",
                        naga::ScalarKind::Uint => "uint",
                        naga::ScalarKind::Sint => "sint",
                        other => panic!("no pass samples {other:?} textures"),
                    },
                    dim,
                },
                ImageClass::Depth { .. } => Kind::Texture {
                    sample: "depth",
                    dim,
                },
                ImageClass::Storage { format, .. } => Kind::StorageTexture {
                    format: match format {
                        naga::StorageFormat::Rgba8Unorm => wgpu::TextureFormat::Rgba8Unorm,
                        naga::StorageFormat::R32Float => wgpu::TextureFormat::R32Float,
                        naga::StorageFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
                        naga::StorageFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
                        other => panic!("add the storage format {other:?} to this test"),
                    },
                    dim,
                },
                other => panic!("no pass declares {other:?} images"),
            }
        }
        other => panic!("a resource of type {other:?}"),
    }
}

/// Checks `entry` of pass `file` against its layouts (`groups[g]` is group g).
fn check(file: &str, entry: &str, groups: &[Vec<wgpu::BindGroupLayoutEntry>]) {
    let m = naga::front::wgsl::parse_str(&shaders::compose(file)).expect("WGSL parses");
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&m)
    .expect("WGSL validates");
    let index = m.entry_points.iter().position(|e| e.name == entry);
    let used = info.get_entry_point(index.unwrap_or_else(|| panic!("{file} has no {entry}")));
    let mut declared = BTreeMap::new();
    for (h, var) in m.global_variables.iter() {
        let Some(rb) = &var.binding else { continue };
        let name = var.name.clone().unwrap_or_default();
        let kind = wgsl_kind(&m, var);
        let layout = groups
            .get(rb.group as usize)
            .and_then(|g| g.iter().find(|e| e.binding == rb.binding));
        match layout {
            Some(e) => assert_eq!(
                rust_kind(&e.ty),
                kind,
                "{file}: `{name}` at group {} binding {} differs from its Rust layout entry",
                rb.group,
                rb.binding
            ),
            None if !used[h].is_empty() => panic!(
                "{file} {entry}: `{name}` (group {}, binding {}) has no Rust layout entry",
                rb.group, rb.binding
            ),
            None => {}
        }
        declared.insert((rb.group, rb.binding), name);
    }
    for (g, entries) in groups.iter().enumerate() {
        for e in entries {
            assert!(
                declared.contains_key(&(g as u32, e.binding)),
                "{file}: the Rust layout of group {g} has binding {} that the WGSL does not \
                 declare",
                e.binding
            );
        }
    }
}

#[test]
fn every_pass_binds_what_its_wgsl_declares() {
    let brick = brick_layout_entries().to_vec();
    for filterable in [true, false] {
        check(
            "dvr.wgsl",
            "main",
            &[DvrPass::layout_entries(filterable), brick.clone()],
        );
        let pt = PathTracePass::layout_entries(filterable);
        check("pathtrace.wgsl", "main", &[pt, brick.clone()]);
    }
    check(
        "firsthit.wgsl",
        "main",
        &[IsoPass::firsthit_layout_entries(), brick.clone()],
    );
    check(
        "deferred.wgsl",
        "main",
        &[IsoPass::deferred_layout_entries(), brick],
    );
    check(
        "unstructured.wgsl",
        "main",
        &[UnstructuredPass::layout_entries()],
    );
    check(
        "firsthit_mesh.wgsl",
        "main",
        &[IsoPass::mesh_firsthit_layout_entries()],
    );
    check(
        "pathtrace_mesh.wgsl",
        "main",
        &[PathTracePass::mesh_layout_entries()],
    );
    check(
        "pathtrace_show.wgsl",
        "main",
        &[PathTracePass::show_layout_entries().to_vec()],
    );
    check(
        "denoise.wgsl",
        "main",
        &[DenoisePass::layout_entries().to_vec()],
    );
    check(
        "depth_changed.wgsl",
        "main",
        &[DepthCheck::layout_entries().to_vec()],
    );
    check(
        "gradient.wgsl",
        "main",
        &[GradientPass::layout_entries().to_vec()],
    );
    check(
        "phase_test.wgsl",
        "main",
        &[scatter_check::layout_entries().to_vec()],
    );
    for (entry, entries) in EnvPipelines::layouts() {
        check("environment.wgsl", entry, &[entries]);
    }
}
