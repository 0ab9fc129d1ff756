//! Helpers shared by the host's tests: hand-made `.npy` and PNG files and a small test scene.
#![allow(dead_code)] // each test binary uses a part

use slf_host::firmware::RowSink;
use slf_host::io::lightfield::LightField;
use slf_host::sim::scene::{SceneSize, named};

/// An `.npy` file byte by byte: magic, version, the header length field, header, body.
pub fn npy_bytes(version: u8, header: &str, body: &[u8]) -> Vec<u8> {
    let mut out = b"\x93NUMPY".to_vec();
    out.extend_from_slice(&[version, 0]);
    if version == 1 {
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(body);
    out
}

/// The `smooth` test scene at 12 x 12 lenslets with `views` x `views` views.
pub fn small_smooth(views: usize) -> LightField {
    named("smooth")
        .map(|s| s.render(SceneSize { views: (views, views), rows: 12, cols: 12 }))
        .unwrap_or_else(|| unreachable!("smooth is a named scene"))
}

/// A light field filled from an overlapped decode's strip rows (13 bands).
pub struct Rows(pub LightField);

impl RowSink for Rows {
    type Error = core::convert::Infallible;
    fn row(&mut self, row: u16, first_col: u16, values: &[f32]) -> Result<(), Self::Error> {
        // `(u, v, x, b)` over the band's columns.
        let (vu, vv) = self.0.views;
        let width = values.len() / (vu * vv * 13);
        for (i, x) in values.chunks(13).enumerate() {
            let (c, u, v) = (i % width, (i / width) / vv, (i / width) % vv);
            let at = self.0.index(u, v, row as usize, first_col as usize + c, 0);
            self.0.data[at..at + 13].copy_from_slice(x);
        }
        Ok(())
    }
}

/// A PNG of a single IHDR (and IEND) claiming `w x h` 8-bit grey pixels: a few dozen bytes.
pub fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let chunk = |kind: &[u8; 4], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend(kind);
        c.extend(data);
        let mut crc = crc32fast::Hasher::new();
        crc.update(kind);
        crc.update(data);
        c.extend(crc.finalize().to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &[]));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// The DCT as the host's `Basis::Dct` decodes with it: with the shipped blob's trained
/// schedules where the patch's blob has them (the full-view one), bare otherwise.
pub enum DctModel<const PU: usize, const PV: usize, const N: usize> {
    Bare(Box<slf_host::firmware::Dictionary<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>>>),
    Scheduled(Box<slf_host::firmware::ScheduledDictionary<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>>>),
}

impl<const PU: usize, const PV: usize, const N: usize> DctModel<PU, PV, N> {
    pub fn shipped() -> Self {
        let dictionary = slf_host::firmware::Dictionary::<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>>::dct();
        match slf_host::decode::cs::ensemble::<PU, PV, N>(None).unwrap().schedules() {
            Some(schedules) => {
                Self::Scheduled(Box::new(slf_host::firmware::ScheduledDictionary { dictionary, schedules }))
            }
            None => Self::Bare(Box::new(dictionary)),
        }
    }
}

impl<const PU: usize, const PV: usize, const N: usize>
    slf_host::firmware::PatchModel<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>> for DctModel<PU, PV, N>
{
    fn decode(
        &self,
        cfg: &slf_host::firmware::Sl0Config,
        ws: &mut slf_host::firmware::Workspace<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>>,
    ) -> Result<slf_host::firmware::ModelOutcome, slf_host::firmware::SolveError> {
        match self {
            Self::Bare(d) => d.decode(cfg, ws),
            Self::Scheduled(d) => d.decode(cfg, ws),
        }
    }

    fn decode_seeded(
        &self,
        cfg: &slf_host::firmware::Sl0Config,
        ws: &mut slf_host::firmware::Workspace<slf_host::firmware::PatchShape<5, 5, PU, PV, 13, N>>,
    ) -> Result<slf_host::firmware::ModelOutcome, slf_host::firmware::SolveError> {
        match self {
            Self::Bare(d) => d.decode_seeded(cfg, ws),
            Self::Scheduled(d) => d.decode_seeded(cfg, ws),
        }
    }
}

/// Drops `files` (each file's size and CRC-32) from the folder's `capture.json`: a folder
/// from another tool or an older slf, whose frames are read without that check.
pub fn forget_records(dir: &std::path::Path) {
    let path = dir.join("capture.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("files");
    std::fs::write(&path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}
