//! Which specialisation of the ray-casting pass a frame uses, and which combinations it
//! refuses: a pure function of the frame's facts ([`select`]), tested over the combinations
//! on the CPU.

use crate::error::Error;
use crate::gpu::pipeline::pipeline_variant;
use crate::gpu::uniforms::{MASK_BINARY, MASK_LABELS, MASK_NONE};
use crate::params::{BlendMode, GradientMethod, Interpolation, MaskKind, Quadrature};

use super::frame::SKIP_MAX_OCCUPANCY;

/// The least share of the occupied blocks' samples an adaptive frame must save for its rays
/// to read their blocks' step multipliers; below it they take every step (the midpoint
/// rule). On lavapipe the reads cost about what half the samples do (docs/PERFORMANCE.md).
const ADAPTIVE_MIN_SAVING: f64 = 0.5;

pipeline_variant! {
    /// The pipeline constants of one specialisation of the DVR pass (overrides in dvr.wgsl).
    pub(crate) struct DvrVariant {
        blend: u32 => "BLEND",
        components: u32 => "NCOMP",
        independent: bool => "INDEPENDENT",
        shade: bool => "SHADE",
        gradient_opacity: bool => "GRAD_OPACITY",
        skip: bool => "SKIP",
        range_skip: bool => "RANGE_SKIP",
        crop: bool => "CROP",
        nearest: bool => "NEAREST",
        cubic: bool => "CUBIC",
        single_brick: bool => "SINGLE_BRICK",
        positional_lights: bool => "POSITIONAL_LIGHTS",
        lights: u32 => "NUM_LIGHTS",
        volumetric: bool => "VOLUMETRIC",
        opacity_normal: bool => "OPACITY_NORMAL",
        clipped_voxel: bool => "CLIPPED_VOXEL",
        blanking: bool => "BLANKING",
        mask: u32 => "MASK",
        /// Bit c: component c is classified by its 2D table.
        tables_2d: u32 => "TF2D",
        precomputed_gradient: bool => "PRECOMPUTED_GRADIENT",
        forward_diff: bool => "FORWARD_DIFF",
        streaming: bool => "STREAMING",
        preintegration: bool => "PREINT",
        midpoint: bool => "MIDPOINT",
        adaptive: bool => "ADAPTIVE",
        rectilinear: bool => "RECTILINEAR",
        /// Number of volumes intermixed with the main one.
        intermix: u32 => "INTERMIX",
        /// The intermixed volumes' atlas is read through a linear sampler (r32float is
        /// filterable on this device).
        intermix_filtered: bool => "INTERMIX_FILTERED",
    }
}

/// What a ray-cast frame is: its settings, the volume's and the device's facts that the
/// variant depends on.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DvrFacts {
    pub blend: BlendMode,
    pub interpolation: Interpolation,
    pub quadrature: Quadrature,
    pub gradient: GradientMethod,
    pub shade: bool,
    pub normal_from_opacity: bool,
    pub empty_space_skipping: bool,
    /// Pre-integration asked for.
    pub preintegration: bool,
    pub cropping: bool,
    /// A clipped voxel value is set and clipping planes clip.
    pub clipped_voxel_value: bool,
    pub average_range: bool,
    pub whole_box: bool,
    /// The mask blend factor is above 0.
    pub mask_blend: bool,
    pub volumetric: bool,
    pub independent: bool,
    pub gradient_opacity: bool,
    pub lights: u32,
    pub positional_lights: bool,
    pub components: u32,
    pub single_brick: bool,
    pub rectilinear: bool,
    pub precomputed_gradient: bool,
    pub blanking: bool,
    pub mask: Option<MaskKind>,
    /// The transfer function has label functions (max_label > 0).
    pub labels: bool,
    /// Bit c: component c has a 2D table.
    pub tables_2d: u32,
    /// The share of blocks the occupancy grid marks occupied.
    pub occupied: f64,
    /// The share of occupied samples adaptive steps would save.
    pub saving: f64,
    /// Volumes intermixed with the main one.
    pub intermix: u32,
    pub float32_filterable: bool,
    /// The bricks in view exceed the memory budget: the frame streams them.
    pub streaming: bool,
}

