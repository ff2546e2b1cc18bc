//! The f64 CPU reference path tracer, written independently of the shader, of the model the
//! GPU path tracer renders (shaders/pathtrace.wgsl).
//!
//! The model: the main medium ([`Medium`]) is an image volume or an unstructured mesh. An
//! image volume's extinction is σ(x) = −ln(1 − min(α(s(x)), 0.9999)) / unit distance, α the
//! transfer function's opacity (a linear ramp over [0, 1] here) and s(x) the trilinearly
//! interpolated scalar (index coordinates = world coordinates: unit spacing, origin 0, voxel
//! centres at integers, the medium inside [0, dims − 1]). A mesh ([`MeshMedium`]) is split
//! into tetrahedra as the ray caster's reference splits it ([`super::mesh::Tets`]), the
//! scalar linear in each (the points' scalars weighted by the barycentric coordinates, or
//! the cell's constant scalar), and its extinction is VTK's unstructured convention,
//! σ(x) = α(s(x)) / unit distance (attenuation = opacity / unit distance, no logarithm), α a
//! linear opacity ramp over the mesh's scalar range [lo, hi] (clamped outside it), zero
//! outside every tetrahedron; its medium box is the mesh's bounding box, and it has no
//! hybrid model (HG everywhere). Either way the single-scattering albedo is the transfer
//! function's (constant) colour; Henyey–Greenstein scattering with anisotropy g; at most
//! `max_bounces` scattering events; the environment (weighted by `environment_light`) and
//! the view's directional lights (the headlight shining along each camera path) light it;
//! paths that miss the medium bring nothing (no background), and coverage is the fraction
//! of paths that met it. Intermixed volumes ([`Intermixed`], each placed by its own
//! matrix) add their media: the extinctions add up, and a collision scatters as the medium
//! it met.
//!
//! The hybrid model: at a collision the gradient ∇s by central differences one voxel apart
//! of the interpolated scalar (lib/volume.wgsl: gradient_at) gives the BSDF's share P (1 if
//! |∇s| > ψ, else 0; or 1 − exp(−k|∇s|) with the stochastic blend); the scattering regions
//! keep the BSDF's share (surfaces), the rest (between) or both (everywhere); the share that
//! does not scatter absorbs (attenuation) or is no collision at all (the extinction scaled
//! by the share). The BSDF (lib/bsdf.wgsl), as a phase function h(ω) = f·|cos|: the normal
//! the gradient's direction facing the arriving path, F Schlick's Fresnel term at the
//! viewing angle; F × GGX specular reflection (uncoloured), (1 − F)(1 − t) × Lambert and
//! (1 − F)·t × a normalised Phong lobe around the continued direction kept on the far side
//! of the surface (both coloured).
//!
//! The reference estimates the same radiance by other means: delta tracking against one
//! global majorant, the environment only by the continuation (no environment next-event
//! estimation, so no MIS), the lights by next-event estimation with ratio-tracking
//! transmittance, no Russian roulette; at a collision it scatters by the expected kernel
//! (P × BSDF + (1 − P) × albedo × HG, not a random choice between them), continuing from a
//! mixture of its own (HG; GGX half vectors, cosine, the Phong lobe and uniform
//! directions); its own random numbers (xoshiro256**), its own orthonormal basis. The GPU
//! (block majorants, luminance-sampled environment with MIS, the BSDF's own lobe sampling,
//! Russian roulette) must converge to the same image. Sampling and the gradient are the
//! ray caster's reference's ([`super::raycast`]).

use super::mesh::Tets;
use super::raycast::{box_interval, gradient, index_box, trilinear};
use ferrovol_core::*;
use glam::{DMat3, DMat4, DVec3, DVec4};
use std::f64::consts::PI;

/// The hybrid model, as the CPU reference sees it.
pub struct Hybrid {
    /// ψ (infinite: none) and the stochastic blend's rate k (0: the hard switch at ψ).
    threshold: f64,
    blend: f64,
    /// GGX roughness α, Fresnel reflectance at normal incidence, transmitted share of the
    /// non-specular part, the transmitted Phong lobe's exponent.
    roughness: f64,
    f0: f64,
    transmission: f64,
    exponent: f64,
    regions: ScatterRegions,
    attenuation: bool,
}

