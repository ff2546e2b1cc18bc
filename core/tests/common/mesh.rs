//! The f64 CPU reference of the unstructured ray caster: the mesh split into the same
//! tetrahedra ([`tetrahedralize`]), each pixel's ray clipped against every tetrahedron's
//! four planes (no traversal, no hierarchy), the scalar linear in each, and the segments
//! integrated by the same conventions (VTK's unstructured integrators: attenuation
//! τ = opacity / unit distance, emission colour · τ) with the transfer functions
//! themselves and composite Gauss–Legendre quadrature instead of closed forms. Shaded
//! composite lights every point of a segment by the gradient interpolated there from the
//! points' (each the volume-weighted mean of its tetrahedra's; the headlight,
//! raycast::shade, clamped point by point). Gradient opacity scales a segment's opacity in
//! composite by its function of that gradient's magnitude at the segment's middle.
//! Volumetric shadows (the headlight's, [`Volumetric`]): each segment lit as at its middle,
//! the transmittance toward the headlight integrated back along the pixel's own segments.

use super::raycast::{eval_pw, pixel_ray, shade, to_pixel, Ray};
use ferrovol_core::*;
use glam::DVec3;
use std::collections::HashMap;

/// One piece of a ray inside a tetrahedron: entry and exit distance, scalar and gradient at
/// each (both linear between), and the ray's direction.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    pub t0: f64,
    pub t1: f64,
    pub s0: f64,
    pub s1: f64,
    pub g0: DVec3,
    pub g1: DVec3,
    pub dir: DVec3,
}

/// The tetrahedra of a mesh with their scalars (per point, or per tetrahedron).
pub struct Tets {
    pub points: Vec<DVec3>,
    pub tets: Vec<[u32; 4]>,
    /// Per point (point scalars) or empty.
    pub point_scalars: Vec<f64>,
    /// Per tetrahedron (cell scalars) or empty.
    pub cell_scalars: Vec<f64>,
    /// The scalar's gradient per point.
    pub point_gradients: Vec<DVec3>,
}

impl Tets {
    pub fn of(v: &UnstructuredVolume) -> Tets {
        let t = tetrahedralize(v).expect("a valid mesh");
        let nc = v.components as usize;
        let cell_scalars = match v.location {
            ScalarLocation::Cells => t
                .tet_cell
                .iter()
                .map(|&c| v.scalars.get(c as usize * nc))
                .collect(),
            ScalarLocation::Points => vec![],
        };
        let mut tets = Tets {
            points: t.points.iter().map(|p| DVec3::from(*p)).collect(),
            point_scalars: match v.location {
                ScalarLocation::Points => t.point_scalars,
                ScalarLocation::Cells => vec![],
            },
            tets: t.tets,
            cell_scalars,
            point_gradients: vec![],
        };
        tets.point_gradients = tets.point_gradients();
        tets
    }

    /// The part of `ray` inside tetrahedron `k`, if any.
    fn clip(&self, k: usize, ray: &Ray) -> Option<Segment> {
        let ids = self.tets[k];
        let p = ids.map(|i| self.points[i as usize]);
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for f in 0..4 {
            let (a, b, c) = (p[(f + 1) % 4], p[(f + 2) % 4], p[(f + 3) % 4]);
            let mut n = (b - a).cross(c - a);
            if n.dot(p[f] - a) > 0.0 {
                n = -n;
            }
            // inside: n · (o + t d − a) ≤ 0
            let dist = n.dot(ray.origin - a);
            let rate = n.dot(ray.dir);
            if rate.abs() < 1e-300 {
                if dist > 0.0 {
                    return None;
                }
            } else if rate > 0.0 {
                t1 = t1.min(-dist / rate);
            } else {
                t0 = t0.max(-dist / rate);
            }
        }
        if t0 >= t1 {
            return None;
        }
        let s = |t: f64| self.scalar(k, ray.origin + t * ray.dir);
        let g = |t: f64| self.gradient(k, ray.origin + t * ray.dir);
        Some(Segment {
            t0,
            t1,
            s0: s(t0),
            s1: s(t1),
            g0: g(t0),
            g1: g(t1),
            dir: ray.dir,
        })
    }

