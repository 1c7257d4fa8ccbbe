//! Small statistics shared by the live stats and the measurements.

/// The median of `values` (the upper one of an even count; 0 for none); reorders them.
#[doc(hidden)]
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

/// Step times of a run of any length in bounded memory: every time while there are at
/// most [`StepTimes::KEPT`], then a uniform sample of that many (reservoir sampling with
/// a fixed seed, so a run is repeatable), whose median estimates the run's.
#[derive(Clone, Debug, Default)]
pub struct StepTimes {
    kept: Vec<f64>,
    seen: u64,
    state: u64,
}

impl StepTimes {
    /// The most times kept.
    pub const KEPT: usize = 1 << 16;

    /// Records one time.
    pub fn push(&mut self, t: f64) {
        self.seen += 1;
        if self.kept.len() < Self::KEPT {
            self.kept.push(t);
            return;
        }
        // xorshift64*, seeded once: replace a kept time with probability KEPT/seen.
        if self.state == 0 {
            self.state = 0x9E37_79B9_7F4A_7C15;
        }
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let r = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D) % self.seen;
        if let Some(slot) = self.kept.get_mut(r as usize) {
            *slot = t;
        }
    }

    /// The median of the times kept (exact up to [`StepTimes::KEPT`] steps).
    pub fn median(&mut self) -> f64 {
        median(&mut self.kept)
    }
}
