//! Which specialisations of the isosurface passes (first hit, deferred shading) a frame
//! uses, and which frames they refuse: a pure function of the frame's facts ([`select`]),
//! tested over the combinations on the CPU.

use crate::error::Error;
use crate::gpu::pipeline::pipeline_variant;
use crate::gpu::uniforms::{MASK_BINARY, MASK_NONE};
use crate::params::{Interpolation, IsoScatterMode, MaskKind};

use super::frame::SKIP_MAX_OCCUPANCY;

pipeline_variant! {
    /// The pipeline constants of one specialisation of the first-hit pass.
    pub(crate) struct FirstHitVariant {
        skip: bool => "SKIP",
        crop: bool => "CROP",
        single_brick: bool => "SINGLE_BRICK",
        streaming: bool => "STREAMING",
        /// The component the isosurfaces are of (iso_component).
        component: u32 => "ISO_COMP",
        /// MASK_BINARY: samples whose nearest point the mask holds 0 at are left out.
        mask: u32 => "MASK",
        /// VTK's blanking: blanked samples are left out as masked ones are.
        blanking: bool => "BLANKING",
        /// A rectilinear grid: samples mapped to its index space (lib/rectilinear.wgsl).
        rectilinear: bool => "RECTILINEAR",
        /// The surfaces of the cubic B-spline (Interpolation::Cubic).
        cubic: bool => "CUBIC",
    }
}

pipeline_variant! {
    /// The pipeline constants of one specialisation of the deferred pass.
    pub(crate) struct DeferredVariant {
        lights: u32 => "NUM_LIGHTS",
        positional_lights: bool => "POSITIONAL_LIGHTS",
        /// 0 none, 1 preview, 2 traced (IsoScattering).
        scatter: u32 => "SCATTER",
        single_brick: bool => "SINGLE_BRICK",
        component: u32 => "ISO_COMP",
        /// MASK_BINARY: the medium between the surfaces is empty where the mask holds 0.
        mask: u32 => "MASK",
        /// VTK's blanking: the medium between the surfaces is empty where blanked.
        blanking: bool => "BLANKING",
        /// A rectilinear grid (lib/rectilinear.wgsl).
        rectilinear: bool => "RECTILINEAR",
        /// An unstructured volume's surfaces (firsthit_mesh.wgsl): no image volume bound.
        mesh: bool => "MESH",
    }
}

/// What an isosurface frame is: its settings, the volume's facts and the frame's plan.
#[derive(Clone, Copy, Debug)]
pub(crate) struct IsoFacts {
    pub interpolation: Interpolation,
    pub empty_space_skipping: bool,
    pub cropping: bool,
    pub single_brick: bool,
    pub rectilinear: bool,
    /// The component the isosurfaces are of.
    pub component: u32,
    pub mask: Option<MaskKind>,
    pub blanking: bool,
    /// The share of blocks the iso-values' occupancy grid marks occupied.
    pub occupied: f64,
    pub lights: u32,
    pub positional_lights: bool,
    pub scattering: Option<IsoScatterMode>,
    /// Ambient-occlusion rays are traced.
    pub ambient_occlusion: bool,
    /// The bricks the surfaces lie in exceed the memory budget: the frame streams them.
    pub streaming: bool,
    /// The sample distance in voxels along the direction the volume stretches most (what a
    /// streamed brick's apron must cover).
    pub step_voxels: f64,
}

/// A frame the isosurface passes do not draw, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum IsoRefusal {
    RectilinearCubic,
    StreamingAmbientOcclusion,
    /// The sample distance in voxels.
    StreamingStep(f64),
    StreamingCubic,
}

impl From<IsoRefusal> for Error {
    fn from(r: IsoRefusal) -> Error {
        use IsoRefusal as R;
        let over = "the bricks the isosurfaces lie in exceed the volume's memory budget";
        Error::Unsupported(match r {
            R::RectilinearCubic => "cubic isosurfaces are found on uniform grids, and this \
                volume is rectilinear (per-axis coordinates): interpolate linearly or resample \
                the grid"
                .into(),
            R::StreamingAmbientOcclusion => format!(
                "{over}, and ambient occlusion reads around them: raise the budget or turn \
                 ambient occlusion off"
            ),
            R::StreamingStep(voxels) => format!(
                "{over}, and streaming them needs a sample distance of at most one voxel (this \
                 one is {voxels:.3} voxels): raise the budget or lower the sample distance"
            ),
            R::StreamingCubic => "cubic interpolation reads two points around each sample, \
                beyond what a streamed brick keeps around it, and the bricks in view exceed the \
                volume's memory budget: raise the budget or interpolate linearly"
                .into(),
        })
    }
}

