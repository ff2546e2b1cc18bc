//! Transfer functions: colour, opacity and gradient opacity per component.

use super::*;

#[derive(Clone, Default)]
struct PartialComponent {
    color: Option<Piecewise<3>>,
    opacity: Option<Piecewise<1>>,
    gradient_opacity: Option<Piecewise<1>>,
    unit_distance: Option<f64>,
    weight: Option<f32>,
    material: Option<[f32; 4]>,
    table_2d: Option<Table2D>,
}

/// Colour, scalar opacity and gradient opacity per component (vtkVolumeProperty's
/// functions), and per label of a label-map mask. Thread use: one thread at a time.
pub struct FvTransferFunction {
    components: Vec<PartialComponent>,
    independent: bool,
    /// Index: label − 1.
    labels: Vec<LabelTransfer>,
}

impl FvTransferFunction {
    fn component(&mut self, c: u32) -> FfiResult<&mut PartialComponent> {
        let n = self.components.len();
        self.components.get_mut(c as usize).ok_or_else(|| {
            FfiError::invalid(format!(
                "component {c}: this transfer function has {n} (0 to {})",
                n - 1
            ))
        })
    }
}

impl FvTransferFunction {
    /// Label `label`'s functions, created empty when it has none.
    fn label(&mut self, label: u32) -> FfiResult<&mut LabelTransfer> {
        let Ok(l @ 1..=255) = u8::try_from(label) else {
            return Err(FfiError::invalid(format!(
                "label {label}: labels with functions of their own are 1 to 255 (label 0 is \
                 the background, drawn with the components' functions)"
            )));
        };
        let i = match self.labels.iter().position(|t| t.label == l) {
            Some(i) => i,
            None => {
                self.labels.push(LabelTransfer {
                    label: l,
                    color: None,
                    opacity: None,
                    gradient_opacity: None,
                });
                self.labels.len() - 1
            }
        };
        Ok(&mut self.labels[i])
    }
}

impl ToCore for FvTransferFunction {
    type Core = TransferFunction;
    fn to_core(&self) -> FfiResult<TransferFunction> {
        let mut components = Vec::with_capacity(self.components.len());
        for (i, c) in self.components.iter().enumerate() {
            let (Some(color), Some(opacity)) = (&c.color, &c.opacity) else {
                return Err(FfiError::invalid(format!(
                    "component {i} needs both a colour and an opacity function (fv_transfer_function_set_color / _set_opacity)"
                )));
            };
            let mut t = ComponentTransfer::new(color.clone(), opacity.clone());
            t.gradient_opacity = c.gradient_opacity.clone();
            t.unit_distance = c.unit_distance.unwrap_or(t.unit_distance);
            t.weight = c.weight.unwrap_or(t.weight);
            t.material = c.material;
            t.table_2d = c.table_2d.clone();
            components.push(t);
        }
        let labels = self
            .labels
            .iter()
            .filter(|l| l.color.is_some() || l.opacity.is_some() || l.gradient_opacity.is_some())
            .cloned()
            .collect();
        Ok(TransferFunction {
            components,
            independent: self.independent,
            labels,
        })
    }
}

fn points<const N: usize>(
    what: &str,
    p: *const f64,
    count: usize,
) -> FfiResult<Option<Piecewise<N>>> {
    if count == 0 {
        return Ok(None);
    }
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: the caller guarantees `count` points of 1 + N doubles.
    let flat = unsafe { std::slice::from_raw_parts(p, count * (N + 1)) };
    let pts = flat
        .chunks_exact(N + 1)
        .map(|c| (c[0], std::array::from_fn(|i| c[i + 1] as f32)))
        .collect();
    Piecewise::new(pts)
        .map(Some)
        .map_err(|e| FfiError::invalid(format!("{what}: {e}")))
}

