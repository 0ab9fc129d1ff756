//! Scenes that look like the world, for training and for tests.
//!
//! slf's named test scenes are flat cards of chart colours; a dictionary learned from them
//! knows little of real content (issue 18). A realistic scene here has:
//!
//! - **natural image statistics**: textures with a `1/f` amplitude spectrum
//!   ([`Texture::Pink`]), detail at every scale from 64 pixels to one;
//! - **geometry**: a slanted background plane (continuous disparity across the frame) and
//!   objects that are slanted or curved (domes), with occlusion edges between them;
//! - **shading** by the surface normal, and **specular highlights** on some objects that
//!   move across views unlike their surface;
//! - **measured reflectances**: every reflectance set colour-science ships
//!   ([`crate::sim::spectra::MEASURED`]: four colour checkers, the CIE test colour samples, the
//!   NIST CQS samples and the 190 RAW-to-ACES training patches; see
//!   `host-sim/scripts/gen_spectra.py`), mixed with smooth random ones;
//! - **illuminants** beyond D65: A, FL2, FL11 and two white LEDs
//!   ([`crate::sim::spectra::ILLUMINANTS`]).
//!
//! [`scene`](realistic) draws one from a seed; [`NAMES`] are fixed draws, one per kind of
//! light, named for tests and tables.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::sim::scene::{Highlight, Layer, Scene, Shape, Texture};
use crate::sim::spectra::{ILLUMINANTS, MEASURED, Spectrum, illuminant, smooth_random};

/// The realistic named scenes: (name, seed, illuminant).
pub const SCENES: [(&str, u64, &str); 4] =
    [("outdoor", 101, "D65"), ("tungsten", 202, "A"), ("office", 303, "FL11"), ("led", 404, "LED-B3")];

/// Names of the realistic named scenes.
pub const NAMES: [&str; 4] = [SCENES[0].0, SCENES[1].0, SCENES[2].0, SCENES[3].0];

/// A realistic named scene ([`NAMES`]); `None` for another name.
pub fn named(name: &str) -> Option<Scene> {
    let &(name, seed, light) = SCENES.iter().find(|s| s.0 == name)?;
    let illuminant = illuminant(light)?;
    Some(Scene { name: name.into(), ..draw(seed, Some(illuminant)) })
}

/// Any named scene: a test scene of [`crate::sim::scene::NAMES`] or a realistic one.
pub fn lookup(name: &str) -> Option<Scene> {
    crate::sim::scene::named(name).or_else(|| named(name))
}

/// The scene `slf scene NAME` renders: a named one ([`lookup`]), `random` (a training scene
/// of the shipped ensemble, [`crate::sim::scene::random`]) or `realistic` ([`realistic`]),
/// the last two drawn from `seed`.
///
/// # Errors
/// An unknown name, with the names there are.
pub fn by_name(name: &str, seed: u64) -> anyhow::Result<Scene> {
    match name {
        "random" => Ok(crate::sim::scene::random(seed)),
        "realistic" => Ok(realistic(seed)),
        _ => lookup(name).ok_or_else(|| {
            anyhow::anyhow!(
                "unknown scene {name:?}: one of {:?}, {:?}, random or realistic",
                crate::sim::scene::NAMES,
                NAMES
            )
        }),
    }
}

/// A random realistic scene (seeded; any illuminant of the table).
pub fn realistic(seed: u64) -> Scene {
    draw(seed, None)
}

fn spectrum(rng: &mut ChaCha8Rng) -> Spectrum {
    if rng.random_bool(0.7) { MEASURED[rng.random_range(0..MEASURED.len())].2 } else { smooth_random(rng) }
}

fn texture(rng: &mut ChaCha8Rng) -> Texture {
    match rng.random_range(0..10) {
        0..=5 => pink(rng),
        6 => Texture::Noise { cell: rng.random_range(6.0..40.0), seed: rng.random() },
        7 => Texture::Fine { seed: rng.random() },
        8 => {
            Texture::Stripes { period: rng.random_range(3.0..14.0), angle: rng.random_range(0.0..std::f32::consts::PI) }
        }
        _ => Texture::Flat,
    }
}

fn pink(rng: &mut ChaCha8Rng) -> Texture {
    Texture::Pink { seed: rng.random(), beta: rng.random_range(0.7..1.2) }
}

fn draw(seed: u64, illuminant: Option<Spectrum>) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EA1_1571_C000_0000);
    let light = ILLUMINANTS[rng.random_range(0..ILLUMINANTS.len())].1;
    // A slanted background: a floor or a wall receding across the frame.
    let mut layers = vec![Layer {
        slope: (rng.random_range(-1.2..1.2), rng.random_range(-0.8..0.8)),
        shading: rng.random_range(0.0..0.3),
        ..Layer::flat(
            rng.random_range(-1.3..-0.6),
            Shape::Everywhere,
            pink(&mut rng),
            [spectrum(&mut rng), spectrum(&mut rng)],
        )
    }];
    let count = rng.random_range(3..=8);
    for i in 0..count {
        // Nearer objects later, spread over the rest of the disparity range.
        let d = -0.5 + 1.8 * (i as f32 + rng.random_range(0.1..0.9)) / count as f32;
        let (cy, cx) = (rng.random_range(0.1..0.9), rng.random_range(0.1..0.9));
        let dome = rng.random_bool(0.5);
        let shape = if dome {
            Shape::Disc { cy, cx, r: rng.random_range(0.05..0.3) }
        } else {
            let (hh, hw) = (rng.random_range(0.04..0.3), rng.random_range(0.04..0.3));
            Shape::Rect { y0: cy - hh, x0: cx - hw, y1: cy + hh, x1: cx + hw }
        };
        let highlight = (rng.random_bool(0.35)).then(|| Highlight {
            cy: cy + rng.random_range(-0.05..0.05),
            cx: cx + rng.random_range(-0.05..0.05),
            radius: rng.random_range(0.01..0.04),
            strength: rng.random_range(0.2..0.8),
            shift: -d * rng.random_range(0.5..1.0),
        });
        layers.push(Layer {
            slope: if dome { (0.0, 0.0) } else { (rng.random_range(-0.8..0.8), rng.random_range(-0.8..0.8)) },
            curvature: if dome { -rng.random_range(3.0..10.0) } else { 0.0 },
            shading: rng.random_range(0.2..0.8),
            highlight,
            ..Layer::flat(d, shape, texture(&mut rng), [spectrum(&mut rng), spectrum(&mut rng)])
        });
    }
    Scene {
        name: format!("realistic-{seed}"),
        layers,
        // Highlights add up to 0.8 of a white reflector: the brightest stays under 1.
        gain: rng.random_range(0.35..0.55),
        illuminant: illuminant.unwrap_or(light),
    }
}
