//! Light fields in HDF5 files, read by the pure-Rust `hdf5-pure` crate (no C library, so
//! no cargo feature is needed; it reads h5py's files, chunked and gzip-compressed ones
//! included).
//!
//! The dataset's path and its axis order are given (`--dataset /lf --axes hwuvb`): any
//! permutation of `u`, `v` (views), `h`, `w` (space) and `b` (bands). Values of any
//! numeric type are read as f32 and divided by `white`; a band count other than the
//! camera's 13 is resampled from the given wavelengths ([`super::bands`]).

use std::path::Path;

use anyhow::{Context, Result, bail, ensure};

use crate::io::lightfield::LightField;

/// The largest HDF5 file read (the reader holds it in memory).
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
    let file = hdf5_pure::File::open(path)
        .map_err(|e| anyhow::anyhow!("{}: not an HDF5 file slf reads: {e}", path.display()))?;
    let ds = file.dataset(layout.dataset.trim_start_matches('/')).map_err(|e| {
        // HDF5's undefined address (all ones) is where the reader meets a link it does not
        // follow: a soft link once said "need 18446744073709551615 bytes".
        if e.to_string().contains(&u64::MAX.to_string()) {
            anyhow::anyhow!(
                "{}: {:?} is a soft link or another object slf's HDF5 reader does not follow (its address is \
                 undefined): give the path of the dataset itself (h5py: f[name].name)",
                path.display(),
                layout.dataset
            )
        } else {
            anyhow::anyhow!("{}: no dataset {:?}: {e}", path.display(), layout.dataset)
        }
    })?;
    let shape: Vec<usize> = ds
        .shape()
        .map_err(|e| anyhow::anyhow!("{}: {}: unreadable shape: {e}", path.display(), layout.dataset))?
        .into_iter()
        .map(|d| d as usize)
        .collect();
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
    // The element type first: a type the reader does not convert (float16, strings,
    // compounds) is named, not reported as the library's "type mismatch".
    use hdf5_pure::DType;
    let dtype = ds
        .dtype()
        .map_err(|e| anyhow::anyhow!("{}: {}: unreadable element type: {e}", path.display(), layout.dataset))?;
    let numeric = matches!(
        dtype,
        DType::F32
            | DType::F64
            | DType::I8
            | DType::I16
            | DType::I32
            | DType::I64
            | DType::U8
            | DType::U16
            | DType::U32
            | DType::U64
    );
    if !numeric {
        let what = match ds.datatype() {
            Ok(hdf5_pure::Datatype::FloatingPoint { size, .. }) => format!("{}-bit floats", 8 * size),
            _ => format!("{dtype:?}").chars().take(60).collect(),
        };
        bail!(
            "{}: {}: holds {what}; slf reads 32- or 64-bit floats and integers (convert it, e.g. h5py: \
             f[name][...].astype('float32'))",
            path.display(),
            layout.dataset
        );
    }
    // What the read holds at its peak, from what the file declares, before anything is
    // allocated (a 1.4 KB file declaring 5 x 5 x 1200 x 1200 x 13 once aborted the process
    // in the allocator): the file, the values in their own type, as f32, and the light
    // field (13 bands after resampling, at most as many as read).
    let element = match dtype {
        DType::F64 | DType::I64 | DType::U64 => 8u64,
        DType::I8 | DType::U8 => 1,
        DType::I16 | DType::U16 => 2,
        _ => 4,
    };
    let light_field = (total / shape[at[4]]) as u64 * shape[at[4]].max(13) as u64 * 4;
    let need = meta.len() + total as u64 * (element + 4) + light_field;
    crate::io::budget::check(
        need,
        &format!("{}: {} of shape {shape:?}", path.display(), layout.dataset),
        "crop or split the dataset",
    )?;
    let values = ds
        .read_f32()
        .map_err(|e| anyhow::anyhow!("{}: {}: cannot read the values: {e}", path.display(), layout.dataset))?;
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
                        let x = values[base + b * st[4]];
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