/// The variants that draw a frame of these facts, or the first reason it cannot be drawn.
/// A streamed frame's first hits and refinement stay within one voxel of the brick serving
/// them only with a sample distance of at most one voxel, and ambient-occlusion rays reach
/// beyond the bricks the surfaces lie in.
pub(crate) fn select(x: &IsoFacts) -> Result<(FirstHitVariant, DeferredVariant), IsoRefusal> {
    use IsoRefusal as R;
    let cubic = x.interpolation == Interpolation::Cubic;
    if x.rectilinear && cubic {
        return Err(R::RectilinearCubic);
    }
    if x.streaming && x.ambient_occlusion {
        return Err(R::StreamingAmbientOcclusion);
    }
    if x.streaming && x.step_voxels > 1.0 + 1e-9 {
        return Err(R::StreamingStep(x.step_voxels));
    }
    if x.streaming && cubic {
        return Err(R::StreamingCubic);
    }
    let mask = if x.mask == Some(MaskKind::Binary) {
        MASK_BINARY
    } else {
        MASK_NONE
    };
    // (blocks and their exits are in the grid's index space, which rays on a rectilinear
    // grid do not march)
    let first_hit = FirstHitVariant {
        skip: x.empty_space_skipping && !x.rectilinear && x.occupied < SKIP_MAX_OCCUPANCY,
        crop: x.cropping,
        single_brick: x.single_brick,
        streaming: x.streaming,
        component: x.component,
        mask,
        blanking: x.blanking,
        rectilinear: x.rectilinear,
        cubic,
    };
    let deferred = DeferredVariant {
        lights: x.lights,
        positional_lights: x.positional_lights,
        scatter: match x.scattering {
            None => 0,
            Some(IsoScatterMode::Preview) => 1,
            Some(IsoScatterMode::Traced) => 2,
        },
        single_brick: x.single_brick,
        component: x.component,
        mask,
        blanking: x.blanking,
        rectilinear: x.rectilinear,
        mesh: false,
    };
    Ok((first_hit, deferred))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    fn facts() -> IsoFacts {
        IsoFacts {
            interpolation: Interpolation::Linear,
            empty_space_skipping: true,
            cropping: false,
            single_brick: true,
            rectilinear: false,
            component: 0,
            mask: None,
            blanking: false,
            occupied: 0.3,
            lights: 1,
            positional_lights: false,
            scattering: None,
            ambient_occlusion: false,
            streaming: false,
            step_voxels: 0.5,
        }
    }

    /// Every frame of the matrix: interpolations, masks, scattering modes, sample distances
    /// below and above a voxel, and 2^7 combinations of the other facts.
    pub(in crate::passes) fn matrix(mut each: impl FnMut(&IsoFacts)) {
        let interps = [
            Interpolation::Nearest,
            Interpolation::Linear,
            Interpolation::Cubic,
        ];
        let masks = [None, Some(MaskKind::Binary), Some(MaskKind::LabelMap)];
        let scatters = [
            None,
            Some(IsoScatterMode::Preview),
            Some(IsoScatterMode::Traced),
        ];
        for interpolation in interps {
            for mask in masks {
                for scattering in scatters {
                    for step_voxels in [0.5, 1.0, 1.5] {
                        for bits in 0u32..1 << 7 {
                            let on = |i: u32| bits & 1 << i != 0;
                            each(&IsoFacts {
                                interpolation,
                                mask,
                                scattering,
                                step_voxels,
                                streaming: on(0),
                                rectilinear: on(1),
                                ambient_occlusion: on(2),
                                empty_space_skipping: on(3),
                                cropping: on(4),
                                blanking: on(5),
                                single_brick: on(6),
                                ..facts()
                            });
                        }
                    }
                }
            }
        }
    }

    /// When each refusal happens (docs/REFUSALS.md), in the order `select` checks them.
    pub(in crate::passes) fn when(r: IsoRefusal) -> (u8, &'static str) {
        use IsoRefusal as R;
        match r {
            R::RectilinearCubic => (0, "cubic isosurfaces on a rectilinear grid"),
            R::StreamingAmbientOcclusion => (1, "ambient occlusion on a streamed frame"),
            R::StreamingStep(_) => (2, "a streamed frame whose sample distance exceeds a voxel"),
            R::StreamingCubic => (3, "cubic interpolation on a streamed frame"),
        }
    }

    #[test]
    fn every_frame_gets_consistent_variants_or_a_justified_refusal() {
        let mut refusals = std::collections::HashSet::new();
        matrix(|x| match select(x) {
            Err(r) => {
                let justified = match r {
                    IsoRefusal::RectilinearCubic => {
                        x.rectilinear && x.interpolation == Interpolation::Cubic
                    }
                    IsoRefusal::StreamingAmbientOcclusion => x.streaming && x.ambient_occlusion,
                    IsoRefusal::StreamingStep(v) => x.streaming && v == x.step_voxels && v > 1.0,
                    IsoRefusal::StreamingCubic => {
                        x.streaming && x.interpolation == Interpolation::Cubic
                    }
                };
                assert!(justified, "{r:?} for {x:?}");
                refusals.insert(when(r).0);
            }
            Ok((f, d)) => {
                assert!(!(f.streaming && (f.cubic || x.ambient_occlusion)), "{x:?}");
                assert!(!f.streaming || x.step_voxels <= 1.0, "{x:?}");
                assert!(!(f.rectilinear && (f.cubic || f.skip)), "{x:?}");
                assert_eq!(f.mask == MASK_BINARY, x.mask == Some(MaskKind::Binary));
                assert_eq!(
                    (f.mask, f.blanking, f.rectilinear),
                    (d.mask, d.blanking, d.rectilinear)
                );
                assert_eq!((f.component, f.single_brick), (d.component, d.single_brick));
                assert_eq!(d.scatter == 0, x.scattering.is_none());
            }
        });
        assert_eq!(refusals.len(), 4, "every refusal is reachable");
    }
}
