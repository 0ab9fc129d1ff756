//! Light fields in HDF5 files, read by the pure-Rust `rust-hdf5` crate (no C library, so
//! no cargo feature is needed; it reads h5py's files, chunked and gzip-compressed ones
//! included, and those written with `libver="latest"`).
//!
//! The dataset's path and its axis order are given (`--dataset /lf --axes hwuvb`): any
//! permutation of `u`, `v` (views), `h`, `w` (space) and `b` (bands). Values of any
//! numeric type are read as f32 and divided by `white`; a band count other than the
//! camera's 13 is resampled from the given wavelengths ([`super::bands`]).

use std::path::Path;

use anyhow::{Context, Result, bail, ensure};

use crate::io::lightfield::LightField;

/// The largest HDF5 file read.
pub const MAX_FILE: u64 = 8 << 30;

/// The most values a light field may have: a light field's own cap, as the README says.
const MAX_VALUES: usize = LightField::MAX_VALUES;

/// Which dataset, in which axis order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Hdf5Layout {
    /// Path of the dataset in the file, e.g. `lf/data`.
    pub dataset: String,
    /// The dataset's axes, slowest first: a permutation of `uvhwb`.
    pub axes: String,
}

/// The position in `axes` of each of `u, v, h, w, b`.
fn axis_order(axes: &str) -> Result<[usize; 5]> {
    ensure!(axes.len() == 5, "axes {axes:?}: need 5 letters, a permutation of u, v, h, w, b");
    let mut at = [usize::MAX; 5];
    for (i, ch) in axes.chars().enumerate() {
        let Some(k) = "uvhwb".find(ch.to_ascii_lowercase()) else {
            bail!("axes {axes:?}: {ch:?} is not one of u, v (views), h, w (space), b (bands)");
        };
        ensure!(at[k] == usize::MAX, "axes {axes:?}: {ch:?} appears twice");
        at[k] = i;
    }
    Ok(at)
}

/// Reads the light field `layout` names from `path`, as `(U, V, H, W, B)` divided by `white`.
pub fn read_hdf5(path: &Path, layout: &Hdf5Layout, white: f32) -> Result<LightField> {
    let at = axis_order(&layout.axes)?;
    ensure!(white.is_finite() && white > 0.0, "white {white} must be finite and above 0");
    let meta = std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    ensure!(meta.is_file(), "{}: not a regular file", path.display());
    ensure!(meta.len() <= MAX_FILE, "{}: {} bytes, more than the {MAX_FILE} read", path.display(), meta.len());
    let file = rust_hdf5::H5File::open(path)
        .map_err(|e| anyhow::anyhow!("{}: not an HDF5 file slf reads: {}", path.display(), one_line(&e)))?;
    // A soft link is followed; one to nothing says where it points.
    let ds = file
        .dataset(layout.dataset.trim_start_matches('/'))
        .map_err(|e| anyhow::anyhow!("{}: no dataset {:?}: {}", path.display(), layout.dataset, one_line(&e)))?;
    let shape = ds.shape();
    ensure!(
        shape.len() == 5,
        "{}: {}: shape {shape:?} has {} axes; a light field has 5 ({})",
        path.display(),
        layout.dataset,
        shape.len(),
        layout.axes
    );
    ensure!(!shape.contains(&0), "{}: {}: shape {shape:?} has an empty axis", path.display(), layout.dataset);
    let total = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).filter(|&n| n <= MAX_VALUES);
    let Some(total) = total else {
        bail!("{}: {}: shape {shape:?} is more than {MAX_VALUES} values", path.display(), layout.dataset);
    };
    // The element type first: a type the reader does not convert (strings, compounds,
    // opaque bytes) is named, not reported as the library's "type mismatch".
    use rust_hdf5::DatatypeMessage as T;
    let dtype = ds.datatype().map_err(|e| {
        anyhow::anyhow!("{}: {}: unreadable element type: {}", path.display(), layout.dataset, one_line(&e))
    })?;
    let element = match dtype {
        T::FixedPoint { size: size @ (1 | 2 | 4 | 8), .. } => u64::from(size),
        T::FloatingPoint { size: size @ (2 | 4 | 8), .. } => u64::from(size),
        other => {
            let what: String = match other {
                T::FloatingPoint { size, .. } => format!("{}-bit floats", 8 * size),
                T::FixedPoint { size, .. } => format!("{}-bit integers", 8 * size),
                other => format!("{other:?}").chars().take(60).collect(),
            };
            bail!(
                "{}: {}: holds {what}; slf reads 32- or 64-bit floats and integers (convert it, e.g. h5py: \
                 f[name][...].astype('float32'))",
                path.display(),
                layout.dataset
            );
        }
    };
    // What the read holds at its peak, from what the file declares, before anything is
    // allocated (a 1.4 KB file declaring 5 x 5 x 1200 x 1200 x 13 once aborted the process
    // in the allocator): the values in their own type, as f64 (the reader converts every
    // numeric type by widening), and the light field (13 bands after resampling, at most as
    // many as read).
    let light_field = (total / shape[at[4]]) as u64 * shape[at[4]].max(13) as u64 * 4;
    let need = total as u64 * (element + 8) + light_field;
    crate::io::budget::check(
        need,
        &format!("{}: {} of shape {shape:?}", path.display(), layout.dataset),
        "crop or split the dataset",
    )?;
    let values = ds.read_numeric_as::<f64>().map_err(|e| {
        anyhow::anyhow!("{}: {}: cannot read the values: {}", path.display(), layout.dataset, one_line(&e))
    })?;
    ensure!(
        values.len() == total,
        "{}: {}: {} values for shape {shape:?}",
        path.display(),
        layout.dataset,
        values.len()
    );
    let dims = at.map(|i| shape[i]);
    let mut lf = LightField::zeros((dims[0], dims[1]), dims[2], dims[3], dims[4]);
    // Strides of the file's axes, then the file index of each (u, v, h, w, b).
    let mut stride = [0usize; 5];
    let mut s = 1;
    for i in (0..5).rev() {
        stride[i] = s;
        s *= shape[i];
    }
    let st = at.map(|i| stride[i]);
    let mut o = 0;
    for u in 0..dims[0] {
        for v in 0..dims[1] {
            for h in 0..dims[2] {
                for w in 0..dims[3] {
                    let base = u * st[0] + v * st[1] + h * st[2] + w * st[3];
                    for b in 0..dims[4] {
                        let x = values[base + b * st[4]] as f32;
                        ensure!(
                            x.is_finite(),
                            "{}: {}: value at (u, v, h, w, b) = ({u}, {v}, {h}, {w}, {b}) is {x}",
                            path.display(),
                            layout.dataset
                        );
                        let y = x / white;
                        ensure!(
                            y.is_finite(),
                            "{}: {}: value {} at (u, v, h, w, b) = ({u}, {v}, {h}, {w}, {b}) divided by --white {} \
                             is {y}: give the value of white in the file's units",
                            path.display(),
                            layout.dataset,
                            crate::io::message::number(x),
                            crate::io::message::number(white)
                        );
                        lf.data[o] = y;
                        o += 1;
                    }
                }
            }
        }
    }
    Ok(lf)
}

/// An HDF5 error on one line (a reader's message may hold a newline), at most 300 characters.
fn one_line(e: &rust_hdf5::Hdf5Error) -> String {
    let s = e.to_string().split_whitespace().collect::<Vec<_>>().join(" ");
    if s.chars().count() > 300 { s.chars().take(300).collect::<String>() + "..." } else { s }
}
