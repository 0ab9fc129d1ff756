//! One file per command: its clap `Args` and its `run`. `main.rs` only dispatches.

pub mod baseline;
pub mod bench;
pub mod calibrate;
pub mod compare;
pub mod decode;
pub mod demo;
pub mod device_capture;
pub mod device_check;
pub mod eval;
pub mod evaluate;
pub mod import;
pub mod scene;
pub mod simulate;
pub mod sweep;
pub mod train;
pub mod train_schedule;
