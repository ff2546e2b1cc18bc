//! Transfer functions: scalar → colour and opacity, gradient magnitude → opacity, sampled
//! into lookup tables the shaders read with linear interpolation.

use crate::error::{Error, Result};

/// Entries per lookup table. VTK's GPU mapper samples its tables at a similar resolution.
pub use crate::gpu::uniforms::TABLE_SIZE;

/// The largest position (x) a transfer-function point may have: the renderer samples the
/// functions between their end points into tables of 32-bit floats, so the span of the
/// points must be a finite 32-bit float.
pub const MAX_TRANSFER_POSITION: f64 = 1e38;

/// A piecewise-linear function of one variable (VTK's vtkPiecewiseFunction / the RGB
/// channels of vtkColorTransferFunction): points sorted by x, clamped outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise<const N: usize> {
    pub points: Vec<(f64, [f32; N])>,
}

impl<const N: usize> Piecewise<N> {
    /// Sorts `points` by x. Refuses an empty list, NaN or infinite numbers and positions
    /// beyond ±[`MAX_TRANSFER_POSITION`]; the error names the point (its index in `points`).
    pub fn new(mut points: Vec<(f64, [f32; N])>) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::InvalidTransferFunction(
                "a function needs at least one point".into(),
            ));
        }
        let problem = points.iter().enumerate().find_map(|(i, (x, v))| {
            if !x.is_finite() || v.iter().any(|c| !c.is_finite()) {
                Some(format!(
                    "point {i} is ({x:?}, {v:?}); NaN and infinite numbers are not allowed"
                ))
            } else if x.abs() > MAX_TRANSFER_POSITION {
                Some(format!(
                    "point {i} is at {x:?}, beyond ±{MAX_TRANSFER_POSITION:e} (the range the renderer's 32-bit tables span)"
                ))
            } else {
                None
            }
        });
        if let Some(problem) = problem {
            return Err(Error::InvalidTransferFunction(problem));
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(Piecewise { points })
    }

    /// The x range spanned by the points.
    pub fn range(&self) -> [f64; 2] {
        [self.points[0].0, self.points[self.points.len() - 1].0]
    }

    /// Evaluates the function at `x` (constant beyond the end points).
    pub fn eval(&self, x: f64) -> [f32; N] {
        let p = &self.points;
        if x <= p[0].0 {
            return p[0].1;
        }
        if x >= p[p.len() - 1].0 {
            return p[p.len() - 1].1;
        }
        let i = p.partition_point(|q| q.0 <= x);
        let (x0, v0) = p[i - 1];
        let (x1, v1) = p[i];
        let f = if x1 > x0 {
            ((x - x0) / (x1 - x0)) as f32
        } else {
            1.0
        };
        let mut out = [0.0; N];
        for c in 0..N {
            out[c] = v0[c] + (v1[c] - v0[c]) * f;
        }
        out
    }
}

/// Colour and opacity for one component (or for all of them when components are dependent).
#[derive(Clone, Debug, PartialEq)]
pub struct ComponentTransfer {
    pub color: Piecewise<3>,
    pub opacity: Piecewise<1>,
    /// Gradient magnitude (scalar units per world unit) → opacity multiplier; `None` = off.
    pub gradient_opacity: Option<Piecewise<1>>,
    /// VTK's ScalarOpacityUnitDistance: the world distance for which `opacity` is defined.
    pub unit_distance: f64,
    /// Weight of this component when components are independent (VTK's component weight).
    pub weight: f32,
    /// This component's own ambient, diffuse and specular coefficients and specular power
    /// (vtkVolumeProperty's per-component shading) when components are independent; `None`:
    /// the render parameters' shading.
    pub material: Option<[f32; 4]>,
    /// A 2D transfer function (vtkVolumeProperty's TF_2D mode) that classifies this
    /// component instead of `color`, `opacity` and `gradient_opacity` in composite ray
    /// casting and path tracing.
    pub table_2d: Option<Table2D>,
}

