//! Multiple importance sampling weights (Veach and Guibas 1995).

/// w_a for a sample of pdf `a` against one other strategy of pdf `b`, by the power
/// heuristic (β = 2); written as a ratio so that huge pdfs do not overflow.
#[inline]
pub fn power_heuristic(a: f64, b: f64) -> f64 {
    if a.is_infinite() {
        return 1.0;
    }
    if a == 0.0 {
        return 0.0;
    }
    let r = b / a;
    1.0 / (1.0 + r * r)
}

#[cfg(test)]
mod tests {
    use super::power_heuristic;

    #[test]
    fn weights_of_two_strategies_sum_to_one() {
        for &(a, b) in &[
            (1.0, 1.0),
            (0.3, 7.0),
            (1e200, 1e-200),
            (1e-300, 2e-300),
            (5.0, 0.0),
        ] {
            let s = power_heuristic(a, b) + power_heuristic(b, a);
            assert!((s - 1.0).abs() < 1e-12, "{a} {b}: {s}");
        }
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert_eq!(power_heuristic(f64::INFINITY, 1.0), 1.0);
        assert!((power_heuristic(1.0, 3.0) - 0.1).abs() < 1e-15);
    }
}