    /// The barycentric coordinates of point x in tetrahedron k.
    fn barycentric(&self, k: usize, x: DVec3) -> [f64; 4] {
        let p = self.tets[k].map(|i| self.points[i as usize]);
        let m = glam::DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
        let l = m.inverse() * (x - p[0]);
        [1.0 - l.x - l.y - l.z, l.x, l.y, l.z]
    }

    /// The gradient at point x of tetrahedron k, interpolated from its points'.
    fn gradient(&self, k: usize, x: DVec3) -> DVec3 {
        let w = self.barycentric(k, x);
        (0..4)
            .map(|i| w[i] * self.point_gradients[self.tets[k][i] as usize])
            .sum()
    }

    /// The gradients of the barycentric coordinates of tetrahedron k.
    fn barycentric_gradients(&self, k: usize) -> [DVec3; 4] {
        let p = self.tets[k].map(|i| self.points[i as usize]);
        let inv = glam::DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0])
            .inverse()
            .transpose();
        let (g1, g2, g3) = (inv.x_axis, inv.y_axis, inv.z_axis);
        [-(g1 + g2 + g3), g1, g2, g3]
    }

    /// Every tetrahedron's gradient: of its linear interpolant (point scalars), or
    /// Green–Gauss over its faces from the cell scalars across them (each face the mean of
    /// the two cells', the cell's own on the boundary), as resources/mesh/gradients.rs.
    fn tet_gradients(&self) -> Vec<DVec3> {
        let mut across: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
        if !self.cell_scalars.is_empty() {
            for (k, ids) in self.tets.iter().enumerate() {
                for f in 0..4 {
                    across.entry(face_key(ids, f)).or_default().push(k);
                }
            }
        }
        (0..self.tets.len())
            .map(|k| {
                let g = self.barycentric_gradients(k);
                let ids = self.tets[k];
                (0..4)
                    .map(|i| {
                        let w = if self.cell_scalars.is_empty() {
                            self.point_scalars[ids[i] as usize]
                        } else {
                            let s = self.cell_scalars[k];
                            let cells = &across[&face_key(&ids, i)];
                            let n = cells.iter().find(|&&c| c != k);
                            let sn = n.map_or(s, |&c| self.cell_scalars[c]);
                            -1.5 * (sn - s)
                        };
                        w * g[i]
                    })
                    .sum()
            })
            .collect()
    }

    /// The scalar at point x of tetrahedron k (barycentric, or the cell's).
    fn scalar(&self, k: usize, x: DVec3) -> f64 {
        if !self.cell_scalars.is_empty() {
            return self.cell_scalars[k];
        }
        let ids = self.tets[k];
        let w = self.barycentric(k, x);
        (0..4)
            .map(|i| w[i] * self.point_scalars[ids[i] as usize])
            .sum()
    }

    /// Every point's gradient: the mean of its tetrahedra's, weighted by their volumes.
    fn point_gradients(&self) -> Vec<DVec3> {
        let mut sum = vec![(DVec3::ZERO, 0.0); self.points.len()];
        for (ids, g) in self.tets.iter().zip(self.tet_gradients()) {
            let p = ids.map(|i| self.points[i as usize]);
            let volume = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])).abs();
            for &i in ids {
                sum[i as usize].0 += volume * g;
                sum[i as usize].1 += volume;
            }
        }
        sum.iter()
            .map(|(g, w)| if *w > 0.0 { *g / *w } else { DVec3::ZERO })
            .collect()
    }

    /// Every pixel's segments, front to back, within [0, far] of its ray.
    pub fn segments(&self, view: &View) -> Vec<Vec<Segment>> {
        let (w, h) = (view.width, view.height);
        let mut out = vec![Vec::new(); (w * h) as usize];
        let rays: Vec<Ray> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| pixel_ray(view, x, y))
            .collect();
        for k in 0..self.tets.len() {
            let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
            for &i in &self.tets[k] {
                let (x, y) = to_pixel(view, self.points[i as usize]);
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x);
                y1 = y1.max(y);
            }
            let xs = (x0.floor().max(0.0) as u32)..((x1.ceil() + 1.0).min(w as f64) as u32);
            for y in (y0.floor().max(0.0) as u32)..((y1.ceil() + 1.0).min(h as f64) as u32) {
                for x in xs.clone() {
                    let p = (y * w + x) as usize;
                    if let Some(mut s) = self.clip(k, &rays[p]) {
                        let (lo, hi) = (s.t0.max(0.0), s.t1.min(rays[p].far));
                        if lo < hi {
                            let span = s.t1 - s.t0;
                            let (u0, u1) = ((lo - s.t0) / span, (hi - s.t0) / span);
                            let (a, b) = (s.s0, s.s1);
                            s.s0 = a + (b - a) * u0;
                            s.s1 = a + (b - a) * u1;
                            let (g0, g1) = (s.g0, s.g1);
                            s.g0 = g0.lerp(g1, u0);
                            s.g1 = g0.lerp(g1, u1);
                            s.t0 = lo;
                            s.t1 = hi;
                            out[p].push(s);
                        }
                    }
                }
            }
        }
        for segs in &mut out {
            segs.sort_by(|a, b| a.t0.total_cmp(&b.t0));
        }
        out
    }
}