/// A 2D transfer function: colour and opacity over scalar × gradient magnitude, as
/// vtkVolumeProperty::SetTransferFunction2D's RGBA image.
#[derive(Clone, Debug, PartialEq)]
pub struct Table2D {
    pub width: u32,
    pub height: u32,
    /// `width × height` RGBA values, x (scalar) fastest, rows of increasing gradient
    /// magnitude. Ray casting reads the opacity as one sample's, whatever the sample
    /// distance and the component's `unit_distance` (VTK 9.2 uploads its 2D table as it
    /// is); the path tracer, which takes no samples, as the opacity per `unit_distance`,
    /// as it reads `opacity`.
    pub rgba: Vec<[f32; 4]>,
    /// The scalars the first and the last column's edges are at (VTK: the component's data
    /// range): a scalar s reads the table at (s − lo) / (hi − lo) · width texels.
    pub scalar_range: [f64; 2],
    /// The gradient magnitude (scalar units per world unit) at the last row's far edge; a
    /// sample reads the row of its gradient magnitude, clamped. `None`: every sample reads
    /// the first row (VTK's TF_2D without gradient opacity).
    pub gradient_max: Option<f64>,
}

impl Table2D {
    /// Checks the sizes and numbers, naming what is wrong.
    pub fn validate(&self) -> Result<()> {
        match self.problem() {
            Some(p) => Err(Error::InvalidTransferFunction(format!("2D table: {p}"))),
            None => Ok(()),
        }
    }

    fn problem(&self) -> Option<String> {
        if self.width == 0 || self.height == 0 || self.width > 4096 || self.height > 4096 {
            return Some(format!(
                "{}x{} entries; each side must be 1 to 4096",
                self.width, self.height
            ));
        }
        let n = self.width as usize * self.height as usize;
        if self.rgba.len() != n {
            return Some(format!(
                "{} RGBA values for {}x{} entries ({n})",
                self.rgba.len(),
                self.width,
                self.height
            ));
        }
        if let Some(i) = self
            .rgba
            .iter()
            .position(|v| v.iter().any(|c| !c.is_finite()))
        {
            return Some(format!(
                "entry {i} is {:?}; NaN and infinity are not allowed",
                self.rgba[i]
            ));
        }
        let [lo, hi] = self.scalar_range;
        let finite = |v: f64| v.is_finite() && v.abs() <= MAX_TRANSFER_POSITION;
        if !(finite(lo) && finite(hi) && hi > lo) {
            return Some(format!(
                "scalar range [{lo}, {hi}] must be finite (within ±{MAX_TRANSFER_POSITION:e}) \
                 with lo < hi"
            ));
        }
        match self.gradient_max {
            Some(g) if !(g.is_finite() && g > 0.0) => Some(format!(
                "gradient magnitude {g} of the last row must be positive"
            )),
            _ => None,
        }
    }
}

impl ComponentTransfer {
    pub fn new(color: Piecewise<3>, opacity: Piecewise<1>) -> Self {
        ComponentTransfer {
            color,
            opacity,
            gradient_opacity: None,
            unit_distance: 1.0,
            weight: 1.0,
            material: None,
            table_2d: None,
        }
    }

    /// The scalar range the colour/opacity table spans: the union of both functions' points.
    pub fn table_range(&self) -> [f64; 2] {
        let c = self.color.range();
        let o = self.opacity.range();
        widen([c[0].min(o[0]), c[1].max(o[1])])
    }

    pub fn gradient_range(&self) -> [f64; 2] {
        match &self.gradient_opacity {
            Some(g) => widen(g.range()),
            None => [0.0, 1.0],
        }
    }
}

/// `[lo, hi]` itself when it has a width; for a single position, a range from `lo` of
/// width 1 or, where 1 is below the resolution of `lo` (|lo| beyond 2^23), one 32-bit ulp
/// of `lo`, so that `hi > lo` in both the f64 tables and the shader's f32 uniforms.
fn widen([lo, hi]: [f64; 2]) -> [f64; 2] {
    if hi > lo {
        [lo, hi]
    } else {
        [lo, lo + (lo.abs() * f64::from(f32::EPSILON)).max(1.0)]
    }
}

/// A label's own functions (vtkVolumeProperty's SetLabelColor / SetLabelScalarOpacity /
/// SetLabelGradientOpacity): where a label-map mask gives a sample this label, these
/// classify it; a function left `None` is the first component's.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelTransfer {
    /// 1 to 255 (label 0 is the unlabelled background: the components' functions).
    pub label: u8,
    pub color: Option<Piecewise<3>>,
    pub opacity: Option<Piecewise<1>>,
    pub gradient_opacity: Option<Piecewise<1>>,
}

