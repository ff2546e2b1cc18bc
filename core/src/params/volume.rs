//! Volume data on the CPU: scalars of any VTK scalar type, 1–4 components, and the
//! geometry that places the index grid in the world (spacing, origin, direction).

use crate::error::{Error, Result};
use std::sync::Arc;

/// Scalar values that are not held in memory: read from a file, or computed, in
/// contiguous runs as the renderer needs them. The renderer reads a volume by whole
/// x-rows (the min–max grid once at upload, each brick when it becomes resident), so a
/// source is never asked for the whole volume at once.
pub trait ScalarSource: Send + Sync + std::fmt::Debug {
    /// The type the values have (and are stored on the device as).
    fn scalar_type(&self) -> ScalarType;
    /// Number of values (points × components).
    fn len(&self) -> usize;
    /// Whether there are no values.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Reads the values `start .. start + out.len()` (components interleaved as in
    /// [`Scalars`]) into `out`. Every value must be exactly representable by
    /// [`ScalarSource::scalar_type`]. The range lies within `len()`.
    fn read(&self, start: usize, out: &mut [f64]) -> std::io::Result<()>;
}

/// Scalar storage, one variant per VTK scalar type the renderer accepts, or a
/// [`ScalarSource`] read in runs. Components are interleaved (`c0 c1 … c0 c1 …`), x
/// fastest, then y, then z.
///
/// Sources are not scanned for NaN and infinite values by [`VolumeData::validate`] (that
/// would read the whole volume each time a builder method validates); the upload reads
/// every value once for the min–max grid and refuses such a value there.
#[derive(Clone, Debug)]
pub enum Scalars {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    U32(Vec<u32>),
    I32(Vec<i32>),
    F32(Vec<f32>),
    F64(Vec<f64>),
    Source(Arc<dyn ScalarSource>),
}

impl PartialEq for Scalars {
    /// In-memory arrays compare by value; sources only by identity (comparing them by
    /// value would read both whole).
    fn eq(&self, other: &Scalars) -> bool {
        use Scalars::*;
        match (self, other) {
            (U8(a), U8(b)) => a == b,
            (I8(a), I8(b)) => a == b,
            (U16(a), U16(b)) => a == b,
            (I16(a), I16(b)) => a == b,
            (U32(a), U32(b)) => a == b,
            (I32(a), I32(b)) => a == b,
            (F32(a), F32(b)) => a == b,
            (F64(a), F64(b)) => a == b,
            (Source(a), Source(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
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
            Scalars::Source($v) => $body,
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
            Scalars::Source(s) => s.scalar_type(),
        }
    }

    /// The source, for scalars that are not in memory.
    pub fn source(&self) -> Option<&Arc<dyn ScalarSource>> {
        match self {
            Scalars::Source(s) => Some(s),
            _ => None,
        }
    }

    /// Reads the values `start .. start + out.len()` into `out`: one call to a source for
    /// the whole run (a positioned read of a file, say), a conversion for arrays in memory.
    pub fn read_run(&self, start: usize, out: &mut [f64]) -> Result<()> {
        fn conv<T: Copy + Into<f64>>(v: &[T], start: usize, out: &mut [f64]) {
            let n = out.len();
            for (o, &x) in out.iter_mut().zip(&v[start..start + n]) {
                *o = x.into();
            }
        }
        match self {
            Scalars::U8(v) => conv(v, start, out),
            Scalars::I8(v) => conv(v, start, out),
            Scalars::U16(v) => conv(v, start, out),
            Scalars::I16(v) => conv(v, start, out),
            Scalars::U32(v) => conv(v, start, out),
            Scalars::I32(v) => conv(v, start, out),
            Scalars::F32(v) => conv(v, start, out),
            Scalars::F64(v) => out.copy_from_slice(&v[start..start + out.len()]),
            Scalars::Source(s) => {
                if start + out.len() > s.len() {
                    return Err(Error::InvalidVolume(format!(
                        "values {start}..{} asked of a source of {} values",
                        start + out.len(),
                        s.len()
                    )));
                }
                s.read(start, out).map_err(|e| {
                    Error::Source(format!(
                        "values {start}..{} of {s:?}: {e}",
                        start + out.len()
                    ))
                })?
            }
        }
        Ok(())
    }

    /// Value `i` (flat index into the interleaved array) as f64.
    ///
    /// # Panics
    /// If a source fails to read the value ([`Scalars::read_run`] returns the error
    /// instead). Reading a source one value at a time is slow: read runs.
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
            Scalars::Source(_) => {
                let mut out = [0.0];
                if let Err(e) = self.read_run(i, &mut out) {
                    panic!("{e}");
                }
                out[0]
            }
        }
    }
}

