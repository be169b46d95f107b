//! The hard-case sweep of every fiber model, as one list: what `strandlight sweep` runs and a
//! benchmark can run too. Each entry names its model, what one sample is, and its chunk size.

use crate::hard_case_sweep::SweepReport;
use crate::{artist, dual_scattering_hard_cases, kajiya_kay, marschner};

/// One model's sweep and the chunk size its work is split into. A chunk should be large next
/// to the sweep's own per-parameter-set granularity (the sweeps round up to whole sets).
pub struct ModelSweep {
    pub name: &'static str,
    /// What one requested sample is for this model.
    pub unit: &'static str,
    pub chunk: u64,
    pub run: fn(u64, u64) -> SweepReport,
}

pub const SWEEPS: [ModelSweep; 4] = [
    ModelSweep {
        name: "marschner",
        unit: "input (S, M_p and N_p of 3 lobes, oriented S)",
        chunk: 1 << 18,
        run: marschner_sweep,
    },
    ModelSweep {
        name: "kajiya-kay",
        unit: "scalar value",
        chunk: 1 << 20,
        run: kajiya_kay::hard_case_sweep,
    },
    ModelSweep {
        name: "artist",
        unit: "scalar value",
        chunk: 1 << 20,
        run: artist::hard_case_sweep,
    },
    ModelSweep {
        name: "dual-scattering",
        unit: "scalar value",
        chunk: 1 << 20,
        run: dual_scattering_hard_cases::hard_case_sweep,
    },
];

/// The Marschner sweep reports in its own type (samples = inputs); recast it to the common
/// report, whose `samples` counts scalar values. Its maximum is that of S only.
fn marschner_sweep(samples: u64, seed: u64) -> SweepReport {
    let r = marschner::hard_case_sweep(samples, seed);
    SweepReport {
        name: "marschner".into(),
        samples: r.values_checked,
        nan: r.nan,
        infinite: r.inf,
        negative: r.negative,
        max_finite: r.max_s,
        rejected: 0,
    }
}
