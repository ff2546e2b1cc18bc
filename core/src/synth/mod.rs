//! Analytic test volumes: VTK's wavelet (`vtkRTAnalyticSource`), the Marschner–Lobb
//! signal, and a sphere signed distance field; generated unstructured volumes (meshes.rs:
//! [`tet_wavelet`], [`mixed_cells`], [`hollow_cylinder`], [`house`]).
//!
//! All image generators return single-component `float32` volumes with identity direction;
//! [`wavelet_generated`] also gives `uint16`, computed in runs as the renderer reads it.

mod meshes;
pub use meshes::{hollow_cylinder, house, mixed_cells, tet_wavelet, HOUSE_POINTS};

use crate::error::{Error, Result};
use crate::params::{ScalarSource, ScalarType, Scalars, VolumeData, IDENTITY_DIRECTION};
use std::sync::Arc;

/// `vtkRTAnalyticSource::Maximum` default.
pub const WAVELET_MAXIMUM: f64 = 255.0;
/// `vtkRTAnalyticSource::StandardDeviation` default.
pub const WAVELET_STANDARD_DEVIATION: f64 = 0.5;
/// `vtkRTAnalyticSource` defaults for (XFreq, YFreq, ZFreq).
pub const WAVELET_FREQ: [f64; 3] = [60.0, 30.0, 40.0];
/// `vtkRTAnalyticSource` defaults for (XMag, YMag, ZMag).
pub const WAVELET_MAG: [f64; 3] = [10.0, 18.0, 5.0];
/// VTK's default wavelet extent, `-10..10` on every axis (21³ points).
pub const WAVELET_DEFAULT_EXTENT: [i32; 6] = [-10, 10, -10, 10, -10, 10];
/// The extent of VTK's `TestGPURayCastMapperBenchmark` scene, `-127..128` (256³ points).
pub const WAVELET_BENCHMARK_EXTENT: [i32; 6] = [-127, 128, -127, 128, -127, 128];

/// Wraps single-component f32 samples (x fastest) into a [`VolumeData`].
fn f32_volume(dims: [u32; 3], spacing: [f64; 3], origin: [f64; 3], data: Vec<f32>) -> VolumeData {
    let v = VolumeData {
        dims,
        spacing,
        origin,
        direction: IDENTITY_DIRECTION,
        components: 1,
        scalars: Scalars::F32(data),
        coordinates: None,
    };
    debug_assert!(v.validate().is_ok());
    v
}

/// VTK's "wavelet": the output of `vtkRTAnalyticSource` with its default parameters
/// (Maximum 255, Center (0, 0, 0), StandardDeviation 0.5, XFreq 60, YFreq 30, ZFreq 40,
/// XMag 10, YMag 18, ZMag 5, SubsampleRate 1) over the whole extent
/// `extent = [xmin, xmax, ymin, ymax, zmin, zmax]` (inclusive, in index units).
///
/// For the point with index `(i, j, k)` in the extent, with
/// `x = -i / (xmax - xmin)` (and `y`, `z` alike; the scale is 1 on a flat axis),
///
/// ```text
/// s = 255 · exp(-(x² + y² + z²) / (2 · 0.5²)) + 10 · sin(60 x) + 18 · sin(30 y) + 5 · cos(40 z)
/// ```
///
/// rounded to `f32` exactly as VTK does (each sine/cosine term is rounded to `f32`
/// first, the sum is taken in `f64`), so the samples match VTK bit for bit on the same
/// libm. At the default extent `-10..10` the range is `[37.3531, 276.829]`.
///
/// The volume has unit spacing; VTK reports origin (0, 0, 0) with an extent starting at
/// `(xmin, ymin, zmin)`, which is the same geometry as the origin
/// `(xmin, ymin, zmin)` used here, since [`VolumeData`] has no extent.
///
/// # Panics
/// If `extent` is empty on some axis (`min > max`).
pub fn wavelet(extent: [i32; 6]) -> VolumeData {
    let w = WaveletTerms::new(extent);
    let mut data = Vec::with_capacity(w.len());
    for k in 0..w.dims[2] as usize {
        for j in 0..w.dims[1] as usize {
            data.extend((0..w.dims[0] as usize).map(|i| w.value(i, j, k)));
        }
    }
    f32_volume(w.dims, [1.0; 3], w.origin(), data)
}

