//! Small statistics shared by the live stats and the measurements.

/// The median of `values` (the upper one of an even count; 0 for none); reorders them.
pub fn median<T: Copy + Default + PartialOrd>(values: &mut [T]) -> T {
    if values.is_empty() {
        return T::default();
    }
    let mid = values.len() / 2;
    *values
        .select_nth_unstable_by(mid, |a, b| {
            a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal)
        })
        .1
}
