//! Synthetic spectral light fields: layered surfaces.
//!
//! A scene is a stack of layers. Each has a shape, a disparity (pixels of shift per view
//! step, -1.5..+1.5 at its centre), a texture that mixes two reflectance spectra, and is lit
//! by the scene's illuminant. View `(u, v)` sees the point `(y + d du, x + d dv)` of a layer
//! of disparity `d`, with `(du, dv)` its offset from the central view; the nearest layer that
//! covers that point wins, so occlusion is correct in every view. Each pixel averages 2 x 2
//! samples, so edges are anti-aliased. Everything is seeded and deterministic.
//!
//! The five named test scenes ([`NAMES`]) and [`random`] use fronto-parallel Lambertian
//! layers under D65, and stay as they are (they are the regression set and the shipped
//! ensemble's training data). A layer can also be slanted and curved (its disparity varies
//! over it, so the point a view sees is found by a fixed-point iteration), shaded by its
//! surface normal, and carry a specular highlight that moves across views unlike its
//! surface; `crate::sim::realistic` builds scenes that use them.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::io::lightfield::LightField;
use crate::sim::spectra::{BANDS, COLORCHECKER, D65, Spectrum, colorchecker, narrow_band, smooth_random};

/// The region a layer covers, in reference-view coordinates normalised to `[0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Everywhere,
    Rect { y0: f32, x0: f32, y1: f32, x1: f32 },
    Disc { cy: f32, cx: f32, r: f32 },
}

impl Shape {
    fn contains(&self, y: f32, x: f32) -> bool {
        match *self {
            Shape::Everywhere => true,
            Shape::Rect { y0, x0, y1, x1 } => (y0..y1).contains(&y) && (x0..x1).contains(&x),
            Shape::Disc { cy, cx, r } => (y - cy).powi(2) + (x - cx).powi(2) < r * r,
        }
    }
}

/// How a layer mixes its two reflectances, as a weight in `[0, 1]`; lengths in pixels.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    Flat,
    /// Smooth value noise with lattice spacing `cell`.
    Noise {
        cell: f32,
        seed: u64,
    },
    Stripes {
        period: f32,
        angle: f32,
    },
    Checks {
        period: f32,
    },
    /// Pixel-scale value noise: fine detail.
    Fine {
        seed: u64,
    },
    /// Detail at every scale: value noise summed over seven octaves from 64 pixels down to
    /// one, each octave's amplitude `2^(1 - beta)` of the one before. An octave of value
    /// noise spreads its variance over a frequency area that grows as `f^2`, so equal
    /// amplitudes (`beta` = 1, equal energy per octave, as natural images have) give an
    /// amplitude spectrum falling as `1 / f`, and in general `1 / f^beta`. Measured from 4 to
    /// 32-pixel periods (`tests/scenes.rs`) the slope is about 0.3 steeper than `-beta`
    /// (-1.29 at `beta` 1): value noise is smooth within its octave.
    Pink {
        seed: u64,
        beta: f32,
    },
}

