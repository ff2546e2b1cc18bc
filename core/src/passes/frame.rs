//! What every pass of a frame shares: the frame uniforms (camera, volume transform, tables'
//! ranges, material, lights, clipping, the screen rectangle the volume covers) and the
//! workgroup size.

use crate::error::{Error, Result};
use crate::gpu::uniforms::{
    flag_bits, mat, FrameUniforms, FLAG_AVERAGE_RANGE, FLAG_DEPTH_INPUT, FLAG_EXTREMUM_DEPTH,
    FLAG_INDEPENDENT, FLAG_JITTER, FLAG_PIECE, FLAG_TWO_SIDED,
};
use crate::gpu::Context;
use crate::params::{
    BlendMode, ClipPlane, LightSpace, MaskKind, RenderParams, TransferFunction, View, MAX_LIGHTS,
};
use crate::resources::bricks::{FrontToBack, BLOCK_SIZE};
use crate::resources::intermix::world_box;
use crate::resources::targets::DepthSource;
use crate::resources::Resources;
use bytemuck::Zeroable;
use glam::{DMat4, DVec3};

/// Edge of the square compute workgroups (`@workgroup_size` of the screen-space passes).
/// 8×8 keeps rays in a workgroup coherent; 16×16 measured slower on lavapipe.
pub(crate) const WORKGROUP: u32 = 8;

/// Empty-space skipping is used only when fewer blocks than this fraction are occupied:
/// skipping costs a block lookup per sample, which cannot pay for itself where nearly every
/// block is occupied.
pub(crate) const SKIP_MAX_OCCUPANCY: f64 = 0.9;

/// An error unless the view has at most [`MAX_LIGHTS`] lights.
pub(crate) fn check_light_count(view: &View) -> Result<()> {
    if view.lights.len() > MAX_LIGHTS {
        return Err(Error::InvalidParameter(format!(
            "{} lights; at most {MAX_LIGHTS} are supported",
            view.lights.len()
        )));
    }
    Ok(())
}

/// Workgroups covering the pixel rectangle `r` ([x0, y0, x1, y1)).
pub(crate) fn groups(r: [u32; 4]) -> [u32; 2] {
    [
        (r[2] - r[0]).div_ceil(WORKGROUP),
        (r[3] - r[1]).div_ceil(WORKGROUP),
    ]
}

/// What a pass renders a frame from: the device, the renderer's resources (which the pass
/// builds on demand and borrows for the frame), the view, the render parameters, where
/// the depth input comes from, and whether the frame is drawn or only prepared.
pub(crate) struct FrameInput<'a> {
    pub ctx: &'a Context,
    pub res: &'a mut Resources,
    pub view: &'a View,
    pub params: &'a RenderParams,
    pub depth: DepthSource<'a>,
    pub purpose: Purpose,
}

/// What a pass does with a frame: draws it, or does everything before the drawing (tables,
/// resident bricks, output images, the selected variant's pipelines) and stops
/// ([`crate::Renderer::prepare`]).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Purpose {
    Draw,
    Prepare,
}

impl<'a> FrameInput<'a> {
    /// The fields, for a pass to take apart: (ctx, res, view, params, depth).
    pub fn parts(
        self,
    ) -> (
        &'a Context,
        &'a mut Resources,
        &'a View,
        &'a RenderParams,
        DepthSource<'a>,
    ) {
        (self.ctx, self.res, self.view, self.params, self.depth)
    }
}

/// One frame's uniforms and the facts about it the passes specialise their pipelines on.
pub(crate) struct Frame {
    pub uniforms: FrameUniforms,
    /// Some component has a gradient opacity function.
    pub gradient_opacity: bool,
    /// The components are classified independently.
    pub independent: bool,
    /// VTK's volumetric shadows are on.
    pub volumetric: bool,
}

impl Frame {
    /// Lights the frame carries.
    pub fn lights(&self) -> u32 {
        self.uniforms.light_count
    }

