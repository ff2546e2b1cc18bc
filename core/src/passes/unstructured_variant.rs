//! Which specialisation of the unstructured pass a frame uses, and which settings it
//! refuses: a pure function of the frame's facts ([`select`]), tested over the combinations
//! on the CPU; its refusals are listed in docs/REFUSALS.md.

use crate::error::Error;
use crate::gpu::pipeline::pipeline_variant;
use crate::params::BlendMode;

pipeline_variant! {
    /// The pipeline constants of one specialisation (overrides in unstructured.wgsl).
    pub(crate) struct UnstructuredVariant {
        blend: u32 => "BLEND",
        cell_scalars: bool => "CELL_SCALARS",
        shade: bool => "SHADE",
        lights: u32 => "NUM_LIGHTS",
        positional_lights: bool => "POSITIONAL_LIGHTS",
        gradient_opacity: bool => "GRAD_OPACITY",
    }
}

pipeline_variant! {
    /// The pipeline constants of one specialisation of the mesh's path tracer
    /// (pathtrace_mesh.wgsl).
    pub(crate) struct MeshPathTraceVariant {
        cell_scalars: bool => "CELL_SCALARS",
        /// The denoiser's guide.
        guide: bool => "GUIDE",
    }
}

/// What a frame of an unstructured volume is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct UnstructuredFacts {
    pub blend: BlendMode,
    pub components: u32,
    pub cell_scalars: bool,
    pub shade: bool,
    /// The lights the frame carries, and whether any is positional.
    pub lights: u32,
    pub positional_lights: bool,
    pub gradient_opacity: bool,
    pub tables_2d: bool,
    pub cropping: bool,
    pub average_range: bool,
    pub whole_box: bool,
    pub volumetric: bool,
    /// Rays limited to a range of depths (Renderer::render_between).
    pub depth_range: bool,
    pub intermix: bool,
    /// Path tracing's surface scattering: a gradient threshold, the stochastic blend or
    /// scattering regions other than everywhere.
    pub hybrid: bool,
}

/// A setting the unstructured pass does not draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum UnstructuredRefusal {
    Blend(BlendMode),
    Components(u32),
    /// A setting it does not draw yet, named.
    Setting(&'static str),
}

impl From<UnstructuredRefusal> for Error {
    fn from(r: UnstructuredRefusal) -> Error {
        use UnstructuredRefusal as R;
        Error::Unsupported(match r {
            R::Blend(b) => format!(
                "unstructured volumes are drawn in the composite, maximum, minimum, average \
                 and additive blend modes and path traced, not {b:?}: use one of those, or \
                 resample the mesh to an image"
            ),
            R::Components(n) => format!(
                "unstructured volumes are drawn from one scalar component, and this mesh has \
                 {n}: extract the component to draw (e.g. ParaView's Calculator)"
            ),
            R::Setting(what) => format!(
                "unstructured volumes are drawn without {what}: turn it off, or resample the \
                 mesh to an image"
            ),
        })
    }
}

