//! Transfer functions: scalar → colour and opacity, gradient magnitude → opacity, sampled
//! into lookup tables the shaders read with linear interpolation.

use crate::error::{Error, Result};

/// Entries per lookup table. VTK's GPU mapper samples its tables at a similar resolution.
pub use crate::gpu::uniforms::TABLE_SIZE;

/// A piecewise-linear function of one variable (VTK's vtkPiecewiseFunction / the RGB
/// channels of vtkColorTransferFunction): points sorted by x, clamped outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise<const N: usize> {
    pub points: Vec<(f64, [f32; N])>,
}

impl<const N: usize> Piecewise<N> {
    pub fn new(mut points: Vec<(f64, [f32; N])>) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::InvalidTransferFunction(
                "a function needs at least one point".into(),
            ));
        }
        if points
            .iter()
            .any(|(x, v)| !x.is_finite() || v.iter().any(|c| !c.is_finite()))
        {
            return Err(Error::InvalidTransferFunction(format!(
                "non-finite value among the points {points:?}"
            )));
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
}

impl ComponentTransfer {
    pub fn new(color: Piecewise<3>, opacity: Piecewise<1>) -> Self {
        ComponentTransfer {
            color,
            opacity,
            gradient_opacity: None,
            unit_distance: 1.0,
            weight: 1.0,
        }
    }

    /// The scalar range the colour/opacity table spans: the union of both functions' points.
    pub fn table_range(&self) -> [f64; 2] {
        let c = self.color.range();
        let o = self.opacity.range();
        let lo = c[0].min(o[0]);
        let mut hi = c[1].max(o[1]);
        if hi <= lo {
            hi = lo + 1.0;
        }
        [lo, hi]
    }

    pub fn gradient_range(&self) -> [f64; 2] {
        match &self.gradient_opacity {
            Some(g) => {
                let r = g.range();
                if r[1] > r[0] {
                    r
                } else {
                    [r[0], r[0] + 1.0]
                }
            }
            None => [0.0, 1.0],
        }
    }
}

/// The transfer function of a volume: one [`ComponentTransfer`] per component when
/// components are independent, one in all when they are dependent.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    pub components: Vec<ComponentTransfer>,
    /// VTK's IndependentComponents (default true). When false: 2 components = (colour
    /// scalar, opacity scalar), 4 components = RGB direct + opacity scalar through the table.
    pub independent: bool,
}

impl TransferFunction {
    /// One component, one colour ramp and one opacity ramp.
    pub fn single(c: ComponentTransfer) -> Self {
        TransferFunction {
            components: vec![c],
            independent: true,
        }
    }

    /// A grey ramp over `range` with opacity rising linearly from 0 to `max_opacity`.
    pub fn ramp(range: [f64; 2], max_opacity: f32) -> Self {
        let color =
            Piecewise::new(vec![(range[0], [0.0; 3]), (range[1], [1.0; 3])]).expect("finite");
        let opacity =
            Piecewise::new(vec![(range[0], [0.0]), (range[1], [max_opacity])]).expect("finite");
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
    let [lo, hi] = c.table_range();
    let [glo, ghi] = c.gradient_range();
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
}
