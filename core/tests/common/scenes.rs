//! Test volumes, transfer functions and render settings.

use ferrovol_core::*;
use glam::DVec3;

/// A single-component float volume with unit spacing, `f` evaluated at index coordinates.
pub fn volume(dims: [u32; 3], f: impl Fn(f64, f64, f64) -> f64) -> VolumeData {
    let mut data = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                data.push(f(i as f64, j as f64, k as f64) as f32);
            }
        }
    }
    VolumeData::new(dims, 1, Scalars::F32(data)).expect("valid volume")
}

/// An n³ volume of `f` of the distance (in voxels) to the grid's centre.
pub fn radial(n: u32, f: impl Fn(f64) -> f64) -> VolumeData {
    let c = (n - 1) as f64 / 2.0;
    volume([n; 3], |x, y, z| {
        f(((x - c).powi(2) + (y - c).powi(2) + (z - c).powi(2)).sqrt())
    })
}

/// A ball of radius `r` voxels in an n³ volume: 1 at the centre falling linearly to 0 at r.
pub fn ball(n: u32, r: f64) -> VolumeData {
    radial(n, |d| (1.0 - d / r).clamp(0.0, 1.0))
}

/// Two overlapping Gaussian blobs, smooth, values in [0, 1]: a volume with gradients in
/// every direction and both soft and steep parts of the transfer function.
pub fn blob_volume(n: u32) -> VolumeData {
    blobs(
        n,
        &[
            (0.95, [0.45, 0.5, 0.55], 0.22),
            (0.7, [0.72, 0.35, 0.4], 0.1),
        ],
    )
}

/// An n³ volume of Gaussian blobs (weight, centre and width as fractions of the volume's
/// edge), their sum clamped to 1.
pub fn blobs(n: u32, blobs: &[(f64, [f64; 3], f64)]) -> VolumeData {
    let m = (n - 1) as f64;
    volume([n; 3], |x, y, z| {
        let g = |c: [f64; 3], s: f64| {
            let r2 = (x - c[0] * m).powi(2) + (y - c[1] * m).powi(2) + (z - c[2] * m).powi(2);
            (-r2 / (2.0 * (s * m).powi(2))).exp()
        };
        blobs
            .iter()
            .map(|&(w, c, s)| w * g(c, s))
            .sum::<f64>()
            .min(1.0)
    })
}

pub fn piecewise3(points: &[(f64, [f32; 3])]) -> Piecewise<3> {
    Piecewise::new(points.to_vec()).expect("finite points")
}

pub fn piecewise1(points: &[(f64, f32)]) -> Piecewise<1> {
    Piecewise::new(points.iter().map(|&(x, a)| (x, [a])).collect()).expect("finite points")
}

/// A transfer function component: colour and opacity points, the opacity per
/// `unit_distance`.
pub fn component_transfer(
    color: &[(f64, [f32; 3])],
    opacity: &[(f64, f32)],
    unit_distance: f64,
) -> ComponentTransfer {
    let mut c = ComponentTransfer::new(piecewise3(color), piecewise1(opacity));
    c.unit_distance = unit_distance;
    c
}

/// White everywhere, the opacity given per `unit_distance`.
pub fn white(opacity: &[(f64, f32)], unit_distance: f64) -> TransferFunction {
    TransferFunction::single(component_transfer(
        &[(0.0, [1.0; 3]), (1.0, [1.0; 3])],
        opacity,
        unit_distance,
    ))
}

/// The colourful, semi-transparent transfer function used with [`blob_volume`].
pub fn blob_transfer() -> ComponentTransfer {
    component_transfer(
        &[
            (0.05, [0.2, 0.3, 0.9]),
            (0.5, [0.9, 0.6, 0.2]),
            (1.0, [1.0, 1.0, 0.9]),
        ],
        &[(0.05, 0.0), (0.5, 0.25), (1.0, 0.7)],
        3.0,
    )
}

/// Default frames in another blend mode.
pub fn blended(blend: BlendMode) -> RenderParams {
    RenderParams {
        blend,
        ..RenderParams::default()
    }
}

/// Composite frames with shading on.
pub fn shaded() -> RenderParams {
    RenderParams {
        shading: Shading {
            enabled: true,
            ..Shading::default()
        },
        ..RenderParams::default()
    }
}

/// `base` with one clipping plane, through `origin`, keeping the side `normal` points to.
pub fn with_clip_plane(base: RenderParams, origin: DVec3, normal: DVec3) -> RenderParams {
    RenderParams {
        clip_planes: vec![ClipPlane { origin, normal }],
        ..base
    }
}

/// An oblique view of `vol` (azimuth 30°, elevation 20°), `size` pixels square: rays cross
/// the volume's axes, and a bricked volume's faces, at an angle.
pub fn oblique(vol: &VolumeData, size: u32) -> View {
    let b = vol.bounds();
    let mut view = View::fit(b, size, size);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(b);
    view
}

/// A homogeneous white slab set on `r`: 9 × 9 points across, 33 along z (L = 32 units
/// thick), opacity α = 1 − 0.25^(1/4) per u = 8 units, so that Beer–Lambert gives 0.75
/// through it; viewed along z with a parallel camera, 33 × 33 pixels. Returns the view,
/// α and u.
pub fn slab(r: &mut Renderer) -> (View, f64, f64) {
    let vol = volume([9, 9, 33], |_, _, _| 0.5);
    let u = 8.0;
    let a = 1.0 - 0.25f64.powf(u / 32.0);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&white(&[(0.0, a as f32), (1.0, a as f32)], u))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 33, 33);
    view.camera.parallel = true;
    view.camera.reset_clipping_range(vol.bounds());
    (view, a, u)
}