    /// Whether any of them is positional.
    pub fn positional_lights(&self) -> bool {
        positional_lights(&self.uniforms)
    }
}

/// The pixels the index-space box `lo`…`hi` can cover: the bounding rectangle of its
/// projected corners widened by a pixel, as [x0, y0, x1, y1) — or the whole image when a
/// corner lies behind the camera (the camera is inside or beside the box).
pub(crate) fn screen_rect(
    vp: DMat4,
    index_to_world: DMat4,
    lo: impl Into<[f64; 3]>,
    hi: impl Into<[f64; 3]>,
    width: u32,
    height: u32,
) -> [u32; 4] {
    let (lo, hi) = (lo.into(), hi.into());
    let full = [0, 0, width, height];
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for c in 0..8u32 {
        let corner = |a: usize| if c & (1 << a) != 0 { hi[a] } else { lo[a] };
        let ijk = DVec3::new(corner(0), corner(1), corner(2));
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

/// The smallest rectangle ([x0, y0, x1, y1)) holding `a` and `b` (either may be empty).
/// Prepares the intermixed volumes, if any, for a frame at sample distance `step` (their
/// tables, and their uniforms with the world box the rays cross: every volume's, the main
/// one's included) and returns `rect` grown by that box's rectangle on the screen.
pub(crate) fn prepare_intermix(
    ctx: &Context,
    res: &mut Resources,
    params: &RenderParams,
    view: &View,
    step: f64,
    rect: [u32; 4],
) -> Result<[u32; 4]> {
    let vol = res.volume()?;
    let main = world_box(params.volume_matrix * vol.index_to_data, vol.data_dims);
    let Some(m) = res.intermix.as_mut() else {
        return Ok(rect);
    };
    let (lo, hi) = m.world_bounds();
    let (lo, hi) = (lo.min(main.0), hi.max(main.1));
    m.prepare(ctx, step, (lo, hi))?;
    let vp = view.camera.view_projection(view.aspect());
    let r = screen_rect(vp, DMat4::IDENTITY, lo, hi, view.width, view.height);
    Ok(union_rect(rect, r))
}

/// Whether a ray-cast frame draws VTK's volumetric shadows (composite, shaded, lit), whose
/// rays leave the pixels' lines (so it cannot stream; past the budget it draws a coarser
/// level, `levels.rs`).
pub(crate) fn casts_shadows(view: &View, params: &RenderParams) -> bool {
    let s = &params.shading;
    s.enabled
        && s.volumetric_blending > 0.0
        && !view.lights.is_empty()
        && params.blend == BlendMode::Composite
}

/// The volumetric shadows' uniforms (lib/volumetric.wgsl, frame.scatter) of shading `s`:
/// the blending, the anisotropy, VTK's reach √3 + (m − √3)(1 − R)^0.33 in texture units
/// (m the step over the largest extent), and 2 over the data range (`range`: VTK's
/// gradient magnitude scale).
pub(crate) fn scatter_uniforms(s: &crate::params::Shading, m: f64, range: [f32; 2]) -> [f32; 4] {
    let root3 = 3f64.sqrt();
    let reach = root3 + (m - root3) * (1.0 - s.global_illumination_reach as f64).powf(0.33);
    let width = if range[1] > range[0] {
        (range[1] - range[0]) as f64
    } else {
        1.0
    };
    [
        s.volumetric_blending,
        s.scattering_anisotropy,
        reach as f32,
        (2.0 / width) as f32,
    ]
}

pub(crate) fn union_rect(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    let empty = |r: [u32; 4]| r[0] >= r[2] || r[1] >= r[3];
    match (empty(a), empty(b)) {
        (true, _) => b,
        (_, true) => a,
        _ => [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ],
    }
}

/// A world plane in index space as (n_i, w): dot(n_i, p) + w is the world distance to the
/// plane of the point p (index coordinates), for any invertible index → world matrix.
pub(crate) fn index_plane(index_to_world: DMat4, p: &ClipPlane) -> [f32; 4] {
    let n = p.normal.normalize();
    let ni = index_to_world.transpose().transform_vector3(n);
    let w = n.dot(index_to_world.transform_point3(DVec3::ZERO) - p.origin);
    [ni.x as f32, ni.y as f32, ni.z as f32, w as f32]
}

/// The frame uniforms of a frame of `view` with `params` at sample distance `step`, with
/// what the passes specialise on.
pub(crate) fn frame(
    res: &Resources,
    view: &View,
    params: &RenderParams,
    step: f64,
    depth_input: bool,
) -> Result<Frame> {
    let vol = res.volume()?;
    // Isosurfaces need no transfer function: a placeholder fills its uniforms.
    let placeholder;
    let tf = match res.tf.as_ref() {
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
        if let Some(t) = &ct.table_2d {
            u.t2d_lo[c] = t.scalar_range[0] as f32;
            u.t2d_inv_width[c] = (1.0 / (t.scalar_range[1] - t.scalar_range[0])) as f32;
            u.t2d_inv_gmax[c] = t.gradient_max.map_or(0.0, |g| (1.0 / g) as f32);
        }
        u.additive_scale[c] = (step / ct.unit_distance) as f32;
        any_go |= ct.gradient_opacity.is_some() && (c as u32) < vol.components;
    }
    if res.mask_kind() == Some(MaskKind::LabelMap) && vol.components == 1 {
        let ([lo, hi], [glo, ghi]) = tf.label_ranges();
        let max_label = tf.max_label();
        if max_label > 0 {
            u.labels = [
                lo as f32,
                (1.0 / (hi - lo)) as f32,
                glo as f32,
                (1.0 / (ghi - glo)) as f32,
            ];
        }
        u.mask = [params.mask_blend, f32::from(max_label), 0.0, 0.0];
        any_go |= params.mask_blend > 0.0 && tf.labels_gradient_opacity();
    }
    let mut flags = set_lights(&mut u, view, params);
    for (c, m) in u.component_materials.iter_mut().enumerate() {
        *m = tf.component(c).material.unwrap_or(u.material);
    }
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
        u.crop_regions = c.regions;
    }
    u.sample_distance = step as f32;
    u.termination = params.termination_threshold;
    u.depth_threshold = params.depth_threshold;
    if let Some(r) = params.average_range {
        flags |= FLAG_AVERAGE_RANGE;
        u.average_range = [r[0] as f32, r[1] as f32, 0.0, 0.0];
    }
    // clipping planes in index space: keep dot(n_i, p) + w >= 0
    for (i, p) in params.clip_planes.iter().enumerate() {
        u.clip[i] = index_plane(index_to_world, p);
    }
    // the slice plane in index space: dot(n_i, p) + w = 0
    if let (BlendMode::Slice, Some(p)) = (params.blend, params.slice_plane) {
        u.slice = index_plane(index_to_world, &p);
    }
    if let Some(v) = params.clipped_voxel_value {
        // (an infinite value, VTK's default VTK_DOUBLE_MIN, kept finite in f32)
        u.clipped_value = v.map(|x| x.clamp(-f32::MAX as f64, f32::MAX as f64) as f32);
    }
    if let Some([lo, hi]) = params.whole_box {
        u.whole_lo = [lo[0] as f32, lo[1] as f32, lo[2] as f32, 0.0];
        u.whole_hi = [hi[0] as f32, hi[1] as f32, hi[2] as f32, 0.0];
    }
    flags |= flag_bits(&[
        (params.jitter, FLAG_JITTER),
        (tf.independent, FLAG_INDEPENDENT),
        (depth_input, FLAG_DEPTH_INPUT),
        (params.extremum_depth, FLAG_EXTREMUM_DEPTH),
        (params.whole_box.is_some(), FLAG_PIECE),
    ]);
    // VTK's volumetric shadows: one component.
    let volumetric = casts_shadows(view, params);
    if volumetric {
        if vol.components != 1 {
            return Err(Error::Unsupported(format!(
                "volumetric scattering needs a one-component volume (this one has {}): turn \
                 the scattering blending off",
                vol.components
            )));
        }
        let extent = [DVec3::X, DVec3::Y, DVec3::Z]
            .iter()
            .zip(vol.data_dims)
            .map(|(axis, n)| {
                index_to_world.transform_vector3(*axis).length() * (n.max(2) - 1) as f64
            })
            .fold(0.0, f64::max);
        let (lo, hi) = vol
            .minmax
            .ranges
            .iter()
            .step_by(vol.components as usize)
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r[0]), hi.max(r[1]))
            });
        u.scatter = scatter_uniforms(&params.shading, step / extent, [lo, hi]);
    }
    u.width = view.width;
    u.height = view.height;
    u.jitter_seed = 0x9e37_79b9;
    let last = vol.data_dims.map(|d| d as f64 - 1.0);
    u.rect = screen_rect(vp, index_to_world, [0.0; 3], last, view.width, view.height);
    u.blend = params.blend.code();
    u.flags = flags;
    u.clip_planes = params.clip_planes.len() as u32;
    u.block_size = BLOCK_SIZE;
    u.components = vol.components;
    u.occupancy_dims = [
        vol.minmax.dims[0],
        vol.minmax.dims[1],
        vol.minmax.dims[2],
        0,
    ];
    Ok(Frame {
        uniforms: u,
        gradient_opacity: any_go,
        independent: tf.independent,
        volumetric,
    })
}

