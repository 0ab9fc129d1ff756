//! How overlapping estimates of a value are weighed ([`Window`]).

use crate::operators::shape::Shape;

/// How overlapping estimates of a value are weighed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Window {
    /// Every value of a patch counts the same.
    #[default]
    Uniform,
    /// A patch's lenslet weighs `1 + its distance from the patch's nearest edge` per axis
    /// (1, 2, 3, 2, 1 across the paper's 5 lenslets), the axes multiplied: a value is
    /// taken mostly from the patches it sits in the middle of, where a patch's model is
    /// best constrained.
    Tapered,
}

impl Window {
    /// The weight of lenslet `(s, t)` of a patch of shape `S`.
    #[inline]
    pub fn weight<S: Shape>(self, s: usize, t: usize) -> f32 {
        let taper = |i: usize, p: usize| (1 + i.min(p.saturating_sub(1).saturating_sub(i))) as f32;
        match self {
            Window::Uniform => 1.0,
            Window::Tapered => taper(s, S::PS) * taper(t, S::PT),
        }
    }
}
