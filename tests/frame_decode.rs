//! End to end: raw frames through the tile decoder (filled in below).
