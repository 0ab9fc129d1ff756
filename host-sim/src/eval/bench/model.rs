//! The f64 reference of the bench's precision points: SL0 with the 5D DCT in f64, run in
//! the same tile pipeline as the f32 decoder.

use anyhow::Result;
use slf_firmware::{Dictionary, Ended, ModelOutcome, Outcome, PatchModel, Sl0Config, SolveError};

use crate::decode::paper_1d::{Factors, analyze_5d, solve_5d, solve_5d_seeded};
use crate::io::patch::{BANDS, HostDictionary, HostShape, HostWorkspace, LENSLETS};

/// The f64 reference: SL0 with the DCT in f64 (the host's 5D reference), written back
/// through the workspace so it runs in the same tile pipeline as the f32 decoder; for
/// `5 x 5 x PU x PV x 13` patches.
pub struct F64Dct<const PU: usize, const PV: usize, const N: usize> {
    factors: Factors<f64>,
    /// The f32 DCT tables widened to f64, for writing the result back through them.
    widened: Factors<f64>,
    dict: HostDictionary<PU, PV, N>,
}

impl<const PU: usize, const PV: usize, const N: usize> Default for F64Dct<PU, PV, N> {
    fn default() -> Self {
        let dict = Dictionary::dct();
        Self {
            factors: Factors::dct_f64_of([LENSLETS, LENSLETS, PU, PV, BANDS]),
            widened: Factors::from_dictionary(&dict),
            dict,
        }
    }
}

impl<const PU: usize, const PV: usize, const N: usize> PatchModel<HostShape<PU, PV, N>> for F64Dct<PU, PV, N> {
    fn decode(&self, cfg: &Sl0Config, ws: &mut HostWorkspace<PU, PV, N>) -> Result<ModelOutcome, SolveError> {
        cfg.validate()?;
        let m = ws.measurements();
        if m.count() == 0 {
            return Err(SolveError::NoMeasurements);
        }
        let meas: Vec<Option<f64>> = (0..N).map(|i| m.get(i).map(f64::from)).collect();
        let (x, iterations) = solve_5d::<f64>(&self.factors, &meas, cfg);
        Ok(self.write_back(&x, iterations, ws))
    }

    fn decode_seeded(&self, cfg: &Sl0Config, ws: &mut HostWorkspace<PU, PV, N>) -> Result<ModelOutcome, SolveError> {
        cfg.validate()?;
        let m = ws.measurements();
        if m.count() == 0 {
            return Err(SolveError::NoMeasurements);
        }
        let meas: Vec<Option<f64>> = (0..N).map(|i| m.get(i).map(f64::from)).collect();
        let start: Vec<f64> = ws.patch().iter().map(|&x| f64::from(x)).collect();
        let (x, iterations) = solve_5d_seeded::<f64>(&self.factors, &meas, &start, cfg);
        Ok(self.write_back(&x, iterations, ws))
    }
}

impl<const PU: usize, const PV: usize, const N: usize> F64Dct<PU, PV, N> {
    /// Writes the f64 patch `x` back: its DCT coefficients (f64 analysis with the f32
    /// tables), then one f32 synthesis (rounding ~1e-7, far below the f32-vs-f64
    /// differences).
    fn write_back(&self, x: &[f64], iterations: u32, ws: &mut HostWorkspace<PU, PV, N>) -> ModelOutcome {
        let s = analyze_5d(&self.widened, x);
        for (dst, v) in ws.coefficients_mut().iter_mut().zip(&s) {
            *dst = *v as f32;
        }
        ws.synthesize(&self.dict);
        let outcome = Outcome { iterations, levels: 0, sigma0: 0.0, residual: 0.0, ended: Ended::SigmaMin };
        ModelOutcome { outcome, member: None, solves: 1 }
    }
}