/// A combination the ray-casting pass does not draw, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DvrRefusal {
    StreamingVolumetric,
    StreamingCubic,
    StreamingSlice,
    MidpointIntermix(Quadrature),
    RectilinearVolumetric,
    RectilinearClippedVoxel,
    Tables2dBlend(BlendMode),
    Tables2dDependent,
    OpacityNormalDependent(u32),
    OpacityNormalGradientOpacityBricked,
    /// Intermixed volumes with something they do not combine with (the reason).
    Intermix(&'static str),
}

impl From<DvrRefusal> for Error {
    fn from(r: DvrRefusal) -> Error {
        use DvrRefusal as R;
        Error::Unsupported(match r {
            R::StreamingVolumetric => "volumetric shadows need every visible brick resident, \
                and the visible bricks exceed the volume's memory budget: raise the budget or \
                turn the scattering blending off"
                .into(),
            R::StreamingCubic => "cubic interpolation reads two points around each sample, \
                beyond what a streamed brick keeps around it, and the bricks in view exceed \
                the volume's memory budget: raise the budget or interpolate linearly"
                .into(),
            R::StreamingSlice => "the slice blend mode needs every brick in view resident, and \
                they exceed the volume's memory budget: raise the budget"
                .into(),
            R::MidpointIntermix(q) => format!(
                "the {} quadrature draws one volume: clear the intermixed volumes or use \
                 Quadrature::Vtk",
                q.name()
            ),
            R::RectilinearVolumetric => "volumetric shadows march uniform grids, and this \
                volume is rectilinear (per-axis coordinates): turn the scattering blending off"
                .into(),
            R::RectilinearClippedVoxel => "the clipped voxel value applies to uniform grids, \
                and this volume is rectilinear (per-axis coordinates): leave the clipped voxel \
                value unset"
                .into(),
            R::Tables2dBlend(b) => format!(
                "2D transfer functions classify composite ray casting, not the {b:?} blend \
                 mode: use 1D functions or the composite mode"
            ),
            R::Tables2dDependent => "2D transfer functions classify one or independent \
                components: these are dependent"
                .into(),
            R::OpacityNormalDependent(n) => format!(
                "shading normals from the opacity gradient need one or independent components \
                 (this volume has {n} dependent ones): turn normal_from_opacity off"
            ),
            R::OpacityNormalGradientOpacityBricked => "shading normals from the opacity \
                gradient with gradient opacity read two voxels around each sample, beyond a \
                brick's apron, and this volume is bricked (larger than one texture or than the \
                memory budget): turn gradient opacity or normal_from_opacity off"
                .into(),
            R::Intermix(why) => format!(
                "intermixed volumes are ray cast with one-component main volumes, linear or \
                 nearest interpolation and no cropping, blanking, masks, pre-integration, \
                 volumetric shadows or streaming, and {why}: clear the intermixed volumes or \
                 turn that off"
            ),
        })
    }
}