/// The extent of an `n`-point wavelet axis centred as VTK's benchmark extents are:
/// `-(n - 1) / 2 ..= n / 2` (`-63..=64` for 128 points), on every axis.
///
/// # Panics
/// If `n` is 0 or above `i32::MAX`.
pub fn wavelet_extent(n: u32) -> [i32; 6] {
    assert!(
        n >= 1 && n <= i32::MAX as u32,
        "wavelet_extent: n = {n} points"
    );
    let lo = -(((n - 1) / 2) as i32);
    let hi = lo + (n - 1) as i32;
    [lo, hi, lo, hi, lo, hi]
}

/// The wavelet as `uint16`: `round((s − WAVELET_U16_OFFSET) · WAVELET_U16_SCALE)` of the
/// float32 sample `s` (whose values lie within `[-33, 288]` on any extent).
pub const WAVELET_U16_OFFSET: f64 = -40.0;
/// See [`WAVELET_U16_OFFSET`].
pub const WAVELET_U16_SCALE: f64 = 180.0;

/// The wavelet ([`wavelet`]) over `extent` as a generated volume: its scalars are a
/// [`ScalarSource`] that computes the samples of whatever run the renderer reads, so no
/// size of volume is ever held in memory. `float32` gives [`wavelet`]'s values bit for
/// bit; `uint16` scales them ([`WAVELET_U16_OFFSET`], [`WAVELET_U16_SCALE`]). Errors for
/// other scalar types and for an extent over `u32::MAX` points per axis.
///
/// # Panics
/// If `extent` is empty on some axis (`min > max`).
pub fn wavelet_generated(extent: [i32; 6], ty: ScalarType) -> Result<VolumeData> {
    if !matches!(ty, ScalarType::F32 | ScalarType::U16) {
        return Err(Error::InvalidParameter(format!(
            "the generated wavelet is float32 or uint16, not {}",
            ty.name()
        )));
    }
    let w = WaveletTerms::new(extent);
    let (dims, origin) = (w.dims, w.origin());
    let v = VolumeData {
        dims,
        spacing: [1.0; 3],
        origin,
        direction: IDENTITY_DIRECTION,
        components: 1,
        scalars: Scalars::Source(Arc::new(WaveletSource { w, ty })),
        coordinates: None,
    };
    v.validate()?;
    Ok(v)
}

/// The wavelet's per-axis terms, as VTK computes them: the squared coordinate in f64 and
/// the trigonometric term rounded to f32.
#[derive(Debug)]
struct WaveletTerms {
    extent: [i32; 6],
    dims: [u32; 3],
    /// Per axis, per index: (coordinate², magnitude · sin or cos).
    axes: [Vec<(f64, f32)>; 3],
}

impl WaveletTerms {
    fn new(extent: [i32; 6]) -> WaveletTerms {
        let mut dims = [0u32; 3];
        let mut scale = [0f64; 3];
        for a in 0..3 {
            let (lo, hi) = (extent[2 * a], extent[2 * a + 1]);
            assert!(
                lo <= hi,
                "wavelet: empty extent {extent:?} (min > max on axis {a})"
            );
            dims[a] = (i64::from(hi) - i64::from(lo) + 1) as u32;
            scale[a] = if hi > lo {
                1.0 / (f64::from(hi) - f64::from(lo))
            } else {
                1.0
            };
        }
        // Center is (0, 0, 0): coordinate = (center - index) * scale.
        let axes = [0, 1, 2].map(|a| {
            (extent[2 * a]..=extent[2 * a + 1])
                .map(|idx| {
                    let c = (0.0 - f64::from(idx)) * scale[a];
                    let arg = WAVELET_FREQ[a] * c;
                    let trig = if a == 2 { arg.cos() } else { arg.sin() };
                    (c * c, (WAVELET_MAG[a] * trig) as f32)
                })
                .collect()
        });
        WaveletTerms { extent, dims, axes }
    }

