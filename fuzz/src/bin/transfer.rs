//! Transfer-function JSON: a function that parses must validate and sample into finite
//! lookup tables, as the renderer samples it.
use ferrovol_core::params::transfer::build_tables;

fn main() {
    ferrovol_fuzz::fuzz(|input| {
        let Ok(text) = std::str::from_utf8(input) else {
            return "not UTF-8 text".to_string();
        };
        let tf = match ferrovol_io::transfer::parse_json(text) {
            Ok(tf) => tf,
            Err(e) => return format!("error: {e}"),
        };
        if let Err(e) = tf.validate(1) {
            panic!("a parsed transfer function fails validation: {e}");
        }
        for step in [1e-3, 1.0] {
            let tables = build_tables(tf.component(0), step);
            if let Some(entry) = tables.iter().find(|e| e.iter().any(|x| !x.is_finite())) {
                panic!("a parsed transfer function samples to a non-finite table entry {entry:?}");
            }
        }
        format!(
            "transfer function of {} point(s)",
            tf.component(0).color.points.len()
        )
    });
}
