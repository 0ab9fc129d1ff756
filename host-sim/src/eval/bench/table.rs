//! The sweep's points as tables: the Pareto front, `bench.csv` and `bench.md` written and
//! read back (`slf bench --from`).

use std::path::Path;

use anyhow::{Context, Result};

use super::plot::plot;
use super::{PSNR_DB, Point, TIME_MS};
use crate::eval::device_frame::{self, DeviceFrame};
use crate::io::file_checks::regular_file;
use crate::io::output::{WholeFile, stage};

/// Marks, per mask family and k, the points no other point beats in both time (one
/// thread) and PSNR.
pub fn mark_pareto(points: &mut [Point]) {
    let snapshot = points.to_vec();
    for p in points.iter_mut() {
        p.pareto = !snapshot.iter().any(|q| {
            q.mask == p.mask
                && q.k == p.k
                && q.ms_one <= p.ms_one
                && q.psnr >= p.psnr
                && (q.ms_one < p.ms_one || q.psnr > p.psnr)
        });
    }
}

/// Writes `bench.csv`, `bench.md` and `bench.png` into `dir`; `bench.md` ends with the
/// device's frame figure when `device` holds any rows. All three are made in memory first,
/// so a point the plot refuses writes no file.
///
/// # Errors
/// I/O and drawing errors.
pub fn write(points: &[Point], device: &[DeviceFrame], dir: &Path) -> Result<()> {
    anyhow::ensure!(!points.is_empty(), "no points to write");
    let csv = csv_of(points)?;
    let (md, png) = (markdown(points, device), plot(points)?);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    put_together(dir, Some(&csv), &md, &png)
}

/// Writes the tables' files into `dir` together: each to its temporary file first, then
/// all put in place, so a file that cannot be written (`bench.png` read-only, a full disk)
/// leaves the others as they were (before, `bench.csv` and `bench.md` were already
/// replaced). `csv`: `None` leaves `bench.csv` as it is.
fn put_together(dir: &Path, csv: Option<&[u8]>, md: &str, png: &[u8]) -> Result<()> {
    let bytes = |b: &[u8]| {
        let b = b.to_vec();
        move |w: &mut dyn std::io::Write| Ok(w.write_all(&b)?)
    };
    let mut staged = Vec::new();
    if let Some(csv) = csv {
        staged.push(stage(&dir.join("bench.csv"), bytes(csv))?);
    }
    staged.push(stage(&dir.join("bench.md"), bytes(md.as_bytes()))?);
    staged.push(stage(&dir.join("bench.png"), bytes(png))?);
    staged.into_iter().try_for_each(WholeFile::persist)
}

/// Draws `bench.md` and `bench.png` into `dir` again from the `bench.csv` at `from` (with
/// the device's figure, say) without sweeping again, and returns the points. `dir`'s
/// `bench.csv` becomes a copy of `from`, byte for byte: when it is `from` itself it is
/// left as it is (before, it was written again at the table's rounding).
///
/// # Errors
/// As [`read_points`] and [`write()`].
pub fn redraw(from: &Path, device: &[DeviceFrame], dir: &Path) -> Result<usize> {
    regular_file(from, 16 << 20, "a bench table holds")?;
    let bytes = std::fs::read(from).with_context(|| format!("cannot read {}", from.display()))?;
    let points = points_of(csv::Reader::from_reader(&bytes[..])).with_context(|| from.display().to_string())?;
    let (md, png) = (markdown(&points, device), plot(&points)?);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let target = dir.join("bench.csv");
    let same = matches!((std::fs::canonicalize(from), std::fs::canonicalize(&target)), (Ok(a), Ok(b)) if a == b);
    put_together(dir, (!same).then_some(&bytes[..]), &md, &png)?;
    Ok(points.len())
}

