//! Coarser copies of a volume: the levels a path-traced frame draws when the bricks it
//! needs exceed the memory budget (resources/levels.rs), and for anyone who wants a
//! smaller volume over the same box.

use super::volume::{ScalarType, Scalars, VolumeData};
use crate::error::{Error, Result};
use std::collections::VecDeque;

/// Points of a level `factor` times coarser along an axis of `n` points: the same ends.
pub(crate) fn coarse_points(n: u32, factor: u32) -> u32 {
    if n == 1 {
        1
    } else {
        (n - 1).div_ceil(factor) + 1
    }
}

/// Per coarse point along an axis of `n` fine points and `m` coarse ones, the fine points
/// it averages with their weights: a tent one coarse spacing wide on each side (the filter
/// linear interpolation's downsampling is the adjoint of), normalised to sum 1.
fn tent_weights(n: u32, m: u32) -> Vec<Vec<(usize, f64)>> {
    if m == 1 {
        return vec![(0..n as usize).map(|j| (j, 1.0 / n as f64)).collect()];
    }
    let r = (n - 1) as f64 / (m - 1) as f64;
    (0..m)
        .map(|i| {
            let p = i as f64 * r;
            let lo = (p - r).ceil().max(0.0) as usize;
            let hi = ((p + r).floor() as usize).min(n as usize - 1);
            let mut w: Vec<(usize, f64)> = (lo..=hi)
                .map(|j| (j, (1.0 - (j as f64 - p).abs() / r).max(0.0)))
                .filter(|&(_, w)| w > 0.0)
                .collect();
            let sum: f64 = w.iter().map(|&(_, w)| w).sum();
            for (_, x) in &mut w {
                *x /= sum;
            }
            w
        })
        .collect()
}

/// [`tent_weights`] for coarse point i at fine point i·`factor`: the axis extended to
/// (m − 1)·factor + 1 points, those past the last reading the last (as a clamping sampler).
fn lattice_weights(n: u32, m: u32, factor: u32) -> Vec<Vec<(usize, f64)>> {
    if m == 1 {
        return tent_weights(n, m);
    }
    let last = n as usize - 1;
    tent_weights((m - 1) * factor + 1, m)
        .into_iter()
        .map(|w| {
            let mut out: Vec<(usize, f64)> = Vec::with_capacity(w.len());
            for (j, x) in w {
                match out.last_mut() {
                    Some((k, y)) if *k == j.min(last) => *y += x,
                    _ => out.push((j.min(last), x)),
                }
            }
            out
        })
        .collect()
}

/// How a coarse point combines the fine points its weights reach: their weighted mean, or
/// (the stand-ins of MIP and MinIP previews, which a mean would dim or brighten where a
/// structure is thinner than the level's spacing) their largest or smallest value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Reduction {
    Mean,
    Max,
    Min,
}

impl Reduction {
    /// The accumulator before any fine point.
    fn start(self) -> f64 {
        match self {
            Reduction::Mean => 0.0,
            Reduction::Max => f64::NEG_INFINITY,
            Reduction::Min => f64::INFINITY,
        }
    }

    /// `acc` with the fine value `v` of weight `w` taken in.
    fn take(self, acc: f64, w: f64, v: f64) -> f64 {
        match self {
            Reduction::Mean => acc + w * v,
            Reduction::Max => acc.max(v),
            Reduction::Min => acc.min(v),
        }
    }
}

/// Per fine point, the coarse points it contributes to with their weights.
fn by_fine(weights: &[Vec<(usize, f64)>], n: u32) -> Vec<Vec<(usize, f64)>> {
    let mut out = vec![Vec::new(); n as usize];
    for (i, w) in weights.iter().enumerate() {
        for &(j, x) in w {
            out[j].push((i, x));
        }
    }
    out
}

