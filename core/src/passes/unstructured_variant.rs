//! Which specialisation of the unstructured pass a frame uses, and which settings it
//! refuses: a pure function of the frame's facts ([`select`]), tested over the combinations
//! on the CPU; its refusals are listed in docs/REFUSALS.md.

use super::iso_variant::DeferredVariant;
use crate::error::Error;
use crate::gpu::pipeline::pipeline_variant;
use crate::gpu::uniforms::MASK_NONE;
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
        /// Volumetric shadows (shaded composite with lights).
        volumetric: bool => "VOLUMETRIC",
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

pipeline_variant! {
    /// The pipeline constants of one specialisation of the mesh's first hit of its
    /// isosurfaces (firsthit_mesh.wgsl).
    pub(crate) struct MeshFirstHitVariant {
        cell_scalars: bool => "CELL_SCALARS",
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
    /// Volumetric shadows asked for (frame::casts_shadows).
    pub volumetric: bool,
    /// Rays limited to a range of depths (Renderer::render_between).
    pub depth_range: bool,
    pub intermix: bool,
    /// Path tracing's surface scattering: a gradient threshold, the stochastic blend or
    /// scattering regions other than everywhere.
    pub hybrid: bool,
    /// Scattering between isosurfaces (IsoParams::scattering).
    pub iso_scattering: bool,
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
                "unstructured volumes are drawn in the composite, maximum, minimum, average, \
                 additive and isosurface blend modes and path traced, not {b:?}: use one of \
                 those, or resample the mesh to an image"
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
        | BlendMode::Isosurface
        | BlendMode::PathTrace => {}
        b => return Err(R::Blend(b)),
    }
    if x.components != 1 {
        return Err(R::Components(x.components));
    }
    // (isosurfaces read no transfer function)
    let iso = x.blend == BlendMode::Isosurface;
    let settings = [
        (x.tables_2d && !iso, "2D transfer functions"),
        (x.cropping, "cropping"),
        (x.average_range && !iso, "an average range"),
        (x.whole_box, "a whole box (pieces of a whole)"),
        (x.depth_range, "a depth range"),
        (x.intermix, "intermixed volumes"),
        (
            x.hybrid && x.blend == BlendMode::PathTrace,
            "surface scattering (a gradient threshold, the stochastic blend or scattering \
             regions; path tracing scatters meshes by Henyey–Greenstein everywhere)",
        ),
        (
            x.iso_scattering && iso,
            "scattering between isosurfaces (their surfaces are shaded as opaque or \
             translucent layers)",
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
        volumetric: shade && x.volumetric && x.lights > 0,
    })
}

/// The variants that draw the isosurfaces of a mesh (its first hit, and the deferred
/// shading of the G-buffer it writes), or the first reason they cannot be drawn.
pub(crate) fn select_iso(
    x: &UnstructuredFacts,
) -> Result<(MeshFirstHitVariant, DeferredVariant), UnstructuredRefusal> {
    select(x)?;
    let deferred = DeferredVariant {
        lights: x.lights,
        positional_lights: x.positional_lights,
        scatter: 0,
        single_brick: true,
        component: 0,
        mask: MASK_NONE,
        blanking: false,
        rectilinear: false,
        mesh: true,
    };
    let first_hit = MeshFirstHitVariant {
        cell_scalars: x.cell_scalars,
    };
    Ok((first_hit, deferred))
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
            iso_scattering: false,
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
                    for k in 0..11 {
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
                            &mut y.iso_scattering,
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
            R::Blend(_) => (0, "the slice blend mode"),
            R::Components(_) => (1, "a mesh of several components"),
            R::Setting(_) => (
                2,
                "2D transfer functions, cropping, an average range, a whole box, a depth \
                 range, intermixed volumes, surface scattering when path tracing, or \
                 scattering between isosurfaces",
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
                    assert_eq!(v.volumetric, v.shade && x.volumetric && x.lights > 0);
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
        assert_eq!(seen, 8 * 4 * 2 * 12);
    }

    #[test]
    fn isosurfaces_read_no_transfer_function_and_shade_with_the_frames_lights() {
        let x = UnstructuredFacts {
            blend: BlendMode::Isosurface,
            tables_2d: true,
            volumetric: true,
            average_range: true,
            lights: 3,
            positional_lights: true,
            cell_scalars: true,
            ..facts()
        };
        let (fh, df) = select_iso(&x).unwrap();
        assert!(fh.cell_scalars && df.mesh && df.scatter == 0);
        assert_eq!((df.lights, df.positional_lights), (3, true));
        let scattering = UnstructuredFacts {
            iso_scattering: true,
            ..x
        };
        assert!(matches!(
            select_iso(&scattering),
            Err(UnstructuredRefusal::Setting(w)) if w.contains("between isosurfaces")
        ));
    }
}