/// The transfer function of a volume: one [`ComponentTransfer`] per component when
/// components are independent, one in all when they are dependent.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    pub components: Vec<ComponentTransfer>,
    /// VTK's IndependentComponents (default true). When false: 2 components = (colour
    /// scalar, opacity scalar), 4 components = RGB direct + opacity scalar through the table.
    pub independent: bool,
    /// The labels' own functions, read where a label-map mask is set (one entry per label).
    pub labels: Vec<LabelTransfer>,
}

impl TransferFunction {
    /// One component, one colour ramp and one opacity ramp.
    pub fn single(c: ComponentTransfer) -> Self {
        TransferFunction {
            components: vec![c],
            independent: true,
            labels: Vec::new(),
        }
    }

    /// A grey ramp over `range` with opacity rising linearly from 0 to `max_opacity`.
    ///
    /// # Panics
    /// If `range` is not finite or reaches beyond ±[`MAX_TRANSFER_POSITION`].
    pub fn ramp(range: [f64; 2], max_opacity: f32) -> Self {
        let color = Piecewise::new(vec![(range[0], [0.0; 3]), (range[1], [1.0; 3])])
            .expect("a finite range within ±MAX_TRANSFER_POSITION");
        let opacity = Piecewise::new(vec![(range[0], [0.0]), (range[1], [max_opacity])])
            .expect("a finite range within ±MAX_TRANSFER_POSITION");
        Self::single(ComponentTransfer::new(color, opacity))
    }

    pub fn validate(&self, volume_components: u32) -> Result<()> {
        if self.components.is_empty() || self.components.len() > 4 {
            return Err(Error::InvalidTransferFunction(format!(
                "{} component transfer functions (give 1 to 4)",
                self.components.len()
            )));
        }
        for (i, c) in self.components.iter().enumerate() {
            if !(c.unit_distance.is_finite() && c.unit_distance > 0.0) {
                return Err(Error::InvalidTransferFunction(format!(
                    "component {i}: scalar opacity unit distance {} must be positive",
                    c.unit_distance
                )));
            }
            if !(c.weight.is_finite() && c.weight >= 0.0) {
                return Err(Error::InvalidTransferFunction(format!(
                    "component {i}: weight {} must be finite and non-negative",
                    c.weight
                )));
            }
            if let Some(p) = c.table_2d.as_ref().and_then(Table2D::problem) {
                return Err(Error::InvalidTransferFunction(format!(
                    "component {i}: 2D table: {p}"
                )));
            }
            if let Some(m) = c.material {
                if !m.iter().all(|v| v.is_finite() && *v >= 0.0) {
                    return Err(Error::InvalidTransferFunction(format!(
                        "component {i}: material {m:?} (ambient, diffuse, specular, specular \
                         power) must be finite and non-negative"
                    )));
                }
            }
        }
        let mut seen = [false; 256];
        for l in &self.labels {
            if l.label == 0 {
                return Err(Error::InvalidTransferFunction(
                    "label 0 is the unlabelled background, classified by the components' \
                     functions: give labels 1 to 255 their own"
                        .into(),
                ));
            }
            if std::mem::replace(&mut seen[l.label as usize], true) {
                return Err(Error::InvalidTransferFunction(format!(
                    "label {} has two entries; give each label one",
                    l.label
                )));
            }
        }
        if !(self.independent || volume_components == 2 || volume_components == 4) {
            return Err(Error::InvalidTransferFunction(format!(
                "dependent components need 2 or 4 components per point, the volume has {volume_components}"
            )));
        }
        Ok(())
    }

    /// The transfer for component `c` (the last one given is reused for the rest).
    pub fn component(&self, c: usize) -> &ComponentTransfer {
        &self.components[c.min(self.components.len() - 1)]
    }

    /// The highest label with functions of its own (0: none). Labels above it classify as
    /// the background does.
    pub fn max_label(&self) -> u8 {
        self.labels.iter().map(|l| l.label).max().unwrap_or(0)
    }

