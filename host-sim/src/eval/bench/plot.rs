//! The sweep's plot: PSNR against time per patch, a curve per mask family, the presets and
//! baselines labelled.

use anyhow::Result;
use plotters::prelude::*;

use super::{PSNR_DB, Point, TIME_MS, label, short};

/// The plot as PNG bytes.
pub(super) fn plot(points: &[Point]) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let (width, height) = (1000u32, 700u32);
    let mut raw = vec![0u8; 3 * (width * height) as usize];
    draw(points, BitMapBackend::with_buffer(&mut raw, (width, height)))?;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png).write_image(&raw, width, height, image::ExtendedColorType::Rgb8)?;
    Ok(png)
}

/// The points by series, one per (mask, k), in one pass: rows in any order (a table of
/// alternating masks once made a series per row, each a pass over every row: 100,000 rows
/// ran for minutes).
fn series(points: &[Point]) -> std::collections::BTreeMap<(&str, u8), Vec<&Point>> {
    let mut series = std::collections::BTreeMap::<(&str, u8), Vec<&Point>>::new();
    for p in points {
        series.entry((p.mask.as_str(), p.k)).or_default().push(p);
    }
    series
}

pub(super) fn draw(points: &[Point], backend: BitMapBackend<'_>) -> Result<()> {
    // A point that cannot be placed (a time of 0 on the log axis, a PSNR of NaN from a
    // decode that failed, values no decode gives) is in the table, not on the plot; the
    // axes span the others.
    let inside = |x: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&x);
    let points: Vec<Point> =
        points.iter().filter(|p| inside(p.ms_one, TIME_MS) && inside(p.psnr, PSNR_DB)).cloned().collect();
    anyhow::ensure!(!points.is_empty(), "no point with a time above 0 and a finite PSNR to plot");
    let points = &points[..];
    let root = backend.into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (tmin, tmax) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.ms_one), b.max(p.ms_one)));
    let (pmin, pmax) =
        points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.psnr), b.max(p.psnr)));
    let mut chart = ChartBuilder::on(&root)
        .caption("PSNR against time per patch (one thread); Pareto fronts joined", ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d((tmin * 0.8..tmax * 1.2).log_scale(), (pmin - 1.0)..(pmax + 1.0))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("ms per patch (one thread, log scale)")
        .y_desc("PSNR dB (mean over scenes)")
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    for (i, ((mask, k), pts)) in series(points).iter().enumerate() {
        let c = colours[i % colours.len()];
        chart
            .draw_series(pts.iter().map(|p| Circle::new((p.ms_one, p.psnr), 4, c.filled())))
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .label(format!("{mask} k={k}"))
            .legend(move |(x, y)| Circle::new((x, y), 4, c.filled()));
        // Presets and baselines by name, beside their dot.
        let style = ("sans-serif", 14).into_font().color(&c);
        chart
            .draw_series(pts.iter().filter_map(|p| {
                label(&p.setting).map(|name| {
                    EmptyElement::at((p.ms_one, p.psnr))
                        + Circle::new((0, 0), 7, c.stroke_width(2))
                        + Text::new(short(name).to_string(), (8, -20), style.clone())
                })
            }))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut front: Vec<(f64, f64)> = pts.iter().filter(|p| p.pareto).map(|p| (p.ms_one, p.psnr)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart.draw_series(LineSeries::new(front, c.stroke_width(2))).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_in_any_order_make_one_series_per_mask_and_k() {
        let point = |mask: &str, k: u8, ms: f64| Point {
            mask: mask.into(),
            k,
            setting: String::new(),
            psnr: 30.0,
            ssim: 0.9,
            sa: 1.0,
            ms_one: ms,
            ms_all: ms,
            solves: 1.0,
            frame_s: 1.0,
            pareto: false,
        };
        let points: Vec<Point> = (0..1000)
            .map(|i| point(if i % 2 == 0 { "pixel" } else { "lenslet" }, 1 + (i % 3) as u8, i as f64))
            .collect();
        let s = series(&points);
        assert_eq!(s.len(), 6);
        assert_eq!(s.values().map(Vec::len).sum::<usize>(), 1000);
        assert!(s.iter().all(|((m, k), pts)| pts.iter().all(|p| p.mask == *m && p.k == *k)));
    }
}
