//! Further volumes drawn with the main one, intermixed per sample (VTK's vtkMultiVolume
//! with vtkGPUVolumeRayCastMapper's extra input ports).

use super::render::Interpolation;
use super::transfer::TransferFunction;
use super::volume::VolumeData;
use crate::error::{Error, Result};
use glam::DMat4;
use std::sync::Arc;

/// At most this many volumes beside the main one ([`crate::Renderer::set_intermixed_volumes`]).
pub use crate::gpu::uniforms::MAX_INTERMIXED as MAX_INTERMIXED_VOLUMES;

/// A volume drawn together with the renderer's main volume: its own data, placement and
/// transfer function. Each ray samples the main volume and every intermixed volume at the
/// same points and composites them in order at each point, as vtkGPUVolumeRayCastMapper
/// does for the ports of a vtkMultiVolume (the main volume is port 0).
#[derive(Clone)]
pub struct IntermixedVolume {
    /// One component on a uniform grid.
    pub volume: Arc<VolumeData>,
    /// Data coordinates → world (the vtkVolume's matrix), as
    /// [`RenderParams::volume_matrix`](crate::RenderParams::volume_matrix) is for the main
    /// volume.
    pub matrix: DMat4,
    /// One component, 1D tables (no 2D table, no labels, no gradient opacity).
    pub transfer: TransferFunction,
    /// How this volume and its tables are read between points and entries (its property's
    /// InterpolationType in VTK): nearest or linear.
    pub interpolation: Interpolation,
}

impl IntermixedVolume {
    /// Checks what intermixing supports; `index` names the volume in the message.
    pub fn validate(&self, index: usize) -> Result<()> {
        let v = &self.volume;
        let name = format!("intermixed volume {index}");
        v.validate()
            .map_err(|e| Error::InvalidParameter(format!("{name}: {e}")))?;
        if v.components != 1 {
            return Err(Error::Unsupported(format!(
                "{name} has {} components: intermixed volumes have one (as vtkMultiVolume \
                 reads each input's first component)",
                v.components
            )));
        }
        if v.coordinates.is_some() {
            return Err(Error::Unsupported(format!(
                "{name} is a rectilinear grid: intermixed volumes are uniform grids"
            )));
        }
        if !self.matrix.is_finite() || self.matrix.determinant().abs() < 1e-12 {
            return Err(Error::InvalidParameter(format!(
                "{name}: its matrix is singular or not finite"
            )));
        }
        if self.interpolation == Interpolation::Cubic {
            return Err(Error::Unsupported(format!(
                "{name}: cubic interpolation; intermixed volumes are read linearly or at the \
                 nearest point"
            )));
        }
        let tf = &self.transfer;
        tf.validate(1)
            .map_err(|e| Error::InvalidParameter(format!("{name}: {e}")))?;
        let c = tf.component(0);
        if c.table_2d.is_some() || c.gradient_opacity.is_some() || tf.max_label() > 0 {
            return Err(Error::Unsupported(format!(
                "{name}: its transfer function has a 2D table, gradient opacity or labels; \
                 intermixed volumes are classified by 1D colour and opacity functions"
            )));
        }
        Ok(())
    }
}

impl std::fmt::Debug for IntermixedVolume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IntermixedVolume")
            .field("dims", &self.volume.dims)
            .field("matrix", &self.matrix)
            .finish_non_exhaustive()
    }
}
