//! Which specialisation of the path tracer a frame uses, and which frames it refuses: a
//! pure function of the frame's facts ([`select`]), tested over the combinations on the CPU.

use crate::error::Error;
use crate::gpu::pipeline::pipeline_variant;
use crate::gpu::uniforms::{MASK_BINARY, MASK_LABELS, MASK_NONE};
use crate::params::{GradientMethod, Interpolation, MaskKind};

pipeline_variant! {
    /// The pipeline constants of one specialisation of the path tracer.
    pub(crate) struct PathTraceVariant {
        /// Nearest table lookups.
        nearest: bool => "NEAREST",
        /// The BSDF and the scattering regions (anything but Henyey–Greenstein everywhere).
        hybrid: bool => "HYBRID",
        /// The denoiser's guide.
        guide: bool => "GUIDE",
        /// Forward-difference gradients (FORWARD_DIFF in lib/volume.wgsl).
        forward_diff: bool => "FORWARD_DIFF",
        /// The volume is one brick (lib/volume.wgsl).
        single_brick: bool => "SINGLE_BRICK",
        /// Cropping regions.
        crop: bool => "CROP",
        /// What the mask does (MASK_NONE, MASK_BINARY or MASK_LABELS).
        mask: u32 => "MASK",
        /// VTK's blanking (lib/blanking.wgsl): the medium is empty at blanked samples.
        blanking: bool => "BLANKING",
        /// A rectilinear grid (lib/rectilinear.wgsl).
        rectilinear: bool => "RECTILINEAR",
        /// 1: the medium's colour and opacity from the 2D table (lib/table2d.wgsl).
        tables_2d: u32 => "TF2D",
        /// Number of volumes intermixed with the main one.
        intermix: u32 => "INTERMIX",
        /// The intermixed volumes' atlas is read through a linear sampler.
        intermix_filtered: bool => "INTERMIX_FILTERED",
    }
}

/// What a path-traced frame is: its settings, the volume's and the device's facts that the
/// variant depends on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathTraceFacts {
    pub interpolation: Interpolation,
    pub gradient: GradientMethod,
    pub components: u32,
    pub single_brick: bool,
    pub rectilinear: bool,
    pub cropping: bool,
    pub mask: Option<MaskKind>,
    /// A label map's labels have functions of their own and the blend factor is above 0.
    pub labels_apply: bool,
    pub blanking: bool,
    /// The transfer function has a 2D table.
    pub tables_2d: bool,
    /// The BSDF or the scattering regions are used (not Henyey–Greenstein everywhere).
    pub hybrid: bool,
    /// The denoiser runs (now or until a number of paths).
    pub guided: bool,
    /// Volumes intermixed with the main one.
    pub intermix: u32,
    pub float32_filterable: bool,
}

/// A frame the path tracer does not draw, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PathTraceRefusal {
    Cubic,
    /// The volume's components.
    Components(u32),
    IntermixOptions,
}

impl From<PathTraceRefusal> for Error {
    fn from(r: PathTraceRefusal) -> Error {
        use PathTraceRefusal as R;
        Error::Unsupported(match r {
            R::Cubic => "path tracing samples the trilinear field: cubic interpolation is for \
                ray casting"
                .into(),
            R::Components(n) => format!(
                "path tracing renders one-component volumes (this one has {n} components): \
                 extract one (vtkImageExtractComponents) or use ray casting"
            ),
            R::IntermixOptions => "intermixed volumes are path traced with a uniform main \
                volume without cropping, a mask or blanking: clear the intermixed volumes or \
                turn those off"
                .into(),
        })
    }
}