impl VolumeData {
    /// This volume on a grid `factor` times coarser per axis over the same bounds:
    /// ⌈(n − 1)/factor⌉ + 1 points along an axis of n (the last coarse point on the last fine
    /// one: spacing × (n − 1)/(m − 1)), each the tent-weighted mean of the fine points within
    /// one coarse spacing of it (the filter linear interpolation's downsampling is the
    /// adjoint of), of the same scalar type (integers rounded). Reads the values once, by
    /// x-rows of one z-slab after another (a [`super::ScalarSource`] is never read whole),
    /// and holds three coarse planes at most besides the result. A rectilinear grid is
    /// refused.
    pub fn downsampled(&self, factor: u32) -> Result<VolumeData> {
        downsample(self, factor, false, Reduction::Mean)
    }

    /// [`VolumeData::downsampled`] with coarse point i at fine point i·`factor` (spacing ×
    /// factor; past the last fine point the tent reads the last), `reduction` combining the
    /// points the tent reaches: a coarse brick then holds the same box as `factor`³ fine
    /// ones (resources/lod.rs).
    pub(crate) fn downsampled_on_lattice(
        &self,
        factor: u32,
        reduction: Reduction,
    ) -> Result<VolumeData> {
        downsample(self, factor, true, reduction)
    }
}

fn downsample(v: &VolumeData, factor: u32, lattice: bool, op: Reduction) -> Result<VolumeData> {
    if factor == 0 {
        return Err(Error::InvalidParameter(
            "a downsampling factor of 0: give 1 or more fine points per coarse point".into(),
        ));
    }
    if v.coordinates.is_some() {
        return Err(Error::Unsupported(
            "a rectilinear grid has no coarser levels: resample it to a uniform grid".into(),
        ));
    }
    let [nx, ny, nz] = v.dims;
    let [mx, my, mz] = v.dims.map(|n| coarse_points(n, factor));
    let c = v.components as usize;
    let weights = |n, m| {
        if lattice {
            lattice_weights(n, m, factor)
        } else {
            tent_weights(n, m)
        }
    };
    let wx = weights(nx, mx);
    let to_y = by_fine(&weights(ny, my), ny);
    let wz = weights(nz, mz);
    let to_z = by_fine(&wz, nz);
    let last_z: Vec<usize> = wz.iter().map(|w| w.last().expect("a weight").0).collect();
    let plane_len = mx as usize * my as usize * c;
    let mut out = empty_scalars(v.scalars.scalar_type(), plane_len * mz as usize);
    let mut row = vec![0.0; nx as usize * c];
    let mut row_sum = vec![op.start(); mx as usize * c];
    let mut slab = vec![op.start(); plane_len];
    let mut planes: VecDeque<(usize, Vec<f64>)> = VecDeque::new();
    for (z, planes_of_z) in to_z.iter().enumerate() {
        slab.fill(op.start());
        for (y, to) in to_y.iter().enumerate() {
            let start = (z * ny as usize + y) * nx as usize * c;
            v.scalars.read_run(start, &mut row)?;
            row_sum.fill(op.start());
            for (i, w) in wx.iter().enumerate() {
                for &(j, x) in w {
                    for k in 0..c {
                        let acc = &mut row_sum[i * c + k];
                        *acc = op.take(*acc, x, row[j * c + k]);
                    }
                }
            }
            for &(yy, x) in to {
                let dst = &mut slab[yy * mx as usize * c..(yy + 1) * mx as usize * c];
                for (d, s) in dst.iter_mut().zip(&row_sum) {
                    *d = op.take(*d, x, *s);
                }
            }
        }
        for &(k, x) in planes_of_z {
            if planes.back().is_none_or(|(b, _)| *b < k) {
                planes.push_back((k, vec![op.start(); plane_len]));
            }
            let plane = &mut planes.iter_mut().find(|(b, _)| *b == k).expect("pushed").1;
            for (d, s) in plane.iter_mut().zip(&slab) {
                *d = op.take(*d, x, *s);
            }
        }
        while planes.front().is_some_and(|(k, _)| last_z[*k] <= z) {
            let (_, plane) = planes.pop_front().expect("checked");
            push_values(&mut out, &plane);
        }
    }
    let r = |a: usize, n: u32, m: u32| {
        if lattice && n > 1 {
            v.spacing[a] * factor as f64
        } else if m > 1 {
            v.spacing[a] * (n - 1) as f64 / (m - 1) as f64
        } else {
            v.spacing[a]
        }
    };
    let mut coarse = VolumeData::new([mx, my, mz], v.components, out)?
        .with_origin(v.origin)?
        .with_direction(v.direction)?;
    coarse.spacing = [r(0, nx, mx), r(1, ny, my), r(2, nz, mz)];
    coarse.validate()?;
    Ok(coarse)
}