fn hash01(seed: u64, ix: i64, iy: i64) -> f32 {
    let mut z =
        seed ^ (ix as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (iy as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

fn value_noise(seed: u64, y: f32, x: f32) -> f32 {
    let (fy, fx) = (y.floor(), x.floor());
    let (ty, tx) = (y - fy, x - fx);
    let (sy, sx) = (ty * ty * (3.0 - 2.0 * ty), tx * tx * (3.0 - 2.0 * tx));
    let (iy, ix) = (fy as i64, fx as i64);
    let a = hash01(seed, ix, iy) * (1.0 - sx) + hash01(seed, ix + 1, iy) * sx;
    let b = hash01(seed, ix, iy + 1) * (1.0 - sx) + hash01(seed, ix + 1, iy + 1) * sx;
    a * (1.0 - sy) + b * sy
}

impl Texture {
    /// The weight of the second reflectance at pixel position `(y, x)`, in `[0, 1]`.
    pub fn weight(&self, y: f32, x: f32) -> f32 {
        match *self {
            Texture::Flat => 0.0,
            Texture::Noise { cell, seed } => value_noise(seed, y / cell, x / cell),
            Texture::Stripes { period, angle } => {
                0.5 + 0.5 * (std::f32::consts::TAU * (x * angle.cos() + y * angle.sin()) / period).sin()
            }
            Texture::Checks { period } => ((y / period).floor() + (x / period).floor()).rem_euclid(2.0),
            Texture::Fine { seed } => value_noise(seed, y, x),
            Texture::Pink { seed, beta } => {
                let (mut sum, mut norm, mut amp, mut freq) = (0.0f32, 0.0f32, 1.0f32, 1.0 / 64.0f32);
                for octave in 0..7u64 {
                    sum += amp * (value_noise(seed.wrapping_add(octave), y * freq, x * freq) - 0.5);
                    norm += amp;
                    amp *= 2.0f32.powf(1.0 - beta);
                    freq *= 2.0;
                }
                (0.5 + 1.6 * sum / norm).clamp(0.0, 1.0)
            }
        }
    }
}

impl Shape {
    /// The centre of the region, normalised (the frame's centre for `Everywhere`).
    pub fn centre(&self) -> (f32, f32) {
        match *self {
            Shape::Everywhere => (0.5, 0.5),
            Shape::Rect { y0, x0, y1, x1 } => ((y0 + y1) / 2.0, (x0 + x1) / 2.0),
            Shape::Disc { cy, cx, .. } => (cy, cx),
        }
    }
}

/// A specular highlight: a white spot (the illuminant's spectrum) on a layer that moves
/// `shift` pixels per view step relative to the layer's surface (a reflection seen at
/// another depth than the surface), so it breaks the Lambertian model.
#[derive(Clone, Debug, PartialEq)]
pub struct Highlight {
    /// Centre, normalised, in the layer's coordinates at the central view.
    pub cy: f32,
    pub cx: f32,
    /// Radius (standard deviation), normalised to the frame height.
    pub radius: f32,
    /// Peak radiance as a fraction of a white reflector's.
    pub strength: f32,
    /// Pixels per view step.
    pub shift: f32,
}

/// One surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Pixels of shift per view step (positive = nearer), at the shape's centre.
    pub disparity: f32,
    pub shape: Shape,
    pub texture: Texture,
    /// The two reflectances the texture mixes.
    pub reflectance: [Spectrum; 2],
    /// Change of disparity across the frame (rows, cols), per frame height / width: a
    /// slanted plane. `(0, 0)`: fronto-parallel.
    pub slope: (f32, f32),
    /// Disparity added at normalised distance `r` from the shape's centre: `curvature r^2`
    /// (negative: a dome, nearest in the middle).
    pub curvature: f32,
    /// How much of the radiance follows the surface normal's angle to the light (0: none,
    /// 1: all of it, black where it faces away).
    pub shading: f32,
    pub highlight: Option<Highlight>,
    /// Materials that change cell by cell, replacing `texture` and `reflectance` where set.
    pub mosaic: Option<Mosaic>,
}

/// A surface of many materials: every `cell x cell` pixels of it (in its own coordinates)
/// one reflectance of `palette`, picked by a hash of the cell, in place of the layer's
/// texture and reflectances. With a cell of a lenslet or two, the spectrum changes at the
/// decoder's patch scale: fields, mosaics, tiled floors.
#[derive(Clone, Debug, PartialEq)]
pub struct Mosaic {
    /// Cell size, pixels.
    pub cell: f32,
    pub seed: u64,
    pub palette: Vec<Spectrum>,
}

impl Mosaic {
    /// The palette index of the cell holding layer point `(y, x)`.
    fn index(&self, y: f32, x: f32) -> usize {
        let c = self.cell.max(1e-3);
        let h = hash01(self.seed, (y / c).floor() as i64, (x / c).floor() as i64);
        ((h * self.palette.len() as f32) as usize).min(self.palette.len().saturating_sub(1))
    }
}

impl Layer {
    /// A fronto-parallel Lambertian layer.
    pub fn flat(disparity: f32, shape: Shape, texture: Texture, reflectance: [Spectrum; 2]) -> Self {
        Self {
            disparity,
            shape,
            texture,
            reflectance,
            slope: (0.0, 0.0),
            curvature: 0.0,
            shading: 0.0,
            highlight: None,
            mosaic: None,
        }
    }

    fn is_flat(&self) -> bool {
        self.slope == (0.0, 0.0)
            && self.curvature == 0.0
            && self.shading == 0.0
            && self.highlight.is_none()
            && self.mosaic.is_none()
    }

    /// Disparity and its gradient (per normalised unit) at normalised `(y, x)`.
    fn disparity_at(&self, y: f32, x: f32) -> (f32, f32, f32) {
        let (cy, cx) = self.shape.centre();
        let (dy, dx) = (y - cy, x - cx);
        let d = self.disparity + self.slope.0 * dy + self.slope.1 * dx + self.curvature * (dy * dy + dx * dx);
        (d, self.slope.0 + 2.0 * self.curvature * dy, self.slope.1 + 2.0 * self.curvature * dx)
    }

    /// The point `(y, x)` (pixels) of this layer that view offset `(du, dv)` sees at sample
    /// `(py, px)`, and the disparity there: `y = py + d(y, x) du`, by fixed-point iteration
    /// (the slopes are small against the frame, so it contracts fast).
    fn hit(&self, py: f32, px: f32, du: f32, dv: f32, h: f32, w: f32) -> (f32, f32, f32) {
        let (mut ly, mut lx) = (py, px);
        let mut d = 0.0;
        for _ in 0..5 {
            d = self.disparity_at(ly / h, lx / w).0;
            (ly, lx) = (py + d * du, px + d * dv);
        }
        (ly, lx, d)
    }
}

/// Direction to the light for [`Layer::shading`] (unnormalised: up-left, towards the camera).
const LIGHT: [f32; 3] = [-0.45, -0.35, 0.82];

/// A scene: layers (any order; rendered by disparity), an illuminant and an exposure gain.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub name: String,
    pub layers: Vec<Layer>,
    /// Scales all radiance: 1 for a normal exposure, small for low light.
    pub gain: f32,
    /// Relative spectral power of the light; radiance is reflectance times this over its
    /// peak, so a white reflector is 1 in the light's brightest band.
    pub illuminant: Spectrum,
}

/// The size of a rendered light field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneSize {
    pub views: (usize, usize),
    pub rows: usize,
    pub cols: usize,
}