/// A transfer function for `components` (1–4) components; `independent` is
/// vtkVolumeProperty::IndependentComponents (with dependent components, give one
/// component's functions). `*out` receives it, NULL on failure.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_new(
    components: u32,
    independent: bool,
    out: *mut *mut FvTransferFunction,
) -> FvStatus {
    guard(|| {
        let slot = out_ptr(out, "out")?;
        if !(1..=4).contains(&components) {
            return Err(FfiError::invalid(format!(
                "{components} components: a transfer function has 1 to 4"
            )));
        }
        *slot = Box::into_raw(Box::new(FvTransferFunction {
            components: vec![PartialComponent::default(); components as usize],
            independent,
            labels: Vec::new(),
        }));
        Ok(())
    })
}

/// Releases a transfer function (NULL is ignored).
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_free(tf: *mut FvTransferFunction) {
    guard_value((), || free_handle(tf))
}

/// Replaces one of a component's piecewise functions (`field`) with `count` points of
/// 1 + N doubles at `p`. `empty` is the refusal for count = 0, or None where no points
/// turn the function off.
fn set_component_points<const N: usize>(
    tf: *mut FvTransferFunction,
    component: u32,
    what: &str,
    p: *const f64,
    count: usize,
    empty: Option<&str>,
    field: fn(&mut PartialComponent) -> &mut Option<Piecewise<N>>,
) -> FvStatus {
    guard(|| {
        let f = field(mut_ref(tf, "tf")?.component(component)?);
        *f = points::<N>(what, p, count)?;
        match empty {
            Some(refusal) if f.is_none() => Err(FfiError::invalid(refusal)),
            _ => Ok(()),
        }
    })
}

/// Colour points of one component: `count` quadruples (x, r, g, b), x increasing.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_color(
    tf: *mut FvTransferFunction,
    component: u32,
    xrgb: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "colour points",
        xrgb,
        count,
        Some("a colour function needs at least one point"),
        |c| &mut c.color,
    )
}

/// Scalar opacity points of one component: `count` pairs (x, opacity), x increasing.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_opacity(
    tf: *mut FvTransferFunction,
    component: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "opacity points",
        xa,
        count,
        Some("an opacity function needs at least one point"),
        |c| &mut c.opacity,
    )
}

/// Gradient-magnitude opacity points of one component: `count` pairs (|∇s| in scalar units
/// per world unit, opacity multiplier); count = 0 turns gradient opacity off.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_gradient_opacity(
    tf: *mut FvTransferFunction,
    component: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_component_points(
        tf,
        component,
        "gradient opacity points",
        xa,
        count,
        None,
        |c| &mut c.gradient_opacity,
    )
}

/// ScalarOpacityUnitDistance (> 0) and the component weight (≥ 0) of one component.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_unit_distance(
    tf: *mut FvTransferFunction,
    component: u32,
    unit_distance: f64,
    weight: f64,
) -> FvStatus {
    guard(|| {
        let t = mut_ref(tf, "tf")?;
        if !(unit_distance.is_finite() && unit_distance > 0.0) {
            return Err(FfiError::invalid(format!(
                "scalar opacity unit distance {unit_distance} must be positive"
            )));
        }
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(FfiError::invalid(format!(
                "component weight {weight} must be finite and non-negative"
            )));
        }
        let c = t.component(component)?;
        c.unit_distance = Some(unit_distance);
        c.weight = Some(weight as f32);
        Ok(())
    })
}

/// One component's own material when components are independent (vtkVolumeProperty's
/// per-component shading): `material` = ambient, diffuse and specular coefficients and
/// specular power, each finite and ≥ 0; NULL: the render parameters' (the default).
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_material(
    tf: *mut FvTransferFunction,
    component: u32,
    material: *const [f32; 4],
) -> FvStatus {
    guard(|| {
        let t = mut_ref(tf, "tf")?;
        // SAFETY: NULL or four floats, as the caller guarantees.
        let m = unsafe { material.as_ref() }.copied();
        if let Some(m) = m {
            if !m.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(FfiError::invalid(format!(
                    "material {m:?} (ambient, diffuse, specular, specular power) must be \
                     finite and non-negative"
                )));
            }
        }
        t.component(component)?.material = m;
        Ok(())
    })
}