/// The face of tetrahedron `ids` opposite its point f, as sorted point indices.
fn face_key(ids: &[u32; 4], f: usize) -> [u32; 3] {
    let mut k = [ids[(f + 1) % 4], ids[(f + 2) % 4], ids[(f + 3) % 4]];
    k.sort_unstable();
    k
}

/// Where a shaded segment's lighting is taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightAt {
    /// At every point (the gradient interpolated there).
    EachPoint,
    /// At the segment's middle, for the whole segment (as unstructured.wgsl).
    Middle,
}

/// Component 0's transfer functions in f64 (the renderer's 1024-entry tables, read
/// linearly, stand in for them to a fraction of a level), and the shading composite
/// applies (none: unshaded).
pub struct Table {
    tf: ComponentTransfer,
    lo: f64,
    hi: f64,
    pub inv_unit: f64,
    pub shading: Option<(Shading, LightAt)>,
    /// Composite with gradient opacity.
    pub gradient_opacity: bool,
    /// Shaded composite with the headlight's volumetric shadows.
    pub volumetric: Option<Volumetric>,
}

/// Volumetric shadows under the headlight, as unstructured.wgsl defines them for a mesh:
/// at a segment's middle the transmittance back toward the eye over the reach, the
/// Henyey–Greenstein phase at μ = −1, mixed with the gradient lighting by VTK's weight.
pub struct Volumetric {
    pub blending: f64,
    pub anisotropy: f64,
    /// The reach in the mesh's box mapped to the unit cube.
    pub reach: f64,
    /// 1 / the box's extent per axis.
    pub inv_extent: DVec3,
    /// A typical cell's size: the step the weight's opacity is taken over.
    pub cell: f64,
    /// 2 / the data range (VTK's gradient magnitude scale).
    pub gradient_scale: f64,
}

impl Volumetric {
    /// (the volumetric term's factor of the colour, its weight) for segment j of `segs`.
    fn at(&self, segs: &[Segment], j: usize, table: &Table, sh: &Shading) -> (f64, f64) {
        let s = &segs[j];
        let mid = 0.5 * (s.t0 + s.t1);
        let reach = self.reach / (s.dir * self.inv_extent).length();
        let from = mid - reach;
        // the optical depth from `from` to the middle, along the pixel's segments
        let mut depth = 0.0;
        for k in segs.iter().take(j + 1) {
            let (a, b) = (k.t0.max(from), k.t1.min(mid));
            if b <= a {
                continue;
            }
            let sv = |t: f64| k.s0 + (k.s1 - k.s0) * (t - k.t0) / (k.t1 - k.t0);
            let (x0, x1) = (sv(a), sv(b));
            for (u0, u1) in table.pieces(x0, x1) {
                depth += (b - a)
                    * (u1 - u0)
                    * quad(1, |u| {
                        table.at(x0 + (x1 - x0) * (u0 + (u1 - u0) * u))[3] * table.inv_unit
                    });
            }
        }
        let g = self.anisotropy;
        let phase = if g.abs() < 0.01 {
            1.0
        } else {
            (1.0 - g * g) / (1.0 + g).powi(3)
        };
        let factor = (-depth).exp() * phase * sh.diffuse as f64;
        let tau = table.at(0.5 * (s.s0 + s.s1))[3] * table.inv_unit;
        let a = 1.0 - (-tau * self.cell).exp();
        let gm = s.g0.lerp(s.g1, 0.5).length() * self.gradient_scale;
        let bl = self.blending;
        let w = if bl >= 1.0 {
            (2.0 - bl) * (-bl * gm * a).exp() + (bl - 1.0)
        } else {
            bl * (-bl * gm * a).exp()
        };
        (factor, w)
    }
}