impl Default for SceneSize {
    /// 5 x 5 views of 100 x 100 pixels.
    fn default() -> Self {
        Self { views: (5, 5), rows: 100, cols: 100 }
    }
}

impl SceneSize {
    /// The most values a rendered light field may hold: [`LightField::MAX_VALUES`].
    pub const MAX_VALUES: usize = LightField::MAX_VALUES;

    /// Checks that no axis is empty and the light field stays within [`Self::MAX_VALUES`]
    /// ([`LightField::check_size`]).
    ///
    /// # Errors
    /// What is out of range, in one line.
    pub fn check(&self) -> anyhow::Result<()> {
        LightField::check_size(self.views, self.rows, self.cols, BANDS)
    }
}

impl Scene {
    /// Renders the light field `(U, V, H, W, 13)`.
    pub fn render(&self, size: SceneSize) -> LightField {
        let mut lf = LightField::zeros(size.views, size.rows, size.cols, BANDS);
        let mut layers: Vec<&Layer> = self.layers.iter().collect();
        layers.sort_by(|a, b| b.disparity.total_cmp(&a.disparity)); // nearest first
        let peak = self.illuminant.iter().fold(0.0f32, |m, &x| m.max(x));
        let lit = |r: &Spectrum| -> Spectrum { core::array::from_fn(|b| r[b] * self.illuminant[b] / peak * self.gain) };
        let radiance: Vec<[Spectrum; 2]> = layers.iter().map(|l| l.reflectance.map(|r| lit(&r))).collect();
        let palettes: Vec<Vec<Spectrum>> = layers
            .iter()
            .map(|l| l.mosaic.as_ref().map_or_else(Vec::new, |m| m.palette.iter().map(lit).collect()))
            .collect();
        let white = lit(&[1.0; BANDS]);
        // Fronto-parallel Lambertian layers (the regression scenes) take the first hit in
        // disparity order; other layers are all intersected and the nearest hit wins. A
        // flat layer's shade is 1 and its highlight 0, so the shared sum below gives the
        // regression scenes the same bits as before layers could slant.
        let all_flat = layers.iter().all(|l| l.is_flat());
        let norm = (LIGHT[0] * LIGHT[0] + LIGHT[1] * LIGHT[1] + LIGHT[2] * LIGHT[2]).sqrt();
        let (cu, cv) = ((size.views.0 as f32 - 1.0) / 2.0, (size.views.1 as f32 - 1.0) / 2.0);
        let (h, w) = (size.rows as f32, size.cols as f32);
        // One spatial row of one view per task (rayon): rows are independent and contiguous.
        let row_len = size.cols * BANDS;
        lf.data.par_chunks_mut(row_len).enumerate().for_each(|(r, out)| {
            let (view, y) = (r / size.rows, r % size.rows);
            let (u, v) = (view / size.views.1, view % size.views.1);
            let (du, dv) = (u as f32 - cu, v as f32 - cv);
            for (x, px_out) in out.chunks_exact_mut(BANDS).enumerate() {
                let mut acc = [0.0f32; BANDS];
                for (sy, sx) in [(0.25, 0.25), (0.25, 0.75), (0.75, 0.25), (0.75, 0.75)] {
                    let (py, px) = (y as f32 + sy, x as f32 + sx);
                    let hit = if all_flat {
                        // Sorted nearest first: the first layer that covers the point.
                        layers.iter().enumerate().find_map(|(i, l)| {
                            let (ly, lx) = (py + l.disparity * du, px + l.disparity * dv);
                            l.shape.contains(ly / h, lx / w).then_some((i, ly, lx))
                        })
                    } else {
                        let mut best: Option<(usize, f32, f32, f32)> = None;
                        for (i, layer) in layers.iter().enumerate() {
                            let (ly, lx, d) = layer.hit(py, px, du, dv, h, w);
                            if layer.shape.contains(ly / h, lx / w) && best.is_none_or(|b| d > b.3) {
                                best = Some((i, ly, lx, d));
                            }
                        }
                        best.map(|(i, ly, lx, _)| (i, ly, lx))
                    };
                    let Some((i, ly, lx)) = hit else { continue };
                    let (layer, rad) = (layers[i], &radiance[i]);
                    let t = layer.texture.weight(ly, lx);
                    let shade = if layer.shading > 0.0 {
                        let (_, gy, gx) = layer.disparity_at(ly / h, lx / w);
                        // Depth falls as disparity rises: the normal leans against the gradient.
                        let n = [gx, gy, 1.0];
                        let nn = (n[0] * n[0] + n[1] * n[1] + 1.0).sqrt();
                        let cos = (n[0] * LIGHT[0] + n[1] * LIGHT[1] + n[2] * LIGHT[2]) / (nn * norm);
                        1.0 - layer.shading + layer.shading * cos.max(0.0)
                    } else {
                        1.0
                    };
                    let spec = layer.highlight.as_ref().map_or(0.0, |hl| {
                        let (cy, cx) = (hl.cy * h + hl.shift * du, hl.cx * w + hl.shift * dv);
                        let r = hl.radius * h;
                        hl.strength * (-((ly - cy).powi(2) + (lx - cx).powi(2)) / (2.0 * r * r)).exp()
                    });
                    match layer.mosaic.as_ref().and_then(|m| palettes[i].get(m.index(ly, lx))) {
                        Some(material) => {
                            for (b, a) in acc.iter_mut().enumerate() {
                                *a += 0.25 * (shade * material[b] + spec * white[b]);
                            }
                        }
                        None => {
                            for (b, a) in acc.iter_mut().enumerate() {
                                *a += 0.25 * (shade * (rad[0][b] + t * (rad[1][b] - rad[0][b])) + spec * white[b]);
                            }
                        }
                    }
                }
                px_out.copy_from_slice(&acc);
            }
        });
        lf
    }
}

