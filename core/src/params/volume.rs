//! Volume data on the CPU: scalars of any VTK scalar type, 1–4 components, and the
//! geometry that places the index grid in the world (spacing, origin, direction).

use crate::error::{Error, Result};

/// Scalar storage, one variant per VTK scalar type the renderer accepts.
/// Components are interleaved (`c0 c1 … c0 c1 …`), x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub enum Scalars {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    U32(Vec<u32>),
    I32(Vec<i32>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// The scalar type of a [`Scalars`] array.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ScalarType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl ScalarType {
    pub fn name(self) -> &'static str {
        match self {
            ScalarType::U8 => "uint8",
            ScalarType::I8 => "int8",
            ScalarType::U16 => "uint16",
            ScalarType::I16 => "int16",
            ScalarType::U32 => "uint32",
            ScalarType::I32 => "int32",
            ScalarType::F32 => "float32",
            ScalarType::F64 => "float64",
        }
    }
    pub fn size_bytes(self) -> usize {
        match self {
            ScalarType::U8 | ScalarType::I8 => 1,
            ScalarType::U16 | ScalarType::I16 => 2,
            ScalarType::U32 | ScalarType::I32 | ScalarType::F32 => 4,
            ScalarType::F64 => 8,
        }
    }
}

macro_rules! each_scalars {
    ($s:expr, $v:ident => $body:expr) => {
        match $s {
            Scalars::U8($v) => $body,
            Scalars::I8($v) => $body,
            Scalars::U16($v) => $body,
            Scalars::I16($v) => $body,
            Scalars::U32($v) => $body,
            Scalars::I32($v) => $body,
            Scalars::F32($v) => $body,
            Scalars::F64($v) => $body,
        }
    };
}

impl Scalars {
    pub fn len(&self) -> usize {
        each_scalars!(self, v => v.len())
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    pub fn scalar_type(&self) -> ScalarType {
        match self {
            Scalars::U8(_) => ScalarType::U8,
            Scalars::I8(_) => ScalarType::I8,
            Scalars::U16(_) => ScalarType::U16,
            Scalars::I16(_) => ScalarType::I16,
            Scalars::U32(_) => ScalarType::U32,
            Scalars::I32(_) => ScalarType::I32,
            Scalars::F32(_) => ScalarType::F32,
            Scalars::F64(_) => ScalarType::F64,
        }
    }
    /// Value `i` (flat index into the interleaved array) as f64.
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match self {
            Scalars::F64(v) => v[i],
            Scalars::U8(v) => v[i] as f64,
            Scalars::I8(v) => v[i] as f64,
            Scalars::U16(v) => v[i] as f64,
            Scalars::I16(v) => v[i] as f64,
            Scalars::U32(v) => v[i] as f64,
            Scalars::I32(v) => v[i] as f64,
            Scalars::F32(v) => v[i] as f64,
        }
    }
}

/// Row-major 3×3 matrix mapping index-axis directions to world directions (VTK's
/// vtkImageData::GetDirectionMatrix). Identity for axis-aligned data.
pub type Direction = [[f64; 3]; 3];

pub const IDENTITY_DIRECTION: Direction = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A volume: a regular grid of point samples. Point `(i, j, k)` sits at
/// `origin + direction · (spacing ⊙ (i, j, k))` in data (world) coordinates, as in VTK.
#[derive(Clone, Debug)]
pub struct VolumeData {
    pub dims: [u32; 3],
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    pub direction: Direction,
    /// Number of components per point, 1–4.
    pub components: u32,
    pub scalars: Scalars,
}

impl VolumeData {
    /// A volume with unit spacing, zero origin and identity direction. Validated.
    pub fn new(dims: [u32; 3], components: u32, scalars: Scalars) -> Result<Self> {
        let v = VolumeData {
            dims,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            direction: IDENTITY_DIRECTION,
            components,
            scalars,
        };
        v.validate()?;
        Ok(v)
    }

    pub fn with_spacing(mut self, spacing: [f64; 3]) -> Result<Self> {
        self.spacing = spacing;
        self.validate()?;
        Ok(self)
    }

    pub fn with_origin(mut self, origin: [f64; 3]) -> Result<Self> {
        self.origin = origin;
        self.validate()?;
        Ok(self)
    }

    pub fn with_direction(mut self, direction: Direction) -> Result<Self> {
        self.direction = direction;
        self.validate()?;
        Ok(self)
    }

