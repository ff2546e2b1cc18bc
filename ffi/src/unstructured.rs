//! Unstructured volumes: the caller's VTK arrays (points, connectivity, offsets, cell types,
//! scalars) copied into an FvUnstructuredVolume, converted to the core's types on the way.

use super::*;
use crate::sized;
use crate::volume::{scalar_size, scalar_type, scalars_from_bytes};
use ferrovol_core::{ScalarLocation, UnstructuredVolume};
use std::fmt::Display;

/// Where the scalars of an unstructured volume live (FvUnstructuredVolumeDesc.location).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvScalarLocation {
    /// One tuple per point, interpolated within each cell (VTK's point data).
    Points = 0,
    /// One tuple per cell, constant within it (VTK's cell data).
    Cells = 1,
}

/// A mesh as VTK's vtkUnstructuredGrid holds it, in the caller's arrays (read during
/// fv_unstructured_volume_new only). Fill with fv_unstructured_volume_desc_default() and set
/// the arrays. A pointer may be NULL only where its count is 0. Each array is aligned for
/// its type. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvUnstructuredVolumeDesc {
    /// sizeof(this struct) as the caller's header declares it, written by
    /// fv_unstructured_volume_desc_default; fields added in later minor versions take their
    /// defaults when it is smaller.
    pub size: usize,
    /// `3 · point_count` coordinates, x, y, z per point, of `point_type`.
    pub points: *const c_void,
    pub point_count: usize,
    /// FV_SCALAR_TYPE_F64 (the default) or FV_SCALAR_TYPE_F32 (vtkPoints' two types).
    pub point_type: u32,
    /// The type of `connectivity` and `offsets` (vtkCellArray's): FV_SCALAR_TYPE_I64 (the
    /// default: VTK's vtkIdType and NumPy's default integer), FV_SCALAR_TYPE_I32,
    /// FV_SCALAR_TYPE_U32 or FV_SCALAR_TYPE_U64. Converted inside, each value checked to lie
    /// in 0 to 2^32 − 1.
    pub index_type: u32,
    /// `connectivity_count` point indices: cell c's points are entries `offsets[c]` to
    /// `offsets[c + 1] − 1`, in VTK's point order for its type.
    pub connectivity: *const c_void,
    pub connectivity_count: usize,
    /// `cell_count + 1` entries, the first 0 and the last `connectivity_count`, increasing
    /// (vtkCellArray's offsets; a .vtu file leaves out the leading 0).
    pub offsets: *const c_void,
    /// `cell_count` VTK cell type codes: VTK_TETRA (10), VTK_VOXEL (11),
    /// VTK_HEXAHEDRON (12), VTK_WEDGE (13), VTK_PYRAMID (14), VTK_PENTAGONAL_PRISM (15),
    /// VTK_HEXAGONAL_PRISM (16), and VTK's quadratic 3D cells (24–27, 29, 31–33, 37), each
    /// linearised to the linear cell of its shape by keeping its corner points; any other
    /// type is refused naming the first cell that has it.
    pub cell_types: *const u8,
    pub cell_count: usize,
    /// One of FvScalarType (64-bit integers are converted to double, exact up to 2^53).
    pub scalar_type: u32,
    /// Components per tuple, 1 to 4, interleaved (the unstructured pass draws one: a mesh
    /// of several fails at render with FV_STATUS_UNSUPPORTED).
    pub components: u32,
    /// One of FvScalarLocation (default FV_SCALAR_LOCATION_POINTS).
    pub location: u32,
    /// `components` values of `scalar_type` per point (`point_count` tuples) or per cell
    /// (`cell_count` tuples), as `location` says.
    pub scalars: *const c_void,
}

crate::sized::sized_params!(
    FvUnstructuredVolumeDesc,
    "FvUnstructuredVolumeDesc",
    scalars: *const c_void,
    96
);

