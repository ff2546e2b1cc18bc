//! Ray casting an unstructured volume (shaders/unstructured.wgsl): one dispatch, one ray per
//! pixel traversing the tetrahedra from face to face (resources/mesh). Composite integrates
//! each segment exactly for the transfer tables as VTK's unstructured ray caster's
//! integrators model it (colour · attenuation emitted, attenuation = opacity / unit
//! distance, scaled by the gradient opacity at the segment's middle); MIP and MinIP take the exact extrema of the linear segments, average and
//! additive the exact integrals of opacity × normalised scalar.

use super::frame::{
    casts_shadows, groups, index_plane, positional_lights, scatter_uniforms, screen_rect,
    set_lights, FrameInput, Purpose,
};
use super::unstructured_variant::{select, UnstructuredFacts, UnstructuredVariant};

use crate::error::{Error, Result};
use crate::gpu::binding::{
    bind, bind_view, buffer_entry, group_layout, storage_texture_entry, texture_entry,
};
use crate::gpu::buffers::{buffer, uniform_buffer};
use crate::gpu::pipeline::{encode_single_group, PipelineCache};
use crate::gpu::slots;
use crate::gpu::uniforms::{
    flag_bits, mat, FrameUniforms, MeshUniforms, FLAG_DEPTH_INPUT, FLAG_EXTREMUM_DEPTH,
    MESH_EVERY_ENTRY, MESH_KNOTS, MESH_OPAQUE_WORDS,
};
use crate::gpu::Context;
use crate::params::{build_tables, ComponentTransfer, ScalarLocation, TABLE_SIZE};
use crate::resources::mesh::gpu::GpuMesh;
use crate::resources::targets::{clear_outputs, DepthSource};
use crate::resources::Resources;
use bytemuck::Zeroable;
use glam::{DMat4, DVec3};

/// The table entries with opacity (`MeshUniforms::opaque`) of a component's transfer.
type OpaqueBits = [[u32; 4]; MESH_OPAQUE_WORDS / 4];

/// The unstructured pass: its pipelines (one per variant) and the mesh's uniforms.
pub(crate) struct UnstructuredPass {
    bgl: wgpu::BindGroupLayout,
    pipelines: PipelineCache<UnstructuredVariant>,
    transfer: MeshTransfer,
}

/// A mesh pass's mesh uniforms (lib/mesh.wgsl: Mesh) and the opaque entries of the last
/// transfer function it wrote (rebuilt only when that changes).
pub(crate) struct MeshTransfer {
    buf: wgpu::Buffer,
    opaque: Option<(ComponentTransfer, OpaqueBits)>,
    /// The opacity row's running integral (lib/mesh.wgsl `depth_prefix`), written with it.
    depth: wgpu::Buffer,
}

impl MeshTransfer {
    pub fn new(ctx: &Context) -> MeshTransfer {
        let buf = uniform_buffer(
            ctx,
            "mesh uniforms",
            std::mem::size_of::<MeshUniforms>() as u64,
        );
        let depth = buffer(
            ctx,
            "mesh opacity integral",
            (TABLE_SIZE * 4) as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        MeshTransfer {
            buf,
            opaque: None,
            depth,
        }
    }

    /// `opaque_entries` of `ct`, from the last frame's when its transfer is the same (the
    /// opacity row's running integral written then).
    fn opaque_bits(&mut self, ctx: &Context, ct: &ComponentTransfer) -> OpaqueBits {
        match &self.opaque {
            Some((last, bits)) if last == ct => *bits,
            _ => {
                let row = opacity_row(ct);
                let bits = opaque_entries(&row);
                ctx.queue.write_buffer(
                    &self.depth,
                    0,
                    bytemuck::cast_slice(&running_integral(&row)),
                );
                self.opaque = Some((ct.clone(), bits));
                bits
            }
        }
    }

    /// The mesh's uniforms for the transfer `ct` (its unit distance, knots and opaque
    /// entries), written to the buffer.
    pub fn write(&mut self, ctx: &Context, mesh: &GpuMesh, ct: &ComponentTransfer) {
        let mut mu = mesh.uniforms;
        mu.unit[0] = (1.0 / ct.unit_distance) as f32;
        set_knots(&mut mu, ct);
        mu.opaque = self.opaque_bits(ctx, ct);
        ctx.queue
            .write_buffer(&self.buf, 0, bytemuck::bytes_of(&mu));
    }

    /// The mesh's uniforms for a pass that walks it without its transfer function.
    pub fn write_walk(&self, ctx: &Context, mesh: &GpuMesh) {
        ctx.queue
            .write_buffer(&self.buf, 0, bytemuck::bytes_of(&mesh.uniforms));
    }

    /// The mesh's bindings (lib/mesh.wgsl).
    pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 11] {
        use wgpu::BufferBindingType as B;
        let read = B::Storage { read_only: true };
        [
            buffer_entry(slots::MESH, B::Uniform),
            buffer_entry(slots::MESH_POINTS, read),
            buffer_entry(slots::MESH_TETS, read),
            buffer_entry(slots::MESH_TETS_HI, read),
            buffer_entry(slots::MESH_NEIGHBOURS, read),
            buffer_entry(slots::MESH_NEIGHBOURS_HI, read),
            buffer_entry(slots::MESH_CELL_SCALARS, read),
            buffer_entry(slots::MESH_NODES, read),
            buffer_entry(slots::MESH_BOUNDARY, read),
            buffer_entry(slots::MESH_GRADIENTS, read),
            buffer_entry(slots::MESH_DEPTH, read),
        ]
    }