    /// Label `label`'s functions, those it lacks taken from the first component.
    pub fn label_transfer(&self, label: u8) -> ComponentTransfer {
        let mut t = self.component(0).clone();
        if let Some(l) = self.labels.iter().find(|l| l.label == label) {
            if let Some(c) = &l.color {
                t.color = c.clone();
            }
            if let Some(o) = &l.opacity {
                t.opacity = o.clone();
            }
            if let Some(g) = &l.gradient_opacity {
                t.gradient_opacity = Some(g.clone());
            }
        }
        t
    }

    /// The scalar and gradient-magnitude ranges every label's table spans: the union of the
    /// ranges of labels 1 to [`Self::max_label`] (theirs and the first component's).
    pub fn label_ranges(&self) -> ([f64; 2], [f64; 2]) {
        let mut r = (
            [f64::INFINITY, f64::NEG_INFINITY],
            [f64::INFINITY, f64::NEG_INFINITY],
        );
        for label in 1..=self.max_label() {
            let t = self.label_transfer(label);
            let (a, g) = (t.table_range(), t.gradient_range());
            r.0 = [r.0[0].min(a[0]), r.0[1].max(a[1])];
            r.1 = [r.1[0].min(g[0]), r.1[1].max(g[1])];
        }
        r
    }

    /// Whether some component is classified by a 2D table.
    pub fn has_2d(&self) -> bool {
        self.components.iter().any(|c| c.table_2d.is_some())
    }

    /// Whether some label from 1 to [`Self::max_label`] has a gradient opacity function.
    pub fn labels_gradient_opacity(&self) -> bool {
        (1..=self.max_label()).any(|l| self.label_transfer(l).gradient_opacity.is_some())
    }
}

/// Opacity correction for a step of `step` world units, VTK's meaning of the unit distance:
/// α' = 1 − (1 − α)^(step / unit_distance).
pub fn correct_opacity(alpha: f32, step: f64, unit_distance: f64) -> f32 {
    let a = alpha.clamp(0.0, 1.0) as f64;
    (1.0 - (1.0 - a).powf(step / unit_distance)) as f32
}

/// The lookup tables of one component, laid out as the shader reads them: `TABLE_SIZE`
/// entries of (r, g, b, α corrected for the step) then `TABLE_SIZE` entries of
/// (α, gradient opacity, 0, 0).
pub fn build_tables(c: &ComponentTransfer, step: f64) -> Vec<[f32; 4]> {
    build_tables_over(c, step, c.table_range(), c.gradient_range())
}

/// [`build_tables`] over the scalar range `[lo, hi]` and gradient range `[glo, ghi]`.
pub fn build_tables_over(
    c: &ComponentTransfer,
    step: f64,
    [lo, hi]: [f64; 2],
    [glo, ghi]: [f64; 2],
) -> Vec<[f32; 4]> {
    let n = TABLE_SIZE;
    let mut out = Vec::with_capacity(2 * n);
    for i in 0..n {
        let x = lo + (hi - lo) * i as f64 / (n - 1) as f64;
        let rgb = c.color.eval(x);
        let a = c.opacity.eval(x)[0].clamp(0.0, 1.0);
        out.push([
            rgb[0],
            rgb[1],
            rgb[2],
            correct_opacity(a, step, c.unit_distance),
        ]);
    }
    for i in 0..n {
        let x = lo + (hi - lo) * i as f64 / (n - 1) as f64;
        let a = c.opacity.eval(x)[0].clamp(0.0, 1.0);
        let g = match &c.gradient_opacity {
            Some(go) => go.eval(glo + (ghi - glo) * i as f64 / (n - 1) as f64)[0].clamp(0.0, 1.0),
            None => 1.0,
        };
        out.push([a, g, 0.0, 0.0]);
    }
    out
}