impl FvUnstructuredVolumeDesc {
    pub fn defaults() -> Self {
        FvUnstructuredVolumeDesc {
            size: std::mem::size_of::<FvUnstructuredVolumeDesc>(),
            points: std::ptr::null(),
            point_count: 0,
            point_type: FvScalarType::F64 as u32,
            index_type: FvScalarType::I64 as u32,
            connectivity: std::ptr::null(),
            connectivity_count: 0,
            offsets: std::ptr::null(),
            cell_types: std::ptr::null(),
            cell_count: 0,
            scalar_type: FvScalarType::F32 as u32,
            components: 1,
            location: FvScalarLocation::Points as u32,
            scalars: std::ptr::null(),
        }
    }
}

/// An unstructured volume on the CPU (a copy of the caller's arrays, validated), ready to
/// upload to renderers; the caller may free it once they have it. Thread use: immutable;
/// may be read from several threads at once.
pub struct FvUnstructuredVolume {
    mesh: UnstructuredVolume,
}

/// `n` values of `T` at `ptr`: NULL is refused unless `n` is 0, as is a pointer not aligned
/// for `T` or an array past the address space.
fn array<'a, T>(ptr: *const c_void, n: usize, what: &str) -> FfiResult<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(FfiError::null(what));
    }
    if !(ptr as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return Err(FfiError::invalid(format!(
            "{what} is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    if n.checked_mul(std::mem::size_of::<T>())
        .is_none_or(|bytes| bytes > isize::MAX as usize)
    {
        return Err(FfiError::invalid(format!(
            "{what}: {n} values do not fit in memory"
        )));
    }
    // SAFETY: non-NULL and aligned (checked); the caller guarantees `n` readable values.
    Ok(unsafe { std::slice::from_raw_parts(ptr.cast::<T>(), n) })
}

/// `n` indices of `ty` at `ptr` as u32, each checked to fit.
fn indices(ty: FvScalarType, ptr: *const c_void, n: usize, what: &str) -> FfiResult<Vec<u32>> {
    fn convert<T: Copy + Display + TryInto<u32>>(values: &[T], what: &str) -> FfiResult<Vec<u32>> {
        values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                v.try_into().map_err(|_| {
                    FfiError::invalid(format!(
                        "{what}[{i}] is {v}: not an index (ferrovol's are 0 to 2^32 − 1)"
                    ))
                })
            })
            .collect()
    }
    use FvScalarType as T;
    match ty {
        T::I64 => convert(array::<i64>(ptr, n, what)?, what),
        T::I32 => convert(array::<i32>(ptr, n, what)?, what),
        T::U32 => Ok(array::<u32>(ptr, n, what)?.to_vec()),
        T::U64 => convert(array::<u64>(ptr, n, what)?, what),
        _ => Err(FfiError::new(
            FvStatus::Unsupported,
            format!("index_type {ty:?}: connectivity and offsets are I64, I32, U32 or U64"),
        )),
    }
}

fn too_large(what: &str) -> FfiError {
    FfiError::invalid(format!("{what}: the count overflows"))
}

impl FvUnstructuredVolumeDesc {
    /// Reads the caller's arrays into a validated mesh.
    fn to_mesh(self) -> FfiResult<UnstructuredVolume> {
        let point_type = scalar_type("point_type", self.point_type)?;
        let coordinates = self
            .point_count
            .checked_mul(3)
            .ok_or_else(|| too_large("point_count"))?;
        let points: Vec<[f64; 3]> = match point_type {
            FvScalarType::F64 => array::<f64>(self.points, coordinates, "points")?
                .chunks_exact(3)
                .map(|p| [p[0], p[1], p[2]])
                .collect(),
            FvScalarType::F32 => array::<f32>(self.points, coordinates, "points")?
                .chunks_exact(3)
                .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
                .collect(),
            t => {
                return Err(FfiError::new(
                    FvStatus::Unsupported,
                    format!("point_type {t:?}: points are F64 or F32"),
                ))
            }
        };
        let index_type = scalar_type("index_type", self.index_type)?;
        let connectivity = indices(
            index_type,
            self.connectivity,
            self.connectivity_count,
            "connectivity",
        )?;
        let offset_count = match self.cell_count {
            0 => 0,
            n => n.checked_add(1).ok_or_else(|| too_large("cell_count"))?,
        };
        let offsets = indices(index_type, self.offsets, offset_count, "offsets")?;
        let cell_types = array::<u8>(self.cell_types.cast(), self.cell_count, "cell_types")?;
        let (location, tuples) = match self.location {
            0 => (ScalarLocation::Points, self.point_count),
            1 => (ScalarLocation::Cells, self.cell_count),
            v => {
                return Err(FfiError::invalid(format!(
                    "location {v} is not an FvScalarLocation (0 points, 1 cells)"
                )))
            }
        };
        if !(1..=4).contains(&self.components) {
            return Err(FfiError::invalid(format!(
                "components is {}; ferrovol renders 1 to 4",
                self.components
            )));
        }
        let t = scalar_type("scalar_type", self.scalar_type)?;
        let bytes = tuples
            .checked_mul(self.components as usize * scalar_size(t))
            .ok_or_else(|| too_large("scalars"))?;
        let scalars = scalars_from_bytes(t, array::<u8>(self.scalars, bytes, "scalars")?);
        Ok(UnstructuredVolume::from_vtk(
            points,
            connectivity,
            offsets,
            cell_types.to_vec(),
            location,
            self.components,
            scalars,
        )?)
    }
}

/// Fills `*desc` with the defaults (no arrays; double points, int64 indices, one float
/// component per point). `size` is `sizeof *desc` (see fv_render_params_default).
#[no_mangle]
pub unsafe extern "C" fn fv_unstructured_volume_desc_default(
    desc: *mut FvUnstructuredVolumeDesc,
    size: usize,
) -> FvStatus {
    guard(|| sized::write_defaults(desc, size, "desc"))
}

/// Copies a mesh from the caller's arrays (`*desc`), converting points, indices and scalars
/// to ferrovol's types, and validates it: a NULL array with a non-zero count, an index
/// outside 0 to 2^32 − 1 or past the points (dangling), offsets that do not start at 0,
/// increase and end at connectivity_count, a cell type ferrovol does not take, a cell with
/// the wrong number of points or a point listed twice, a face shared by more than two
/// cells, NaN or infinite coordinates or scalars are refused with a message naming the
/// array entry or the cell. `*out` receives the volume, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_unstructured_volume_new(
    desc: *const FvUnstructuredVolumeDesc,
    out: *mut *mut FvUnstructuredVolume,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        let mesh = sized::read(desc, "desc")?.to_mesh()?;
        *slot = Box::into_raw(Box::new(FvUnstructuredVolume { mesh }));
        Ok(())
    })
}

