//! The lenslet rows of one stage of a baseline that are still needed: computed in order,
//! dropped once every later row has passed them.
//!
//! A baseline's output row needs its neighbours' rows of earlier stages (the demosaic's
//! estimate reads the sums of the rows within its radius; PPID's chain reaches three radii
//! ahead), so each stage is held as a window a few rows tall that slides down the frame:
//! the memory is the window's, whatever the frame's height.

use std::collections::VecDeque;

/// Rows `first..first + rows.len()` of one stage.
pub(super) struct Lagged<T> {
    first: usize,
    rows: VecDeque<T>,
}

impl<T> Lagged<T> {
    pub(super) fn new() -> Self {
        Self { first: 0, rows: VecDeque::new() }
    }

    /// Computes rows with `make` until row `last` is held (or row `end - 1`, the frame's
    /// last): every row once, in order.
    ///
    /// # Errors
    /// The first error `make` returns (a frame's row that cannot be read).
    pub(super) fn fill_to(
        &mut self,
        last: usize,
        end: usize,
        mut make: impl FnMut(usize) -> anyhow::Result<T>,
    ) -> anyhow::Result<()> {
        let stop = (last + 1).min(end);
        while self.first + self.rows.len() < stop {
            let s = self.first + self.rows.len();
            self.rows.push_back(make(s)?);
        }
        Ok(())
    }

    /// Row `s`, which must be held (computed and not yet dropped).
    pub(super) fn get(&self, s: usize) -> &T {
        &self.rows[s - self.first]
    }

    /// Drops the rows before `s`.
    pub(super) fn keep_from(&mut self, s: usize) {
        while self.first < s && !self.rows.is_empty() {
            self.rows.pop_front();
            self.first += 1;
        }
    }

    /// Rows held now.
    #[cfg(test)]
    pub(super) fn held(&self) -> usize {
        self.rows.len()
    }
}

/// The rows `s - r ..= s + r` inside `0..end`.
pub(super) fn around(s: usize, r: usize, end: usize) -> std::ops::Range<usize> {
    s.saturating_sub(r)..(s + r + 1).min(end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_made_once_in_order_and_dropped_behind() {
        let mut made = Vec::new();
        let mut w = Lagged::new();
        w.fill_to(2, 5, |s| {
            made.push(s);
            Ok(s * 10)
        })
        .unwrap();
        w.fill_to(1, 5, Ok).unwrap();
        assert_eq!(made, [0, 1, 2]);
        assert_eq!(*w.get(2), 20);
        w.keep_from(2);
        assert_eq!(w.held(), 1);
        w.fill_to(9, 5, |s| Ok(s * 10)).unwrap();
        assert_eq!((w.held(), *w.get(4)), (3, 40));
        assert_eq!(around(0, 2, 5), 0..3);
        assert_eq!(around(4, 2, 5), 2..5);
    }
}
