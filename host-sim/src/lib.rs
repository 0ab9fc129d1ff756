//! The workstation side of slf: it decodes with the firmware crate's own code, so host
//! results are the device's results. The simulator, training, metrics and the full `slf`
//! command arrive with the host-simulator issue; today this crate holds the command's
//! entry point and the dictionary blob inspection it already offers.

pub use slf_firmware as firmware;