    fn len(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    fn origin(&self) -> [f64; 3] {
        [0, 2, 4].map(|a| f64::from(self.extent[a]))
    }

    /// The sample at point (i, j, k) (0-based).
    #[inline]
    fn value(&self, i: usize, j: usize, k: usize) -> f32 {
        let temp2 = 1.0 / (2.0 * WAVELET_STANDARD_DEVIATION * WAVELET_STANDARD_DEVIATION);
        let (x2, xfactor) = self.axes[0][i];
        let (y2, yfactor) = self.axes[1][j];
        let (z2, zfactor) = self.axes[2][k];
        let sum = z2 + y2 + x2;
        (WAVELET_MAXIMUM * (-sum * temp2).exp()
            + f64::from(xfactor)
            + f64::from(yfactor)
            + f64::from(zfactor)) as f32
    }
}

/// The generated wavelet's scalars ([`wavelet_generated`]).
#[derive(Debug)]
struct WaveletSource {
    w: WaveletTerms,
    ty: ScalarType,
}

impl ScalarSource for WaveletSource {
    fn scalar_type(&self) -> ScalarType {
        self.ty
    }

    fn len(&self) -> usize {
        self.w.len()
    }

    fn read(&self, start: usize, out: &mut [f64]) -> std::io::Result<()> {
        let [nx, ny, _] = self.w.dims.map(|d| d as usize);
        let mut p = start;
        let mut rest = out;
        while !rest.is_empty() {
            // the rest of the x-row holding point p
            let (i0, j, k) = (p % nx, (p / nx) % ny, p / (nx * ny));
            let n = (nx - i0).min(rest.len());
            let (run, tail) = rest.split_at_mut(n);
            for (o, i) in run.iter_mut().zip(i0..) {
                let s = self.w.value(i, j, k);
                *o = match self.ty {
                    ScalarType::U16 => ((f64::from(s) - WAVELET_U16_OFFSET) * WAVELET_U16_SCALE)
                        .round()
                        .clamp(0.0, 65535.0),
                    _ => f64::from(s),
                };
            }
            p += n;
            rest = tail;
        }
        Ok(())
    }
}

/// Marschner–Lobb frequency `f_M`.
pub const MARSCHNER_LOBB_FM: f64 = 6.0;
/// Marschner–Lobb `α`.
pub const MARSCHNER_LOBB_ALPHA: f64 = 0.25;
/// The customary sampling of the Marschner–Lobb signal, 41³.
pub const MARSCHNER_LOBB_DEFAULT_N: u32 = 41;

/// The Marschner–Lobb test signal (Marschner & Lobb, "An evaluation of reconstruction
/// filters for volume rendering", 1994) at `(x, y, z)`:
///
/// ```text
/// ρ = (1 − sin(πz/2) + α (1 + cos(2π f_M cos(π r / 2)))) / (2 (1 + α)),  r = √(x² + y²)
/// ```
///
/// with `f_M = 6`, `α = 0.25`. Defined on `[-1, 1]³`, with values in `[0, 1]`.
pub fn marschner_lobb_value(x: f64, y: f64, z: f64) -> f64 {
    use std::f64::consts::PI;
    let r = (x * x + y * y).sqrt();
    let rho_r = (2.0 * PI * MARSCHNER_LOBB_FM * (PI * r / 2.0).cos()).cos();
    (1.0 - (PI * z / 2.0).sin() + MARSCHNER_LOBB_ALPHA * (1.0 + rho_r))
        / (2.0 * (1.0 + MARSCHNER_LOBB_ALPHA))
}

/// The Marschner–Lobb signal ([`marschner_lobb_value`]) sampled on `n³` points spanning
/// `[-1, 1]³`: spacing `2 / (n − 1)`, origin `(-1, -1, -1)`, `float32`. The customary
/// `n` is 41 ([`MARSCHNER_LOBB_DEFAULT_N`]).
///
/// # Panics
/// If `n < 2`.
pub fn marschner_lobb(n: u32) -> VolumeData {
    assert!(
        n >= 2,
        "marschner_lobb: n = {n}, need at least 2 samples per axis"
    );
    let h = 2.0 / f64::from(n - 1);
    let c = |i: u32| -1.0 + f64::from(i) * h;
    let mut data = Vec::with_capacity((n as usize).pow(3));
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                data.push(marschner_lobb_value(c(i), c(j), c(k)) as f32);
            }
        }
    }
    f32_volume([n; 3], [h; 3], [-1.0; 3], data)
}