impl Hybrid {
    /// The model of `p`, None where it never looks at the gradient (HG everywhere).
    pub fn of(p: &PathTraceParams) -> Option<Hybrid> {
        let f = |v: f32| v as f64;
        if p.gradient_threshold.is_infinite() && p.stochastic_blend <= 0.0 {
            return None;
        }
        // half the lobe cos^m within the cone: 1 − cos^(m+1)(cone) = 1/2
        let cone = f(p.bsdf.cone_angle).to_radians();
        Some(Hybrid {
            threshold: f(p.gradient_threshold),
            blend: f(p.stochastic_blend),
            roughness: f(p.bsdf.roughness),
            f0: f(p.bsdf.fresnel),
            transmission: f(p.bsdf.transmission),
            exponent: (0.5f64.log(cone.cos()) - 1.0).max(0.0),
            regions: p.scatter,
            attenuation: p.attenuation,
        })
    }

    /// The BSDF's share of the collisions where the gradient magnitude is m.
    fn bsdf_share(&self, m: f64) -> f64 {
        if self.blend > 0.0 {
            -(-self.blend * m).exp_m1()
        } else if m > self.threshold {
            1.0
        } else {
            0.0
        }
    }
}

/// What a real collision does with the path: scatters by the BSDF with weight `bsdf`
/// (oriented by `n`, facing the arriving path, with Fresnel term `fresnel`) and by albedo ×
/// Henyey–Greenstein with weight `hg` (the albedo `hg_albedo`: the media's, weighted by
/// their shares of the collision); the weights' sum short of 1 is absorbed.
struct Kernel {
    bsdf: f64,
    hg: f64,
    hg_albedo: DVec3,
    n: DVec3,
    fresnel: f64,
}

/// A volume intermixed with the main one: its medium adds to the main one's (extinction from
/// its own linear opacity ramp over [0, 1] and unit distance, its own albedo), read without
/// its gradient (it scatters as the main medium where the gradient is zero), empty outside
/// its grid.
pub struct Intermixed {
    pub volume: VolumeData,
    /// World → the volume's index space.
    pub world_to_index: DMat4,
    pub alpha: [f64; 2],
    pub inv_unit: f64,
    pub albedo: DVec3,
}

impl Intermixed {
    /// Its extinction at world point p.
    fn sigma(&self, p: DVec3) -> f64 {
        let q = self.world_to_index.transform_point3(p);
        let (lo, hi) = index_box(&self.volume);
        if q.cmplt(lo).any() || q.cmpgt(hi).any() {
            return 0.0;
        }
        ramp_extinction(self.alpha, trilinear(&self.volume, q), self.inv_unit)
    }

    /// The largest extinction its ramp takes.
    pub fn majorant(&self) -> f64 {
        ramp_extinction(self.alpha, 1.0, self.inv_unit)
    }

    /// Its world box (lo, hi).
    fn world_box(&self) -> (DVec3, DVec3) {
        let (lo, hi) = index_box(&self.volume);
        let to_world = self.world_to_index.inverse();
        let mut b = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for c in 0..8 {
            let corner =
                DVec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo);
            let w = to_world.transform_point3(corner);
            b = (b.0.min(w), b.1.max(w));
        }
        b
    }
}

/// σ = −ln(1 − α) / unit distance for the opacity ramp `alpha` over scalars [0, 1] at s
/// (clamped), α clamped as the path tracer clamps it.
fn ramp_extinction(alpha: [f64; 2], s: f64, inv_unit: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    let a = (alpha[0] + (alpha[1] - alpha[0]) * s).min(0.9999);
    -(1.0 - a).ln() * inv_unit
}

/// Probabilities with which the reference draws a BSDF continuation from GGX half vectors,
/// the cosine around the normal, the Phong lobe around the propagation direction and
/// uniformly over the sphere (the last keeps every direction possible).
const PROPOSAL: [f64; 4] = [0.3, 0.3, 0.25, 0.15];

/// The main medium.
pub enum Medium {
    /// An image volume, its index space the world's, its extinction −ln(1 − α) / unit
    /// distance; the hybrid model applies.
    Grid(VolumeData),
    /// An unstructured mesh, its extinction α / unit distance; no hybrid model.
    Mesh(MeshMedium),
}

impl Medium {
    /// The medium's box (lo, hi): the grid's index box, or the mesh's bounding box.
    fn bounds(&self) -> (DVec3, DVec3) {
        match self {
            Medium::Grid(v) => index_box(v),
            Medium::Mesh(m) => (m.lo, m.hi),
        }
    }
}

