//! The prepared mesh on the device: storage buffers for points, their gradients,
//! tetrahedra, neighbours, cell scalars, the boundary triangles and their hierarchy
//! (shaders/unstructured.wgsl).
//!
//! Per tetrahedron the device holds 16 bytes of points indices, 16 of neighbours (each split
//! over two bindings where one binding of the device holds fewer) and, with
//! cell scalars, 4 of scalar; per point 32 bytes (position and scalar, gradient); per
//! boundary triangle 4 bytes and about half a 32-byte hierarchy node. A tetrahedral mesh of
//! n tetrahedra has about n / 5 to n / 6 points, so about 38 bytes per tetrahedron.

use super::bvh::BvhNode;
use super::TetMesh;
use crate::error::{Error, Result};
use crate::gpu::uniforms::{
    MeshUniforms, MESH_BVH_STACK, MESH_EVERY_ENTRY, MESH_KNOTS, MESH_OPAQUE_WORDS,
};
use crate::gpu::Context;
use crate::params::{ScalarLocation, UnstructuredVolume};
use crate::resources::Resources;

/// Bytes per tetrahedron of the tetrahedra and neighbours buffers (16 each).
pub(crate) const TET_BYTES: u64 = 16;

pub(crate) struct GpuMesh {
    pub points: wgpu::Buffer,
    pub gradients: wgpu::Buffer,
    /// The tetrahedra and their neighbours, each in two bindings: the first
    /// `uniforms.halves[0]` tetrahedra, and the rest (a placeholder where none are left).
    pub tets: [wgpu::Buffer; 2],
    pub neighbours: [wgpu::Buffer; 2],
    /// One value per tetrahedron (cell scalars), or a placeholder of one.
    pub cell_scalars: wgpu::Buffer,
    pub nodes: wgpu::Buffer,
    pub boundary: wgpu::Buffer,
    pub uniforms: MeshUniforms,
    pub location: ScalarLocation,
    pub components: u32,
    /// Where the device's coordinates are relative to.
    pub origin: [f64; 3],
    pub bounds: [f64; 6],
    /// The scalars' range (NaN left out; [0, 0] without a number).
    pub range: [f32; 2],
}

impl GpuMesh {
    /// The size of a typical cell ([`cell_size`]).
    pub fn cell_size(&self) -> f64 {
        cell_size(self.bounds, self.uniforms.counts[0])
    }
}

/// The size of a typical cell of `tets` tetrahedra in `bounds`: the box's diagonal over the
/// tetrahedra's cube root.
fn cell_size(b: [f64; 6], tets: u32) -> f64 {
    let diagonal = ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
    diagonal / (tets.max(1) as f64).cbrt()
}

/// The least and greatest of `values` that are numbers ([0, 0] where none is).
fn range_of(values: impl Iterator<Item = f32>) -> [f32; 2] {
    let r = values
        .filter(|v| !v.is_nan())
        .fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], v| {
            [lo.min(v), hi.max(v)]
        });
    if r[0] <= r[1] {
        r
    } else {
        [0.0; 2]
    }
}

/// An error when the mesh's `label` of `size` bytes exceed `max`, the most one storage
/// buffer binding holds on the device.
pub(crate) fn check_binding_size(label: &str, size: u64, max: u64) -> Result<()> {
    if size > max {
        return Err(too_large(
            label,
            size,
            &format!("{max} bytes in one storage buffer"),
        ));
    }
    Ok(())
}

fn too_large(label: &str, size: u64, binds: &str) -> Error {
    Error::OutOfMemory(format!(
        "the mesh's {label} take {size} bytes, but this device binds at most {binds} \
         (max_storage_buffer_binding_size): the mesh is too large for it; decimate or split \
         it (the tetrahedra and their neighbours take {TET_BYTES} bytes per tetrahedron, each \
         over two bindings)"
    ))
}

/// How many of `n` tetrahedra the first of their two bindings holds, where one binding
/// holds at most `max` bytes: all of them when they fit, else as many as fit (the rest in
/// the second); an error past two bindings.
pub(crate) fn first_half(n: u64, max: u64) -> Result<u32> {
    let per = max / TET_BYTES;
    if n > 2 * per {
        return Err(too_large(
            "tetrahedra",
            n * TET_BYTES,
            &format!("two storage buffers of {max} bytes"),
        ));
    }
    Ok(n.min(per) as u32)
}