impl Table {
    pub fn of(tf: &TransferFunction) -> Table {
        let c = tf.component(0).clone();
        let [lo, hi] = c.table_range();
        Table {
            inv_unit: 1.0 / c.unit_distance,
            tf: c,
            lo,
            hi,
            shading: None,
            gradient_opacity: false,
            volumetric: None,
        }
    }

    /// The gradient opacity's factor for gradient magnitude m (1 without one).
    fn gradient_factor(&self, m: f64) -> f64 {
        match &self.tf.gradient_opacity {
            Some(go) if self.gradient_opacity => eval_pw(go, m)[0].clamp(0.0, 1.0),
            _ => 1.0,
        }
    }

    /// (r, g, b, opacity) at scalar s.
    pub fn at(&self, s: f64) -> [f64; 4] {
        let c = eval_pw(&self.tf.color, s);
        let a = eval_pw(&self.tf.opacity, s)[0].clamp(0.0, 1.0);
        [c[0], c[1], c[2], a]
    }

    /// The scalar normalised to the tables' range, clamped.
    pub fn unit(&self, s: f64) -> f64 {
        ((s - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0)
    }

    /// The pieces of a segment with scalars s0 to s1 between the functions' points, where
    /// the opacity is clamped and the tables' ends (where the functions are linear), as
    /// fractions of the segment.
    fn pieces(&self, s0: f64, s1: f64) -> Vec<(f64, f64)> {
        let mut cuts: Vec<f64> = vec![0.0, 1.0];
        if s1 != s0 {
            let knots = self.tf.color.points.iter().map(|p| p.0);
            let knots = knots.chain(self.tf.opacity.points.iter().map(|p| p.0));
            // (and where the opacity crosses 0 or 1, which it is clamped to)
            let op = &self.tf.opacity.points;
            let clamps = op.windows(2).flat_map(|w| {
                let ((x0, [a0]), (x1, [a1])) = (w[0], w[1]);
                [0.0, 1.0].into_iter().filter_map(move |l: f64| {
                    let (a0, a1) = (a0 as f64, a1 as f64);
                    ((a0 - l) * (a1 - l) < 0.0).then(|| x0 + (l - a0) / (a1 - a0) * (x1 - x0))
                })
            });
            for k in knots.chain(clamps).chain([self.lo, self.hi]) {
                let u = (k - s0) / (s1 - s0);
                if u > 0.0 && u < 1.0 {
                    cuts.push(u);
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        cuts.windows(2).map(|w| (w[0], w[1])).collect()
    }
}

/// Gauss–Legendre nodes and weights on [0, 1] (8 points).
const GL: [(f64, f64); 8] = [
    (0.019_855_071_751_231_88, 0.050_614_268_145_188_13),
    (0.101_666_761_293_186_6, 0.111_190_517_226_687_2),
    (0.237_233_795_041_835_5, 0.156_853_322_938_943_6),
    (0.408_282_678_752_175, 0.181_341_891_689_181),
    (0.591_717_321_247_825, 0.181_341_891_689_181),
    (0.762_766_204_958_164_5, 0.156_853_322_938_943_6),
    (0.898_333_238_706_813_4, 0.111_190_517_226_687_2),
    (0.980_144_928_248_768_1, 0.050_614_268_145_188_13),
];

/// ∫₀¹ f, composite Gauss–Legendre over `m` equal parts.
fn quad(m: usize, f: impl Fn(f64) -> f64) -> f64 {
    (0..m)
        .map(|j| {
            GL.iter()
                .map(|&(x, w)| w * f((j as f64 + x) / m as f64))
                .sum::<f64>()
                / m as f64
        })
        .sum()
}

/// The pixel's premultiplied RGBA in blend mode `blend` from its segments.
pub fn integrate(segs: &[Segment], table: &Table, blend: BlendMode, termination: f64) -> [f64; 4] {
    let mut c = [0.0; 4];
    match blend {
        BlendMode::Maximum | BlendMode::Minimum => {
            let vals = segs.iter().flat_map(|s| [s.s0, s.s1]);
            let v = if blend == BlendMode::Maximum {
                vals.fold(f64::NEG_INFINITY, f64::max)
            } else {
                vals.fold(f64::INFINITY, f64::min)
            };
            if segs.is_empty() {
                return c;
            }
            let e = table.at(v);
            return [e[0] * e[3], e[1] * e[3], e[2] * e[3], e[3]];
        }
        BlendMode::Average | BlendMode::Additive => {
            let (mut sum, mut len) = (0.0, 0.0);
            for s in segs {
                let (x0, x1) = (s.s0, s.s1);
                let l = s.t1 - s.t0;
                for (u0, u1) in table.pieces(x0, x1) {
                    sum += l
                        * (u1 - u0)
                        * quad(1, |u| {
                            let x = x0 + (x1 - x0) * (u0 + (u1 - u0) * u);
                            table.at(x)[3] * table.unit(x)
                        });
                }
                len += l;
            }
            if segs.is_empty() {
                return c;
            }
            let g = if blend == BlendMode::Average {
                sum / len
            } else {
                sum * table.inv_unit
            };
            let g = g.clamp(0.0, 1.0);
            return [g, g, g, 1.0];
        }
        _ => {}
    }
    for (j, s) in segs.iter().enumerate() {
        let (x0, x1) = (s.s0, s.s1);
        let l = s.t1 - s.t0;
        let go = table.gradient_factor(s.g0.lerp(s.g1, 0.5).length());
        let shadow = match (&table.volumetric, &table.shading) {
            (Some(v), Some((sh, _))) => Some(v.at(segs, j, table, sh)),
            _ => None,
        };
        for (u0, u1) in table.pieces(x0, x1) {
            let d = l * (u1 - u0);
            let at = |u: f64| {
                let f = u0 + (u1 - u0) * u;
                let mut e = table.at(x0 + (x1 - x0) * f);
                e[3] *= go;
                let Some((sh, at)) = &table.shading else {
                    return e;
                };
                let g = match at {
                    LightAt::EachPoint => s.g0.lerp(s.g1, f),
                    LightAt::Middle => s.g0.lerp(s.g1, 0.5),
                };
                let mut c = shade([e[0], e[1], e[2]], g, s.dir, sh);
                if let Some((factor, w)) = shadow {
                    for ch in 0..3 {
                        c[ch] = (c[ch] + w * (e[ch] * factor - c[ch])).clamp(0.0, 1.0);
                    }
                }
                [c[0], c[1], c[2], e[3]]
            };
            let (tf, tb) = (at(0.0)[3] * table.inv_unit, at(1.0)[3] * table.inv_unit);
            // optical depth from the piece's start to u (τ linear)
            let depth = |u: f64| d * (tf * u + 0.5 * (tb - tf) * u * u);
            let m = 4 + (depth(1.0) * 4.0).ceil() as usize;
            let keep = 1.0 - c[3];
            for ch in 0..3 {
                c[ch] += keep
                    * d
                    * quad(m, |u| {
                        let e = at(u);
                        e[ch] * e[3] * table.inv_unit * (-depth(u)).exp()
                    });
            }
            c[3] += keep * (1.0 - (-depth(1.0)).exp());
            if c[3] >= termination {
                return c;
            }
        }
    }
    c
}

/// The reference image of `v` under `tf` in `view` with `params`' blend mode, shading (lit
/// at each point) and early termination (premultiplied RGBA per pixel, rows top to bottom).
pub fn render(
    v: &UnstructuredVolume,
    tf: &TransferFunction,
    view: &View,
    params: &RenderParams,
) -> Vec<[f64; 4]> {
    render_lit(v, tf, view, params, LightAt::EachPoint)
}

/// [`render`], shaded segments lit as `at` says.
pub fn render_lit(
    v: &UnstructuredVolume,
    tf: &TransferFunction,
    view: &View,
    params: &RenderParams,
    at: LightAt,
) -> Vec<[f64; 4]> {
    let tets = Tets::of(v);
    let mut table = Table::of(tf);
    if params.shading.enabled && params.blend == BlendMode::Composite {
        table.shading = Some((params.shading, at));
    }
    table.gradient_opacity = params.blend == BlendMode::Composite;
    let sh = &params.shading;
    if table.shading.is_some() && sh.volumetric_blending > 0.0 {
        let b = v.bounds();
        let ext = DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]);
        let cell = ext.length() / (tets.tets.len() as f64).cbrt();
        let m = cell / ext.max_element();
        let root3 = 3f64.sqrt();
        let scalars = if tets.cell_scalars.is_empty() {
            &tets.point_scalars
        } else {
            &tets.cell_scalars
        };
        let lo = scalars.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = scalars.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        table.volumetric = Some(Volumetric {
            blending: sh.volumetric_blending as f64,
            anisotropy: sh.scattering_anisotropy as f64,
            reach: root3 + (m - root3) * (1.0 - sh.global_illumination_reach as f64).powf(0.33),
            inv_extent: DVec3::ONE / ext,
            cell,
            gradient_scale: 2.0 / (hi - lo),
        });
    }
    tets.segments(view)
        .iter()
        .map(|segs| {
            integrate(
                segs,
                &table,
                params.blend,
                params.termination_threshold as f64,
            )
        })
        .collect()
}

/// A crossing of an iso-value along a ray: its distance, which value, the gradient there
/// (the points' interpolated) and whether the scalar is below the value on the ray's side.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    pub t: f64,
    pub which: usize,
    pub gradient: DVec3,
    pub below: bool,
}

/// The crossings of `values` (value, opacity) along a ray's segments, front to back, as
/// firsthit_mesh.wgsl defines them: within a segment where its linear scalar passes a value,
/// and, between segments that meet, where the scalar jumps past one (cell scalars); kept
/// until `max` of them or their accumulated opacity reaches `termination`.
pub fn crossings(
    segs: &[Segment],
    values: &[(f64, f64)],
    max: usize,
    termination: f64,
) -> Vec<Crossing> {
    let mut out = Vec::new();
    let mut alpha = 0.0;
    let mut prev: Option<&Segment> = None;
    for s in segs {
        let mut here = Vec::new();
        let mut piece = |t0: f64, s0: f64, t1: f64, s1: f64, g0: DVec3, g1: DVec3| {
            for (which, &(v, _)) in values.iter().enumerate() {
                if (s0 < v) != (s1 < v) {
                    let u = (v - s0) / (s1 - s0);
                    here.push(Crossing {
                        t: t0 + u * (t1 - t0),
                        which,
                        gradient: g0.lerp(g1, u),
                        below: s0 < v,
                    });
                }
            }
        };
        if let Some(p) = prev.filter(|p| (s.t0 - p.t1).abs() <= 1e-9 * (1.0 + s.t0.abs())) {
            piece(s.t0, p.s1, s.t0, s.s0, s.g0, s.g0);
        }
        piece(s.t0, s.s0, s.t1, s.s1, s.g0, s.g1);
        here.sort_by(|a, b| a.t.total_cmp(&b.t));
        for c in here {
            if out.len() >= max || alpha >= termination {
                return out;
            }
            alpha += (1.0 - alpha) * values[c.which].1;
            out.push(c);
        }
        prev = Some(s);
    }
    out
}