/// Replaces one of label `label`'s functions (`field`) with `count` points of 1 + N doubles
/// at `p`; no points: the first component's function again.
fn set_label_points<const N: usize>(
    tf: *mut FvTransferFunction,
    label: u32,
    what: &str,
    p: *const f64,
    count: usize,
    field: fn(&mut LabelTransfer) -> &mut Option<Piecewise<N>>,
) -> FvStatus {
    guard(|| {
        let t = mut_ref(tf, "tf")?;
        let pts = points::<N>(what, p, count)?;
        *field(t.label(label)?) = pts;
        Ok(())
    })
}

/// Colour points of label `label` (1 to 255; vtkVolumeProperty::SetLabelColor): `count`
/// quadruples (x, r, g, b); count = 0: the first component's colour function again. Read
/// where a label-map mask gives a sample this label (fv_renderer_set_mask).
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_label_color(
    tf: *mut FvTransferFunction,
    label: u32,
    xrgb: *const f64,
    count: usize,
) -> FvStatus {
    set_label_points(tf, label, "label colour points", xrgb, count, |l| {
        &mut l.color
    })
}

/// Scalar opacity points of label `label` (vtkVolumeProperty::SetLabelScalarOpacity):
/// `count` pairs (x, opacity); count = 0: the first component's opacity function again.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_label_opacity(
    tf: *mut FvTransferFunction,
    label: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_label_points(tf, label, "label opacity points", xa, count, |l| {
        &mut l.opacity
    })
}

/// Gradient-magnitude opacity points of label `label`
/// (vtkVolumeProperty::SetLabelGradientOpacity): `count` pairs (|∇s|, opacity multiplier);
/// count = 0: the first component's gradient opacity again.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_label_gradient_opacity(
    tf: *mut FvTransferFunction,
    label: u32,
    xa: *const f64,
    count: usize,
) -> FvStatus {
    set_label_points(tf, label, "label gradient opacity points", xa, count, |l| {
        &mut l.gradient_opacity
    })
}

/// One component's 2D transfer function (vtkVolumeProperty::SetTransferFunction2D, TF_2D):
/// `width × height` RGBA floats at `rgba`, x (scalar) fastest, rows of increasing gradient
/// magnitude, opacity per sample in ray casting (not corrected for the sample distance or
/// the unit distance, as VTK 9.2 reads it) and per unit distance in path tracing; the
/// columns span the scalars `scalar_lo` to
/// `scalar_hi` (VTK: the component's data range), the rows gradient magnitudes 0 to
/// `gradient_max` (scalar units per world unit; 0: every sample reads the first row, as VTK
/// without gradient opacity). It classifies composite ray casting and path tracing instead
/// of the colour and opacity functions; NULL `rgba` removes it.
#[no_mangle]
pub unsafe extern "C" fn fv_transfer_function_set_table_2d(
    tf: *mut FvTransferFunction,
    component: u32,
    width: u32,
    height: u32,
    rgba: *const f32,
    scalar_lo: f64,
    scalar_hi: f64,
    gradient_max: f64,
) -> FvStatus {
    guard(|| {
        let c = mut_ref(tf, "tf")?.component(component)?;
        if rgba.is_null() {
            c.table_2d = None;
            return Ok(());
        }
        if width == 0 || height == 0 || width > 4096 || height > 4096 {
            return Err(FfiError::invalid(format!(
                "2D table of {width}x{height} entries: each side must be 1 to 4096"
            )));
        }
        let n = width as usize * height as usize;
        // SAFETY: the caller guarantees width · height RGBA floats at `rgba`.
        let flat = unsafe { std::slice::from_raw_parts(rgba, 4 * n) };
        let t = Table2D {
            width,
            height,
            rgba: flat
                .chunks_exact(4)
                .map(|v| [v[0], v[1], v[2], v[3]])
                .collect(),
            scalar_range: [scalar_lo, scalar_hi],
            gradient_max: (gradient_max != 0.0).then_some(gradient_max),
        };
        t.validate().map_err(|e| FfiError::invalid(e.to_string()))?;
        c.table_2d = Some(t);
        Ok(())
    })
}