/// The variant that draws a frame of these facts, or the first reason it cannot be drawn.
pub(crate) fn select(x: &UnstructuredFacts) -> Result<UnstructuredVariant, UnstructuredRefusal> {
    use UnstructuredRefusal as R;
    match x.blend {
        BlendMode::Composite
        | BlendMode::Maximum
        | BlendMode::Minimum
        | BlendMode::Average
        | BlendMode::Additive
        | BlendMode::PathTrace => {}
        b => return Err(R::Blend(b)),
    }
    if x.components != 1 {
        return Err(R::Components(x.components));
    }
    let settings = [
        (x.tables_2d, "2D transfer functions"),
        (x.cropping, "cropping"),
        (x.average_range, "an average range"),
        (x.whole_box, "a whole box (pieces of a whole)"),
        (x.volumetric, "volumetric shadows"),
        (x.depth_range, "a depth range"),
        (x.intermix, "intermixed volumes"),
        (
            x.hybrid && x.blend == BlendMode::PathTrace,
            "surface scattering (a gradient threshold, the stochastic blend or scattering \
             regions; path tracing scatters meshes by Henyey–Greenstein everywhere)",
        ),
    ];
    if let Some((_, what)) = settings.iter().find(|(on, _)| *on) {
        return Err(R::Setting(what));
    }
    // Shading lights composite alone, as VTK's ray casters shade (the projections are of
    // the scalar); a frame without lights is ambient only, as an image volume's is.
    // Gradient opacity scales the opacity composite accumulates, as for images (path
    // tracing reads the opacity alone, as for images).
    let shade = x.shade && x.blend == BlendMode::Composite;
    Ok(UnstructuredVariant {
        blend: x.blend.code(),
        cell_scalars: x.cell_scalars,
        shade,
        lights: if shade { x.lights } else { 0 },
        positional_lights: shade && x.positional_lights,
        gradient_opacity: x.gradient_opacity && x.blend == BlendMode::Composite,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn facts() -> UnstructuredFacts {
        UnstructuredFacts {
            blend: BlendMode::Composite,
            components: 1,
            cell_scalars: false,
            shade: false,
            lights: 1,
            positional_lights: false,
            gradient_opacity: false,
            tables_2d: false,
            cropping: false,
            average_range: false,
            whole_box: false,
            volumetric: false,
            depth_range: false,
            intermix: false,
            hybrid: false,
        }
    }

    /// Frames over every blend mode, component count and each setting on alone.
    pub(crate) fn matrix(each: &mut dyn FnMut(&UnstructuredFacts)) {
        for blend in BlendMode::ALL {
            for components in 1..=4 {
                for cell_scalars in [false, true] {
                    let x = UnstructuredFacts {
                        blend,
                        components,
                        cell_scalars,
                        ..facts()
                    };
                    each(&x);
                    for k in 0..10 {
                        let mut y = x;
                        *[
                            &mut y.shade,
                            &mut y.gradient_opacity,
                            &mut y.tables_2d,
                            &mut y.cropping,
                            &mut y.average_range,
                            &mut y.whole_box,
                            &mut y.volumetric,
                            &mut y.depth_range,
                            &mut y.intermix,
                            &mut y.hybrid,
                        ][k] = true;
                        each(&y);
                    }
                }
            }
        }
    }

    /// When each refusal happens, as docs/REFUSALS.md says it, in the order checked.
    pub(crate) fn when(r: UnstructuredRefusal) -> (u8, &'static str) {
        use UnstructuredRefusal as R;
        match r {
            R::Blend(_) => (0, "the isosurface or slice blend mode"),
            R::Components(_) => (1, "a mesh of several components"),
            R::Setting(_) => (
                2,
                "2D transfer functions, cropping, an average range, a whole box, \
                 volumetric shadows, a depth range, intermixed volumes, or surface \
                 scattering when path tracing",
            ),
        }
    }

    #[test]
    fn every_frame_gets_its_variant_or_a_refusal_in_order() {
        let mut seen = 0;
        matrix(&mut |x| {
            seen += 1;
            match select(x) {
                Ok(v) => {
                    assert_eq!(v.blend, x.blend.code());
                    assert_eq!(v.cell_scalars, x.cell_scalars);
                    assert_eq!(x.components, 1);
                    assert_eq!(v.shade, x.shade && x.blend == BlendMode::Composite);
                    assert!(v.shade || (v.lights == 0 && !v.positional_lights));
                    assert_eq!(
                        v.gradient_opacity,
                        x.gradient_opacity && x.blend == BlendMode::Composite
                    );
                }
                Err(UnstructuredRefusal::Blend(b)) => assert_eq!(b, x.blend),
                Err(UnstructuredRefusal::Components(n)) => {
                    assert_eq!(n, x.components);
                    let one = UnstructuredFacts {
                        components: 1,
                        ..*x
                    };
                    assert!(!matches!(select(&one), Err(UnstructuredRefusal::Blend(_))));
                }
                Err(UnstructuredRefusal::Setting(what)) => {
                    let Error::Unsupported(m) = Error::from(select(x).unwrap_err()) else {
                        panic!("not Unsupported")
                    };
                    assert!(m.contains(what) && m.contains("turn it off"), "{m}");
                }
            }
        });
        assert_eq!(seen, 8 * 4 * 2 * 11);
    }
}
