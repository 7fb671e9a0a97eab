//! The recorded result of a simulation.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;
use std::sync::Mutex;

pub use crate::trajectory::Trajectory;

/// Record buffers of trajectories that are no longer used, handed back by [`recycle`] and taken again by
/// [`Trajectory::with_capacity`]. Fresh memory costs one page fault per 4 kB page on first write: a 10-s, 1-kHz run
/// of the 15-DoF benchmark robot records 5.7 MB, and its ~1,860 faults (with the torque table's copy) took 3.6 ms
/// of kernel time in a 34-ms `ff.simulate` call (`getrusage`); with the pages kept, none. Buffers held here are
/// capped at [`SPARE_BYTES`] in all.
static SPARE: Mutex<Vec<Vec<f64>>> = Mutex::new(Vec::new());
/// At most this many bytes of unused record buffers are kept for reuse (beyond, a recycled buffer is freed).
pub const SPARE_BYTES: usize = 64 << 20;

/// Hand back a record buffer that is no longer used (the Python binding does it when numpy frees the array that
/// viewed it), for the next run to fill without faulting fresh pages in; freed instead when the buffers kept would
/// exceed [`SPARE_BYTES`].
pub fn recycle(mut buf: Vec<f64>) {
    if buf.capacity() == 0 {
        return;
    }
    let mut spare = SPARE.lock().unwrap_or_else(|e| e.into_inner());
    let held: usize = spare.iter().map(|b| b.capacity()).sum();
    if 8 * (held + buf.capacity()) <= SPARE_BYTES {
        buf.clear();
        spare.push(buf);
    }
}

/// An empty buffer with room for `n` entries: a kept one if one fits (the smallest, and at most twice `n`, so
/// that a small run does not hold on to a large buffer), else none.
fn spare(n: usize) -> Option<Vec<f64>> {
    if n == 0 {
        return None;
    }
    let mut spare = SPARE.lock().unwrap_or_else(|e| e.into_inner());
    let fits = |b: &Vec<f64>| b.capacity() >= n && b.capacity() / 2 <= n;
    let k = (0..spare.len()).filter(|&k| fits(&spare[k])).min_by_key(|&k| spare[k].capacity())?;
    Some(spare.swap_remove(k))
}

impl Trajectory {
    /// An empty trajectory with room for `samples` records (growing the arrays during a run costs
    /// several percent of a simulation). The reservation is fallible: a size the allocator refuses
    /// (or whose byte count overflows) is an error naming the size, never an abort.
    pub fn with_capacity(m: &Model, samples: usize) -> Result<Self> {
        let (nq, nv) = (m.nq, m.nv);
        let mut tr = Trajectory { nq, nv, ..Default::default() };
        let refuse = || {
            FfError::arg(
                "t_final",
                format!(
                    "a trajectory of {samples} samples ({:.3} GB) could not be allocated; record fewer samples \
                     (a larger record_every or dt, a shorter t_final)",
                    samples as f64 * Self::bytes_per_sample(m) as f64 / 1e9
                ),
            )
        };
        for (buf, width) in [
            (&mut tr.q, nq),
            (&mut tr.v, nv),
            (&mut tr.ddq, nv),
            (&mut tr.tau, nv),
            (&mut tr.momentum, 6),
            (&mut tr.t, 1),
            (&mut tr.kinetic_energy, 1),
            (&mut tr.work, 1),
        ] {
            let n = samples.checked_mul(width).ok_or_else(refuse)?;
            if let Some(b) = spare(n) {
                *buf = b;
            }
            buf.try_reserve_exact(n).map_err(|_| refuse())?;
        }
        Ok(tr)
    }

    /// Bytes one recorded sample takes: t, q, v, ddq, tau, momentum, kinetic energy, work.
    pub fn bytes_per_sample(m: &Model) -> usize {
        8 * (m.nq + 3 * m.nv + 6 + 3)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no sample was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Append a sample; `d` must hold the results of the dynamics evaluated at (t, q, v): `ddq`,
    /// `tau`, and the momentum and kinetic energy ABA forms on the way.
    pub(crate) fn push(&mut self, d: &Data, t: f64, q: &[f64], v: &[f64], work: f64) {
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.v.extend_from_slice(v);
        self.ddq.extend_from_slice(&d.ddq);
        self.tau.extend_from_slice(&d.tau);
        let mut h = [0.0; 6];
        d.aba_momentum.write(&mut h);
        self.momentum.extend_from_slice(&h);
        self.kinetic_energy.push(d.aba_kinetic_energy);
        self.work.push(work);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spare_buffers_are_reused_when_they_fit_and_kept_within_the_cap() {
        // a capacity no other test's record needs (the spare buffers are shared by the whole process)
        let cap = 3_000_017;
        let b: Vec<f64> = Vec::with_capacity(cap);
        let ptr = b.as_ptr();
        recycle(b);
        // too large for a need of less than half its size: not handed out
        assert!(spare(cap / 2 - 10).is_none());
        let got = spare(cap - 17).expect("the recycled buffer fits");
        assert_eq!((got.as_ptr(), got.capacity(), got.len()), (ptr, cap, 0));
        assert!(spare(cap - 17).is_none(), "handed out twice");
        // beyond the cap: freed, not kept
        let big = SPARE_BYTES / 8 + 1;
        recycle(Vec::with_capacity(big));
        assert!(spare(big).is_none());
        // a recycled buffer that held data comes back empty
        let mut used = Vec::with_capacity(cap);
        used.extend([1.0, 2.0]);
        recycle(used);
        assert!(spare(cap).expect("fits").is_empty());
    }
}