/// The points as `bench.csv`'s bytes.
fn csv_of(points: &[Point]) -> Result<Vec<u8>> {
    // Setting names hold commas ("ensemble screened, tolerance 1e-3, ..."): the csv crate
    // quotes them.
    let mut csv = csv::Writer::from_writer(Vec::new());
    csv.write_record([
        "mask",
        "k",
        "setting",
        "psnr_db",
        "ssim",
        "sa_deg",
        "ms_per_patch_1_thread",
        "ms_per_patch_all_threads",
        "solves_per_patch",
        "frame_512_s_1_thread",
        "pareto",
    ])?;
    for p in points {
        csv.write_record([
            p.mask.clone(),
            p.k.to_string(),
            p.setting.clone(),
            format!("{:.4}", p.psnr),
            format!("{:.5}", p.ssim),
            format!("{:.4}", p.sa),
            format!("{:.4}", p.ms_one),
            format!("{:.4}", p.ms_all),
            format!("{:.2}", p.solves),
            format!("{:.2}", p.frame_s),
            p.pareto.to_string(),
        ])?;
    }
    csv.into_inner().context("csv buffer")
}

/// The points as `bench.md`, with the device's figure after the table when there is one.
pub(super) fn markdown(points: &[Point], device: &[DeviceFrame]) -> String {
    let mut md = String::from(
        "| mask | k | setting | PSNR dB | SSIM | SA deg | ms / patch (1 thread) | ms / patch (all) | solves | 512 x 512 frame, s (1 thread) | Pareto |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for p in points {
        md += &format!(
            "| {} | {} | {} | {:.2} | {:.4} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {} |\n",
            p.mask,
            p.k,
            p.setting,
            p.psnr,
            p.ssim,
            p.sa,
            p.ms_one,
            p.ms_all,
            p.solves,
            p.frame_s,
            if p.pareto { "yes" } else { "" }
        );
    }
    if !device.is_empty() {
        md += &device_frame::markdown(device);
    }
    md
}

/// The points of a `bench.csv` that [`write()`] wrote, to draw its table and plot again
/// (with the device's figure, say) without sweeping again. Values are as the CSV rounds
/// them (four decimals).
///
/// # Errors
/// A file that cannot be read, is not a regular file or is larger than 16 MiB, or has a
/// row that is not a point (its line is named).
pub fn read_points(path: &Path) -> Result<Vec<Point>> {
    regular_file(path, 16 << 20, "a bench table holds")?;
    let r = csv::Reader::from_path(path).with_context(|| format!("cannot read {}", path.display()))?;
    points_of(r).with_context(|| path.display().to_string())
}