/// How far outside a tetrahedron (in barycentric coordinates) a point still counts as in it:
/// a point on a face shared by two may be found in either.
const INSIDE_TOLERANCE: f64 = 1e-9;

/// An unstructured mesh as a medium: its tetrahedra ([`Tets::of`]) with their scalars, and
/// for point location a uniform grid of bins over its bounding box, each listing the
/// tetrahedra whose bounding boxes meet it.
pub struct MeshMedium {
    /// Per tetrahedron: its first point and the inverse of the matrix of its edges from
    /// there (x − p0 ↦ its barycentric coordinates 1 to 3).
    frames: Vec<(DVec3, DMat3)>,
    /// Per tetrahedron: the scalar at its four points (the cell's, four times, with cell
    /// scalars).
    scalars: Vec<[f64; 4]>,
    /// The scalars over which the opacity ramps from `Scene::alpha[0]` to `alpha[1]`.
    pub range: [f64; 2],
    /// The bounding box.
    lo: DVec3,
    hi: DVec3,
    /// Bins per axis and each bin's size.
    bins: [usize; 3],
    bin_size: DVec3,
    /// Bin b's tetrahedra are `items[start[b]..start[b + 1]]`.
    start: Vec<usize>,
    items: Vec<u32>,
}

impl MeshMedium {
    /// The mesh `v` (its first scalar component), its opacity ramp over the scalars `range`.
    pub fn new(v: &UnstructuredVolume, range: [f64; 2]) -> MeshMedium {
        let t = Tets::of(v);
        let mut frames = Vec::with_capacity(t.tets.len());
        let mut scalars = Vec::with_capacity(t.tets.len());
        let mut boxes = Vec::with_capacity(t.tets.len());
        for (k, ids) in t.tets.iter().enumerate() {
            let p = ids.map(|i| t.points[i as usize]);
            let edges = DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
            frames.push((p[0], edges.inverse()));
            scalars.push(if t.cell_scalars.is_empty() {
                ids.map(|i| t.point_scalars[i as usize])
            } else {
                [t.cell_scalars[k]; 4]
            });
            boxes.push(
                p.iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &q| {
                        (a.min(q), b.max(q))
                    }),
            );
        }
        let (lo, hi) = boxes
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &(c, d)| {
                (a.min(c), b.max(d))
            });
        // about as many bins as tetrahedra, as near to cubes as the box allows
        let size = hi - lo;
        let edge = (size.x * size.y * size.z / t.tets.len() as f64).cbrt();
        let bins = size.to_array().map(|e| ((e / edge).ceil() as usize).max(1));
        let bin_size = size / DVec3::from_array(bins.map(|b| b as f64));
        let mut mesh = MeshMedium {
            frames,
            scalars,
            range,
            lo,
            hi,
            bins,
            bin_size,
            start: vec![],
            items: vec![],
        };
        // each tetrahedron in the bins its box meets, by a counting sort
        let spans: Vec<_> = boxes
            .iter()
            .map(|&(a, b)| (mesh.bin(a), mesh.bin(b)))
            .collect();
        let index = |c: [usize; 3]| c[0] + bins[0] * (c[1] + bins[1] * c[2]);
        let each = |(a, b): ([usize; 3], [usize; 3]), f: &mut dyn FnMut(usize)| {
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        f(index([x, y, z]));
                    }
                }
            }
        };
        let mut count = vec![0usize; bins.iter().product::<usize>() + 1];
        for &span in &spans {
            each(span, &mut |b| count[b + 1] += 1);
        }
        for b in 1..count.len() {
            count[b] += count[b - 1];
        }
        let mut items = vec![0u32; count[count.len() - 1]];
        let mut next = count.clone();
        for (k, &span) in spans.iter().enumerate() {
            each(span, &mut |b| {
                items[next[b]] = k as u32;
                next[b] += 1;
            });
        }
        mesh.start = count;
        mesh.items = items;
        mesh
    }

    /// The number of tetrahedra.
    pub fn tetrahedra(&self) -> usize {
        self.frames.len()
    }

    /// The bin holding point p (clamped to the grid of bins).
    fn bin(&self, p: DVec3) -> [usize; 3] {
        let c = ((p - self.lo) / self.bin_size).to_array();
        [0, 1, 2].map(|a| (c[a].floor().max(0.0) as usize).min(self.bins[a] - 1))
    }

    /// The scalar at p, linear in the tetrahedron holding it; None outside every one.
    fn scalar(&self, p: DVec3) -> Option<f64> {
        if p.cmplt(self.lo).any() || p.cmpgt(self.hi).any() {
            return None;
        }
        let c = self.bin(p);
        let b = c[0] + self.bins[0] * (c[1] + self.bins[1] * c[2]);
        self.items[self.start[b]..self.start[b + 1]]
            .iter()
            .find_map(|&k| {
                let (p0, inv) = &self.frames[k as usize];
                let l = *inv * (p - *p0);
                let w = [1.0 - l.x - l.y - l.z, l.x, l.y, l.z];
                if w.iter().any(|&x| x < -INSIDE_TOLERANCE) {
                    return None;
                }
                let s = self.scalars[k as usize];
                Some((0..4).map(|i| w[i] * s[i]).sum())
            })
    }

    /// σ = α / unit distance at p for the opacity ramp `alpha` over [`MeshMedium::range`]
    /// (clamped beyond it); 0 outside the mesh.
    fn sigma(&self, p: DVec3, alpha: [f64; 2], inv_unit: f64) -> f64 {
        let Some(s) = self.scalar(p) else {
            return 0.0;
        };
        let [lo, hi] = self.range;
        let u = ((s - lo) / (hi - lo)).clamp(0.0, 1.0);
        (alpha[0] + (alpha[1] - alpha[0]) * u) * inv_unit
    }
}