    /// What they bind.
    pub fn entries<'a>(&'a self, mesh: &'a GpuMesh) -> [wgpu::BindGroupEntry<'a>; 11] {
        [
            bind(slots::MESH, self.buf.as_entire_binding()),
            bind(slots::MESH_POINTS, mesh.points.as_entire_binding()),
            bind(slots::MESH_TETS, mesh.tets[0].as_entire_binding()),
            bind(slots::MESH_TETS_HI, mesh.tets[1].as_entire_binding()),
            bind(
                slots::MESH_NEIGHBOURS,
                mesh.neighbours[0].as_entire_binding(),
            ),
            bind(
                slots::MESH_NEIGHBOURS_HI,
                mesh.neighbours[1].as_entire_binding(),
            ),
            bind(
                slots::MESH_CELL_SCALARS,
                mesh.cell_scalars.as_entire_binding(),
            ),
            bind(slots::MESH_NODES, mesh.nodes.as_entire_binding()),
            bind(slots::MESH_BOUNDARY, mesh.boundary.as_entire_binding()),
            bind(slots::MESH_GRADIENTS, mesh.gradients.as_entire_binding()),
            bind(slots::MESH_DEPTH, self.depth.as_entire_binding()),
        ]
    }
}

impl UnstructuredPass {
    /// The bind group of unstructured.wgsl.
    pub fn layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        use wgpu::BufferBindingType as B;
        use wgpu::TextureViewDimension as V;
        [
            buffer_entry(slots::FRAME, B::Uniform),
            texture_entry(slots::TABLES, false, V::D2),
            texture_entry(slots::DEPTH_IN, false, V::D2),
            storage_texture_entry(slots::OUT_COLOR, wgpu::TextureFormat::Rgba8Unorm, V::D2),
            storage_texture_entry(slots::OUT_DEPTH, wgpu::TextureFormat::R32Float, V::D2),
        ]
        .into_iter()
        .chain(MeshTransfer::layout_entries())
        .collect()
    }

    pub fn new(ctx: &Context) -> Result<UnstructuredPass> {
        let bgl = group_layout(&ctx.device, "unstructured", &Self::layout_entries());
        let pipelines = PipelineCache::new(ctx, "unstructured.wgsl", "unstructured", &[&bgl])?;
        Ok(UnstructuredPass {
            bgl,
            pipelines,
            transfer: MeshTransfer::new(ctx),
        })
    }

    /// One frame of the renderer's mesh.
    pub fn render(&mut self, input: FrameInput<'_>) -> Result<()> {
        let purpose = input.purpose;
        let (ctx, res, view, params, depth) = input.parts();
        params.validate()?;
        let tf = res.transfer_function()?.clone();
        let mesh = res.mesh.as_ref().ok_or_else(crate::resources::no_volume)?;
        let ct = tf.component(0);
        let u = frame_uniforms(res, view, params, !matches!(depth, DepthSource::None))?;
        let variant = select(&UnstructuredFacts {
            blend: params.blend,
            components: mesh.components,
            cell_scalars: mesh.location == ScalarLocation::Cells,
            shade: params.shading.enabled,
            lights: u.light_count,
            positional_lights: positional_lights(&u),
            gradient_opacity: ct.gradient_opacity.is_some(),
            tables_2d: ct.table_2d.is_some(),
            cropping: params.cropping.is_some(),
            average_range: params.average_range.is_some(),
            whole_box: params.whole_box.is_some(),
            volumetric: casts_shadows(view, params),
            depth_range: matches!(depth, DepthSource::Range(..)),
            intermix: res.intermix.is_some(),
            hybrid: false,
            iso_scattering: false,
        })
        .map_err(Error::from)?;
        res.ensure_tables(ctx, 1.0)?;
        res.ensure_targets(ctx, view.width, view.height)?;
        res.write_depth_input(ctx, view, depth)?;
        let pipeline = self.pipelines.get(ctx, variant)?;
        if purpose == Purpose::Prepare {
            return Ok(());
        }
        let mesh = res.mesh.as_ref().expect("checked above");
        let t = res.targets.as_ref().expect("targets allocated above");
        let (_, tables) = res.tables.as_ref().expect("tables built above");
        ctx.queue
            .write_buffer(&res.frame_buf, 0, bytemuck::bytes_of(&u));
        self.transfer.write(ctx, mesh, ct);
        let depth_in_view = t.depth_in.create_view(&Default::default());
        let color_view = t.color.create_view(&Default::default());
        let depth_view = t.depth.create_view(&Default::default());
        let entries: Vec<_> = [
            bind(slots::FRAME, res.frame_buf.as_entire_binding()),
            bind_view(slots::TABLES, &tables.view),
            bind_view(slots::DEPTH_IN, &depth_in_view),
            bind_view(slots::OUT_COLOR, &color_view),
            bind_view(slots::OUT_DEPTH, &depth_view),
        ]
        .into_iter()
        .chain(self.transfer.entries(mesh))
        .collect();
        let rect = u.rect;
        let gr = groups(rect);
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("unstructured frame"),
            });
        if rect != [0, 0, view.width, view.height] {
            clear_outputs(&mut enc, &color_view, &depth_view);
        }
        encode_single_group(
            ctx,
            &mut enc,
            "unstructured",
            (&self.bgl, &pipeline),
            &entries,
            [gr[0], gr[1], 1],
        );
        ctx.submit([enc.finish()]);
        res.stats.frames += 1;
        Ok(())
    }
}