/// The variant that draws a frame of these facts, or the first reason it cannot be drawn.
pub(crate) fn select(x: &DvrFacts) -> Result<DvrVariant, DvrRefusal> {
    use DvrRefusal as R;
    let composite = x.blend == BlendMode::Composite;
    let one_or_independent = x.components == 1 || x.independent;
    if x.streaming && x.volumetric {
        return Err(R::StreamingVolumetric);
    }
    if x.streaming && x.interpolation == Interpolation::Cubic {
        return Err(R::StreamingCubic);
    }
    if x.streaming && x.blend == BlendMode::Slice {
        return Err(R::StreamingSlice);
    }
    if x.quadrature.midpoints() && x.intermix > 0 {
        return Err(R::MidpointIntermix(x.quadrature));
    }
    if x.rectilinear && x.volumetric {
        return Err(R::RectilinearVolumetric);
    }
    let clipped_voxel = x.clipped_voxel_value && composite && (x.shade || x.gradient_opacity);
    if x.rectilinear && clipped_voxel {
        return Err(R::RectilinearClippedVoxel);
    }
    if x.tables_2d != 0 && !composite {
        return Err(R::Tables2dBlend(x.blend));
    }
    if x.tables_2d != 0 && !x.independent && x.components > 1 {
        return Err(R::Tables2dDependent);
    }
    // label maps: composite ray casting of one component, as VTK's
    let mask = match x.mask {
        Some(MaskKind::Binary) => MASK_BINARY,
        Some(MaskKind::LabelMap) if composite && x.components == 1 && x.mask_blend && x.labels => {
            MASK_LABELS
        }
        _ => MASK_NONE,
    };
    // Additive and average skip empty blocks too, counting the skipped samples (their terms
    // are 0), as long as every sample counts (no cropping, blanking or average range) and
    // the occupancy is of the components they sum (one or independent).
    let counts_all = !x.cropping
        && !x.blanking
        && mask != MASK_BINARY
        && one_or_independent
        && (x.blend == BlendMode::Additive || (x.blend == BlendMode::Average && !x.average_range));
    // (the occupancy is the 1D tables': blocks are not skipped under 2D tables; blocks and
    // their exits are in the grid's index space, which rays on a rectilinear grid do not
    // march)
    let skip = x.empty_space_skipping
        && !x.rectilinear
        && x.tables_2d == 0
        && (composite || counts_all)
        && x.occupied < SKIP_MAX_OCCUPANCY;
    // MIP and MinIP skip blocks whose range cannot move the ray's extremum, on one-component
    // volumes (the range grid holds the first component).
    let range_skip = x.empty_space_skipping
        && !x.rectilinear
        && matches!(x.blend, BlendMode::Maximum | BlendMode::Minimum)
        && x.components == 1
        && !x.streaming;
    // ComputeNormalFromOpacity: composite and shaded; one or independent components.
    let opacity_normal = x.shade && x.normal_from_opacity && composite;
    if opacity_normal && !one_or_independent {
        return Err(R::OpacityNormalDependent(x.components));
    }
    if opacity_normal && x.gradient_opacity && !x.single_brick {
        return Err(R::OpacityNormalGradientOpacityBricked);
    }
    // Pre-integration: composite, one or independent components, no volumetric shadows and
    // no label map (a labelled sample is classified alone).
    let preintegration = x.preintegration
        && composite
        && one_or_independent
        && !x.volumetric
        && mask != MASK_LABELS
        && x.tables_2d == 0;
    // Adaptive steps: composite and unshaded (lighting turns with the gradient's direction,
    // which a block's values do not bound), classified by the 1D tables the occupancy grid's
    // step multipliers come from, on a uniform grid whose blocks rays march, with nothing
    // that cuts samples out inside a block (cropping, blanking, masks); and only where the
    // coarse steps save enough samples to pay for reading the blocks.
    let adaptive = x.quadrature == Quadrature::Adaptive
        && !x.shade
        && x.saving >= ADAPTIVE_MIN_SAVING
        && composite
        && !preintegration
        && !x.gradient_opacity
        && x.tables_2d == 0
        && mask == MASK_NONE
        && one_or_independent
        && !x.rectilinear
        && !x.cropping
        && !x.blanking;
    if x.intermix > 0 {
        let refused = [
            (
                x.streaming,
                "the bricks in view exceed the volume's memory budget",
            ),
            (x.cropping, "cropping is on"),
            (x.blanking, "the main volume has blanking"),
            (mask != MASK_NONE, "the main volume has a mask"),
            (x.rectilinear, "the main volume is rectilinear"),
            (x.volumetric, "volumetric shadows are on"),
            (x.preintegration, "pre-integration is on"),
            (x.components > 1, "the main volume has several components"),
            (
                x.tables_2d != 0,
                "the main volume has a 2D transfer function",
            ),
            (
                x.interpolation == Interpolation::Cubic,
                "the interpolation is cubic",
            ),
            (x.whole_box, "the volume is a piece of a whole"),
        ];
        if let Some((_, why)) = refused.iter().find(|(on, _)| *on) {
            return Err(R::Intermix(why));
        }
    }
    Ok(DvrVariant {
        blend: x.blend.code(),
        components: x.components,
        independent: x.independent,
        shade: x.shade,
        gradient_opacity: x.gradient_opacity,
        skip: skip && x.intermix == 0,
        range_skip,
        crop: x.cropping,
        nearest: x.interpolation == Interpolation::Nearest,
        cubic: x.interpolation == Interpolation::Cubic,
        single_brick: x.single_brick,
        positional_lights: x.positional_lights,
        lights: x.lights,
        volumetric: x.volumetric,
        opacity_normal,
        blanking: x.blanking,
        mask,
        tables_2d: x.tables_2d,
        clipped_voxel,
        precomputed_gradient: x.precomputed_gradient,
        forward_diff: x.gradient == GradientMethod::Forward,
        streaming: x.streaming,
        preintegration,
        midpoint: x.quadrature.midpoints(),
        adaptive,
        rectilinear: x.rectilinear,
        intermix: x.intermix,
        intermix_filtered: x.intermix > 0 && x.float32_filterable,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blend modes ray casting draws.
    const BLENDS: [BlendMode; 6] = {
        let [composite, max, min, average, additive, _, _, slice] = BlendMode::ALL;
        [composite, max, min, average, additive, slice]
    };

    fn facts() -> DvrFacts {
        DvrFacts {
            blend: BlendMode::Composite,
            interpolation: Interpolation::Linear,
            quadrature: Quadrature::Vtk,
            gradient: GradientMethod::Central,
            shade: false,
            normal_from_opacity: false,
            empty_space_skipping: true,
            preintegration: false,
            cropping: false,
            clipped_voxel_value: false,
            average_range: false,
            whole_box: false,
            mask_blend: true,
            volumetric: false,
            independent: true,
            gradient_opacity: false,
            lights: 1,
            positional_lights: false,
            components: 1,
            single_brick: true,
            rectilinear: false,
            precomputed_gradient: false,
            blanking: false,
            mask: None,
            labels: true,
            tables_2d: 0,
            occupied: 0.3,
            saving: 0.6,
            intermix: 0,
            float32_filterable: true,
            streaming: false,
        }
    }

    /// Every frame of the matrix: blend modes ray casting draws, interpolations,
    /// quadratures, masks, one or two components, 2D tables, intermixed volumes, and 2^13
    /// combinations of the other facts.
    fn matrix(mut each: impl FnMut(&DvrFacts)) {
        let interps = [
            Interpolation::Nearest,
            Interpolation::Linear,
            Interpolation::Cubic,
        ];
        let quads = [Quadrature::Vtk, Quadrature::Midpoint, Quadrature::Adaptive];
        let masks = [None, Some(MaskKind::Binary), Some(MaskKind::LabelMap)];
        for blend in BLENDS {
            for interpolation in interps {
                for quadrature in quads {
                    for mask in masks {
                        for (components, tables_2d) in [(1, 0), (1, 1), (2, 0), (2, 3)] {
                            for intermix in [0, 1] {
                                for bits in 0u32..1 << 13 {
                                    let on = |i: u32| bits & 1 << i != 0;
                                    each(&DvrFacts {
                                        blend,
                                        interpolation,
                                        quadrature,
                                        mask,
                                        components,
                                        tables_2d,
                                        intermix,
                                        streaming: on(0),
                                        rectilinear: on(1),
                                        volumetric: on(2),
                                        shade: on(3),
                                        normal_from_opacity: on(4),
                                        gradient_opacity: on(5),
                                        single_brick: on(6),
                                        independent: on(7),
                                        cropping: on(8),
                                        blanking: on(9),
                                        clipped_voxel_value: on(10),
                                        preintegration: on(11),
                                        whole_box: on(12),
                                        ..facts()
                                    });
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// Whether `r` is the right refusal for `x`: its condition holds.
    fn justified(r: DvrRefusal, x: &DvrFacts) -> bool {
        use DvrRefusal as R;
        let one_or_independent = x.components == 1 || x.independent;
        match r {
            R::StreamingVolumetric => x.streaming && x.volumetric,
            R::StreamingCubic => x.streaming && x.interpolation == Interpolation::Cubic,
            R::StreamingSlice => x.streaming && x.blend == BlendMode::Slice,
            R::MidpointIntermix(q) => q == x.quadrature && q.midpoints() && x.intermix > 0,
            R::RectilinearVolumetric => x.rectilinear && x.volumetric,
            R::RectilinearClippedVoxel => x.rectilinear && x.clipped_voxel_value,
            R::Tables2dBlend(b) => x.tables_2d != 0 && b == x.blend && b != BlendMode::Composite,
            R::Tables2dDependent => x.tables_2d != 0 && !one_or_independent,
            R::OpacityNormalDependent(n) => {
                x.shade && x.normal_from_opacity && !one_or_independent && n == x.components
            }
            R::OpacityNormalGradientOpacityBricked => {
                x.shade && x.normal_from_opacity && x.gradient_opacity && !x.single_brick
            }
            R::Intermix(_) => x.intermix > 0,
        }
    }

    #[test]
    fn every_frame_of_the_matrix_gets_a_consistent_variant_or_a_justified_refusal() {
        let mut refusals = std::collections::HashSet::new();
        let mut drawn = std::collections::HashSet::new();
        matrix(|x| match select(x) {
            Err(r) => {
                assert!(justified(r, x), "{r:?} for {x:?}");
                refusals.insert(std::mem::discriminant(&r));
            }
            Ok(v) => {
                drawn.insert((v.blend, v.components, v.mask, v.intermix, v.tables_2d));
                let composite = x.blend == BlendMode::Composite;
                assert!(!(v.streaming && (v.volumetric || v.cubic)), "{x:?}");
                assert!(!(v.streaming && x.blend == BlendMode::Slice), "{x:?}");
                assert!(
                    !(v.rectilinear && (v.volumetric || v.clipped_voxel)),
                    "{x:?}"
                );
                assert!(v.tables_2d == 0 || (composite && (v.independent || v.components == 1)));
                assert!(!v.opacity_normal || (composite && x.shade), "{x:?}");
                assert!(!v.preintegration || (composite && !v.volumetric && v.mask != MASK_LABELS));
                assert!(!v.preintegration || v.tables_2d == 0, "{x:?}");
                assert!(
                    !v.adaptive || (composite && !v.shade && !v.preintegration),
                    "{x:?}"
                );
                assert!(!v.adaptive || (v.mask == MASK_NONE && !v.crop && !v.blanking));
                assert!(!v.skip || (!v.rectilinear && v.tables_2d == 0 && v.intermix == 0));
                assert!(
                    !v.range_skip || (v.components == 1 && !v.streaming),
                    "{x:?}"
                );
                assert!(
                    v.mask != MASK_LABELS || (composite && v.components == 1),
                    "{x:?}"
                );
                if v.intermix > 0 {
                    assert!(!v.midpoint && !v.streaming && !v.crop && !v.blanking);
                    assert!(v.mask == MASK_NONE && !v.rectilinear && !v.volumetric);
                    assert!(!x.preintegration && v.components == 1 && !v.cubic);
                    assert!(v.tables_2d == 0 && !x.whole_box, "{x:?}");
                }
            }
        });
        assert_eq!(refusals.len(), 11, "every refusal is reachable");
        // (blend, components, mask, intermixed volumes, 2D tables) that draw: every blend
        // mode with one or two components, binary masks or none, and intermixed with one
        // component; label maps and 2D tables in composite only
        let composite = BlendMode::Composite.code();
        let mut expected = std::collections::HashSet::new();
        for b in BLENDS.map(BlendMode::code) {
            for c in [1, 2] {
                for m in [MASK_NONE, MASK_BINARY] {
                    expected.insert((b, c, m, 0, 0));
                }
            }
            expected.insert((b, 1, MASK_NONE, 1, 0));
        }
        for m in [MASK_NONE, MASK_BINARY] {
            expected.extend([(composite, 1, m, 0, 1), (composite, 2, m, 0, 3)]);
        }
        expected.extend([
            (composite, 1, MASK_LABELS, 0, 0),
            (composite, 1, MASK_LABELS, 0, 1),
        ]);
        assert_eq!(drawn, expected);
    }

    /// When each refusal happens, as docs/REFUSALS.md says it, and its place in the order
    /// `select` checks them.
    fn when(r: DvrRefusal) -> (u8, &'static str) {
        use DvrRefusal as R;
        match r {
            R::StreamingVolumetric => (0, "volumetric shadows on a streamed frame (the bricks in view exceed the volume's memory budget)"),
            R::StreamingCubic => (1, "cubic interpolation on a streamed frame"),
            R::StreamingSlice => (2, "the slice blend mode on a streamed frame"),
            R::MidpointIntermix(_) => (3, "the midpoint or adaptive quadrature with intermixed volumes"),
            R::RectilinearVolumetric => (4, "volumetric shadows on a rectilinear grid"),
            R::RectilinearClippedVoxel => (5, "a clipped voxel value (with shading or gradient opacity) on a rectilinear grid"),
            R::Tables2dBlend(_) => (6, "2D transfer functions in another blend mode than composite"),
            R::Tables2dDependent => (7, "2D transfer functions on dependent components"),
            R::OpacityNormalDependent(_) => (8, "normals from the opacity gradient on dependent components"),
            R::OpacityNormalGradientOpacityBricked => (9, "normals from the opacity gradient with gradient opacity on a bricked volume"),
            R::Intermix(_) => (10, "intermixed volumes with what they do not combine with"),
        }
    }

    /// Messages that differ in one part, as one: their common start and end around the
    /// parts (`start [a / b] end`).
    fn merged(messages: &std::collections::BTreeSet<String>) -> String {
        let all: Vec<&str> = messages.iter().map(String::as_str).collect();
        if all.len() == 1 {
            return all[0].to_string();
        }
        let common = |f: &dyn Fn(&str) -> Vec<char>| {
            let seqs: Vec<Vec<char>> = all.iter().map(|m| f(m)).collect();
            (0..seqs[0].len())
                .take_while(|&i| seqs.iter().all(|q| q.get(i) == seqs[0].get(i)))
                .count()
        };
        let chars: Vec<Vec<char>> = all.iter().map(|m| m.chars().collect()).collect();
        // (whole words only)
        let mut head = common(&|m| m.chars().collect());
        while head > 0 && chars[0][head - 1] != ' ' {
            head -= 1;
        }
        let mut tail = common(&|m| m.chars().rev().collect());
        let shortest = chars.iter().map(Vec::len).min().unwrap_or(0);
        tail = tail.min(shortest - head);
        while tail > 0 && !matches!(chars[0][chars[0].len() - tail], ' ' | ':' | ',') {
            tail -= 1;
        }
        let parts: Vec<String> = chars
            .iter()
            .map(|c| c[head..c.len() - tail].iter().collect())
            .collect();
        let start: String = chars[0][..head].iter().collect();
        let end: String = chars[0][chars[0].len() - tail..].iter().collect();
        format!("{start}[{}]{end}", parts.join(" / "))
    }

    /// A table of refusals: each condition (in the order they are checked) and the messages
    /// its refusals give, merged.
    fn table(
        rows: &std::collections::BTreeMap<(u8, &str), std::collections::BTreeSet<String>>,
    ) -> String {
        let mut out = String::from("| when | the error says |\n| --- | --- |\n");
        for ((_, when), messages) in rows {
            out.push_str(&format!(
                "| {when} | {} |\n",
                merged(messages).replace('|', "\\|")
            ));
        }
        out
    }

    /// The messages of the refusals `select` gives over a matrix of frames (`walk` calls
    /// its argument on each), by when they happen.
    fn rows<X, V, R>(
        walk: impl FnOnce(&mut dyn FnMut(&X)),
        select: fn(&X) -> Result<V, R>,
        when: fn(R) -> (u8, &'static str),
    ) -> std::collections::BTreeMap<(u8, &'static str), std::collections::BTreeSet<String>>
    where
        R: Copy + std::fmt::Debug,
        Error: From<R>,
    {
        let mut rows = std::collections::BTreeMap::new();
        walk(&mut |x: &X| {
            if let Err(r) = select(x) {
                let Error::Unsupported(m) = Error::from(r) else {
                    panic!("{r:?} is not Unsupported")
                };
                rows.entry(when(r))
                    .or_insert_with(std::collections::BTreeSet::new)
                    .insert(m);
            }
        });
        rows
    }

    /// docs/REFUSALS.md: every refusal of the ray-casting, isosurface and path-tracing
    /// matrices, its condition and the messages it gives, in the order the passes check them.
    fn refusals_doc() -> String {
        use crate::passes::{iso_variant, pathtrace_variant, unstructured_variant};
        let dvr = rows(|each| matrix(each), select, when);
        let iso = rows(
            |each| iso_variant::tests::matrix(each),
            iso_variant::select,
            iso_variant::tests::when,
        );
        let pt = rows(
            |each| pathtrace_variant::tests::matrix(each),
            pathtrace_variant::select,
            pathtrace_variant::tests::when,
        );
        let mesh = rows(
            |each| unstructured_variant::tests::matrix(each),
            unstructured_variant::select,
            unstructured_variant::tests::when,
        );
        format!(
            "<!-- Generated from core/src/passes/dvr_variant.rs, iso_variant.rs, \
             pathtrace_variant.rs and unstructured_variant.rs by their tests: FERROVOL_UPDATE_DOCS=1 cargo test -p \
             ferrovol-core --lib refusals -->\n\
             # What the passes refuse\n\n\
             The combinations of settings the ray-casting, isosurface, path-tracing and \
             unstructured passes do not draw, each with the error it gives: `Error::Unsupported` in Rust, \
             FV_STATUS_UNSUPPORTED and the message from the C ABI, vtkErrorMacro in VTK and \
             ParaView, an error from the CLI. Each message names the way out. The list is \
             written once, in the code (each pass's variant selection, a pure function of \
             the frame's facts); this page is generated from it, and a test keeps it \
             current.\n\n## Ray casting\n\n{}\n## Isosurfaces\n\n{}\n## Path tracing\n\n{}\n\
             ## Unstructured volumes\n\n{}",
            table(&dvr),
            table(&iso),
            table(&pt),
            table(&mesh)
        )
    }

    /// The refusal list is written once (here) and generated into docs/REFUSALS.md; the
    /// READMEs and the C header send their readers there.
    #[test]
    fn refusals_doc_is_current_and_linked() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        if !root.join("docs").is_dir() {
            // (the crate packaged alone has no docs/)
            return;
        }
        let path = root.join("docs/REFUSALS.md");
        let doc = refusals_doc();
        if std::env::var_os("FERROVOL_UPDATE_DOCS").is_some() {
            std::fs::write(&path, &doc).expect("docs/REFUSALS.md written");
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            on_disk == doc,
            "docs/REFUSALS.md is not what the code refuses: regenerate it with \
             FERROVOL_UPDATE_DOCS=1 cargo test -p ferrovol-core --lib refusals"
        );
        for file in [
            "README.md",
            "vtk_plugin/README.md",
            "ffi/include/ferrovol.h",
        ] {
            let text = std::fs::read_to_string(root.join(file)).expect(file);
            assert!(
                text.contains("docs/REFUSALS.md"),
                "{file} does not link docs/REFUSALS.md"
            );
        }
    }

    #[test]
    fn the_first_refusal_in_order_wins_and_says_what_to_do() {
        let x = DvrFacts {
            streaming: true,
            volumetric: true,
            interpolation: Interpolation::Cubic,
            ..facts()
        };
        assert_eq!(select(&x), Err(DvrRefusal::StreamingVolumetric));
        let x = DvrFacts {
            intermix: 2,
            cropping: true,
            blanking: true,
            ..facts()
        };
        assert_eq!(select(&x), Err(DvrRefusal::Intermix("cropping is on")));
        let Error::Unsupported(m) = Error::from(select(&x).unwrap_err()) else {
            panic!("not Unsupported")
        };
        assert!(
            m.contains("cropping is on: clear the intermixed volumes"),
            "{m}"
        );
    }

    #[test]
    fn adaptive_steps_only_where_they_save_enough() {
        let x = DvrFacts {
            quadrature: Quadrature::Adaptive,
            ..facts()
        };
        assert!(select(&x).unwrap().adaptive);
        let x = DvrFacts { saving: 0.4, ..x };
        let v = select(&x).unwrap();
        assert!(
            !v.adaptive && v.midpoint,
            "the midpoint rule below the saving"
        );
    }
}