/// A storage buffer holding `data` (at least 16 bytes: an element of any of the mesh's
/// arrays), refused with the sizes when it exceeds
/// what one binding can hold.
fn storage(ctx: &Context, label: &str, data: &[u8]) -> Result<wgpu::Buffer> {
    use wgpu::util::DeviceExt;
    let max = ctx.max_binding_size();
    check_binding_size(label, data.len() as u64, max)?;
    let padded;
    let contents = if data.len() < 16 {
        padded = [0u8; 16];
        &padded[..]
    } else {
        data
    };
    ctx.checked(&format!("allocating the mesh's {label}"), || {
        ctx.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
    })
}

impl GpuMesh {
    pub fn upload(ctx: &Context, m: &TetMesh) -> Result<GpuMesh> {
        if m.bvh.depth > MESH_BVH_STACK {
            return Err(Error::Unsupported(format!(
                "the mesh's boundary hierarchy is {} levels deep; rays search at most {} \
                 (split the mesh)",
                m.bvh.depth, MESH_BVH_STACK
            )));
        }
        use bytemuck::cast_slice as cast;
        let cells: &[f32] = match m.location {
            ScalarLocation::Cells => &m.cell_scalars,
            ScalarLocation::Points => &[0.0],
        };
        let points = storage(ctx, "points", cast::<[f32; 4], u8>(&m.points))?;
        let gradients = storage(ctx, "gradients", cast::<[f32; 4], u8>(&m.point_gradients))?;
        let half = first_half(m.tets.len() as u64, ctx.max_binding_size())?;
        let halves = |label: &str, all: &[[u32; 4]]| -> Result<[wgpu::Buffer; 2]> {
            let (lo, hi) = all.split_at(half as usize);
            Ok([
                storage(ctx, label, cast::<[u32; 4], u8>(lo))?,
                storage(ctx, label, cast::<[u32; 4], u8>(hi))?,
            ])
        };
        let tets = halves("tetrahedra", &m.tets)?;
        let neighbours = halves("neighbours", &m.neighbours)?;
        let cell_scalars = storage(ctx, "cell scalars", cast::<f32, u8>(cells))?;
        let nodes_data: &[BvhNode] = &m.bvh.nodes;
        let nodes = storage(ctx, "boundary hierarchy", cast::<BvhNode, u8>(nodes_data))?;
        let boundary = storage(ctx, "boundary triangles", cast::<u32, u8>(&m.boundary))?;
        let n = m.tets.len() as u32;
        // Steps a ray may take at most: every tetrahedron crossed once per entry, with room
        // for re-entries; bounds the loop where rounding sends a ray back and forth.
        let max_steps = n.saturating_mul(2).saturating_add(64);
        let uniforms = MeshUniforms {
            counts: [
                n,
                m.boundary.len() as u32,
                m.bvh.nodes.len() as u32,
                max_steps,
            ],
            unit: [1.0, 0.0, 0.0, 0.0],
            split: [MESH_EVERY_ENTRY, 0, 0, 0],
            knots: [[0.0; 4]; MESH_KNOTS / 4],
            opaque: [[u32::MAX; 4]; MESH_OPAQUE_WORDS / 4],
            halves: [half, 0, 0, 0],
            shadow: {
                let b = m.bounds;
                let inv = |lo: f64, hi: f64| (1.0 / (hi - lo).max(1e-30)) as f32;
                [
                    inv(b[0], b[1]),
                    inv(b[2], b[3]),
                    inv(b[4], b[5]),
                    cell_size(b, n) as f32,
                ]
            },
        };
        let range = match m.location {
            ScalarLocation::Cells => range_of(m.cell_scalars.iter().copied()),
            ScalarLocation::Points => range_of(m.points.iter().map(|p| p[3])),
        };
        Ok(GpuMesh {
            range,
            points,
            gradients,
            tets,
            neighbours,
            cell_scalars,
            nodes,
            boundary,
            uniforms,
            location: m.location,
            components: m.components,
            origin: m.origin,
            bounds: m.bounds,
        })
    }
}

impl Resources {
    /// Prepares and uploads an unstructured volume, drawn from then on instead of the image
    /// volume, which it replaces (with its level, occupancy, blanking and mask).
    pub fn set_mesh(&mut self, ctx: &Context, v: &UnstructuredVolume) -> Result<()> {
        let prepared = TetMesh::prepare(v)?;
        let mesh = GpuMesh::upload(ctx, &prepared)?;
        self.mesh = Some(mesh);
        self.volume = None;
        self.new_volume_state();
        Ok(())
    }
}