/// Row-major 3×3 matrix mapping index-axis directions to world directions (VTK's
/// vtkImageData::GetDirectionMatrix). Identity for axis-aligned data.
pub type Direction = [[f64; 3]; 3];

pub const IDENTITY_DIRECTION: Direction = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A volume: a regular grid of point samples. Point `(i, j, k)` sits at
/// `origin + direction · (spacing ⊙ (i, j, k))` in data (world) coordinates, as in VTK;
/// with per-axis [`VolumeData::coordinates`] (VTK's vtkRectilinearGrid) it sits at
/// `origin + direction · (x_i − x_0, y_j − y_0, z_k − z_0)` instead, and `origin` and
/// `spacing` describe the uniform lattice over the same box (see
/// [`VolumeData::with_coordinates`]).
#[derive(Clone, Debug)]
pub struct VolumeData {
    pub dims: [u32; 3],
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    pub direction: Direction,
    /// Number of components per point, 1–4.
    pub components: u32,
    pub scalars: Scalars,
    /// Per-axis point coordinates (strictly increasing, one per point), or none for a
    /// uniform grid.
    pub coordinates: Option<Arc<[Vec<f64>; 3]>>,
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Columns of a rectilinear grid's lookup per width of its narrowest cell
/// ([`VolumeData::grid_lookup`]).
const LOOKUP_COLUMNS_PER_CELL: f64 = 64.0;

/// Checks per-axis coordinates against the grid's dimensions: one per point, finite,
/// strictly increasing; the error names the axis and the first offending value.
fn check_coordinates(dims: [u32; 3], coordinates: &[Vec<f64>; 3]) -> Result<()> {
    for (a, c) in coordinates.iter().enumerate() {
        if c.len() != dims[a] as usize {
            return Err(Error::InvalidVolume(format!(
                "{} {} coordinates for a grid of {} points along {}: give one per point",
                c.len(),
                AXES[a],
                dims[a],
                AXES[a]
            )));
        }
        if let Some(i) = c.iter().position(|x| !x.is_finite()) {
            return Err(Error::InvalidVolume(format!(
                "{} coordinate {i} is {}: coordinates must be finite",
                AXES[a], c[i]
            )));
        }
        if let Some(i) = c.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::InvalidVolume(format!(
                "{} coordinates {} and {} are {} and {}: coordinates must be strictly increasing",
                AXES[a],
                i,
                i + 1,
                c[i],
                c[i + 1]
            )));
        }
    }
    Ok(())
}

/// The largest world coordinate (and extent) a volume's bounds may reach: the GPU
/// computes positions in 32-bit floats.
const MAX_COORDINATE: f64 = f32::MAX as f64;