/// An empty array of `t` with room for `n` values.
fn empty_scalars(t: ScalarType, n: usize) -> Scalars {
    match t {
        ScalarType::U8 => Scalars::U8(Vec::with_capacity(n)),
        ScalarType::I8 => Scalars::I8(Vec::with_capacity(n)),
        ScalarType::U16 => Scalars::U16(Vec::with_capacity(n)),
        ScalarType::I16 => Scalars::I16(Vec::with_capacity(n)),
        ScalarType::U32 => Scalars::U32(Vec::with_capacity(n)),
        ScalarType::I32 => Scalars::I32(Vec::with_capacity(n)),
        ScalarType::F32 => Scalars::F32(Vec::with_capacity(n)),
        ScalarType::F64 => Scalars::F64(Vec::with_capacity(n)),
    }
}

/// Appends `values` to `out` in its type (integers rounded: a weighted mean, the largest or
/// the smallest of values of a type lies within its range).
fn push_values(out: &mut Scalars, values: &[f64]) {
    fn put<T>(out: &mut Vec<T>, values: &[f64], f: impl Fn(f64) -> T) {
        out.extend(values.iter().map(|&x| f(x)));
    }
    match out {
        Scalars::U8(o) => put(o, values, |x| x.round() as u8),
        Scalars::I8(o) => put(o, values, |x| x.round() as i8),
        Scalars::U16(o) => put(o, values, |x| x.round() as u16),
        Scalars::I16(o) => put(o, values, |x| x.round() as i16),
        Scalars::U32(o) => put(o, values, |x| x.round() as u32),
        Scalars::I32(o) => put(o, values, |x| x.round() as i32),
        Scalars::F32(o) => put(o, values, |x| x as f32),
        Scalars::F64(o) => o.extend_from_slice(values),
        Scalars::Source(_) => unreachable!("levels are built in memory"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tent_weights_keep_the_ends_and_sum_to_one() {
        for (n, f) in [(9, 2), (10, 2), (17, 4), (5, 8), (2, 2)] {
            let m = coarse_points(n, f);
            let w = tent_weights(n, m);
            assert_eq!(w.len(), m as usize);
            assert_eq!(w[0][0], (0, w[0][0].1));
            assert_eq!(w[m as usize - 1].last().unwrap().0, n as usize - 1);
            for wi in &w {
                let s: f64 = wi.iter().map(|&(_, x)| x).sum();
                assert!((s - 1.0).abs() < 1e-12);
            }
            // every fine point is read by some coarse point
            assert!(by_fine(&w, n).iter().all(|t| !t.is_empty()));
        }
    }

    /// A spike one point wide: the mean level spreads and lowers it, the largest and
    /// smallest keep it whole in the coarse point whose tent reaches it.
    #[test]
    fn max_and_min_levels_keep_a_one_point_spike() {
        let line =
            |values: [u8; 7]| VolumeData::new([7, 1, 1], 1, Scalars::U8(values.to_vec())).unwrap();
        let level = |v: &VolumeData, r| {
            let c = v.downsampled_on_lattice(2, r).unwrap();
            (0..c.dims[0] as usize)
                .map(|i| c.scalars.get(i))
                .collect::<Vec<f64>>()
        };
        let bright = line([10, 10, 10, 200, 10, 10, 10]);
        assert_eq!(level(&bright, Reduction::Max), [10.0, 200.0, 200.0, 10.0]);
        assert_eq!(level(&bright, Reduction::Mean), [10.0, 58.0, 58.0, 10.0]);
        let dark = line([90, 90, 90, 3, 90, 90, 90]);
        assert_eq!(level(&dark, Reduction::Min), [90.0, 3.0, 3.0, 90.0]);
    }

    #[test]
    fn lattice_levels_put_coarse_point_i_on_fine_point_i_times_the_factor() {
        // f = x along 6 points (5 cells), factor 2: coarse points on fine 0, 2, 4 and 6 (past
        // the end, reading the last point); inside, the tent reproduces the field exactly
        let v = VolumeData::new(
            [6, 1, 1],
            1,
            Scalars::F32((0..6).map(|x| x as f32).collect()),
        )
        .unwrap()
        .with_spacing([0.5, 1.0, 1.0])
        .unwrap();
        let c = v.downsampled_on_lattice(2, Reduction::Mean).unwrap();
        assert_eq!(c.dims, [4, 1, 1]);
        assert_eq!(c.spacing, [1.0, 1.0, 1.0]);
        let values: Vec<f64> = (0..4).map(|i| c.scalars.get(i)).collect();
        assert!((values[1] - 2.0).abs() < 1e-6 && (values[2] - 4.0).abs() < 1e-6);
        assert!(
            (values[3] - 5.0).abs() < 1e-6,
            "the edge, clamped: {values:?}"
        );
        for w in lattice_weights(6, 4, 2) {
            assert!((w.iter().map(|&(_, x)| x).sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_linear_field_stays_linear_and_the_bounds_stay() {
        // f = x/2 + 2y − z: where the factor divides the cells the tents are symmetric and
        // reproduce it exactly inside; elsewhere their centroids shift by under a tenth of a
        // fine spacing. The coarse grid spans the same box.
        let p = |x: f64, y: f64, z: f64| x * 0.5 + 2.0 * y - z;
        for (dims, tolerance) in [([17u32, 13, 9], 1e-4), ([17, 12, 10], 0.25)] {
            let n = dims.iter().product::<u32>() as usize;
            let mut s = Vec::with_capacity(n);
            for k in 0..dims[2] {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        s.push(p(i as f64, j as f64, k as f64) as f32);
                    }
                }
            }
            let v = VolumeData::new(dims, 1, Scalars::F32(s))
                .unwrap()
                .with_spacing([0.5, 1.0, 2.0])
                .unwrap()
                .with_origin([1.0, -2.0, 3.0])
                .unwrap();
            let c = v.downsampled(4).unwrap();
            assert_eq!(c.dims, dims.map(|n| coarse_points(n, 4)));
            assert_eq!(c.bounds(), v.bounds());
            let r = |a: usize| (dims[a] - 1) as f64 / (c.dims[a] - 1) as f64;
            for (i, j, k) in [(1u32, 1u32, 1u32), (2, 2, 1), (3, 1, 1)] {
                let want = p(i as f64 * r(0), j as f64 * r(1), k as f64 * r(2));
                let got = c.value(i, j, k, 0);
                assert!(
                    (got - want).abs() < tolerance,
                    "{dims:?} {i} {j} {k}: {got} {want}"
                );
            }
        }
    }

    #[test]
    fn integer_types_round_and_components_stay_apart() {
        let dims = [5u32, 5, 5];
        let mut s = Vec::new();
        for p in 0..125u16 {
            s.push(p % 5 * 100);
            s.push(7);
        }
        let v = VolumeData::new(dims, 2, Scalars::U16(s)).unwrap();
        let c = v.downsampled(2).unwrap();
        assert_eq!(c.dims, [3, 3, 3]);
        assert_eq!(c.scalars.scalar_type(), ScalarType::U16);
        for k in 0..3 {
            assert_eq!(c.value(1, 1, k, 0), 200.0);
            assert_eq!(c.value(1, 1, k, 1), 7.0);
        }
    }
}
