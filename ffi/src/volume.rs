//! Volumes: the caller's scalars copied into an FvVolume.

use super::*;
use std::sync::Arc;

/// Volume data on the CPU (a copy of the caller's array), ready to upload to renderers;
/// renderers that keep a bricked volume's data share it (the caller may free the volume).
/// Thread use: immutable once its coordinates (if any) are set; may then be read from
/// several threads at once.
pub struct FvVolume {
    pub(crate) data: Arc<VolumeData>,
}

pub(crate) fn scalars_from_bytes(t: FvScalarType, bytes: &[u8]) -> Scalars {
    fn read<T: Copy, const N: usize>(b: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
        b.chunks_exact(N)
            .map(|c| f(c.try_into().expect("chunk of N")))
            .collect()
    }
    use FvScalarType as T;
    match t {
        T::U8 => Scalars::U8(bytes.to_vec()),
        T::I8 => Scalars::I8(read(bytes, i8::from_ne_bytes)),
        T::U16 => Scalars::U16(read(bytes, u16::from_ne_bytes)),
        T::I16 => Scalars::I16(read(bytes, i16::from_ne_bytes)),
        T::U32 => Scalars::U32(read(bytes, u32::from_ne_bytes)),
        T::I32 => Scalars::I32(read(bytes, i32::from_ne_bytes)),
        T::F32 => Scalars::F32(read(bytes, f32::from_ne_bytes)),
        T::F64 => Scalars::F64(read(bytes, f64::from_ne_bytes)),
        T::I64 => Scalars::F64(read(bytes, |b| i64::from_ne_bytes(b) as f64)),
        T::U64 => Scalars::F64(read(bytes, |b| u64::from_ne_bytes(b) as f64)),
    }
}

const SCALAR_TYPES: [FvScalarType; 10] = [
    FvScalarType::U8,
    FvScalarType::I8,
    FvScalarType::U16,
    FvScalarType::I16,
    FvScalarType::U32,
    FvScalarType::I32,
    FvScalarType::F32,
    FvScalarType::F64,
    FvScalarType::I64,
    FvScalarType::U64,
];

/// The FvScalarType a C caller's `code` names (`what` is the field, for the message).
pub(crate) fn scalar_type(what: &str, code: u32) -> FfiResult<FvScalarType> {
    SCALAR_TYPES.get(code as usize).copied().ok_or_else(|| {
        FfiError::new(
            FvStatus::Unsupported,
            format!(
                "{what} {code} is not an FvScalarType (0 to {})",
                SCALAR_TYPES.len() - 1
            ),
        )
    })
}

pub(crate) fn scalar_size(t: FvScalarType) -> usize {
    use FvScalarType as T;
    match t {
        T::U8 | T::I8 => 1,
        T::U16 | T::I16 => 2,
        T::U32 | T::I32 | T::F32 => 4,
        T::F64 | T::I64 | T::U64 => 8,
    }
}

/// Copies a volume: `data` holds `dims[0]·dims[1]·dims[2]·components` values of
/// `desc->scalar_type`, components interleaved, x fastest; `data_bytes` is its size in
/// bytes (checked). Scalars are validated (NaN/Inf refused, spacing > 0, direction
/// invertible). `*out` receives the volume, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_new(
    desc: *const FvVolumeDesc,
    data: *const c_void,
    data_bytes: usize,
    out: *mut *mut FvVolume,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let d = const_ref(desc, "desc")?;
        if data.is_null() {
            return Err(FfiError::null("data"));
        }
        let t = scalar_type("scalar type", d.scalar_type)?;
        let count = d
            .dims
            .iter()
            .map(|&n| n as u64)
            .product::<u64>()
            .checked_mul(d.components as u64)
            .ok_or_else(|| FfiError::invalid("volume size overflows"))?;
        let expected = count
            .checked_mul(scalar_size(t) as u64)
            .filter(|&b| b <= usize::MAX as u64)
            .ok_or_else(|| FfiError::invalid("volume size overflows"))?;
        if expected != data_bytes as u64 {
            return Err(FfiError::invalid(format!(
                "data_bytes is {data_bytes} but {}x{}x{} points × {} component(s) of {:?} need {expected}",
                d.dims[0], d.dims[1], d.dims[2], d.components, t
            )));
        }
        // SAFETY: the caller guarantees `data` points to `data_bytes` readable bytes.
        let bytes = unsafe { std::slice::from_raw_parts(data.cast::<u8>(), data_bytes) };
        let m = &d.direction;
        let direction = [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]];
        let v = VolumeData {
            dims: d.dims,
            spacing: d.spacing,
            origin: d.origin,
            direction,
            components: d.components,
            scalars: scalars_from_bytes(t, bytes),
            coordinates: None,
        };
        v.validate()?;
        *slot = Box::into_raw(Box::new(FvVolume { data: Arc::new(v) }));
        Ok(())
    })
}

/// Places the volume's points at per-axis coordinates (a rectilinear grid, VTK's
/// vtkRectilinearGrid): `x` holds `nx` values, one per point along x, strictly increasing
/// and finite, and likewise `y` and `z`. The origin becomes the first coordinates and the
/// spacing the uniform lattice over the same box. Ray casting renders such volumes;
/// isosurfaces, path tracing and volumes too large for one texture refuse them. On an
/// error the volume is unchanged. Not while another thread uses the volume.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_set_coordinates(
    volume: *mut FvVolume,
    x: *const f64,
    nx: usize,
    y: *const f64,
    ny: usize,
    z: *const f64,
    nz: usize,
) -> FvStatus {
    guard(|| {
        let v = mut_ref(volume, "volume")?;
        let mut axes: [Vec<f64>; 3] = Default::default();
        for (out, (ptr, n, name)) in axes
            .iter_mut()
            .zip([(x, nx, "x"), (y, ny, "y"), (z, nz, "z")])
        {
            if ptr.is_null() {
                return Err(FfiError::null(name));
            }
            // SAFETY: the caller guarantees `ptr` points to `n` readable doubles.
            *out = unsafe { std::slice::from_raw_parts(ptr, n) }.to_vec();
        }
        Arc::make_mut(&mut v.data).set_coordinates(axes)?;
        Ok(())
    })
}

/// Releases a volume (NULL is ignored). Renderers keep what they uploaded.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_free(volume: *mut FvVolume) {
    guard_value((), || free_handle(volume))
}

/// Minimum and maximum of one component into `range[0..2]`.
#[no_mangle]
pub unsafe extern "C" fn fv_volume_range(
    volume: *const FvVolume,
    component: u32,
    range: *mut [f64; 2],
) -> FvStatus {
    guard(|| {
        let v = const_ref(volume, "volume")?;
        let out = mut_ref(range, "range")?;
        if component >= v.data.components {
            return Err(FfiError::invalid(format!(
                "component {component}: the volume has {}",
                v.data.components
            )));
        }
        *out = v.data.try_range(component)?;
        Ok(())
    })
}
