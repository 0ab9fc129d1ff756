//! The simulator: spectral scenes and the camera that records them.
//!
//! - [`spectra`] (tables in [`spectra_data`]): measured and synthetic reflectances and
//!   illuminants at the camera's 13 band centres;
//! - [`scene`]: the named test scenes and the random training scenes;
//! - [`realistic`]: scenes that look like the world (slanted and curved surfaces, 1/f
//!   textures, measured spectra, five illuminants);
//! - [`hard`]: the hard-case set, content the decode was measured to tie or lose on
//!   (materials at the lenslet scale, disparities between the shears, speculars, spiky
//!   light, dim captures);
//! - [`camera`]: a light field to raw frames with the firmware's masks, noise, black level,
//!   quantisation, saturation and defects, as a capture;
//! - [`footprint`]: the share of a pixel each view cell of a lenslet grid covers;
//! - [`calibration`]: a simulated sensor's calibration captures (dark, flat, band sweep);
//! - [`sensor`]: the sensor as it is: leaky filters, dark levels and gains per pixel, hot
//!   pixels, vignetted views;
//! - [`settings`]: what a user asks of a simulated capture (`slf simulate`'s flags,
//!   `slf.simulate`'s keywords);
//! - [`flags`]: parsers the settings types share;
//! - [`import`]: real data as the camera sees it (`slf import views` and `cube`'s flags, a
//!   light field brought to the camera's 13 bands), with [`crate::io::import`]'s readers.
//!
//! May use: [`crate::io`]. Used by the decode, train and eval layers.

pub mod calibration;
pub mod camera;
pub mod flags;
pub mod footprint;
pub mod hard;
pub mod import;
pub mod realistic;
pub mod scene;
pub mod sensor;
pub mod settings;
pub mod spectra;
pub mod spectra_data;
