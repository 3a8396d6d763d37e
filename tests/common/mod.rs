//! Helpers shared by the integration tests that compare runs.

/// Largest difference between two position sets, relative to the largest coordinate.
pub fn max_relative_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len(), "different particle counts");
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
        / scale
}
