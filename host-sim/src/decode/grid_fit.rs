//! The lenslet grid found from a flat (issue 52): micro-image centres, then a least-squares
//! grid, as the light-field toolboxes find it from a white image (Dansereau, Pizarro and
//! Williams, CVPR 2013; Cho et al., ICCV 2013).
//!
//! A flat is bright at each micro-image's centre and darker toward its borders (the
//! vignetting of views far from the centre), and that pattern is point-symmetric about each
//! centre. A centre is where the flat's first moment over a square window of one pitch
//! about it vanishes: the flat is sampled at a quarter-pixel grid of points (bilinearly
//! between pixel centres), the moment of its values above their mean taken, and the point
//! moved by Newton's method (the moment's derivative by central differences) until it
//! stays. Centres are found outward from the sensor's middle in squares of growing size,
//! each square's grid fitted (an affine lattice by least squares: origin and the two
//! lenslet steps) and predicting the next square's centres, so a rotation of a degree
//! across a thousand lenslets never loses count. The last fit over every centre, outliers
//! (a centre more than [`OUTLIER_PX`], or 4 times the median, from the fit) left out,
//! gives the grid: its pitch the
//! steps' lengths, its rotation their mean angle. Lenslet `(0, 0)` is the lattice point
//! nearest where the calibration captures' stated grid puts it (recorded as the grid's
//! `indexed_at`), so a capture stating the same grid names the same lenslets; the decode
//! re-names them for a capture stating another ([`GridDescription::indexed_as`]).

use anyhow::{Result, bail, ensure};

use crate::io::grid::GridDescription;

/// A centre farther than this from the grid fitted to all is left out of the fit, pixels.
pub const OUTLIER_PX: f64 = 0.5;

/// Quarter-pixel sampling of a window.
const STEP: f64 = 0.25;

/// Newton steps per centre.
const ITERATIONS: usize = 8;

/// The fewest micro-image centres a grid is fitted to.
const MIN_CENTRES: usize = 9;

/// A grid found from a flat, and how well it fits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridFit {
    /// The grid, its `centres_rms_px` set.
    pub grid: GridDescription,
    /// Micro-image centres the grid was fitted to.
    pub centres: usize,
    /// Centres left out as outliers.
    pub outliers: usize,
}

/// A flat frame read between its pixel centres.
struct Flat<'a> {
    values: &'a [f32],
    rows: usize,
    cols: usize,
}

impl Flat<'_> {
    /// Bilinear at sensor point `p` (pixel `(r, c)`'s centre at `(r + 0.5, c + 0.5)`), `None`
    /// outside the pixel centres.
    fn at(&self, p: [f64; 2]) -> Option<f64> {
        let (y, x) = (p[0] - 0.5, p[1] - 0.5);
        if !(y >= 0.0 && x >= 0.0 && y <= (self.rows - 1) as f64 && x <= (self.cols - 1) as f64) {
            return None;
        }
        let (r, c) = (
            (y.floor() as usize).min(self.rows.saturating_sub(2)),
            (x.floor() as usize).min(self.cols.saturating_sub(2)),
        );
        let (fy, fx) = (y - r as f64, x - c as f64);
        let v = |r: usize, c: usize| f64::from(self.values[(r.min(self.rows - 1)) * self.cols + c.min(self.cols - 1)]);
        Some(
            (1.0 - fy) * ((1.0 - fx) * v(r, c) + fx * v(r, c + 1))
                + fy * ((1.0 - fx) * v(r + 1, c) + fx * v(r + 1, c + 1)),
        )
    }

    /// The first moment of the values above their mean over the square of half-width
    /// `half` about `c`; `None` if the square leaves the sensor.
    fn moment(&self, c: [f64; 2], half: [f64; 2]) -> Option<[f64; 2]> {
        let n = [(half[0] / STEP).floor() as i64, (half[1] / STEP).floor() as i64];
        let (mut sum, mut count, mut m) = (0.0, 0.0, [0.0f64; 2]);
        let mut first = [0.0f64; 2];
        for i in -n[0]..=n[0] {
            for j in -n[1]..=n[1] {
                let d = [i as f64 * STEP, j as f64 * STEP];
                let v = self.at([c[0] + d[0], c[1] + d[1]])?;
                sum += v;
                count += 1.0;
                m[0] += d[0] * v;
                m[1] += d[1] * v;
                first[0] += d[0];
                first[1] += d[1];
            }
        }
        // Values above the mean: a constant flat has no moment anywhere.
        let mean = sum / count;
        Some([(m[0] - mean * first[0]) / count, (m[1] - mean * first[1]) / count])
    }

    /// The micro-image centre nearest `start` for micro-images of `pitch`: where the
    /// moment vanishes, by Newton's method; `None` if it does not settle within half a
    /// pitch of `start`, or the window leaves the sensor.
    fn centre(&self, start: [f64; 2], pitch: [f64; 2]) -> Option<[f64; 2]> {
        let half = [pitch[0] / 2.0, pitch[1] / 2.0];
        let mut c = start;
        for _ in 0..ITERATIONS {
            let m = self.moment(c, half)?;
            let h = STEP;
            let mut jac = [[0.0f64; 2]; 2];
            for k in 0..2 {
                let mut plus = c;
                let mut minus = c;
                plus[k] += h;
                minus[k] -= h;
                let (a, b) = (self.moment(plus, half)?, self.moment(minus, half)?);
                jac[0][k] = (a[0] - b[0]) / (2.0 * h);
                jac[1][k] = (a[1] - b[1]) / (2.0 * h);
            }
            let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
            // A peak's moment falls as the window passes it: the derivative is negative
            // definite. A flat without micro-images, or a trough, has none.
            if !(det > 0.0 && jac[0][0] < 0.0 && jac[1][1] < 0.0) {
                return None;
            }
            let step = [-(jac[1][1] * m[0] - jac[0][1] * m[1]) / det, -(-jac[1][0] * m[0] + jac[0][0] * m[1]) / det];
            let len = step[0].hypot(step[1]);
            let scale = if len > 0.5 { 0.5 / len } else { 1.0 };
            c = [c[0] + step[0] * scale, c[1] + step[1] * scale];
            if (c[0] - start[0]).abs() > half[0] || (c[1] - start[1]).abs() > half[1] {
                return None;
            }
            if len < 1e-5 {
                break;
            }
        }
        Some(c)
    }
}

