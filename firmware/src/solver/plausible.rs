//! The plausibility check: a decoded patch against what its own measurements allow.
//!
//! A solve can end far from the truth and still meet every measurement: SL0 fills the
//! unmeasured values from the prior, and a solve that went wrong (a start that diverged, a
//! shear that put a bright edge inside a dark patch) fills them with light nothing
//! measured. Measured on a canopy beside water and shade (`slf scene canopy`, 80 x 80
//! lenslets, pixel k = 1): the DCT alone decoded 17 of 256 blocks of 5 x 5 lenslets to
//! more than twice their truth's maximum + 0.05, with "0 flagged".
//!
//! The check needs no truth: a pixel's light is seen, in other bands, by the pixels next to
//! it in space and view, so no value there should be far above the brightest of their
//! measurements. With the band gains divided out (white-balanced units, in which the decode
//! works), the bound of pixel `(s, t, u, v)` of a patch is
//!
//! ```text
//! bound = factor * max { y / g_b : y measured at (s', t', u', v'), each within 1 of (s, t, u, v) } + margin
//! ```
//!
//! for the bands the neighbourhood measured, and the same over the whole patch for the
//! others; a value above its bound is implausible. A pixel whose neighbourhood holds no
//! measurement has no bound. The neighbourhood is in the patch's own frame (a sheared
//! patch's, along its shear), so the check reads nothing but the workspace. Why the views
//! are in it and not only the lenslets: a patch sheared to a wrong disparity carries a
//! bright neighbour's edge into a dark lenslet's outer views; a bound over the whole
//! lenslet (3 x 3 lenslets, every view) let 13 blocks of the canopy through where this one
//! catches them.
//!
//! What the decode does with an implausible patch is the tile decoder's
//! ([`crate::decode::tile`]): it decodes it again by a safer path and, if values are still
//! above their bounds, [`clip`]s them; both are counted in its report.

use crate::operators::shape::{PerBand, PerValue, Pixels, Shape};
use crate::sensor::extent::{Array, Bands};
use crate::solver::workspace::Measurements;

/// The bound's parameters (config: immutable, set once on the tile decoder).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plausibility {
    /// How far above the neighbourhood's brightest measurement a value may lie, as a
    /// factor, >= 1.
    pub factor: f32,
    /// Added to the bound (white-balanced normalised units, white = 1), >= 0: dark
    /// neighbourhoods' measurements are mostly noise.
    pub margin: f32,
}

impl Plausibility {
    /// The default: three times the neighbourhood's brightest measurement, plus 0.05.
    /// Chosen on the canopy, saturated and texture scenes (`slf scene`, 48 x 48 lenslets,
    /// pixel k = 1 and lenslet k = 3; `docs/results-plausible.md` has every scene): at 2
    /// the saturated scene lost 1.1 dB at lenslet k = 3 (a lenslet mask's neighbourhood
    /// sees few bands, and a saturated colour's unseen band can be far above its seen
    /// ones), at 3 it loses 0.4 while the canopy gains 0.9 dB at pixel k = 1 (2: 0.8, 4:
    /// 0.2) with half the re-decoded patches.
    pub const DEFAULT: Self = Self { factor: 3.0, margin: 0.05 };

    /// No bound: the check never fires.
    pub const OFF: Self = Self { factor: f32::INFINITY, margin: f32::INFINITY };

    /// Whether the check is off.
    pub fn is_off(&self) -> bool {
        self.factor == f32::INFINITY || self.margin == f32::INFINITY
    }

    /// Whether both fields are in range (`factor >= 1`, `margin >= 0`, neither NaN; infinity
    /// is [`Self::OFF`]).
    pub fn is_valid(&self) -> bool {
        self.factor >= 1.0 && self.margin >= 0.0
    }

    /// The bounds of the patch measured by `m` (values in the solve's units, as `m` holds
    /// them).
    pub fn bounds<S: Shape>(&self, m: &Measurements<S::Values>) -> Bounds<S> {
        let mut b = Bounds {
            local: S::PerPixel::<f32>::splat(f32::NEG_INFINITY),
            seen: S::PerPixel::<u32>::splat(0),
            wide: f32::INFINITY,
        };
        if self.is_off() {
            b.local = S::PerPixel::<f32>::splat(f32::INFINITY);
            b.seen = S::PerPixel::<u32>::splat(u32::MAX);
            return b;
        }
        let mut widest = f32::NEG_INFINITY;
        {
            let local = b.local.flat_mut();
            let seen = b.seen.flat_mut();
            let pixels = S::Bands::chunks(m.values.as_ref()).iter().zip(S::Bands::chunks(m.measured.as_ref()));
            for ((most, bits), (values, measured)) in local.iter_mut().zip(seen.iter_mut()).zip(pixels) {
                for (band, (&y, &k)) in values.iter().zip(measured.iter()).enumerate() {
                    if k {
                        *most = if y > *most { y } else { *most };
                        *bits |= 1 << (band & 31);
                    }
                }
                widest = if *most > widest { *most } else { widest };
            }
        }
        // The neighbourhood's maximum and bands, one axis at a time (a 3 x 3 x 3 x 3
        // neighbourhood is four 3-tap ones), in place.
        for (len, stride) in [(S::PS, S::PT * S::PU * S::PV), (S::PT, S::PU * S::PV), (S::PU, S::PV), (S::PV, 1)] {
            along(b.local.flat_mut(), len, stride, f32::NEG_INFINITY, |a, c| if a > c { a } else { c });
            along(b.seen.flat_mut(), len, stride, 0, |a, c| a | c);
        }
        for most in b.local.flat_mut() {
            *most = self.bound(*most);
        }
        b.wide = self.bound(widest);
        b
    }