fn cc(name: &str) -> Spectrum {
    colorchecker(name).unwrap_or_else(|| panic!("no ColorChecker patch named {name:?}"))
}

fn rect(y0: f32, x0: f32, y1: f32, x1: f32) -> Shape {
    Shape::Rect { y0, x0, y1, x1 }
}

/// The named test scenes, each of a distinct character.
pub const NAMES: [&str; 5] = ["smooth", "texture", "depth", "saturated", "dark"];

/// The fewest lenslets a side of a test scene (`slf scene --size`, `slf.scene`): the
/// smallest light field the metrics score (SSIM's 11 x 11 window), so every scene made can
/// be evaluated. (Training scenes may be smaller: `slf train --size` from 5.)
pub const MIN_SCENE: usize = 11;

/// A named test scene (see [`NAMES`]); `None` for an unknown name (the realistic named
/// scenes are in `crate::sim::realistic`).
pub fn named(name: &str) -> Option<Scene> {
    let layer = |disparity, shape, texture, r0, r1| Layer::flat(disparity, shape, texture, [r0, r1]);
    let layers = match name {
        // Broad gradients and soft noise: what compressed sensing finds easiest.
        "smooth" => vec![
            layer(-0.5, Shape::Everywhere, Texture::Noise { cell: 40.0, seed: 1 }, cc("blue sky"), cc("foliage")),
            layer(
                0.5,
                Shape::Disc { cy: 0.5, cx: 0.5, r: 0.3 },
                Texture::Noise { cell: 25.0, seed: 2 },
                cc("light skin"),
                cc("orange yellow"),
            ),
        ],
        // Stripes, checks and pixel-scale noise at three depths.
        "texture" => vec![
            layer(
                -1.0,
                Shape::Everywhere,
                Texture::Stripes { period: 3.0, angle: 0.4 },
                cc("neutral 8 (.23 D)"),
                cc("moderate red"),
            ),
            layer(
                0.0,
                rect(0.15, 0.1, 0.6, 0.55),
                Texture::Checks { period: 2.0 },
                cc("white 9.5 (.05 D)"),
                cc("black 2 (1.5 D)"),
            ),
            layer(
                1.0,
                Shape::Disc { cy: 0.65, cx: 0.65, r: 0.25 },
                Texture::Fine { seed: 3 },
                cc("yellow green"),
                cc("purple"),
            ),
        ],
        // Flat surfaces whose edges jump in disparity: occlusion boundaries in every view.
        "depth" => vec![
            layer(
                -1.5,
                Shape::Everywhere,
                Texture::Noise { cell: 30.0, seed: 4 },
                cc("neutral 5 (.70 D)"),
                cc("neutral 6.5 (.44 D)"),
            ),
            layer(-0.5, rect(0.1, 0.1, 0.7, 0.45), Texture::Flat, cc("red"), cc("red")),
            layer(0.5, rect(0.3, 0.3, 0.9, 0.7), Texture::Flat, cc("blue"), cc("blue")),
            layer(1.5, Shape::Disc { cy: 0.35, cx: 0.7, r: 0.18 }, Texture::Flat, cc("yellow"), cc("yellow")),
        ],
        // Saturated chart colours and narrow-band lines.
        "saturated" => {
            let mut l =
                vec![layer(0.0, Shape::Everywhere, Texture::Flat, cc("black 2 (1.5 D)"), cc("black 2 (1.5 D)"))];
            let colours = [cc("red"), cc("green"), cc("blue"), cc("yellow"), cc("magenta"), cc("cyan")];
            for (i, c) in colours.iter().enumerate() {
                let (y, x) = ((i / 3) as f32 * 0.5, (i % 3) as f32 / 3.0);
                l.push(layer(0.4, rect(y + 0.05, x + 0.03, y + 0.45, x + 0.3), Texture::Flat, *c, *c));
            }
            for (i, nm) in [450.0, 530.0, 610.0, 660.0].iter().enumerate() {
                let c = narrow_band(*nm, 12.0);
                l.push(layer(
                    1.0,
                    Shape::Disc { cy: 0.25 + 0.5 * (i / 2) as f32, cx: 0.2 + 0.6 * (i % 2) as f32, r: 0.08 },
                    Texture::Flat,
                    c,
                    c,
                ));
            }
            l
        }
        // The depth scene at 4 % exposure: low light.
        "dark" => {
            return named("depth").map(|s| Scene { name: "dark".into(), gain: 0.04, ..s });
        }
        _ => return None,
    };
    Some(Scene { name: name.into(), layers, gain: 1.0, illuminant: D65 })
}