/// For bounds (`[xmin, xmax, ymin, …]`) beyond [`MAX_COORDINATE`] along an axis, the
/// message's start: "bounds along x are [lo, hi], beyond the 32-bit float range …".
pub(crate) fn beyond_f32(b: [f64; 6]) -> Option<String> {
    (0..3).find_map(|axis| {
        let [lo, hi] = [b[2 * axis], b[2 * axis + 1]];
        let within =
            lo.abs() <= MAX_COORDINATE && hi.abs() <= MAX_COORDINATE && hi - lo <= MAX_COORDINATE;
        (!within).then(|| {
            format!(
                "bounds along {} are [{lo:e}, {hi:e}], beyond the 32-bit float range \
                 (±{MAX_COORDINATE:.1e}) the GPU computes in",
                ["x", "y", "z"][axis]
            )
        })
    })
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
            coordinates: None,
        };
        v.validate()?;
        Ok(v)
    }

    /// Places the points at per-axis coordinates (a rectilinear grid): `coordinates[a]`
    /// holds one strictly increasing, finite coordinate per point along axis `a`. Sets
    /// `origin` to the first coordinates and `spacing` to the uniform lattice over the
    /// same box ((last − first) / (points − 1); an axis of one point keeps its spacing),
    /// which rays march in; each sample is mapped to the grid's index space per axis.
    pub fn with_coordinates(mut self, coordinates: [Vec<f64>; 3]) -> Result<Self> {
        self.set_coordinates(coordinates)?;
        Ok(self)
    }

    /// [`VolumeData::with_coordinates`] in place; on an error the volume is unchanged.
    pub fn set_coordinates(&mut self, coordinates: [Vec<f64>; 3]) -> Result<()> {
        check_coordinates(self.dims, &coordinates)?;
        let before = (self.origin, self.spacing, self.coordinates.take());
        for (a, c) in coordinates.iter().enumerate() {
            self.origin[a] = c[0];
            if c.len() > 1 {
                self.spacing[a] = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64;
            }
        }
        self.coordinates = Some(Arc::new(coordinates));
        if let Err(e) = self.validate() {
            (self.origin, self.spacing, self.coordinates) = before;
            return Err(e);
        }
        Ok(())
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
        if let Some(beyond) = beyond_f32(self.bounds()) {
            return Err(Error::InvalidVolume(format!(
                "the volume's {beyond}: origin {:?}, spacing {:?}, dimensions {}x{}x{}",
                self.origin, self.spacing, self.dims[0], self.dims[1], self.dims[2]
            )));
        }
        if let Some(c) = &self.coordinates {
            check_coordinates(self.dims, c)?;
            for (a, c) in c.iter().enumerate() {
                let n = c.len();
                let span = c[n - 1] - c[0];
                let lattice = self.spacing[a] * (n - 1) as f64;
                let tolerance = 1e-9 * span.abs().max(c[0].abs());
                if (self.origin[a] - c[0]).abs() > tolerance || (lattice - span).abs() > tolerance {
                    return Err(Error::InvalidVolume(format!(
                        "the {} coordinates run from {} to {}, but the origin ({}) and spacing \
                         ({}) place the grid elsewhere: set the coordinates after the origin \
                         and spacing (with_coordinates sets both)",
                        AXES[a],
                        c[0],
                        c[n - 1],
                        self.origin[a],
                        self.spacing[a]
                    )));
                }
            }
        }
        if let Some(i) = self.first_non_finite() {
            return Err(self.non_finite(i, self.scalars.get(i)));
        }
        Ok(())
    }

    /// The error for the non-finite `value` at flat index `i`.
    pub(crate) fn non_finite(&self, i: usize, value: f64) -> Error {
        let c = self.components as usize;
        let p = i / c;
        let nx = self.dims[0] as usize;
        let ny = self.dims[1] as usize;
        Error::InvalidVolume(format!(
            "scalar at point ({}, {}, {}) component {} is {} (NaN and infinite values are not renderable)",
            p % nx,
            (p / nx) % ny,
            p / (nx * ny),
            i % c,
            value
        ))
    }

    /// The first NaN or infinite value of in-memory data (a source's values are checked
    /// as the upload reads them: see [`Scalars`]).
    fn first_non_finite(&self) -> Option<usize> {
        match &self.scalars {
            Scalars::F32(v) => v.iter().position(|x| !x.is_finite()),
            Scalars::F64(v) => v.iter().position(|x| !x.is_finite()),
            _ => None,
        }
    }

    /// Minimum and maximum of component `c`.
    ///
    /// # Panics
    /// If a source fails to read ([`VolumeData::try_range`] returns the error instead).
    pub fn range(&self, c: u32) -> [f64; 2] {
        match self.try_range(c) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        }
    }

    /// [`VolumeData::range`], reading a source in runs of whole x-rows.
    pub fn try_range(&self, c: u32) -> Result<[f64; 2]> {
        let nc = self.components as usize;
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let n = self.num_points();
        if self.scalars.source().is_some() {
            let row = self.dims[0] as usize * nc;
            let rows_per_read = (1 << 16) / row + 1;
            let mut buf = vec![0.0; rows_per_read * row];
            let total = n * nc;
            let mut start = 0;
            while start < total {
                let len = buf.len().min(total - start);
                self.scalars.read_run(start, &mut buf[..len])?;
                for &v in buf[..len].iter().skip(c as usize).step_by(nc) {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                start += len;
            }
            return Ok([lo, hi]);
        }
        for p in 0..n {
            let v = self.scalars.get(p * nc + c as usize);
            lo = lo.min(v);
            hi = hi.max(v);
        }
        Ok([lo, hi])
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

    /// A rectilinear grid's lattice-to-index lookup (dvr.wgsl's `grid_lookup`), or none
    /// for a uniform grid: `width` columns per axis (rows x, y, z, one after the other),
    /// column j holding the index-space coordinate of the lattice point j·(n − 1)/(width − 1)
    /// (the physical point `first + j/(width − 1)·(last − first)`), read linearly between
    /// columns. The width resolves the narrowest cell by LOOKUP_COLUMNS_PER_CELL columns (at
    /// most `max_width`): a column that straddles a coordinate, where the index's rate
    /// changes, is off by at most a quarter of a column's width in the narrower cell's
    /// units there, 1/256 of an index; a table capped by `max_width` is off by more.
    pub fn grid_lookup(&self, max_width: u32) -> Option<(u32, Vec<f32>)> {
        let coords = self.coordinates.as_ref()?;
        let mut width = 2.0f64;
        for c in coords.iter().filter(|c| c.len() > 1) {
            let span = c[c.len() - 1] - c[0];
            let narrowest = c
                .windows(2)
                .map(|w| w[1] - w[0])
                .fold(f64::INFINITY, f64::min);
            width = width.max((LOOKUP_COLUMNS_PER_CELL * span / narrowest).ceil() + 1.0);
        }
        let width = width.min(max_width.max(2) as f64) as u32;
        let mut table = Vec::with_capacity(3 * width as usize);
        for c in coords.iter() {
            let n = c.len();
            let mut cell = 0;
            for j in 0..width {
                if n == 1 {
                    table.push(0.0);
                    continue;
                }
                let x = c[0] + (c[n - 1] - c[0]) * j as f64 / (width - 1) as f64;
                while cell + 2 < n && x > c[cell + 1] {
                    cell += 1;
                }
                let f = (x - c[cell]) / (c[cell + 1] - c[cell]);
                table.push((cell as f64 + f.clamp(0.0, 1.0)) as f32);
            }
        }
        Some((width, table))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(dims: [u32; 3]) -> VolumeData {
        let n = dims.iter().map(|&d| d as usize).product();
        VolumeData::new(dims, 1, Scalars::U8(vec![0; n])).unwrap()
    }

    /// Origins, spacings and dimensions whose bounds leave the 32-bit float range (or
    /// overflow to infinity in f64) were accepted; they are refused, naming the axis.
    #[test]
    fn bounds_beyond_the_f32_range_are_refused() {
        for (v, want) in [
            (
                volume([2, 2, 2]).with_spacing([1e308, 1.0, 1.0]),
                "along x are [0e0, 1e308]",
            ),
            (
                volume([2, 3, 2]).with_spacing([1.0, 1e308, 1.0]),
                "along y are [0e0, inf]",
            ),
            (
                volume([1, 1, 2])
                    .with_origin([0.0, 0.0, 3e38])
                    .and_then(|v| v.with_spacing([1.0, 1.0, 1e38])),
                "along z",
            ),
            (
                volume([4, 2, 2])
                    .with_origin([-3e38, 0.0, 0.0])
                    .and_then(|v| v.with_spacing([2e38, 1.0, 1.0])),
                "along x are [-3e38, 3e38]",
            ),
            (volume([1, 1, 1]).with_origin([0.0, 1e39, 0.0]), "along y"),
        ] {
            let e = v.unwrap_err().to_string();
            println!("{e}");
            assert!(e.contains(want), "{e}");
            assert!(e.contains("beyond the 32-bit float range"), "{e}");
        }
        let v = volume([2, 2, 2])
            .with_origin([-1e38, 0.0, 0.0])
            .and_then(|v| v.with_spacing([2e38, 1e30, 1.0]))
            .expect("bounds within the f32 range");
        assert_eq!(v.bounds()[..4], [-1e38, 1e38, 0.0, 1e30]);
    }

    /// Coordinates that are not one per point, not finite or not strictly increasing are
    /// refused, naming the axis; good ones set the origin and the lattice spacing.
    #[test]
    fn coordinates_are_checked_per_axis() {
        let ok = || [vec![0.0, 1.0, 3.0], vec![-1.0, 1.0], vec![5.0]];
        for (coords, want) in [
            (
                [vec![0.0, 1.0], vec![-1.0, 1.0], vec![5.0]],
                "2 x coordinates for a grid of 3 points along x",
            ),
            (
                [vec![0.0, 1.0, 3.0], vec![-1.0, f64::NAN], vec![5.0]],
                "y coordinate 1 is NaN",
            ),
            (
                [vec![0.0, 1.0, 3.0], vec![-1.0, 1.0], vec![f64::INFINITY]],
                "z coordinate 0 is inf",
            ),
            (
                [vec![0.0, 1.0, 1.0], vec![-1.0, 1.0], vec![5.0]],
                "x coordinates 1 and 2 are 1 and 1: coordinates must be strictly increasing",
            ),
            (
                [vec![0.0, 1.0, 3.0], vec![1.0, -1.0], vec![5.0]],
                "y coordinates 0 and 1",
            ),
        ] {
            let e = volume([3, 2, 1])
                .with_coordinates(coords)
                .unwrap_err()
                .to_string();
            println!("{e}");
            assert!(e.contains(want), "{e}");
        }
        let v = volume([3, 2, 1]).with_coordinates(ok()).unwrap();
        assert_eq!(v.origin, [0.0, -1.0, 5.0]);
        assert_eq!(v.spacing, [1.5, 2.0, 1.0]);
        assert_eq!(v.bounds(), [0.0, 3.0, -1.0, 1.0, 5.0, 5.0]);
        // x: the narrowest cell is 1 of a 3 span, 64 columns each: 193 columns
        let (width, table) = v.grid_lookup(8192).unwrap();
        assert_eq!(width, 193);
        let at = |a: usize, x: f64| table[a * 193 + (x * 192.0).round() as usize];
        assert_eq!(
            [at(0, 0.0), at(0, 1.0 / 3.0), at(0, 2.0 / 3.0), at(0, 1.0)],
            [0.0, 1.0, 1.5, 2.0]
        );
        assert_eq!([at(1, 0.0), at(1, 0.5), at(1, 1.0)], [0.0, 0.5, 1.0]);
        assert_eq!(at(2, 0.7), 0.0);
        assert_eq!(v.grid_lookup(100).unwrap().0, 100);
        let e = v.with_spacing([1.0; 3]).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains("the x coordinates run from 0 to 3"), "{e}");
    }
}

/// How a mask's values act on the volume (VTK's MaskType): one byte per point of the
/// volume's grid ([`crate::Renderer::set_mask`]), read at the point nearest to a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaskKind {
    /// A sample whose point holds 0 is left out, in every blend mode ray casting has.
    Binary,
    /// Each point's value is its label: composite ray casting of a one-component volume
    /// classifies a sample labelled 1 to [`crate::TransferFunction::max_label`] with its
    /// label's functions ([`crate::LabelTransfer`]), blended with the components' by
    /// [`crate::RenderParams::mask_blend`]; label 0 and higher labels as without a mask.
    LabelMap,
}