    /// `factor * max(most, 0) + margin`; no bound (infinity) where nothing was measured.
    fn bound(&self, most: f32) -> f32 {
        if most == f32::NEG_INFINITY {
            return f32::INFINITY;
        }
        // A negative measurement (noise about a black level) bounds as zero.
        self.factor * (if most > 0.0 { most } else { 0.0 }) + self.margin
    }
}

/// The bounds of a patch's values: per pixel `[s][t][u][v]`, from the brightest
/// measurement of its neighbourhood, for the bands the neighbourhood measured; the patch's
/// brightest measurement bounds the other bands (a lenslet mask's neighbourhood sees a few
/// bands, and a saturated colour's unseen band can be many times its seen ones: bounded by
/// the neighbourhood's, the saturated test scene lost 1.3 dB at lenslet k = 3).
#[derive(Clone, Debug)]
pub struct Bounds<S: Shape> {
    /// The neighbourhood's bound of each pixel.
    pub local: S::PerPixel<f32>,
    /// The bands (bit `b`: band `b`) measured in each pixel's neighbourhood.
    pub seen: S::PerPixel<u32>,
    /// The patch's bound, for the bands a neighbourhood did not measure.
    pub wide: f32,
}

impl<S: Shape> Bounds<S> {
    /// Each pixel's `B` bounds, in the patch's pixel order.
    fn per_pixel(&self) -> impl Iterator<Item = PerBand<S, f32>> + '_ {
        self.local.flat().iter().zip(self.seen.flat()).map(move |(&near, &bits)| {
            let mut bounds = <PerBand<S, f32>>::splat(self.wide);
            for (b, x) in bounds.iter_mut().enumerate() {
                if bits & (1 << (b & 31)) != 0 {
                    *x = near;
                }
            }
            bounds
        })
    }
}

/// Each value of `a` (lines of `len` values `stride` apart) `join`ed with its two
/// neighbours along the line (`none` beyond its ends).
fn along<T: Copy>(a: &mut [T], len: usize, stride: usize, none: T, join: impl Fn(T, T) -> T) {
    let block = len * stride;
    if block == 0 {
        return;
    }
    for chunk in a.chunks_exact_mut(block) {
        for first in 0..stride {
            let mut prev = none;
            for k in 0..len {
                let here = chunk.get(k * stride + first).copied().unwrap_or(none);
                let next =
                    if k + 1 < len { chunk.get((k + 1) * stride + first).copied().unwrap_or(none) } else { none };
                if let Some(x) = chunk.get_mut(k * stride + first) {
                    *x = join(join(prev, here), next);
                }
                prev = here;
            }
        }
    }
}

impl Default for Plausibility {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// How many values of `patch` lie above their bound (`bounds`, from
/// [`Plausibility::bounds`]); a NaN counts as above.
pub fn implausible<S: Shape>(bounds: &Bounds<S>, patch: &PerValue<S, f32>) -> u32 {
    let mut above = 0u32;
    for (run, bound) in S::Bands::chunks(patch.as_ref()).iter().zip(bounds.per_pixel()) {
        for (&x, &bound) in run.iter().zip(bound.iter()) {
            // Above, or NaN (which no bound holds).
            above += u32::from(x > bound || x.is_nan());
        }
    }
    above
}

/// Every value of `patch` above its bound set to the bound (a NaN too). Measured values lie
/// within their own bound (`factor >= 1`, `margin >= 0`), so a patch that met its
/// measurements still does.
pub fn clip<S: Shape>(bounds: &Bounds<S>, patch: &mut PerValue<S, f32>) {
    for (run, bound) in S::Bands::chunks_mut(patch.as_mut()).iter_mut().zip(bounds.per_pixel()) {
        for (x, &bound) in run.iter_mut().zip(bound.iter()) {
            *x = if *x <= bound { *x } else { bound };
        }
    }
}
