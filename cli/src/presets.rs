//! Transfer-function presets, and JSON transfer-function files (the format:
//! [`ferrovol_io::transfer`]).

use crate::CliError;
use ferrovol_core::{ComponentTransfer, Piecewise, TransferFunction, VolumeData};
use std::path::Path;

pub const PRESETS: &[&str] = &[
    "auto",
    "wavelet",
    "marschner-lobb",
    "sphere",
    "ct-bone",
    "ct-skin-bone",
    "mri",
    "grey",
];

/// VTK's TestGPURayCastMapperBenchmark transfer function (for the wavelet).
pub fn wavelet_tf() -> TransferFunction {
    tf(
        &[
            (37.3531, [0.2, 0.29, 1.0]),
            (157.091, [0.87, 0.87, 0.87]),
            (276.829, [0.7, 0.015, 0.15]),
        ],
        &[(37.3531, 0.0), (276.829, 1.0)],
    )
}

fn tf(color: &[(f64, [f32; 3])], opacity: &[(f64, f32)]) -> TransferFunction {
    let c = Piecewise::new(color.to_vec()).expect("preset points are finite");
    let o = Piecewise::new(opacity.iter().map(|&(x, a)| (x, [a])).collect())
        .expect("preset points are finite");
    TransferFunction::single(ComponentTransfer::new(c, o))
}

/// A preset by name, or a JSON file, for a volume.
pub fn transfer_function(name: &str, vol: &VolumeData) -> Result<TransferFunction, CliError> {
    // Preset opacities are per voxel: the unit distance is the mean spacing (as ParaView
    // derives ScalarOpacityUnitDistance from the data), so a preset looks alike at any scale.
    let unit = vol.spacing.iter().sum::<f64>() / 3.0;
    preset(name, || Ok(vol.try_range(0)?), unit)
}

/// A preset by name, or a JSON file, for data whose first component's range `range` gives
/// (read only by the presets placed by it: a pass over the whole data), the presets' unit
/// distance `unit`.
pub fn preset(
    name: &str,
    range: impl FnOnce() -> Result<[f64; 2], CliError>,
    unit: f64,
) -> Result<TransferFunction, CliError> {
    let [lo, hi] = if matches!(name, "mri" | "grey" | "auto") {
        range()?
    } else {
        [0.0, 1.0]
    };
    let at = |f: f64| lo + (hi - lo) * f;
    let mut t = match name {
        "wavelet" => wavelet_tf(),
        "marschner-lobb" => tf(
            &[
                (0.0, [0.9, 0.5, 0.3]),
                (0.5, [1.0, 0.85, 0.6]),
                (1.0, [1.0, 1.0, 1.0]),
            ],
            &[(0.0, 0.0), (0.4, 0.0), (0.5, 0.8), (0.6, 0.0), (1.0, 0.0)],
        ),
        "sphere" => tf(
            &[(-2.0, [1.0, 0.9, 0.7]), (2.0, [0.8, 0.4, 0.2])],
            &[(-2.0, 0.0), (-0.5, 0.9), (0.5, 0.9), (2.0, 0.0)],
        ),
        "ct-bone" => tf(
            &[
                (-1000.0, [0.0, 0.0, 0.0]),
                (200.0, [0.9, 0.8, 0.7]),
                (1500.0, [1.0, 1.0, 0.95]),
            ],
            &[(-1000.0, 0.0), (200.0, 0.0), (400.0, 0.6), (1500.0, 0.9)],
        ),
        "ct-skin-bone" => tf(
            &[
                (-1000.0, [0.0, 0.0, 0.0]),
                (-500.0, [0.75, 0.5, 0.4]),
                (0.0, [0.9, 0.65, 0.55]),
                (300.0, [1.0, 0.95, 0.85]),
                (1500.0, [1.0, 1.0, 1.0]),
            ],
            &[
                (-1000.0, 0.0),
                (-600.0, 0.0),
                (-400.0, 0.15),
                (-100.0, 0.0),
                (200.0, 0.0),
                (400.0, 0.8),
                (1500.0, 0.95),
            ],
        ),
        "mri" => tf(
            &[
                (at(0.0), [0.0, 0.0, 0.0]),
                (at(0.3), [0.8, 0.55, 0.45]),
                (at(0.7), [1.0, 0.9, 0.8]),
                (at(1.0), [1.0, 1.0, 1.0]),
            ],
            &[
                (at(0.0), 0.0),
                (at(0.15), 0.0),
                (at(0.35), 0.15),
                (at(1.0), 0.8),
            ],
        ),
        "grey" | "auto" => tf(&[(lo, [0.0; 3]), (hi, [1.0; 3])], &[(lo, 0.0), (hi, 0.5)]),
        other => {
            let p = Path::new(other);
            if !p.exists() {
                return Err(CliError::Usage(format!(
                    "--tf '{other}' is neither a preset ({}) nor an existing JSON file",
                    PRESETS.join(", ")
                )));
            }
            return from_json(p);
        }
    };
    t.components[0].unit_distance = unit;
    Ok(t)
}

fn from_json(path: &Path) -> Result<TransferFunction, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::Usage(format!("{}: cannot read: {e}", path.display())))?;
    Ok(ferrovol_io::transfer::parse_json(&text).map_err(|e| e.in_file(path))?)
}