/// Releases an unstructured volume (NULL is ignored). Renderers keep what they uploaded.
#[no_mangle]
pub unsafe extern "C" fn fv_unstructured_volume_free(volume: *mut FvUnstructuredVolume) {
    guard_value((), || free_handle(volume))
}

/// Uploads an unstructured volume, replacing the renderer's volume or mesh
/// (fv_renderer_set_volume goes back to an image volume): its cells split into tetrahedra,
/// their neighbours and a hierarchy over the boundary. Frames then ray cast it (composite,
/// with volumetric shadows when shaded; the projections; FV_BLEND_MODE_ISOSURFACE: exact
/// crossings), or path trace it (FV_BLEND_MODE_PATH_TRACE: Henyey–Greenstein scattering),
/// with the same camera, parameters and transfer function; what its passes do not draw (the
/// slice mode, several components, surface scattering, scattering between isosurfaces, …)
/// fails at render with FV_STATUS_UNSUPPORTED naming it. The tetrahedra may take two of the
/// device's storage bindings; a mesh too large for its buffers is refused with the sizes.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_unstructured(
    renderer: *mut FvRenderer,
    volume: *const FvUnstructuredVolume,
) -> FvStatus {
    guard(|| {
        let r = mut_ref(renderer, "renderer")?;
        let v = const_ref(volume, "volume")?;
        r.r.set_unstructured(&v.mesh)?;
        Ok(())
    })
}