/// Whether any of the lights `u` carries is positional.
pub(crate) fn positional_lights(u: &FrameUniforms) -> bool {
    u.lights[..u.light_count as usize]
        .iter()
        .any(|l| l.position[3] == 1.0)
}

/// The material and, where the frame is shaded, the view's lights (world placement, colours
/// times intensity) in `u`; returns the flags they set (two-sided lighting).
pub(crate) fn set_lights(u: &mut FrameUniforms, view: &View, params: &RenderParams) -> u32 {
    let s = &params.shading;
    u.material = [s.ambient, s.diffuse, s.specular, s.specular_power];
    let mut nl = 0;
    let mut flags = 0;
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
    u.light_count = nl as u32;
    flags
}

/// The volume's bricks front to back for this view (index space), for streaming.
pub(crate) fn visibility_order(
    res: &Resources,
    view: &View,
    params: &RenderParams,
) -> Result<FrontToBack> {
    let vol = res.volume()?;
    let world_to_index = (params.volume_matrix * vol.index_to_data).inverse();
    Ok(vol.grid.front_to_back(
        world_to_index.transform_point3(view.camera.position),
        world_to_index.transform_vector3(view.camera.direction()),
        view.camera.parallel,
    ))
}

/// Per brick: whether any pixel's ray can reach it, by its box (one cell wider on every
/// side, within the volume) projected on the screen; a brick with a corner behind the
/// camera counts as reached. Rays that stay on their pixel's line (ray casting, the first
/// hit) read no other brick.
pub(crate) fn bricks_in_view(
    res: &Resources,
    view: &View,
    params: &RenderParams,
) -> Result<Vec<bool>> {
    let vol = res.volume()?;
    let vp = view.camera.view_projection(view.aspect());
    let index_to_world = params.volume_matrix * vol.index_to_data;
    let g = &vol.grid;
    let last = vol.data_dims.map(|d| d.max(1) as f64 - 1.0);
    Ok((0..g.len())
        .map(|i| {
            let cell = g.cell(i);
            let b = g.brick_cells as f64;
            let lo: [f64; 3] =
                std::array::from_fn(|a| (cell[a] as f64 * b - 1.0).clamp(0.0, last[a]));
            let hi: [f64; 3] =
                std::array::from_fn(|a| ((cell[a] + 1) as f64 * b + 1.0).clamp(0.0, last[a]));
            let r = screen_rect(vp, index_to_world, lo, hi, view.width, view.height);
            r[0] < r[2] && r[1] < r[3]
        })
        .collect())
}
