//! WGSL sources. Each pass is one file in the crate's shaders/; shared pieces live in
//! shaders/lib/ and are pulled in with `#include "lib/NAME.wgsl"` lines, expanded here (each
//! file once). The constants shared with Rust are not written in WGSL: [`compose`] declares
//! them first, from [`super::uniforms::WGSL_CONSTANTS`] and [`super::slots::WGSL_SLOTS`].

/// (path relative to shaders/, source) for every WGSL file.
pub const FILES: &[(&str, &str)] = &[
    (
        "lib/common.wgsl",
        include_str!("../../shaders/lib/common.wgsl"),
    ),
    ("lib/ray.wgsl", include_str!("../../shaders/lib/ray.wgsl")),
    (
        "lib/volume.wgsl",
        include_str!("../../shaders/lib/volume.wgsl"),
    ),
    (
        "lib/shading.wgsl",
        include_str!("../../shaders/lib/shading.wgsl"),
    ),
    (
        "lib/output.wgsl",
        include_str!("../../shaders/lib/output.wgsl"),
    ),
    (
        "lib/march.wgsl",
        include_str!("../../shaders/lib/march.wgsl"),
    ),
    (
        "lib/envmap.wgsl",
        include_str!("../../shaders/lib/envmap.wgsl"),
    ),
    ("lib/iso.wgsl", include_str!("../../shaders/lib/iso.wgsl")),
    (
        "lib/phase.wgsl",
        include_str!("../../shaders/lib/phase.wgsl"),
    ),
    ("lib/bsdf.wgsl", include_str!("../../shaders/lib/bsdf.wgsl")),
    (
        "lib/shadow.wgsl",
        include_str!("../../shaders/lib/shadow.wgsl"),
    ),
    (
        "lib/blanking.wgsl",
        include_str!("../../shaders/lib/blanking.wgsl"),
    ),
    (
        "lib/rectilinear.wgsl",
        include_str!("../../shaders/lib/rectilinear.wgsl"),
    ),
    (
        "lib/table2d.wgsl",
        include_str!("../../shaders/lib/table2d.wgsl"),
    ),
    (
        "lib/intermix.wgsl",
        include_str!("../../shaders/lib/intermix.wgsl"),
    ),
    (
        "lib/surface.wgsl",
        include_str!("../../shaders/lib/surface.wgsl"),
    ),
    (
        "lib/classify.wgsl",
        include_str!("../../shaders/lib/classify.wgsl"),
    ),
    ("lib/mesh.wgsl", include_str!("../../shaders/lib/mesh.wgsl")),
    (
        "lib/volumetric.wgsl",
        include_str!("../../shaders/lib/volumetric.wgsl"),
    ),
    (
        "lib/pathtrace.wgsl",
        include_str!("../../shaders/lib/pathtrace.wgsl"),
    ),
    ("dvr.wgsl", include_str!("../../shaders/dvr.wgsl")),
    (
        "unstructured.wgsl",
        include_str!("../../shaders/unstructured.wgsl"),
    ),
    ("firsthit.wgsl", include_str!("../../shaders/firsthit.wgsl")),
    ("deferred.wgsl", include_str!("../../shaders/deferred.wgsl")),
    (
        "firsthit_mesh.wgsl",
        include_str!("../../shaders/firsthit_mesh.wgsl"),
    ),
    (
        "environment.wgsl",
        include_str!("../../shaders/environment.wgsl"),
    ),
    (
        "pathtrace.wgsl",
        include_str!("../../shaders/pathtrace.wgsl"),
    ),
    (
        "pathtrace_mesh.wgsl",
        include_str!("../../shaders/pathtrace_mesh.wgsl"),
    ),
    (
        "phase_test.wgsl",
        include_str!("../../shaders/phase_test.wgsl"),
    ),
    (
        "pathtrace_show.wgsl",
        include_str!("../../shaders/pathtrace_show.wgsl"),
    ),
    (
        "depth_changed.wgsl",
        include_str!("../../shaders/depth_changed.wgsl"),
    ),
    ("denoise.wgsl", include_str!("../../shaders/denoise.wgsl")),
    ("gradient.wgsl", include_str!("../../shaders/gradient.wgsl")),
];

/// The passes (entry files, not library pieces).
#[cfg(test)]
pub const PASSES: &[&str] = &[
    "dvr.wgsl",
    "unstructured.wgsl",
    "firsthit.wgsl",
    "deferred.wgsl",
    "firsthit_mesh.wgsl",
    "environment.wgsl",
    "pathtrace.wgsl",
    "pathtrace_mesh.wgsl",
    "pathtrace_show.wgsl",
    "depth_changed.wgsl",
    "denoise.wgsl",
    "gradient.wgsl",
    "phase_test.wgsl",
];

fn source(path: &str) -> Option<&'static str> {
    FILES.iter().find(|(p, _)| *p == path).map(|(_, s)| *s)
}

/// The complete source of a pass: the shared constants and binding slots, then the pass
/// with its includes expanded.
pub fn compose(path: &str) -> String {
    let mut out = super::uniforms::wgsl_constants();
    for (name, slot) in super::slots::WGSL_SLOTS {
        out.push_str(&format!("const {name}: u32 = {slot}u;\n"));
    }
    let mut seen = Vec::new();
    expand(path, &mut out, &mut seen);
    out
}

/// The files a pass is composed of: itself and everything it includes, directly or not.
#[cfg(test)]
pub fn files_of(path: &str) -> Vec<String> {
    let mut seen = Vec::new();
    expand(path, &mut String::new(), &mut seen);
    seen
}

fn expand(path: &str, out: &mut String, seen: &mut Vec<String>) {
    if seen.iter().any(|s| s == path) {
        return;
    }
    seen.push(path.to_string());
    let src =
        source(path).unwrap_or_else(|| panic!("shader '{path}' is not listed in shaders::FILES"));
    for line in src.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("#include") {
            let inc = rest.trim().trim_matches('"');
            expand(inc, out, seen);
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
}