    pub fn num_points(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Checks everything a renderer relies on; the error names the problem.
    pub fn validate(&self) -> Result<()> {
        if self.dims.contains(&0) {
            return Err(Error::InvalidVolume(format!(
                "empty volume: dimensions {}x{}x{} (every dimension must be at least 1)",
                self.dims[0], self.dims[1], self.dims[2]
            )));
        }
        if !(1..=4).contains(&self.components) {
            return Err(Error::InvalidVolume(format!(
                "{} components per point; ferrovol renders 1 to 4",
                self.components
            )));
        }
        let expected = self.num_points() * self.components as usize;
        if self.scalars.len() != expected {
            return Err(Error::InvalidVolume(format!(
                "{} scalar values for {}x{}x{} points with {} component(s): expected {}",
                self.scalars.len(),
                self.dims[0],
                self.dims[1],
                self.dims[2],
                self.components,
                expected
            )));
        }
        for (axis, s) in self.spacing.iter().enumerate() {
            if !s.is_finite() || *s <= 0.0 {
                return Err(Error::InvalidVolume(format!(
                    "spacing along {} is {s}; spacing must be finite and positive",
                    ["x", "y", "z"][axis]
                )));
            }
        }
        if self.origin.iter().any(|o| !o.is_finite()) {
            return Err(Error::InvalidVolume(format!(
                "origin {:?} is not finite",
                self.origin
            )));
        }
        let d = self.direction;
        let det = d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
            - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
            + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
        if !det.is_finite() || det.abs() < 1e-9 {
            return Err(Error::InvalidVolume(format!(
                "direction matrix {d:?} is singular (determinant {det})"
            )));
        }
        if let Some(i) = self.first_non_finite() {
            let c = self.components as usize;
            let p = i / c;
            let nx = self.dims[0] as usize;
            let ny = self.dims[1] as usize;
            return Err(Error::InvalidVolume(format!(
                "scalar at point ({}, {}, {}) component {} is {} (NaN and infinite values are not renderable)",
                p % nx,
                (p / nx) % ny,
                p / (nx * ny),
                i % c,
                self.scalars.get(i)
            )));
        }
        Ok(())
    }

    fn first_non_finite(&self) -> Option<usize> {
        match &self.scalars {
            Scalars::F32(v) => v.iter().position(|x| !x.is_finite()),
            Scalars::F64(v) => v.iter().position(|x| !x.is_finite()),
            _ => None,
        }
    }

    /// Minimum and maximum of component `c`.
    pub fn range(&self, c: u32) -> [f64; 2] {
        let nc = self.components as usize;
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let n = self.num_points();
        for p in 0..n {
            let v = self.scalars.get(p * nc + c as usize);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        [lo, hi]
    }

    /// Value of component `c` at point (i, j, k).
    #[inline]
    pub fn value(&self, i: u32, j: u32, k: u32, c: u32) -> f64 {
        let idx =
            (k as usize * self.dims[1] as usize + j as usize) * self.dims[0] as usize + i as usize;
        self.scalars
            .get(idx * self.components as usize + c as usize)
    }

    /// The 4×4 (column-major, glam) matrix from index space (i, j, k) to data coordinates.
    pub fn index_to_data(&self) -> glam::DMat4 {
        let d = self.direction;
        let s = self.spacing;
        // columns: direction column times spacing
        let c0 = glam::DVec4::new(d[0][0] * s[0], d[1][0] * s[0], d[2][0] * s[0], 0.0);
        let c1 = glam::DVec4::new(d[0][1] * s[1], d[1][1] * s[1], d[2][1] * s[1], 0.0);
        let c2 = glam::DVec4::new(d[0][2] * s[2], d[1][2] * s[2], d[2][2] * s[2], 0.0);
        let c3 = glam::DVec4::new(self.origin[0], self.origin[1], self.origin[2], 1.0);
        glam::DMat4::from_cols(c0, c1, c2, c3)
    }

    /// Axis-aligned bounds of the volume in data coordinates: [xmin, xmax, ymin, ymax, zmin, zmax].
    pub fn bounds(&self) -> [f64; 6] {
        let m = self.index_to_data();
        let mut b = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for corner in 0..8u32 {
            let ijk = glam::DVec3::new(
                if corner & 1 != 0 {
                    (self.dims[0] - 1) as f64
                } else {
                    0.0
                },
                if corner & 2 != 0 {
                    (self.dims[1] - 1) as f64
                } else {
                    0.0
                },
                if corner & 4 != 0 {
                    (self.dims[2] - 1) as f64
                } else {
                    0.0
                },
            );
            let p = m.transform_point3(ijk);
            for a in 0..3 {
                b[2 * a] = b[2 * a].min(p[a]);
                b[2 * a + 1] = b[2 * a + 1].max(p[a]);
            }
        }
        b
    }
}