/// The scene, as the CPU reference sees it (everything in f64; an image volume's index space
/// is the world).
pub struct Scene {
    /// Image size (pixels, square).
    pub size: u32,
    /// The main medium: the volume as the GPU holds it, or a mesh.
    pub medium: Medium,
    /// Opacity at the ends of the transfer function's linear ramp: scalars 0 and 1 for an
    /// image volume, the mesh's [`MeshMedium::range`] for a mesh.
    pub alpha: [f64; 2],
    pub inv_unit: f64,
    pub albedo: DVec3,
    pub g: f64,
    pub hybrid: Option<Hybrid>,
    pub max_bounces: u32,
    /// The largest σ anywhere (the opacity ramps rise, so at scalar 1, or a mesh's at the
    /// top of its range, max(α) / unit; the intermixed volumes' added).
    pub majorant: f64,
    /// Volumes intermixed with the main one.
    pub intermixed: Vec<Intermixed>,
    pub env_weight: f64,
    /// The world direction that is up in the sky, and its upper and lower radiance.
    pub env_up: DVec3,
    pub sky: [DVec3; 2],
    /// Directional lights: toward the light (None: the headlight, toward the camera along
    /// each camera path), and colour × intensity.
    pub lights: Vec<(Option<DVec3>, DVec3)>,
    /// Clip → world.
    pub inv_view_proj: DMat4,
}

/// Counts over the reference's paths: real collisions that scattered or absorbed, and the
/// BSDF's summed share of them.
#[derive(Clone, Copy, Default)]
pub struct Tally {
    pub collisions: u64,
    pub bsdf: f64,
}

/// The unit vector at polar cosine `cos` and azimuth `phi` about the unit vector z (any two
/// unit vectors perpendicular to z and to each other span the azimuth).
fn around(z: DVec3, cos: f64, phi: f64) -> DVec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let helper = if z.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let a = z.cross(helper).normalize();
    let b = z.cross(a);
    (cos * z + sin * (phi.cos() * a + phi.sin() * b)).normalize()
}

impl Scene {
    /// The gradient the hybrid model sees at p: half the difference of the interpolated
    /// scalar one voxel ahead and one behind along each axis (index = world units here).
    fn gradient(&self, p: DVec3) -> DVec3 {
        let Medium::Grid(volume) = &self.medium else {
            panic!("the hybrid model is an image volume's, not a mesh's");
        };
        gradient(volume, p, Interpolation::Linear, GradientMethod::Central)
    }