/// The table coordinates where a segment's pieces end (the colour's and opacity's points,
/// where the opacity crosses 0 or 1, which the tables clamp it to, and the tables' ends),
/// or every entry when there are more than [`MESH_KNOTS`].
fn set_knots(mu: &mut MeshUniforms, ct: &ComponentTransfer) {
    let [lo, hi] = ct.table_range();
    let last = (TABLE_SIZE - 1) as f64;
    let op = &ct.opacity.points;
    let crossings = op.windows(2).flat_map(|w| {
        let ((x0, [a0]), (x1, [a1])) = (w[0], w[1]);
        [0.0, 1.0].into_iter().filter_map(move |l: f64| {
            let (a0, a1) = (a0 as f64, a1 as f64);
            ((a0 - l) * (a1 - l) < 0.0).then(|| x0 + (l - a0) / (a1 - a0) * (x1 - x0))
        })
    });
    let mut knots: Vec<f32> = ct
        .color
        .points
        .iter()
        .map(|p| p.0)
        .chain(op.iter().map(|p| p.0))
        .chain(crossings)
        .map(|s| (s - lo) / (hi - lo) * last)
        .filter(|x| *x > 0.0 && *x < last)
        .chain([0.0, last])
        .map(|x| x as f32)
        .collect();
    knots.sort_by(f32::total_cmp);
    knots.dedup();
    if knots.len() > MESH_KNOTS {
        mu.split[0] = MESH_EVERY_ENTRY;
        return;
    }
    mu.split[0] = knots.len() as u32;
    for (i, k) in knots.into_iter().enumerate() {
        mu.knots[i / 4][i % 4] = k;
    }
}

/// The opacity row of the tables the mesh passes read (row 1 of `build_tables`).
fn opacity_row(ct: &ComponentTransfer) -> Vec<f32> {
    build_tables(ct, 1.0)[TABLE_SIZE..2 * TABLE_SIZE]
        .iter()
        .map(|e| e[0])
        .collect()
}

