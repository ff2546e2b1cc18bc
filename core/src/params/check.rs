//! The range checks every parameter type's `validate` is made of, so that a value out of
//! range is reported the same way everywhere.

use crate::error::{Error, Result};
use std::fmt::Display;

fn bad(message: String) -> Result<()> {
    Err(Error::InvalidParameter(message))
}

/// A count: "`n` `what`: give `lo` to `hi`" unless lo ≤ n ≤ hi.
pub(crate) fn count(what: &str, n: u32, lo: u32, hi: u32) -> Result<()> {
    if (lo..=hi).contains(&n) {
        Ok(())
    } else {
        bad(format!("{n} {what}: give {lo} to {hi}"))
    }
}

/// A value in a closed interval: "`what` `v` must be in [`lo`, `hi`]" unless lo ≤ v ≤ hi
/// (NaN is outside).
pub(crate) fn within<T: PartialOrd + Display>(what: &str, v: T, lo: T, hi: T) -> Result<()> {
    if lo <= v && v <= hi {
        Ok(())
    } else {
        bad(format!("{what} {v} must be in [{lo}, {hi}]"))
    }
}

/// "`what` `v` must be finite and non-negative" unless it is.
pub(crate) fn non_negative(what: &str, v: f32) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        bad(format!("{what} {v} must be finite and non-negative"))
    }
}