/// Signed distance from `p` to the sphere of `radius` around `center`: negative inside,
/// zero on the surface, positive outside.
pub fn sphere_sdf(p: [f64; 3], center: [f64; 3], radius: f64) -> f64 {
    let d = [p[0] - center[0], p[1] - center[1], p[2] - center[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - radius
}

/// A sphere's signed distance field ([`sphere_sdf`]) on an `n³` grid, in voxel units
/// (negative inside), `float32`, spacing 1, origin 0.
///
/// The sphere is centred in the grid, at `((n − 1) / 2, …)`, and its radius is
/// `radius_fraction · (n − 1) / 2`, so a fraction of 1 touches the centres of the
/// outermost voxels in the middle of each face.
///
/// # Panics
/// If `n == 0` or `radius_fraction` is not finite and non-negative.
pub fn sphere(n: u32, radius_fraction: f64) -> VolumeData {
    assert!(n >= 1, "sphere: n = 0, need at least 1 sample per axis");
    assert!(
        radius_fraction.is_finite() && radius_fraction >= 0.0,
        "sphere: radius_fraction = {radius_fraction}, must be finite and non-negative"
    );
    let half = f64::from(n - 1) / 2.0;
    let center = [half; 3];
    let radius = radius_fraction * half;
    let mut data = Vec::with_capacity((n as usize).pow(3));
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [f64::from(i), f64::from(j), f64::from(k)];
                data.push(sphere_sdf(p, center, radius) as f32);
            }
        }
    }
    f32_volume([n; 3], [1.0; 3], [0.0; 3], data)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// Value at the point with extent index `(i, j, k)`.
    fn at(v: &VolumeData, ijk: [i32; 3]) -> f64 {
        let rel: Vec<u32> = (0..3)
            .map(|a| (f64::from(ijk[a]) - v.origin[a]) as u32)
            .collect();
        v.value(rel[0], rel[1], rel[2], 0)
    }

    // Reference values printed by VTK 9.2 (`vtkRTAnalyticSource`, default parameters).
    #[test]
    fn the_generated_wavelet_is_the_wavelet() {
        let extent = [-5, 7, -3, 2, 0, 4];
        let memory = wavelet(extent);
        let generated = wavelet_generated(extent, ScalarType::F32).unwrap();
        assert_eq!(
            (generated.dims, generated.origin),
            (memory.dims, memory.origin)
        );
        let n = memory.scalars.len();
        // runs that start mid-row and cross rows and slices
        let mut all = vec![0.0; n];
        for start in (0..n).step_by(11) {
            let end = (start + 11).min(n);
            generated
                .scalars
                .read_run(start, &mut all[start..end])
                .unwrap();
        }
        let Scalars::F32(want) = &memory.scalars else {
            panic!("float32")
        };
        assert!(all.iter().zip(want).all(|(&a, &b)| a == b as f64));
        let u16 = wavelet_generated(extent, ScalarType::U16).unwrap();
        let mut q = vec![0.0; n];
        u16.scalars.read_run(0, &mut q).unwrap();
        for (&a, &b) in q.iter().zip(want) {
            let back = a / WAVELET_U16_SCALE + WAVELET_U16_OFFSET;
            assert!(a.fract() == 0.0 && (0.0..=65535.0).contains(&a));
            assert!(
                (back - b as f64).abs() <= 0.5 / WAVELET_U16_SCALE,
                "{a} {b}"
            );
        }
        assert_eq!(wavelet_extent(128), [-63, 64, -63, 64, -63, 64]);
        assert!(wavelet_generated(extent, ScalarType::U8).is_err());
    }

    #[test]
    fn synth_wavelet_matches_vtk_default_extent() {
        let v = wavelet(WAVELET_DEFAULT_EXTENT);
        assert_eq!(v.dims, [21, 21, 21]);
        assert_eq!(v.origin, [-10.0, -10.0, -10.0]);
        assert_eq!(v.spacing, [1.0; 3]);
        assert_eq!(v.scalars.scalar_type(), crate::ScalarType::F32);
        let r = v.range(0);
        assert!(close(r[0], 37.353_103_637_695_31, 1e-4), "{r:?}");
        assert!(close(r[1], 276.828_826_904_296_9, 1e-4), "{r:?}");
        expect_values(
            &v,
            &[
                ([-10, -10, -10], 60.763_465_881_347_656),
                ([0, 0, 0], 260.0),
                ([10, 10, 10], 57.113_735_198_974_61),
                ([3, -7, 2], 163.805_053_710_937_5),
                ([-5, 4, 9], 153.388_412_475_585_94),
                ([10, -10, 0], 120.394_752_502_441_4),
                ([1, 2, 3], 238.609_909_057_617_2),
            ],
        );
    }

    /// Checks the values VTK's vtkRTAnalyticSource gives at these points.
    fn expect_values(v: &VolumeData, points: &[([i32; 3], f64)]) {
        for &(ijk, want) in points {
            let got = at(v, ijk);
            assert!(close(got, want, 1e-4), "{ijk:?}: {got} vs VTK {want}");
        }
    }

    #[test]
    fn synth_wavelet_matches_vtk_other_extents() {
        // Non-symmetric, non-cubic extent starting at 0.
        let v = wavelet([0, 15, 0, 7, 0, 3]);
        assert_eq!(v.dims, [16, 8, 4]);
        assert_eq!(v.origin, [0.0; 3]);
        let r = v.range(0);
        assert!(close(r[0], -21.320_985_794_067_383, 1e-4), "{r:?}");
        assert!(close(r[1], 271.589_294_433_593_75, 1e-4), "{r:?}");
        expect_values(
            &v,
            &[
                ([0, 0, 0], 260.0),
                ([15, 7, 3], 18.130_065_917_968_75),
                ([5, 3, 1], 102.545_974_731_445_31),
            ],
        );
        // A flat axis has scale 1 in VTK.
        let flat = wavelet([-2, 2, -2, 2, 0, 0]);
        assert_eq!(flat.dims, [5, 5, 1]);
        assert!(close(at(&flat, [0, 0, 0]), 260.0, 1e-4));
    }

    #[test]
    #[ignore = "builds the 256³ benchmark volume (64 MiB); run with --ignored"]
    fn synth_wavelet_matches_vtk_benchmark_extent() {
        let v = wavelet(WAVELET_BENCHMARK_EXTENT);
        assert_eq!(v.dims, [256, 256, 256]);
        let r = v.range(0);
        assert!(close(r[0], 33.450_988_769_531_25, 1e-4), "{r:?}");
        assert!(close(r[1], 286.255_615_234_375, 1e-4), "{r:?}");
        expect_values(
            &v,
            &[
                ([-127, -127, -127], 62.457_767_486_572_266),
                ([0, 0, 0], 260.0),
                ([128, 128, 128], 56.657_852_172_851_56),
                ([50, -30, 77], 196.187_362_670_898_44),
                ([1, 1, 1], 255.471_023_559_570_3),
            ],
        );
    }

    #[test]
    fn synth_marschner_lobb_values() {
        // Origin: r = 0 → cos(12π) = 1 → (1 + 0.5) / 2.5.
        assert!(close(marschner_lobb_value(0.0, 0.0, 0.0), 0.6, 1e-12));
        // Top and bottom of the cube on the axis.
        assert!(close(marschner_lobb_value(0.0, 0.0, 1.0), 0.2, 1e-12));
        assert!(close(marschner_lobb_value(0.0, 0.0, -1.0), 1.0, 1e-12));
        // r = 1: cos(π/2) = 0 → cos(0) = 1, same as the axis.
        assert!(close(marschner_lobb_value(1.0, 0.0, 0.0), 0.6, 1e-12));
        assert!(close(
            marschner_lobb_value(0.0, -1.0, 0.5),
            marschner_lobb_value(0.0, 0.0, 0.5),
            1e-12
        ));
        // Where cos(πr/2) = 1/12 the radial term is cos(π) = −1: ρ = (1 − sin(πz/2)) / 2.5.
        let r = (1.0f64 / 12.0).acos() * 2.0 / std::f64::consts::PI;
        assert!(close(marschner_lobb_value(r, 0.0, 0.0), 0.4, 1e-12));
        assert!(close(marschner_lobb_value(0.0, r, -1.0), 0.8, 1e-12));
        // Radial symmetry.
        assert!(close(
            marschner_lobb_value(0.3, 0.4, 0.1),
            marschner_lobb_value(0.5, 0.0, 0.1),
            1e-12
        ));
    }

    #[test]
    fn synth_marschner_lobb_volume() {
        let v = marschner_lobb(MARSCHNER_LOBB_DEFAULT_N);
        assert_eq!(v.dims, [41, 41, 41]);
        assert_eq!(v.origin, [-1.0; 3]);
        assert!(close(v.spacing[0], 0.05, 1e-15));
        assert_eq!(v.bounds(), [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0]);
        assert!(v.validate().is_ok());
        // Centre sample (20, 20, 20) is (0, 0, 0).
        assert!(close(v.value(20, 20, 20, 0), 0.6, 1e-6));
        assert!(close(v.value(20, 20, 0, 0), 1.0, 1e-6));
        assert!(close(v.value(20, 20, 40, 0), 0.2, 1e-6));
        // Sample (27, 13, 5) is (0.35, -0.35, -0.75).
        let want = marschner_lobb_value(0.35, -0.35, -0.75);
        assert!(close(v.value(27, 13, 5, 0), want, 1e-6));
        let r = v.range(0);
        assert!(r[0] >= 0.0 && r[1] <= 1.0 + 1e-6, "{r:?}");
        assert!(r[0] < 0.05 && r[1] > 0.95, "{r:?}");
        // Smallest grid.
        let small = marschner_lobb(2);
        assert_eq!(small.dims, [2, 2, 2]);
        assert!(close(small.spacing[0], 2.0, 1e-15));
    }

    #[test]
    fn synth_sphere_sdf() {
        assert!(close(sphere_sdf([0.0; 3], [0.0; 3], 2.0), -2.0, 1e-12));
        assert!(close(
            sphere_sdf([3.0, 4.0, 0.0], [0.0; 3], 5.0),
            0.0,
            1e-12
        ));
        assert!(close(
            sphere_sdf([1.0, 1.0, 11.0], [1.0, 1.0, 1.0], 4.0),
            6.0,
            1e-12
        ));
    }

    #[test]
    fn synth_sphere_volume() {
        let v = sphere(33, 0.5); // centre (16, 16, 16), radius 8
        assert_eq!(v.dims, [33, 33, 33]);
        assert_eq!(v.origin, [0.0; 3]);
        assert_eq!(v.spacing, [1.0; 3]);
        assert!(v.validate().is_ok());
        assert!(close(v.value(16, 16, 16, 0), -8.0, 1e-6));
        assert!(close(v.value(24, 16, 16, 0), 0.0, 1e-6));
        assert!(close(v.value(16, 8, 16, 0), 0.0, 1e-6));
        assert!(close(v.value(16, 16, 0, 0), 8.0, 1e-6));
        assert!(close(v.value(20, 16, 16, 0), -4.0, 1e-6));
        let corner = 16.0 * 3f64.sqrt() - 8.0;
        assert!(close(v.value(0, 0, 0, 0), corner, 1e-5));
        assert!(close(v.value(32, 32, 32, 0), corner, 1e-5));
        let r = v.range(0);
        assert!(
            close(r[0], -8.0, 1e-6) && close(r[1], corner, 1e-5),
            "{r:?}"
        );
        // Even n: the centre falls between voxels.
        let e = sphere(4, 1.0); // centre 1.5, radius 1.5
        assert!(close(e.value(1, 1, 1, 0), 0.75f64.sqrt() - 1.5, 1e-6));
        assert!(close(e.value(0, 1, 1, 0), 2.75f64.sqrt() - 1.5, 1e-6));
    }
}
