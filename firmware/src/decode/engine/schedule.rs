//! The order of an overlapped decode's work ([`Schedule`]): which tiles are ready, and
//! which rows are final.
//!
//! Every value is the weighted mean of the estimates that cover it, summed in the order of
//! the plan ([`crate::decode::engine::plan`]) whatever the batches, so a decode is the same
//! bit for bit with batches of one tile or of the whole frame. A shifted tile waits until
//! every disjoint tile that reaches its rows has been added (its seed, and the order), and a
//! row is finished once no tile left reaches it:
//!
//! - rows from [`Schedule::disjoint_done`] to [`Schedule::end`] hold the disjoint grid's
//!   sums while disjoint tiles still reach them;
//! - a row no pending disjoint tile reaches is final in the disjoint grid: its finished
//!   values are the seeds of the shifted patches that reach it, and from then on only
//!   shifted tiles add to it;
//! - a row no pending tile reaches at all is finished, put to the sink, and its place
//!   reused.

use core::iter::Peekable;
use core::ops::Range;

use crate::decode::engine::plan::{Grids, Planned};

/// What the next batch is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Next {
    /// The next this many disjoint tiles ([`Schedule::take_disjoint`]).
    Disjoint(usize),
    /// The next this many shifted tiles ([`Schedule::take_shifted`]): their rows are final
    /// in the disjoint grid, their seeds made.
    Shifted(usize),
    /// Every tile is added and every row finished.
    Done,
    /// No tile can be added: the next disjoint tile reaches past the rows held (more than
    /// the strip's slots beyond the first unfinished row).
    Stalled,
}

/// The rows an [`Schedule::advance`] made final.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Advanced {
    /// Rows now final in the disjoint grid: their seeds are to be made.
    pub seeds: Range<usize>,
    /// Rows now finished: to be put to the sink.
    pub finished: Range<usize>,
}

/// Where a decode is: the tiles left (of a frame, or of a band of its columns) and the rows
/// held.
#[derive(Clone, Debug)]
pub struct Schedule<D: Iterator<Item = Planned>, S: Iterator<Item = Planned>> {
    grids: Grids,
    disjoint: Peekable<D>,
    shifted: Peekable<S>,
    /// Rows below: no disjoint tile left reaches them.
    disjoint_done: usize,
    /// Rows below: finished and put.
    put: usize,
    /// Rows below: reached by an added tile (held from `put`).
    end: usize,
}

impl<D: Iterator<Item = Planned> + Clone, S: Iterator<Item = Planned> + Clone> Schedule<D, S> {
    /// The schedule of `disjoint` and `shifted` (in the plan's order, of `grids`).
    pub fn new(grids: Grids, disjoint: D, shifted: S) -> Self {
        Self { grids, disjoint: disjoint.peekable(), shifted: shifted.peekable(), disjoint_done: 0, put: 0, end: 0 }
    }

    /// The grids scheduled.
    pub fn grids(&self) -> &Grids {
        &self.grids
    }

    /// Rows below are final in the disjoint grid.
    pub fn disjoint_done(&self) -> usize {
        self.disjoint_done
    }

    /// Rows below are finished.
    pub fn put(&self) -> usize {
        self.put
    }

    /// Rows below are reached by an added tile: `put..end` are held.
    pub fn end(&self) -> usize {
        self.end
    }

    /// The next batch of at most `max` (at least 1) tiles, holding at most `slots` rows
    /// from the first unfinished: the shifted tiles whose rows are final in the disjoint
    /// grid, else the next disjoint tiles.
    pub fn next(&self, max: usize, slots: usize) -> Next {
        let max = max.max(1);
        let grids = self.grids;
        let shifted =
            self.shifted.clone().take(max).take_while(|p| grids.rows(&p.tile).end <= self.disjoint_done).count();
        if shifted > 0 {
            return Next::Shifted(shifted);
        }
        let limit = self.put.saturating_add(slots);
        let disjoint = self.disjoint.clone().take(max).take_while(|p| grids.rows(&p.tile).end <= limit).count();
        match (disjoint, self.disjoint.clone().next().is_some() || self.shifted.clone().next().is_some()) {
            (0, true) => Next::Stalled,
            (0, false) => Next::Done,
            (n, _) => Next::Disjoint(n),
        }
    }

    /// The next disjoint tile, taken.
    pub fn take_disjoint(&mut self) -> Option<Planned> {
        let p = self.disjoint.next()?;
        self.end = self.end.max(self.grids.rows(&p.tile).end);
        Some(p)
    }

    /// The next shifted tile, taken.
    pub fn take_shifted(&mut self) -> Option<Planned> {
        self.shifted.next()
    }

    /// After a batch is added: the rows no pending disjoint tile reaches are final in the
    /// disjoint grid, and those no pending tile reaches are finished.
    pub fn advance(&mut self) -> Advanced {
        let grids = self.grids;
        let (rows, done) = (grids.lenslets().0, self.disjoint_done);
        let until = self.disjoint.peek().map_or(rows, |p| grids.rows(&p.tile).start);
        self.disjoint_done = done.max(until);
        let put = self.put;
        let until =
            self.shifted.peek().map_or(self.disjoint_done, |p| grids.rows(&p.tile).start.min(self.disjoint_done));
        self.put = put.max(until);
        self.end = self.end.max(self.put);
        Advanced { seeds: done..self.disjoint_done, finished: put..self.put }
    }

    /// Rows a strip must hold for batches of `max` tiles: the schedule run dry, the most
    /// rows any disjoint tile reached beyond the first unfinished row, and the most rows
    /// final in the disjoint grid and not finished (their seeds). Every step of the plan is
    /// visited once: bounded by the frame's tiles.
    pub fn needs(mut self, max: usize) -> Needs {
        let mut needs = Needs { rows: 1, seed_rows: 1 };
        loop {
            match self.next(max, usize::MAX) {
                Next::Disjoint(n) => {
                    for _ in 0..n {
                        if let Some(p) = self.take_disjoint() {
                            needs.rows = needs.rows.max(self.grids.rows(&p.tile).end.saturating_sub(self.put));
                        }
                    }
                }
                Next::Shifted(n) => {
                    for _ in 0..n {
                        self.take_shifted();
                    }
                }
                Next::Done | Next::Stalled => return needs,
            }
            let a = self.advance();
            needs.seed_rows = needs.seed_rows.max(a.seeds.end.saturating_sub(a.finished.start));
        }
    }
}

/// The rows a strip holds ([`Schedule::needs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Needs {
    /// Rows of sums, from the first unfinished.
    pub rows: usize,
    /// Rows of seeds, from the first unfinished.
    pub seed_rows: usize,
}
