//! Files in and out: `.npy`, light fields, capture folders, and real data imported as the
//! camera's bands.
//!
//! - [`npy`]: `.npy` files of float32, float64 or uint16 in either byte order and either
//!   memory order, every size checked before anything is allocated;
//! - [`lightfield`]: the `(U, V, H, W, B)` light field and its `.npy` files;
//! - [`npy_rows`]: a light field's `.npy` file written as its rows come;
//! - [`row_reader`]: a two-axis array in a file (a `.npy`'s or a binary PGM's body) read a
//!   few rows at a time (paged frames, calibration maps);
//! - [`png_rows`]: a grey PNG raw frame read a few rows at a time, one decoder going down it;
//! - [`map`]: a per-pixel map of the sensor (a calibration's dark levels or flats) read a
//!   few rows at a time;
//! - [`budget`]: the memory a command may take, checked before the work starts;
//! - [`calibration`]: the calibration folder `slf calibrate` writes and a calibrated
//!   decode reads;
//! - [`capture`]: the capture folder (frames and `capture.json`), loaded and saved;
//! - [`frame_file`]: a raw frame's file (PGM, PNG, `.npy`), read and written;
//! - [`frames`]: a capture's frames, held or read a band at a time, as the decoder reads them;
//! - [`paged_frame`]: a raw frame read from its file a band of rows at a time;
//! - [`file_checks`]: a file checked before it is opened (regular, not too large);
//! - [`json`]: descriptions parsed from JSON, errors naming the field;
//! - [`hdf5_rows`]: a light field's HDF5 file, from its rows;
//! - [`zarr_rows`]: a light field's Zarr v3 store, from its rows;
//! - [`zarr_stack`]: many captures' light fields in one store, a slot each (`slf.batch`);
//! - [`row_band`]: rows gathered into bands of whole chunks (what the HDF5 and Zarr outputs
//!   write at a time);
//! - [`folder`]: folders written whole, and the checksums their descriptions record;
//! - [`grid`]: the lenslet grid, where a real lenslet array sits on the sensor;
//! - [`interrupt`]: an interrupt ends a command and removes its temporaries;
//! - [`import`]: views, hyperspectral cubes, HDF5 light fields and band resampling;
//! - [`message`]: an error as the one line a user reads;
//! - [`output`]: results written whole, never over an input of the same run;
//! - [`output_file`]: a light field's file (`.npy`, HDF5, Zarr, a batch store's slot) as the rows come;
//! - [`patch`]: the patch the host decodes, its extents named once;
//! - [`rows`]: a light field put a lenslet row at a time (a streamed decode's sink);
//! - [`sensor`]: a simulated sensor's imperfections as its captures record them;
//! - [`stdout`]: lines to standard output that fail as errors ([`crate::outln!`]).
//!
//! May use: nothing of this crate (the firmware crate's checked types). Used by every
//! layer above.

pub mod budget;
pub mod calibration;
pub mod capture;
pub mod file_checks;
pub mod folder;
pub mod frame_file;
pub mod frames;
pub mod grid;
pub mod hdf5_rows;
pub mod import;
pub mod interrupt;
pub mod json;
pub mod lightfield;
pub mod map;
pub mod message;
pub mod npy;
pub mod npy_rows;
pub mod output;
pub mod output_file;
pub mod paged_frame;
pub mod patch;
pub mod png_rows;
pub mod row_band;
pub mod row_reader;
pub mod rows;
pub mod sensor;
#[macro_use]
pub mod stdout;
pub mod zarr_rows;
pub mod zarr_stack;