/// The table entries whose opacity is above 0: a tetrahedron whose scalars reach none of
/// them adds nothing to a composite, and the shader skips its integral.
fn opaque_entries(row: &[f32]) -> OpaqueBits {
    let mut bits = [[0; 4]; MESH_OPAQUE_WORDS / 4];
    for (i, a) in row.iter().enumerate() {
        if *a > 0.0 {
            bits[i / 128][i / 32 % 4] |= 1 << (i % 32);
        }
    }
    bits
}

/// ∫₀ⁱ of the row at each entry i (entry units; linear between entries), summed in f64.
fn running_integral(row: &[f32]) -> Vec<f32> {
    let mut sum = 0.0f64;
    let mut out = Vec::with_capacity(row.len());
    for (i, a) in row.iter().enumerate() {
        if i > 0 {
            sum += 0.5 * (row[i - 1] as f64 + *a as f64);
        }
        out.push(sum as f32);
    }
    out
}

/// The frame uniforms of a frame of the renderer's mesh: the camera, the mesh's coordinates
/// (relative to its centre) as the index space, the first component's table range (where a
/// transfer function is set), the material and lights, the clipping planes and the pixels
/// the mesh's box covers.
pub(crate) fn frame_uniforms(
    res: &Resources,
    view: &crate::params::View,
    params: &crate::params::RenderParams,
    depth_input: bool,
) -> Result<FrameUniforms> {
    let mesh = res.mesh.as_ref().ok_or_else(crate::resources::no_volume)?;
    let vp = view.camera.view_projection(view.aspect());
    if !vp.is_finite() || vp.determinant().abs() < 1e-300 {
        return Err(Error::InvalidParameter("the camera gives a singular projection (check position, focal point, view up and clipping range)".into()));
    }
    let index_to_world = params.volume_matrix * DMat4::from_translation(DVec3::from(mesh.origin));
    let world_to_index = index_to_world.inverse();
    let mut u = FrameUniforms::zeroed();
    u.camera = [mat(vp.inverse()), mat(vp)];
    u.world_to_index = mat(world_to_index);
    u.index_to_data = mat(DMat4::from_translation(DVec3::from(mesh.origin)));
    u.gradient_to_world = mat(world_to_index.transpose());
    u.dims = [1.0, 1.0, 1.0, 1.0];
    u.scalar_scale = [1.0; 4];
    u.weights[0] = 1.0;
    // (the isosurfaces read none)
    if let Some(tf) = res.tf.as_ref() {
        let ct = tf.component(0);
        let [lo, hi] = ct.table_range();
        u.tf_lo[0] = lo as f32;
        u.tf_inv_width[0] = (1.0 / (hi - lo)) as f32;
        let [glo, ghi] = ct.gradient_range();
        u.go_lo[0] = glo as f32;
        u.go_inv_width[0] = (1.0 / (ghi - glo)) as f32;
        u.weights[0] = ct.weight;
    }
    u.termination = params.termination_threshold;
    u.depth_threshold = params.depth_threshold;
    for (i, p) in params.clip_planes.iter().enumerate() {
        u.clip[i] = index_plane(index_to_world, p);
    }
    u.width = view.width;
    u.height = view.height;
    let b = mesh.bounds;
    let o = mesh.origin;
    u.rect = screen_rect(
        vp,
        index_to_world,
        [b[0] - o[0], b[2] - o[1], b[4] - o[2]],
        [b[1] - o[0], b[3] - o[1], b[5] - o[2]],
        view.width,
        view.height,
    );
    u.blend = params.blend.code();
    u.flags = set_lights(&mut u, view, params)
        | flag_bits(&[
            (depth_input, FLAG_DEPTH_INPUT),
            (params.extremum_depth, FLAG_EXTREMUM_DEPTH),
        ]);
    u.clip_planes = params.clip_planes.len() as u32;
    u.components = 1;
    if casts_shadows(view, params) {
        // (the reach in the mesh's box mapped to the unit cube, a typical cell's size the
        // step)
        let extent = (0..3).map(|a| b[2 * a + 1] - b[2 * a]).fold(0.0, f64::max);
        let m = mesh.cell_size() / extent.max(1e-30);
        u.scatter = scatter_uniforms(&params.shading, m, mesh.range);
    }
    Ok(u)
}
