//! Transfer functions as JSON.
//!
//! `{"color": [[x, r, g, b], …], "opacity": [[x, a], …], "gradient_opacity": [[g, a], …],
//! "unit_distance": 1.0}`; x in scalar units, g in scalar units per world unit, both
//! within ±[`ferrovol_core::MAX_TRANSFER_POSITION`]; r, g, b and a from 0 to 1; gradient_opacity and
//! unit_distance are optional.

use ferrovol_core::{ComponentTransfer, Error, Piecewise, TransferFunction};

use crate::error::Problem;
use crate::ReadError;

fn error(message: String) -> ReadError {
    Problem::TransferFunction(message).into()
}

/// The points of `key` in `v`, each `[x, v1, …, vN]`; `None` if `v` has no `key`.
fn points<const N: usize>(
    v: &serde_json::Value,
    key: &str,
) -> Result<Option<Piecewise<N>>, ReadError> {
    let bad = |m: String| error(format!("transfer function '{key}': {m}"));
    let Some(arr) = v.get(key) else {
        return Ok(None);
    };
    let arr = arr
        .as_array()
        .ok_or_else(|| bad("must be an array of points".into()))?;
    let mut pts = Vec::new();
    for (i, p) in arr.iter().enumerate() {
        let nums: Vec<f64> = p
            .as_array()
            .ok_or_else(|| bad(format!("point {i} must be an array")))?
            .iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| bad(format!("point {i} has a non-number")))
            })
            .collect::<Result<_, _>>()?;
        if nums.len() != N + 1 {
            return Err(bad(format!(
                "point {i} has {} numbers, expected {}",
                nums.len(),
                N + 1
            )));
        }
        if let Some(v) = nums[1..].iter().find(|v| !(0.0..=1.0).contains(*v)) {
            return Err(bad(format!(
                "point {i} has the value {v:?}; colours and opacities go from 0 to 1"
            )));
        }
        let mut val = [0f32; N];
        for c in 0..N {
            val[c] = nums[c + 1] as f32;
        }
        pts.push((nums[0], val));
    }
    // Piecewise::new refuses empty lists, non-finite numbers and positions beyond
    // ±MAX_TRANSFER_POSITION, naming the point.
    Piecewise::new(pts).map(Some).map_err(|e| match e {
        Error::InvalidTransferFunction(m) => bad(m),
        other => bad(other.to_string()),
    })
}

/// Parses a transfer function from JSON text (the format is in the module
/// documentation). Errors name the field that is wrong; [`ReadError::in_file`] adds the
/// file's name.
pub fn parse_json(text: &str) -> Result<TransferFunction, ReadError> {
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| error(format!("not valid JSON: {e}")))?;
    let color = points::<3>(&v, "color")?
        .ok_or_else(|| error("a 'color' array of [x, r, g, b] points is required".into()))?;
    let opacity = points::<1>(&v, "opacity")?
        .ok_or_else(|| error("an 'opacity' array of [x, a] points is required".into()))?;
    let mut c = ComponentTransfer::new(color, opacity);
    c.gradient_opacity = points::<1>(&v, "gradient_opacity")?;
    if let Some(u) = v.get("unit_distance") {
        c.unit_distance = u
            .as_f64()
            .filter(|u| *u > 0.0)
            .ok_or_else(|| error("'unit_distance' must be a positive number".into()))?;
    }
    Ok(TransferFunction::single(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_points_and_options() {
        let t = parse_json(
            r#"{"color": [[0, 0, 0, 0], [100, 1, 0.5, 0.25]], "opacity": [[0, 0], [100, 0.8]],
                "gradient_opacity": [[0, 0], [10, 1]], "unit_distance": 2.5}"#,
        )
        .unwrap();
        let c = &t.components[0];
        assert_eq!(c.unit_distance, 2.5);
        assert!(c.gradient_opacity.is_some());
        let t = parse_json(r#"{"color": [[0, 1, 1, 1]], "opacity": [[0, 1]]}"#).unwrap();
        assert!(t.components[0].gradient_opacity.is_none());
    }

    #[test]
    fn errors_name_the_field() {
        for (json, want) in [
            ("{", "not valid JSON"),
            (r#"{"opacity": [[0, 1]]}"#, "a 'color' array"),
            (r#"{"color": [[0, 1, 1, 1]]}"#, "an 'opacity' array"),
            (
                r#"{"color": 3, "opacity": [[0, 1]]}"#,
                "'color': must be an array of points",
            ),
            (
                r#"{"color": [[0, 1, 1]], "opacity": [[0, 1]]}"#,
                "'color': point 0 has 3 numbers, expected 4",
            ),
            (
                r#"{"color": [[0, 1, 1, 1]], "opacity": [[0, "a"]]}"#,
                "'opacity': point 0 has a non-number",
            ),
            (
                r#"{"color": [[0, 1, 1, 1]], "opacity": [5]}"#,
                "'opacity': point 0 must be an array",
            ),
            (
                r#"{"color": [[0, 1, 1, 1]], "opacity": [[0, 1]], "unit_distance": 0}"#,
                "'unit_distance' must be a positive number",
            ),
        ] {
            let e = parse_json(json).unwrap_err();
            let m = e.in_file(std::path::Path::new("tf.json")).to_string();
            println!("{m}");
            assert!(m.starts_with("tf.json: "), "{m}");
            assert!(m.contains(want), "{json}: wanted {want:?} in {m}");
        }
    }
}
