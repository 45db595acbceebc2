//! Where the direct inextensibility solve starts: each of a substep's first [`WARM_SLOTS`] solves starts
//! from the multipliers the same solve of the last two substeps ended with, extrapolated, instead of from
//! none.
//!
//! Why: the multipliers are the bonds' tensions (times the substep squared), and they change little from
//! one substep to the next: gravity pulls a hanging chain by `g h^2` every substep and the solve pulls it
//! back by as much. From none, the lane solver's solves on the 1000 x 16 benchmark scene took 2.64 forward
//! passes on average (19 999 first and 32 713 later passes for 20 000 solves); from the extrapolated
//! multipliers 1.43 (249 and 28 399): `callgrind_annotate --tree=calling` of `valgrind --tool=callgrind
//! target/release/examples/scene_cost 20 1000x16 lanes`, built at 4bb5b3d and at 4e4e179. The start is the
//! line through the last two substeps' multipliers because a swaying chain's tensions move steadily: the last
//! substep's alone lags them.
//!
//! Each solve of a substep has a slot of its own: the solve after the first shape-matching pass meets other
//! errors than the one after the prediction. A solve whose start is worse than none (its first pass's
//! largest error above `inextensible::TRUSTED_START` and above that of the positions it was given) starts
//! again from none, with what a cold start computes, to the bit: a history that no longer fits (a collider's
//! push, a teleport, a chain woken from sleep) costs one pass, not a solve from far off. A solve that ends in
//! a fallback forgets its history, and so does a change of substep length or iteration count.
//!
//! A solve also counts the substeps in a row it ended in the Gauss-Newton projection
//! (`MultiplierHistory::relinearized`): while that streak runs, `inextensible` goes straight to that projection.

/// The solves of a substep that start from their history: the first after the prediction and the one after
/// the second shape-matching pass. Later ones (more than two iterations) start from none.
pub const WARM_SLOTS: usize = 2;

/// One solve's multipliers in the last two substeps it ended in the direct solve, per bond.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MultiplierHistory {
    /// The last substep's, and the one's before it (equal to the last's after the first).
    pub(crate) last: Vec<f64>,
    pub(crate) before: Vec<f64>,
    /// Whether `last` and `before` hold multipliers (a solve that fell back, or none yet, leaves none).
    pub(crate) remembered: bool,
    /// Substeps in a row this solve ended in the Gauss-Newton projection (`inextensible`'s fallback after a
    /// direct solve that fails: hair-length segments of long chains, which turn too far in a substep for the
    /// start directions).
    pub(crate) relinearized: u32,
}

impl MultiplierHistory {
    pub fn new(bonds: usize) -> Self {
        Self { last: vec![0.0; bonds], before: vec![0.0; bonds], remembered: false, relinearized: 0 }
    }

    pub fn remembered(&self) -> bool {
        self.remembered
    }

    /// Forgets the multipliers (the streak of Gauss-Newton projections stays).
    pub fn forget(&mut self) {
        self.remembered = false;
    }

    /// Forgets the multipliers and the streak.
    pub fn forget_all(&mut self) {
        self.remembered = false;
        self.relinearized = 0;
    }

    /// The start of bond `k`'s multiplier: the last two's line extended by a substep (`2 last - before`;
    /// exactly `last` while `before` equals it).
    #[inline(always)]
    pub fn start(last: f64, before: f64) -> f64 {
        2.0 * last - before
    }

    /// Writes the start of every bond into `mu` (none where nothing is remembered).
    pub fn write_start(&self, mu: &mut [f64]) {
        if !self.remembered {
            mu.fill(0.0);
            return;
        }
        for ((mu, &last), &before) in mu.iter_mut().zip(&self.last).zip(&self.before) {
            *mu = Self::start(last, before);
        }
    }

    /// A solve ended in the direct solve with the multipliers `mu`.
    pub fn learn(&mut self, mu: &[f64]) {
        if self.remembered {
            std::mem::swap(&mut self.last, &mut self.before);
        } else {
            self.before.copy_from_slice(mu);
        }
        self.last.copy_from_slice(mu);
        self.remembered = true;
    }

    /// Words for the engine's state hash (the multipliers only while they are used; the streak shares the
    /// flag's word, so that a state without one hashes as before the streak was kept).
    pub(crate) fn words(&self) -> impl Iterator<Item = u64> + '_ {
        let used = if self.remembered { self.last.len() } else { 0 };
        let values = self.last[..used].iter().chain(&self.before[..used]).map(|v| v.to_bits());
        std::iter::once(self.remembered as u64 | (self.relinearized as u64) << 1).chain(values)
    }
}

#[cfg(test)]
mod tests {
    use super::MultiplierHistory;

    #[test]
    fn the_start_is_none_then_the_last_then_the_line_through_the_last_two() {
        let mut history = MultiplierHistory::new(2);
        let mut mu = [7.0, 7.0];
        history.write_start(&mut mu);
        assert_eq!(mu, [0.0, 0.0], "nothing remembered: no start");
        history.learn(&[1.0, -2.0]);
        history.write_start(&mut mu);
        assert_eq!(mu, [1.0, -2.0], "one substep remembered: its multipliers");
        history.learn(&[1.5, -1.0]);
        history.write_start(&mut mu);
        assert_eq!(mu, [2.0, 0.0], "two: extrapolated");
        history.forget();
        history.write_start(&mut mu);
        assert_eq!(mu, [0.0, 0.0], "forgotten");
        history.learn(&[3.0, 4.0]);
        history.write_start(&mut mu);
        assert_eq!(mu, [3.0, 4.0], "after forgetting, the next solve's alone");
    }
}