/// The rows of a `bench.csv` reader as points; a fault names its line.
fn points_of<R: std::io::Read>(mut r: csv::Reader<R>) -> Result<Vec<Point>> {
    let mut points = Vec::new();
    for (i, row) in r.records().enumerate() {
        let line = i + 2;
        let row = row.with_context(|| format!("line {line}"))?;
        let at = |j: usize| row.get(j).with_context(|| format!("line {line}: {} fields", row.len()));
        let number = |j: usize| -> Result<f64> {
            let x = at(j)?;
            x.parse().with_context(|| format!("line {line}: field {} {x:?} is not a number", j + 1))
        };
        // What the plot and the Pareto front need: finite values in the range a decode can
        // give (a PSNR of 1.7e308 or a time of 1e-200 ms once held the plot's axes for
        // minutes), a time above zero.
        let within = |j: usize, what: &str, (lo, hi): (f64, f64)| -> Result<f64> {
            let x = number(j)?;
            anyhow::ensure!(x.is_finite(), "line {line}: field {} is {x}, not a finite number", j + 1);
            let show =
                |v: f64| if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() };
            anyhow::ensure!(
                (lo..=hi).contains(&x),
                "line {line}: field {} is {what} of {}, outside [{}, {}]",
                j + 1,
                show(x),
                show(lo),
                show(hi)
            );
            Ok(x)
        };
        let time = |j: usize| -> Result<f64> {
            let x = number(j)?;
            anyhow::ensure!(x.is_finite() && x > 0.0, "line {line}: field {} is a time of {x} ms, not above 0", j + 1);
            within(j, "a time in ms", TIME_MS)
        };
        points.push(Point {
            mask: at(0)?.to_owned(),
            k: at(1)?.parse().with_context(|| format!("line {line}: k"))?,
            setting: at(2)?.to_owned(),
            psnr: within(3, "a PSNR in dB", PSNR_DB)?,
            ssim: within(4, "an SSIM", (-1.0, 1.0))?,
            sa: within(5, "a spectral angle in degrees", (0.0, 180.0))?,
            ms_one: time(6)?,
            ms_all: time(7)?,
            solves: within(8, "a count of solves", (0.0, 1e9))?,
            frame_s: within(9, "a time in s", (0.0, 1e15))?,
            pareto: at(10)? == "true",
        });
    }
    anyhow::ensure!(!points.is_empty(), "no points (a header and no rows)");
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::bench::run::{BenchOptions, run};

    #[test]
    fn csv_keeps_settings_with_commas_in_one_field() {
        let point = |setting: &str| Point {
            mask: "pixel".into(),
            k: 3,
            setting: setting.into(),
            psnr: 31.5,
            ssim: 0.9,
            sa: 4.2,
            ms_one: 1.5,
            ms_all: 0.8,
            solves: 2.25,
            frame_s: 12.5,
            pareto: true,
        };
        let dir = tempfile::tempdir().unwrap();
        let points = [point("DCT default"), point("ensemble screened, tolerance 1e-3, flat 4e-3")];
        write(&points, &[], dir.path()).unwrap();
        let mut r = csv::Reader::from_path(dir.path().join("bench.csv")).unwrap();
        let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
        assert_eq!(r.headers().unwrap().len(), 11);
        assert_eq!(rows.len(), 2);
        assert!(rows.iter().all(|row| row.len() == 11));
        assert_eq!(&rows[0][9], "12.50");
        assert_eq!(&rows[1][2], "ensemble screened, tolerance 1e-3, flat 4e-3");
        assert_eq!(&rows[1][3], "31.5000");
        // Read back, the points draw the same table; with the device's rows it gains their
        // figure after it.
        let md = std::fs::read_to_string(dir.path().join("bench.md")).unwrap();
        let again = read_points(&dir.path().join("bench.csv")).unwrap();
        assert_eq!(again.len(), 2);
        assert_eq!(again[1].setting, points[1].setting);
        assert_eq!((again[1].psnr, again[1].solves, again[1].frame_s, again[1].pareto), (31.5, 2.25, 12.5, true));
        let device =
            device_frame::parse("decode,patch_solves,instructions_per_solve,clock_mhz\nDCT,1600,5e7,480\n").unwrap();
        let other = tempfile::tempdir().unwrap();
        write(&again, &device, other.path()).unwrap();
        let md2 = std::fs::read_to_string(other.path().join("bench.md")).unwrap();
        assert_eq!(md2, md.clone() + &device_frame::markdown(&device));
        assert!(md2.contains("| DCT | 1600 | 50.0 M | 480 | 167 |"), "{md2}");
        // Issue 51, item 12: drawn again from its own folder's bench.csv, the file keeps
        // its bytes (before: 30.123456789 became 30.1235); into another folder, a copy.
        let own = dir.path().join("bench.csv");
        let text = std::fs::read_to_string(&own).unwrap().replace("31.5000", "30.123456789");
        std::fs::write(&own, &text).unwrap();
        assert_eq!(redraw(&own, &device, dir.path()).unwrap(), 2);
        assert_eq!(std::fs::read_to_string(&own).unwrap(), text);
        assert!(std::fs::read_to_string(dir.path().join("bench.md")).unwrap().contains("| 30.12 |"));
        let third = tempfile::tempdir().unwrap();
        redraw(&own, &[], third.path()).unwrap();
        assert_eq!(std::fs::read_to_string(third.path().join("bench.csv")).unwrap(), text);
        // A row that is not a point is refused with its line.
        let bad = dir.path().join("bad.csv");
        std::fs::write(&bad, "mask,k,setting\npixel,three,x\n").unwrap();
        assert!(format!("{:#}", read_points(&bad).unwrap_err()).contains("line 2"));
    }

    /// Issue 41, item 2: nothing to sweep or to draw is an error at once, and a point the
    /// plot cannot place does not stall it (before: `--only bogus` grew to 24 GB, a time
    /// of 0 or a PSNR of NaN ran past a minute).
    #[test]
    fn empty_or_unplaceable_benches_are_refused_or_drawn_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let opts = BenchOptions { quick: true, progress: false, only: Some("bogus".into()), masks: Vec::new() };
        let e = run(&opts).unwrap_err().to_string();
        assert!(e.contains("--only \"bogus\" names no setting"), "{e}");
        assert!(write(&[], &[], dir.path()).is_err());
        let header = "mask,k,setting,psnr_db,ssim,sa_deg,ms_per_patch_1_thread,ms_per_patch_all_threads,\
                      solves_per_patch,frame_512_s_1_thread,pareto\n";
        let csv = dir.path().join("bench.csv");
        std::fs::write(&csv, header).unwrap();
        assert!(format!("{:#}", read_points(&csv).unwrap_err()).contains("no points"));
        for (row, says) in [
            ("pixel,3,x,30,0.9,4,0,0.5,1,2,true", "line 2: field 7 is a time of 0 ms"),
            ("pixel,3,x,NaN,0.9,4,1,0.5,1,2,true", "line 2: field 4 is NaN"),
            ("pixel,3,x,inf,0.9,4,1,0.5,1,2,true", "line 2: field 4 is inf"),
        ] {
            std::fs::write(&csv, format!("{header}{row}\n")).unwrap();
            let e = format!("{:#}", read_points(&csv).unwrap_err());
            assert!(e.contains(says), "{e}");
        }
        // A sweep's own point of NaN or 0 ms: in the table, not on the plot; written quickly.
        let point = |psnr: f64, ms: f64| Point {
            mask: "pixel".into(),
            k: 3,
            setting: "x".into(),
            psnr,
            ssim: 0.9,
            sa: 4.0,
            ms_one: ms,
            ms_all: ms,
            solves: 1.0,
            frame_s: 1.0,
            pareto: false,
        };
        // Issue 51, item 1: values no decode gives are refused with their line and field,
        // at once (before: +-1.7e308 dB or times of 1e-200 and 1e200 ms ran the plot's axes
        // past 150 s, with bench.csv and bench.md already written).
        for (rows, says) in [
            ("pixel,3,x,1.7e308,0.9,4,1,0.5,1,2,true\npixel,3,y,-1.7e308,0.9,4,1,0.5,1,2,true", "line 2: field 4"),
            ("pixel,3,x,30,0.9,4,1e-200,0.5,1,2,true\npixel,3,y,30,0.9,4,1e200,0.5,1,2,true", "line 2: field 7"),
            ("pixel,3,x,30,0.9,4,1,0.5,1,2,true\npixel,3,y,30,0.9,4,1e200,0.5,1,2,true", "line 3: field 7"),
            ("pixel,3,x,30,1.5,4,1,0.5,1,2,true", "line 2: field 5 is an SSIM of 1.5"),
            ("pixel,3,x,30,0.9,-4,1,0.5,1,2,true", "line 2: field 6 is a spectral angle"),
        ] {
            let out = tempfile::tempdir().unwrap();
            std::fs::write(&csv, format!("{header}{rows}\n")).unwrap();
            let start = std::time::Instant::now();
            let e = format!("{:#}", redraw(&csv, &[], out.path()).unwrap_err());
            assert!(e.contains(says), "{e}");
            assert!(start.elapsed().as_secs() < 10, "refusing took {:?}", start.elapsed());
            assert_eq!(std::fs::read_dir(out.path()).unwrap().count(), 0, "a refused table wrote files");
        }
        // The widest table allowed draws at once.
        let wide = "pixel,3,x,-1000,0.9,4,1e-9,0.5,1,2,true\npixel,3,y,1000,0.9,4,1e12,0.5,1,2,true";
        std::fs::write(&csv, format!("{header}{wide}\n")).unwrap();
        let start = std::time::Instant::now();
        assert_eq!(redraw(&csv, &[], dir.path()).unwrap(), 2);
        assert!(start.elapsed().as_secs() < 30, "drawing took {:?}", start.elapsed());
        let start = std::time::Instant::now();
        write(&[point(f64::NAN, 1.0), point(30.0, 0.0), point(31.0, 2.0)], &[], dir.path()).unwrap();
        assert!(start.elapsed().as_secs() < 30, "drawing took {:?}", start.elapsed());
        assert!(std::fs::read_to_string(dir.path().join("bench.md")).unwrap().contains("| NaN |"));
        assert!(write(&[point(f64::NAN, 1.0)], &[], dir.path()).is_err());
    }
}