/// The pre-integration table of one component (Engel, Kraus, Ertl 2001): for a ray segment
/// of `step` world units along which the scalar runs linearly from the front sample's value
/// to the back sample's, the premultiplied colour and the opacity the segment adds. Entry
/// `front · TABLE_SIZE + back` holds (r·α, g·α, b·α, α) for the scalars at table entries
/// `front` and `back` (the positions of [`build_tables`]).
///
/// Between entries the colour and the extinction τ = −ln(1 − α) / unit distance (VTK's
/// meaning of the unit distance) vary linearly, as the shader's linear reads of the
/// one-dimensional table make them at small steps. Integral functions over the entries
/// (Engel et al.) make the table O(n²): T(s) = ∫τ ds and K(s) = ∫c·τ ds, exact for
/// piecewise-linear c and τ. The segment's opacity is exact, 1 − exp(−step·ΔT / Δs); its
/// colour is the τ-weighted mean colour ΔK / ΔT times that opacity, which leaves out the
/// order of emission inside the segment (exact where the colour is constant across it, and
/// never brighter than the opacity allows). A segment of one value (front = back) is the
/// one-dimensional table's entry: colour c and opacity corrected for the step.
pub fn build_preintegration(c: &ComponentTransfer, step: f64) -> Vec<[f32; 4]> {
    let [lo, hi] = c.table_range();
    let n = TABLE_SIZE;
    let (mut color, mut tau) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let x = lo + (hi - lo) * i as f64 / (n - 1) as f64;
        let a = f64::from(c.opacity.eval(x)[0].clamp(0.0, 1.0));
        color.push(c.color.eval(x).map(f64::from));
        // α = 1 has no finite extinction: one that leaves 1e-12 of the light over a unit
        tau.push(-(1.0 - a).max(1e-12).ln() / c.unit_distance);
    }
    // Integral functions in table entries as the scalar unit: t[i] = ∫τ, k[i] = ∫c·τ up to
    // entry i, each cell's integral that of the product of two linear functions.
    let (mut t, mut k) = (vec![0.0; n], vec![[0.0; 3]; n]);
    for i in 1..n {
        let (t0, t1) = (tau[i - 1], tau[i]);
        t[i] = t[i - 1] + 0.5 * (t0 + t1);
        for ch in 0..3 {
            let (c0, c1) = (color[i - 1][ch], color[i][ch]);
            k[i][ch] = k[i - 1][ch] + (2.0 * (c0 * t0 + c1 * t1) + c0 * t1 + c1 * t0) / 6.0;
        }
    }
    let mut out = Vec::with_capacity(n * n);
    for f in 0..n {
        for b in 0..n {
            let (rgb, optical) = if f == b {
                (color[f], tau[f] * step)
            } else {
                let cells = f.abs_diff(b) as f64;
                let dt = (t[b] - t[f]).abs();
                let mean = if dt > 0.0 {
                    [0, 1, 2].map(|ch| (k[b][ch] - k[f][ch]).abs() / dt)
                } else {
                    [0.0; 3]
                };
                (mean, dt * step / cells)
            };
            let a = 1.0 - (-optical).exp();
            out.push([
                (rgb[0] * a) as f32,
                (rgb[1] * a) as f32,
                (rgb[2] * a) as f32,
                a as f32,
            ]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_interpolates_and_clamps() {
        let f = Piecewise::new(vec![(10.0, [1.0]), (0.0, [0.0])]).unwrap();
        assert_eq!(f.eval(-5.0), [0.0]);
        assert_eq!(f.eval(5.0), [0.5]);
        assert_eq!(f.eval(50.0), [1.0]);
    }

    #[test]
    fn opacity_correction_matches_vtk_definition() {
        // Two half steps compose to one unit step.
        let a = 0.4;
        let h = correct_opacity(a, 0.5, 1.0);
        let two = 1.0 - (1.0 - h) * (1.0 - h);
        assert!((two - a).abs() < 1e-6, "{two} vs {a}");
        assert_eq!(correct_opacity(a, 1.0, 1.0), a);
    }

    #[test]
    fn empty_function_is_an_error() {
        assert!(Piecewise::<1>::new(vec![]).is_err());
        assert!(Piecewise::<1>::new(vec![(f64::NAN, [0.0])]).is_err());
    }

    /// Positions beyond ±1e38 made build_tables panic (a span of ±1e308 is infinite, the
    /// sample positions NaN); every caller (JSON, C ABI, VTK through the C ABI) now gets an
    /// error naming the point, and the widest accepted span samples to finite tables.
    #[test]
    fn positions_beyond_the_table_range_are_refused() {
        for (points, want) in [
            (
                vec![(-1e308, [0.0]), (1e308, [1.0])],
                "point 0 is at -1e308, beyond ±1e38",
            ),
            (
                vec![(0.0, [0.0]), (3.5e38, [1.0])],
                "point 1 is at 3.5e38, beyond ±1e38",
            ),
            (
                vec![(0.0, [0.0]), (1.0, [f32::NAN]), (f64::INFINITY, [1.0])],
                "point 1 is (1.0, [NaN]); NaN and infinite numbers are not allowed",
            ),
        ] {
            let e = Piecewise::<1>::new(points).unwrap_err().to_string();
            println!("{e}");
            assert!(e.contains(want), "{e}");
        }
        fn widest<const N: usize>(v: [f32; N]) -> Piecewise<N> {
            Piecewise::new(vec![(-1e38, v), (1e38, v)]).unwrap()
        }
        let mut c = ComponentTransfer::new(widest([1.0; 3]), widest([0.5]));
        c.gradient_opacity = Some(widest([1.0]));
        let tables = build_tables(&c, 1.0);
        assert!(tables.iter().flatten().all(|x| x.is_finite()));
    }

    /// A single point where x + 1 == x (beyond 2^53) gave a table range of width 0: the
    /// shader's 1 / width was infinite. The width is now at least one 32-bit ulp of x.
    #[test]
    fn single_point_ranges_have_width() {
        for x in [0.0, -5.0, 1e10, 2f64.powi(53), 1e17, -1e30, 1e38, -1e38] {
            let c = ComponentTransfer::new(
                Piecewise::new(vec![(x, [1.0; 3])]).unwrap(),
                Piecewise::new(vec![(x, [0.5])]).unwrap(),
            );
            let mut g = c.clone();
            g.gradient_opacity = Some(Piecewise::new(vec![(x, [1.0])]).unwrap());
            for [lo, hi] in [c.table_range(), g.gradient_range()] {
                assert_eq!(lo, x);
                assert!(hi > lo, "{x}: [{lo}, {hi}]");
                assert!((hi as f32) > (lo as f32), "{x}: [{lo}, {hi}] in f32");
                let inv = (1.0 / (hi - lo)) as f32;
                assert!(inv.is_finite() && inv > 0.0, "{x}: 1 / width = {inv}");
            }
            let tables = build_tables(&g, 1.0);
            assert!(tables.iter().flatten().all(|v| v.is_finite()), "{x}");
        }
    }

    /// The pre-integrated table: constant segments are the step-corrected 1D entries; a
    /// segment across a thin peak holds the peak's optical depth spread over the step's
    /// scalar span, in either direction; colour never exceeds opacity.
    #[test]
    fn preintegration_integrates_between_the_samples() {
        let n = TABLE_SIZE;
        let grey = Piecewise::new(vec![(0.0, [1.0; 3]), (1023.0, [1.0; 3])]).unwrap();
        // a peak one table entry wide at entry 500 (scalar = entry)
        let peak = Piecewise::new(vec![
            (0.0, [0.0]),
            (499.0, [0.0]),
            (500.0, [0.5]),
            (501.0, [0.0]),
            (1023.0, [0.0]),
        ])
        .unwrap();
        let c = ComponentTransfer::new(grey, peak);
        let step = 0.5;
        let t0 = std::time::Instant::now();
        let pre = build_preintegration(&c, step);
        println!(
            "pre-integration table {n}²: built in {:.1} ms",
            t0.elapsed().as_secs_f64() * 1e3
        );
        let one = build_tables(&c, step);
        assert_eq!(pre.len(), n * n);
        for i in [0, 499, 500, 501] {
            let e = pre[i * n + i];
            assert!(
                (e[3] - one[i][3]).abs() < 1e-6,
                "{i}: {e:?} vs {:?}",
                one[i]
            );
        }
        // across the peak: ∫τ ds over entries 499..501 = τ(0.5) = ln 2 (per unit distance,
        // per scalar unit), and the ray crosses cells = |b − f| scalar units in one step
        for (f, b) in [(400usize, 600usize), (600, 400), (499, 501), (0, 1023)] {
            let want = 1.0 - 2f64.powf(-step / f.abs_diff(b) as f64);
            let e = pre[f * n + b];
            println!("segment {f}→{b}: α {:.6} (want {want:.6})", e[3]);
            assert!((e[3] as f64 - want).abs() < 1e-5, "{f}→{b}: {e:?}");
            assert!(e[0] <= e[3] + 1e-6);
        }
        // a segment that misses the peak adds nothing
        assert_eq!(pre[100 * n + 400][3], 0.0);
        assert!(pre.iter().flatten().all(|v| v.is_finite()));
    }
}