/// A random training scene: a textured background and 2 to 5 shapes at distinct
/// disparities, with ColorChecker, smooth random and narrow-band spectra.
pub fn random(seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let spectrum = |rng: &mut ChaCha8Rng| match rng.random_range(0..3) {
        0 => COLORCHECKER[rng.random_range(0..COLORCHECKER.len())].1,
        1 => smooth_random(rng),
        _ => narrow_band(rng.random_range(420.0..690.0), rng.random_range(8.0..30.0)),
    };
    let texture = |rng: &mut ChaCha8Rng| match rng.random_range(0..5) {
        0 => Texture::Flat,
        1 => Texture::Noise { cell: rng.random_range(4.0..40.0), seed: rng.random() },
        2 => {
            Texture::Stripes { period: rng.random_range(2.0..12.0), angle: rng.random_range(0.0..std::f32::consts::PI) }
        }
        3 => Texture::Checks { period: rng.random_range(1.0..8.0) },
        _ => Texture::Fine { seed: rng.random() },
    };
    let count = rng.random_range(3..=6);
    // Distinct disparities, evenly spread over -1.5..1.5 with jitter, far to near.
    let mut layers = Vec::with_capacity(count);
    for i in 0..count {
        let d = -1.5 + 3.0 * (i as f32 + rng.random_range(0.1..0.9)) / count as f32;
        let shape = if i == 0 {
            Shape::Everywhere
        } else if rng.random_bool(0.5) {
            let (y0, x0) = (rng.random_range(-0.1..0.7), rng.random_range(-0.1..0.7));
            rect(y0, x0, y0 + rng.random_range(0.15..0.6), x0 + rng.random_range(0.15..0.6))
        } else {
            Shape::Disc {
                cy: rng.random_range(0.0..1.0),
                cx: rng.random_range(0.0..1.0),
                r: rng.random_range(0.08..0.35),
            }
        };
        let tex = texture(&mut rng);
        let r = [spectrum(&mut rng), spectrum(&mut rng)];
        layers.push(Layer::flat(d, shape, tex, r));
    }
    Scene { name: format!("random-{seed}"), layers, gain: rng.random_range(0.5..1.0), illuminant: D65 }
}