/// An affine lattice: centre `(a, b)` at `origin + a * steps[0] + b * steps[1]`.
#[derive(Clone, Copy, Debug)]
struct Lattice {
    origin: [f64; 2],
    steps: [[f64; 2]; 2],
}

impl Lattice {
    fn at(&self, a: f64, b: f64) -> [f64; 2] {
        [
            self.origin[0] + a * self.steps[0][0] + b * self.steps[1][0],
            self.origin[1] + a * self.steps[0][1] + b * self.steps[1][1],
        ]
    }

    /// The least-squares lattice through `found` (`(a, b)` and its centre), each
    /// coordinate a linear regression on `(1, a, b)`.
    fn fit(found: &[([i64; 2], [f64; 2])]) -> Option<Self> {
        let mut ata = [[0.0f64; 3]; 3];
        let mut atb = [[0.0f64; 3]; 2];
        for &([a, b], c) in found {
            let x = [1.0, a as f64, b as f64];
            for i in 0..3 {
                for j in 0..3 {
                    ata[i][j] += x[i] * x[j];
                }
                atb[0][i] += x[i] * c[0];
                atb[1][i] += x[i] * c[1];
            }
        }
        let solve = |rhs: [f64; 3]| solve3(ata, rhs);
        let (y, x) = (solve(atb[0])?, solve(atb[1])?);
        Some(Self { origin: [y[0], x[0]], steps: [[y[1], x[1]], [y[2], x[2]]] })
    }
}

/// `m x = rhs` for a symmetric 3 x 3 `m` (Cramer's rule); `None` if singular.
fn solve3(m: [[f64; 3]; 3], rhs: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    if d.abs() < 1e-9 {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = rhs[i];
        }
        *o = det(mk) / d;
    }
    Some(out)
}

