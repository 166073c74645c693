//! Flags a report writes beside numbers a reader must not take at face value.

use impactcal_core::Parameter;

/// Fraction of a parameter's range within which a value counts as at its bound.
pub const AT_BOUND: f64 = 1e-3;

/// `AT LOWER BOUND` or `AT UPPER BOUND` when `v` lies within [`AT_BOUND`] of the range's
/// width from that bound of `p` (the data pushed the value there and the optimum may lie
/// beyond), else the empty string; empty for NaN.
pub fn bound_flag(p: &Parameter, v: f64) -> &'static str {
    let near = AT_BOUND * p.width();
    if v - p.lower <= near {
        "AT LOWER BOUND"
    } else if p.upper - v <= near {
        "AT UPPER BOUND"
    } else {
        ""
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_at_and_near_the_bounds_are_flagged_and_inner_ones_not() {
        let p = Parameter::new("t", 0.048, 0.072, 0.06).map_err(|e| e.to_string());
        let p = p.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(bound_flag(&p, 0.048), "AT LOWER BOUND");
        assert_eq!(bound_flag(&p, 0.048 + 0.5e-3 * 0.024), "AT LOWER BOUND");
        assert_eq!(bound_flag(&p, 0.072), "AT UPPER BOUND");
        assert_eq!(bound_flag(&p, 0.0485), "");
        assert_eq!(bound_flag(&p, 0.06), "");
        assert_eq!(bound_flag(&p, f64::NAN), "");
    }
}
