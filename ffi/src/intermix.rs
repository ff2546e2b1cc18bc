//! Volumes intermixed with the renderer's main volume per sample (VTK's vtkMultiVolume).

use super::*;
use ferrovol_core::{IntermixedVolume, Interpolation, MAX_INTERMIXED_VOLUMES};

/// Most volumes fv_renderer_set_intermixed_volumes takes beside the main volume.
pub const FV_MAX_INTERMIXED_VOLUMES: usize = 3;
const _: () = assert!(FV_MAX_INTERMIXED_VOLUMES == MAX_INTERMIXED_VOLUMES);

/// A volume drawn with the main one, intermixed per sample: its data (one component, a
/// uniform grid), its transfer function (one component; colour and opacity only) and its
/// placement. The renderer copies what it needs: both handles may be freed after the call.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvIntermixedVolume {
    pub volume: *const FvVolume,
    pub transfer_function: *const FvTransferFunction,
    /// The vtkVolume's matrix (data → world), column-major, as FvRenderParams::volume_matrix
    /// is for the main volume.
    pub matrix: [f64; 16],
    /// FV_INTERPOLATION_NEAREST or FV_INTERPOLATION_LINEAR: how this volume and its tables are
    /// read (its property's InterpolationType).
    pub interpolation: u32,
}

/// Sets the volumes drawn with the main one (`count` at `volumes`, 0 clears them), as
/// vtkGPUVolumeRayCastMapper draws the ports of a vtkMultiVolume (the main volume is port
/// 0, `volumes[i]` port i + 1): each ray marches the world box holding them all at the main
/// volume's sample distance and, at each sample, composites the main volume and then each
/// intermixed volume that holds the sample, each classified by its own transfer function
/// and shaded (when shading is on) by its own gradient with the main volume's lights and
/// material. At most FV_MAX_INTERMIXED_VOLUMES. Frames then ray cast in the composite blend
/// mode only, without cropping, blanking, masks, pre-integration, volumetric shadows or
/// streaming, with a one-component main volume: others fail with FV_STATUS_UNSUPPORTED
/// naming what is refused. Setting the same FvVolume handles again does not re-upload them.
#[no_mangle]
pub unsafe extern "C" fn fv_renderer_set_intermixed_volumes(
    renderer: *mut FvRenderer,
    volumes: *const FvIntermixedVolume,
    count: usize,
) -> FvStatus {
    guard(|| {
        let r = mut_ref(renderer, "renderer")?;
        if count > FV_MAX_INTERMIXED_VOLUMES {
            return Err(FfiError::new(
                FvStatus::Unsupported,
                format!(
                    "{count} intermixed volumes: at most {FV_MAX_INTERMIXED_VOLUMES} beside the \
                 main volume"
                ),
            ));
        }
        let given = if count == 0 {
            &[][..]
        } else {
            if volumes.is_null() {
                return Err(FfiError::null("volumes"));
            }
            // SAFETY: the caller guarantees `count` descriptions at `volumes`.
            unsafe { std::slice::from_raw_parts(volumes, count) }
        };
        let mut core = Vec::with_capacity(count);
        for (i, v) in given.iter().enumerate() {
            let data = const_ref(v.volume, &format!("volumes[{i}].volume"))?;
            let tf = const_ref(
                v.transfer_function,
                &format!("volumes[{i}].transfer_function"),
            )?;
            let interpolation = match v.interpolation {
                x if x == FvInterpolation::Nearest as u32 => Interpolation::Nearest,
                x if x == FvInterpolation::Linear as u32 => Interpolation::Linear,
                x => {
                    return Err(FfiError::invalid(format!(
                        "volumes[{i}].interpolation {x}: intermixed volumes are read \
                         nearest (0) or linear (1)"
                    )))
                }
            };
            core.push(IntermixedVolume {
                volume: data.data.clone(),
                matrix: column_major(&v.matrix),
                transfer: tf.to_core()?,
                interpolation,
            });
        }
        r.r.set_intermixed_volumes(&core)?;
        Ok(())
    })
}