/// The variant that draws a frame of these facts, or the first reason it cannot be drawn.
pub(crate) fn select(x: &PathTraceFacts) -> Result<PathTraceVariant, PathTraceRefusal> {
    use PathTraceRefusal as R;
    if x.interpolation == Interpolation::Cubic {
        return Err(R::Cubic);
    }
    if x.components != 1 {
        return Err(R::Components(x.components));
    }
    if x.intermix > 0 && (x.cropping || x.mask.is_some() || x.blanking || x.rectilinear) {
        return Err(R::IntermixOptions);
    }
    Ok(PathTraceVariant {
        nearest: x.interpolation == Interpolation::Nearest,
        hybrid: x.hybrid,
        guide: x.guided,
        forward_diff: x.gradient == GradientMethod::Forward,
        single_brick: x.single_brick,
        crop: x.cropping,
        mask: match x.mask {
            Some(MaskKind::Binary) => MASK_BINARY,
            Some(MaskKind::LabelMap) if x.labels_apply => MASK_LABELS,
            _ => MASK_NONE,
        },
        blanking: x.blanking,
        rectilinear: x.rectilinear,
        tables_2d: u32::from(x.tables_2d),
        intermix: x.intermix,
        intermix_filtered: x.intermix > 0 && x.float32_filterable,
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Every frame of the matrix: interpolations, gradients, masks, one or two components,
    /// intermixed volumes or none, and 2^9 combinations of the other facts.
    pub(in crate::passes) fn matrix(mut each: impl FnMut(&PathTraceFacts)) {
        let interps = [
            Interpolation::Nearest,
            Interpolation::Linear,
            Interpolation::Cubic,
        ];
        let masks = [None, Some(MaskKind::Binary), Some(MaskKind::LabelMap)];
        for interpolation in interps {
            for gradient in [GradientMethod::Central, GradientMethod::Forward] {
                for mask in masks {
                    for components in [1, 2] {
                        for intermix in [0, 2] {
                            for bits in 0u32..1 << 9 {
                                let on = |i: u32| bits & 1 << i != 0;
                                each(&PathTraceFacts {
                                    interpolation,
                                    gradient,
                                    mask,
                                    components,
                                    intermix,
                                    single_brick: on(0),
                                    rectilinear: on(1),
                                    cropping: on(2),
                                    labels_apply: on(3),
                                    blanking: on(4),
                                    tables_2d: on(5),
                                    hybrid: on(6),
                                    guided: on(7),
                                    float32_filterable: on(8),
                                });
                            }
                        }
                    }
                }
            }
        }
    }

    /// When each refusal happens (docs/REFUSALS.md), in the order `select` checks them.
    pub(in crate::passes) fn when(r: PathTraceRefusal) -> (u8, &'static str) {
        use PathTraceRefusal as R;
        match r {
            R::Cubic => (0, "cubic interpolation"),
            R::Components(_) => (1, "a volume of several components"),
            R::IntermixOptions => (
                2,
                "intermixed volumes with cropping, a mask, blanking or a rectilinear main volume",
            ),
        }
    }

    #[test]
    fn every_frame_gets_a_consistent_variant_or_a_justified_refusal() {
        let mut refusals = std::collections::HashSet::new();
        matrix(|x| match select(x) {
            Err(r) => {
                let justified = match r {
                    PathTraceRefusal::Cubic => x.interpolation == Interpolation::Cubic,
                    PathTraceRefusal::Components(n) => n == x.components && n != 1,
                    PathTraceRefusal::IntermixOptions => {
                        x.intermix > 0
                            && (x.cropping || x.mask.is_some() || x.blanking || x.rectilinear)
                    }
                };
                assert!(justified, "{r:?} for {x:?}");
                refusals.insert(when(r).0);
            }
            Ok(v) => {
                assert!(x.interpolation != Interpolation::Cubic && x.components == 1);
                assert_eq!(v.nearest, x.interpolation == Interpolation::Nearest);
                assert!(v.intermix == 0 || (!v.crop && v.mask == MASK_NONE && !v.blanking));
                assert!(!v.intermix_filtered || v.intermix > 0, "{x:?}");
                assert_eq!(
                    v.mask == MASK_LABELS,
                    x.mask == Some(MaskKind::LabelMap) && x.labels_apply
                );
            }
        });
        assert_eq!(refusals.len(), 3, "every refusal is reachable");
    }
}