/// The lenslet grid of a flat `flat` (`rows x cols`, each pixel's light over white; hot
/// pixels already replaced), for a light field of `lenslets` lenslets of `views` views,
/// starting from micro-images `views` pixels apart, unrotated; its lenslet (0, 0) the
/// lattice point nearest sensor point `index_at`.
///
/// # Errors
/// A flat without micro-images to find (no vignetting, too much noise), or a grid outside
/// what [`GridDescription::check`] accepts.
pub fn fit_grid(
    flat: &[f32],
    (rows, cols): (usize, usize),
    lenslets: [usize; 2],
    views: [usize; 2],
    index_at: [f64; 2],
) -> Result<GridFit> {
    ensure!(flat.len() == rows * cols && rows >= 3 && cols >= 3, "a flat of {} values for {rows} x {cols}", flat.len());
    let f = Flat { values: flat, rows, cols };
    let nominal = [views[0] as f64, views[1] as f64];
    // The brightest micro-image near the middle, a 3 x 3 mean against noise.
    let mid = [rows as f64 / 2.0, cols as f64 / 2.0];
    let mut best = (f64::NEG_INFINITY, mid);
    for r in (mid[0] - nominal[0]) as usize..=(mid[0] + nominal[0]) as usize {
        for c in (mid[1] - nominal[1]) as usize..=(mid[1] + nominal[1]) as usize {
            let p = [r as f64 + 0.5, c as f64 + 0.5];
            let sum: Option<f64> = (-1..=1)
                .flat_map(|i| (-1..=1).map(move |j| (i, j)))
                .map(|(i, j)| f.at([p[0] + f64::from(i), p[1] + f64::from(j)]))
                .sum();
            if let Some(s) = sum.filter(|&s| s > best.0) {
                best = (s, p);
            }
        }
    }
    let Some(start) = f.centre(best.1, nominal) else {
        bail!(
            "the flats show no micro-image near the sensor's middle: the lenslet grid is found from the vignetting \
             of the views toward each micro-image's border, and these flats have none to see"
        );
    };
    let mut lattice = Lattice { origin: start, steps: [[nominal[0], 0.0], [0.0, nominal[1]]] };
    let reach = (rows as f64 / nominal[0]).max(cols as f64 / nominal[1]) as i64 + 2;
    let mut radius = 2i64;
    let mut found = Vec::new();
    loop {
        found.clear();
        let pitch = [lattice.steps[0][0].hypot(lattice.steps[0][1]), lattice.steps[1][0].hypot(lattice.steps[1][1])];
        for a in -radius..=radius {
            for b in -radius..=radius {
                if let Some(c) = f.centre(lattice.at(a as f64, b as f64), pitch) {
                    found.push(([a, b], c));
                }
            }
        }
        ensure!(
            found.len() >= MIN_CENTRES,
            "the flats show {} micro-image centres near the sensor's middle, too few for a grid (at least \
             {MIN_CENTRES}): is the vignetting too weak against the noise?",
            found.len()
        );
        let Some(l) = Lattice::fit(&found) else { bail!("the micro-image centres do not span a grid") };
        lattice = l;
        if radius >= reach {
            break;
        }
        radius = (radius * 2).min(reach);
    }
    // Outliers out (beyond OUTLIER_PX, or 4 times the median residual: micro-images at
    // the edge of the light, a hot pixel's), refitted twice.
    let before = found.len();
    for _ in 0..2 {
        let off = |&([a, b], c): &([i64; 2], [f64; 2])| {
            let p = lattice.at(a as f64, b as f64);
            (p[0] - c[0]).hypot(p[1] - c[1])
        };
        let mut residuals: Vec<f64> = found.iter().map(off).collect();
        residuals.sort_by(f64::total_cmp);
        let limit = OUTLIER_PX.min(4.0 * residuals[residuals.len() / 2]).max(0.02);
        found.retain(|x| off(x) <= limit);
        ensure!(found.len() >= MIN_CENTRES, "the micro-image centres scatter too far for a grid");
        let Some(l) = Lattice::fit(&found) else { bail!("the micro-image centres do not span a grid") };
        lattice = l;
    }
    let outliers = before - found.len();
    let [a, b] = lattice.steps;
    let pitch = [a[0].hypot(a[1]), b[0].hypot(b[1])];
    // Down a lenslet column is (cos, -sin) * p0, along a row (sin, cos) * p1.
    let rotation_deg = 0.5 * ((-a[1]).atan2(a[0]) + b[0].atan2(b[1])).to_degrees();
    // Lenslet (0, 0): the lattice point nearest the one the captures state.
    let want = index_at;
    let (mut near, mut dist) = ([0i64; 2], f64::INFINITY);
    // The lattice index of `want`, and the integers about it.
    let det = a[0] * b[1] - b[0] * a[1];
    let d = [want[0] - lattice.origin[0], want[1] - lattice.origin[1]];
    let (ia, ib) = ((d[0] * b[1] - b[0] * d[1]) / det, (a[0] * d[1] - d[0] * a[1]) / det);
    for i in [ia.floor() as i64, ia.ceil() as i64] {
        for j in [ib.floor() as i64, ib.ceil() as i64] {
            let p = lattice.at(i as f64, j as f64);
            let e = (p[0] - want[0]).hypot(p[1] - want[1]);
            if e < dist {
                (near, dist) = ([i, j], e);
            }
        }
    }
    let mut grid = GridDescription {
        rotation_deg,
        pitch,
        offset: lattice.at(near[0] as f64, near[1] as f64),
        sensor: [rows, cols],
        centres_rms_px: None,
        indexed_at: Some(index_at),
    };
    let sq: f64 = found
        .iter()
        .map(|&([i, j], c)| {
            let p = grid.centre((i - near[0]) as f64, (j - near[1]) as f64);
            (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)
        })
        .sum();
    grid.centres_rms_px = Some((sq / found.len() as f64).sqrt());
    grid.check(lenslets, views)?;
    Ok(GridFit { grid, centres: found.len(), outliers })
}