    /// The main medium's extinction at p (empty outside its grid or mesh): the image
    /// volume's trilinearly interpolated scalar (clamped to the box, as the texture's
    /// clamp-to-edge addressing does) through −ln(1 − α), or the mesh's α.
    fn sigma(&self, p: DVec3) -> f64 {
        match &self.medium {
            Medium::Grid(volume) => {
                let (lo, hi) = index_box(volume);
                if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                    return 0.0;
                }
                ramp_extinction(self.alpha, trilinear(volume, p), self.inv_unit)
            }
            Medium::Mesh(mesh) => mesh.sigma(p, self.alpha, self.inv_unit),
        }
    }

    /// The share of an intermixed medium's collisions that happen: its gradient taken as
    /// zero, the BSDF's share there is 0; without attenuation only the scattering ones.
    fn intermixed_share(&self) -> f64 {
        match &self.hybrid {
            Some(h) if !h.attenuation => match h.regions {
                ScatterRegions::Nowhere | ScatterRegions::Surfaces => 0.0,
                ScatterRegions::Between | ScatterRegions::Everywhere => 1.0,
            },
            _ => 1.0,
        }
    }

    /// The shares of the collisions at p that scatter by the BSDF and by HG, by the
    /// scattering regions (before attenuation's absorption or its absence), and the
    /// gradient.
    fn shares(&self, h: &Hybrid, p: DVec3) -> (f64, f64, DVec3) {
        let grad = self.gradient(p);
        let b = h.bsdf_share(grad.length());
        let (sb, sh) = match h.regions {
            ScatterRegions::Nowhere => (0.0, 0.0),
            ScatterRegions::Surfaces => (b, 0.0),
            ScatterRegions::Between => (0.0, 1.0 - b),
            ScatterRegions::Everywhere => (b, 1.0 - b),
        };
        (sb, sh, grad)
    }

    /// The extinction paths meet at p: without attenuation the collisions that do not
    /// scatter do not happen.
    fn extinction(&self, p: DVec3) -> f64 {
        self.main_extinction(p) + self.intermixed_extinction(p)
    }

    /// The main medium's part of `extinction`.
    fn main_extinction(&self, p: DVec3) -> f64 {
        let sigma = self.sigma(p);
        match &self.hybrid {
            Some(h) if !h.attenuation && sigma > 0.0 => {
                let (sb, sh, _) = self.shares(h, p);
                sigma * (sb + sh)
            }
            _ => sigma,
        }
    }

    /// The intermixed media's part of `extinction`, and their albedo weighted by it.
    fn intermixed_parts(&self, p: DVec3) -> (f64, DVec3) {
        let share = self.intermixed_share();
        self.intermixed
            .iter()
            .fold((0.0, DVec3::ZERO), |(e, a), v| {
                let s = v.sigma(p) * share;
                (e + s, a + s * v.albedo)
            })
    }

    fn intermixed_extinction(&self, p: DVec3) -> f64 {
        self.intermixed_parts(p).0
    }

    /// What a real collision at p does with a path propagating along d: the expected kernel
    /// over the media it may have met, each in proportion to its share of the extinction.
    fn kernel(&self, p: DVec3, d: DVec3) -> Kernel {
        let k = self.main_kernel(p, d);
        if self.intermixed.is_empty() {
            return k;
        }
        let main = self.main_extinction(p);
        let (others, albedo) = self.intermixed_parts(p);
        let total = main + others;
        if total <= 0.0 {
            return k;
        }
        let w = main / total;
        // an intermixed medium's collision scatters by Henyey–Greenstein with its albedo:
        // always, or with attenuation as the regions let it where the BSDF's share is 0
        let kept = match &self.hybrid {
            Some(h) if h.attenuation => match h.regions {
                ScatterRegions::Nowhere | ScatterRegions::Surfaces => 0.0,
                ScatterRegions::Between | ScatterRegions::Everywhere => 1.0,
            },
            _ => 1.0,
        };
        let hg = w * k.hg + (1.0 - w) * kept;
        let hg_albedo = if hg > 0.0 {
            (w * k.hg * k.hg_albedo + kept * albedo / total) / hg
        } else {
            DVec3::ZERO
        };
        Kernel {
            bsdf: w * k.bsdf,
            hg,
            hg_albedo,
            ..k
        }
    }

    /// What a real collision in the main medium at p does with a path propagating along d.
    fn main_kernel(&self, p: DVec3, d: DVec3) -> Kernel {
        let Some(h) = &self.hybrid else {
            return Kernel {
                bsdf: 0.0,
                hg: 1.0,
                hg_albedo: self.albedo,
                n: DVec3::ZERO,
                fresnel: 0.0,
            };
        };
        let (mut sb, mut sh, grad) = self.shares(h, p);
        if !h.attenuation {
            // (only the scattering collisions happened)
            let total = sb + sh;
            if total > 0.0 {
                sb /= total;
                sh /= total;
            }
        }
        let mut n = DVec3::ZERO;
        let mut fresnel = 0.0;
        if sb > 0.0 {
            n = grad.normalize();
            if n.dot(d) > 0.0 {
                n = -n;
            }
            let c = -n.dot(d);
            fresnel = h.f0 + (1.0 - h.f0) * (1.0 - c).powi(5);
        }
        Kernel {
            bsdf: sb,
            hg: sh,
            hg_albedo: self.albedo,
            n,
            fresnel,
        }
    }

    /// The BSDF's value h(w) (per steradian) for a path that arrived along d (h(w) =
    /// f(w)·|n·w|, so that it integrates to the albedo over the sphere).
    fn bsdf(&self, k: &Kernel, d: DVec3, w: DVec3) -> DVec3 {
        let h = self.hybrid.as_ref().expect("the hybrid model");
        let v = -d;
        let (cv, cl) = (k.n.dot(v), k.n.dot(w));
        let f = k.fresnel;
        let mut value = DVec3::ZERO;
        if cl > 0.0 {
            // GGX: D(m) = 1 / (π α² cos⁴θm (1 + tan²θm / α²)²); Smith's G1(c) / c =
            // 2 / (c + √(α² + (1 − α²) c²)) (finite at grazing view)
            let a2 = h.roughness * h.roughness;
            let m = (v + w).normalize();
            let cm = k.n.dot(m);
            let tan2 = (1.0 - cm * cm) / (cm * cm);
            let dist = 1.0 / (PI * a2 * cm.powi(4) * (1.0 + tan2 / a2).powi(2));
            let g1_over = |c: f64| 2.0 / (c + (a2 + (1.0 - a2) * c * c).sqrt());
            // D·G1(v)·G1(l)/(4 cos v cos l) × cos l
            let spec = dist * g1_over(cv) * g1_over(cl) * cl / 4.0;
            let lambert = cl / PI;
            value +=
                DVec3::splat(f * spec) + (1.0 - f) * (1.0 - h.transmission) * lambert * self.albedo;
        } else {
            let c = d.dot(w);
            if c > 0.0 {
                let phong = (h.exponent + 1.0) / (2.0 * PI) * c.powf(h.exponent);
                value += (1.0 - f) * h.transmission * phong * self.albedo;
            }
        }
        value
    }

    /// The density with which `bsdf_draw` draws w.
    fn bsdf_density(&self, k: &Kernel, d: DVec3, w: DVec3) -> f64 {
        let h = self.hybrid.as_ref().expect("the hybrid model");
        let v = -d;
        let mut pdf = PROPOSAL[3] / (4.0 * PI);
        // the half vector that reflects v into w, on the normal's side
        let hv = v + w;
        if hv.length_squared() > 1e-24 {
            let mut m = hv.normalize();
            if m.dot(k.n) < 0.0 {
                m = -m;
            }
            let cm = k.n.dot(m);
            if cm > 0.0 {
                // the half vectors' density D(m)·cos θm, mapped by 1 / (4 |v·m|)
                let a2 = h.roughness * h.roughness;
                let tan2 = (1.0 - cm * cm) / (cm * cm);
                let dist = 1.0 / (PI * a2 * cm.powi(4) * (1.0 + tan2 / a2).powi(2));
                pdf += PROPOSAL[0] * dist * cm / (4.0 * v.dot(m).abs().max(1e-300));
            }
        }
        pdf += PROPOSAL[1] * k.n.dot(w).max(0.0) / PI;
        let c = d.dot(w);
        if c > 0.0 {
            pdf += PROPOSAL[2] * (h.exponent + 1.0) / (2.0 * PI) * c.powf(h.exponent);
        }
        pdf
    }

    /// A direction from the reference's own mixture for the BSDF.
    fn bsdf_draw(&self, k: &Kernel, d: DVec3, rng: &mut Rng) -> DVec3 {
        let h = self.hybrid.as_ref().expect("the hybrid model");
        let (pick, u, phi) = (rng.next(), rng.next(), 2.0 * PI * rng.next());
        if pick < PROPOSAL[0] {
            // GGX half vector: tan²θm = α² u / (1 − u) has density D(m)·cos θm
            let tan2 = h.roughness * h.roughness * u / (1.0 - u);
            let m = around(k.n, 1.0 / (1.0 + tan2).sqrt(), phi);
            let v = -d;
            2.0 * v.dot(m) * m - v
        } else if pick < PROPOSAL[0] + PROPOSAL[1] {
            around(k.n, u.sqrt(), phi)
        } else if pick < PROPOSAL[0] + PROPOSAL[1] + PROPOSAL[2] {
            around(d, u.powf(1.0 / (h.exponent + 1.0)), phi)
        } else {
            around(d, 1.0 - 2.0 * u, phi)
        }
    }

    /// The kernel's value toward w (per steradian, rgb): what a path arriving along d
    /// carries on toward w.
    fn kernel_value(&self, k: &Kernel, d: DVec3, w: DVec3) -> DVec3 {
        let mut value = k.hg * self.phase(d.dot(w)) * k.hg_albedo;
        if k.bsdf > 0.0 {
            value += k.bsdf * self.bsdf(k, d, w);
        }
        value
    }

    /// A continuation for the kernel and its weight (value / density).
    fn kernel_sample(&self, k: &Kernel, d: DVec3, rng: &mut Rng) -> (DVec3, DVec3) {
        if k.bsdf <= 0.0 {
            return (self.scatter(d, rng), k.hg * k.hg_albedo);
        }
        // HG and the BSDF's mixture in proportion to their weights
        let q = k.hg / (k.hg + k.bsdf);
        let w = if q > 0.0 && rng.next() < q {
            self.scatter(d, rng)
        } else {
            self.bsdf_draw(k, d, rng)
        };
        let pdf = q * self.phase(d.dot(w)) + (1.0 - q) * self.bsdf_density(k, d, w);
        (w, self.kernel_value(k, d, w) / pdf)
    }

    /// Parameter interval of the ray o + t·d inside the medium's box (the volume's or the
    /// mesh's, or the world box holding every volume), from t = 0 on.
    fn box_interval(&self, o: DVec3, d: DVec3) -> (f64, f64) {
        let (lo, hi) = self
            .intermixed
            .iter()
            .map(Intermixed::world_box)
            .fold(self.medium.bounds(), |(a, b), (c, e)| (a.min(c), b.max(e)));
        let (t0, t1) = box_interval(o, d, lo, hi);
        (t0.max(0.0), t1)
    }

    /// Delta tracking: the distance of the first collision in [t0, t1), None if none.
    fn collide(&self, o: DVec3, d: DVec3, t0: f64, t1: f64, rng: &mut Rng) -> Option<f64> {
        let mut t = t0;
        loop {
            t += -(1.0 - rng.next()).ln() / self.majorant;
            if t >= t1 {
                return None;
            }
            if rng.next() * self.majorant < self.extinction(o + t * d) {
                return Some(t);
            }
        }
    }

    /// Ratio tracking: an unbiased estimate of the transmittance from p out of the box
    /// along d.
    fn transmittance(&self, p: DVec3, d: DVec3, rng: &mut Rng) -> f64 {
        let (t0, t1) = self.box_interval(p, d);
        let (mut t, mut tr) = (t0, 1.0);
        loop {
            t += -(1.0 - rng.next()).ln() / self.majorant;
            if t >= t1 {
                return tr;
            }
            tr *= 1.0 - self.extinction(p + t * d) / self.majorant;
        }
    }

    /// Henyey–Greenstein density over the sphere for the cosine between propagation
    /// directions.
    fn phase(&self, cos: f64) -> f64 {
        let g = self.g;
        (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
    }

    /// A direction scattered from d by Henyey–Greenstein (inverse CDF of the cosine).
    fn scatter(&self, d: DVec3, rng: &mut Rng) -> DVec3 {
        let g = self.g;
        let u = rng.next();
        let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u);
        let cos = ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0);
        around(d, cos, 2.0 * PI * rng.next())
    }

    fn environment(&self, d: DVec3) -> DVec3 {
        self.sky[usize::from(d.dot(self.env_up) < 0.0)] * self.env_weight
    }

    /// One path through pixel (x, y): radiance and whether it met the medium.
    fn path(&self, x: u32, y: u32, rng: &mut Rng, tally: &mut Tally) -> ([f64; 3], bool) {
        // the camera ray through a uniformly jittered point of the pixel, from the near
        // plane to the far plane
        let px = (x as f64 + rng.next()) / self.size as f64;
        let py = (y as f64 + rng.next()) / self.size as f64;
        let (nx, ny) = (2.0 * px - 1.0, 1.0 - 2.0 * py);
        let unproject = |z: f64| {
            let p = self.inv_view_proj * DVec4::new(nx, ny, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (unproject(-1.0), unproject(1.0));
        let view_dir = (far - near).normalize();
        let (t0, t1) = self.box_interval(near, view_dir);
        let t1 = t1.min((far - near).length());
        let Some(t) = self.collide(near, view_dir, t0, t1, rng) else {
            return ([0.0; 3], false);
        };
        let mut p = near + t * view_dir;
        let mut d = view_dir;
        // (colours as DVec3: r, g, b)
        let mut beta = DVec3::ONE;
        let mut radiance = DVec3::ZERO;
        for event in 1..=self.max_bounces {
            let k = self.kernel(p, d);
            tally.collisions += 1;
            tally.bsdf += k.bsdf;
            if k.bsdf + k.hg <= 0.0 {
                break;
            }
            for &(to_light, color) in &self.lights {
                let l = to_light.unwrap_or(-view_dir);
                let w = self.kernel_value(&k, d, l) * self.transmittance(p, l, rng);
                radiance += beta * w * color;
            }
            let (next, weight) = self.kernel_sample(&k, d, rng);
            beta *= weight;
            d = next;
            let (s0, s1) = self.box_interval(p, d);
            match self.collide(p, d, s0, s1, rng) {
                None => {
                    radiance += beta * self.environment(d);
                    break;
                }
                Some(t) if event < self.max_bounces => p += t * d,
                Some(_) => break,
            }
        }
        (radiance.to_array(), true)
    }
}

/// xoshiro256** (Blackman & Vigna), seeded by SplitMix64.
struct Rng([u64; 4]);

impl Rng {
    fn new(seed: u64) -> Rng {
        let mut z = seed;
        Rng([0; 4].map(|_| {
            z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut x = z;
            x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            x ^ (x >> 31)
        }))
    }

    /// Uniform in [0, 1) (53 bits).
    fn next(&mut self) -> f64 {
        let s = &mut self.0;
        let out = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        (out >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Per pixel: mean radiance and coverage, and the variance of the radiance's mean; and the
/// collisions' tally over all paths.
pub struct Reference {
    pub mean: Vec<[f64; 4]>,
    pub var: Vec<[f64; 3]>,
    pub tally: Tally,
}

/// `spp` reference paths per pixel, on two threads.
pub fn reference(scene: &Scene, spp: u32) -> Reference {
    assert!(
        scene.hybrid.is_none() || matches!(scene.medium, Medium::Grid(_)),
        "the hybrid model is an image volume's: a mesh scatters by Henyey–Greenstein"
    );
    let size = scene.size;
    let n = (size * size) as usize;
    let threads = 2;
    // per pixel: its index, mean radiance and coverage, variance of the radiance's mean
    type Pixel = (usize, [f64; 4], [f64; 3]);
    let parts: Vec<(Vec<Pixel>, Tally)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|th| {
                s.spawn(move || {
                    let mut out = vec![];
                    let mut tally = Tally::default();
                    for i in (th..n).step_by(threads) {
                        let mut rng = Rng::new(0x5eed_0000 + i as u64);
                        let (x, y) = ((i as u32) % size, (i as u32) / size);
                        let mut sum = [0.0f64; 4];
                        let mut sq = [0.0f64; 3];
                        for _ in 0..spp {
                            let (l, hit) = scene.path(x, y, &mut rng, &mut tally);
                            for c in 0..3 {
                                sum[c] += l[c];
                                sq[c] += l[c] * l[c];
                            }
                            sum[3] += f64::from(u8::from(hit));
                        }
                        let k = spp as f64;
                        let mean = sum.map(|v| v / k);
                        let var = [0, 1, 2].map(|c| (sq[c] / k - mean[c] * mean[c]).max(0.0) / k);
                        out.push((i, mean, var));
                    }
                    (out, tally)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut r = Reference {
        mean: vec![[0.0; 4]; n],
        var: vec![[0.0; 3]; n],
        tally: Tally::default(),
    };
    for (pixels, tally) in parts {
        for (i, m, v) in pixels {
            r.mean[i] = m;
            r.var[i] = v;
        }
        r.tally.collisions += tally.collisions;
        r.tally.bsdf += tally.bsdf;
    }
    r
}
