//! Inputs the fuzz targets (fuzz/, docs/FUZZING.md) showed a reader mishandling, each
//! with what the reader does now. Allocation findings are in allocation.rs.

use ferrovol_core::params::transfer::build_tables;
use ferrovol_io::transfer::parse_json;

/// Transfer functions whose points span more than a 32-bit float (positions ±1e308) or
/// whose values differ by more than one (±3e38) made `build_tables` panic (NaN sample
/// position, index underflow) or sample infinite entries. They are refused now, naming the
/// point; the extremes that are accepted sample to finite tables.
#[test]
fn transfer_function_extremes() {
    for (json, want) in [
        (
            r#"{"color": [[-1e308, 0, 0, 0], [1e308, 1, 1, 1]], "opacity": [[0, 1]]}"#,
            "'color': point 0 is at -1e308, beyond ±1e38",
        ),
        (
            r#"{"color": [[0, 0, 0, 0]], "opacity": [[0, 1], [3.5e38, 1]]}"#,
            "'opacity': point 1 is at 3.5e38, beyond ±1e38",
        ),
        (
            r#"{"color": [[0, -3e38, 0, 0], [1, 3e38, 1, 1]], "opacity": [[0, 1]]}"#,
            "'color': point 0 has the value -3e38; colours and opacities go from 0 to 1",
        ),
        (
            r#"{"color": [[0, 1, 1, 1]], "opacity": [[0, 1.5]]}"#,
            "'opacity': point 0 has the value 1.5",
        ),
        (
            r#"{"color": [[0, 1, 1, 1]], "opacity": [[0, 1]], "gradient_opacity": [[0, -0.5]]}"#,
            "'gradient_opacity': point 0 has the value -0.5",
        ),
    ] {
        let m = parse_json(json).expect_err(json).to_string();
        println!("{m}");
        assert!(m.contains(want), "{json}: wanted {want:?} in {m}");
    }

    let widest = r#"{"color": [[-1e38, 0, 0, 0], [1e38, 1, 1, 1]], "opacity": [[-1e38, 0], [1e38, 1]],
                     "gradient_opacity": [[-1e38, 0], [1e38, 1]]}"#;
    let tf = parse_json(widest).unwrap();
    let tables = build_tables(tf.component(0), 1.0);
    let bad = tables
        .iter()
        .filter(|e| e.iter().any(|x| !x.is_finite()))
        .count();
    println!(
        "points at ±1e38: {} table entries, {bad} not finite",
        tables.len()
    );
    assert_eq!(bad, 0);
}
