//! A timing loop over one engine kernel, for the benchmarks (`benches/kernels_vs_pinocchio.py`): the same shape as
//! the C++ Pinocchio peer's loop (`benches/pinocchio_peer.cpp`), so that both sides are timed core to core, warm,
//! with no Python call, argument conversion or output allocation inside the timed region. Not a user API.

use crate::algorithms::Arr;
use crate::batch::{common_rows, model_arg, Batch};
use crate::errors::{guard, to_py};
use freefloat_core::dynamics::{aba, crba, rnea};
use freefloat_core::FfError;
use pyo3::prelude::*;
use std::time::Instant;

/// `calls` calls of `kernel` ("aba", "rnea" or "crba") cycling through the rows of q, v, tau (tau is the
/// acceleration for rnea; v and tau are ignored by crba), each through the checked public function as a user calls
/// it. Returns (wall seconds of the loop, this thread's CPU seconds over the same loop, a checksum of the outputs
/// that keeps the loop from being optimised away). Both clocks are read around the loop alone, as the C++ peer
/// reads its own: the argument copies before it (page faults of a fresh 7 MB batch) are not the kernel's time.
#[pyfunction]
pub fn _time_kernel<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    kernel: &str,
    q: Arr<'_, 'py>,
    v: Arr<'_, 'py>,
    tau: Arr<'_, 'py>,
    calls: usize,
) -> PyResult<(f64, f64, f64)> {
    let mb = model_arg(model)?;
    let model = mb.get();
    let m = &model.inner;
    let (qb, vb, tb) =
        (Batch::shape("q", q, &[m.nq])?, Batch::shape("v", v, &[m.nv])?, Batch::shape("tau", tau, &[m.nv])?);
    let (rows, _) = common_rows(&[("q", &qb), ("v", &vb), ("tau", &tb)])?;
    let kind = match kernel {
        "aba" => 0,
        "rnea" => 1,
        "crba" => 2,
        k => return Err(to_py(FfError::arg("kernel", format!("expected aba, rnea or crba, got '{k}'")))),
    };
    py.detach(|| {
        model.with_data(|m, d| {
            guard(|| {
                let mut sum = 0.0;
                let (t0, c0) = (Instant::now(), thread_cpu_seconds());
                for i in 0..calls {
                    let k = i % rows;
                    let (q, v, t) = (qb.row(k), vb.row(k), tb.row(k));
                    sum += match kind {
                        0 => {
                            aba(m, d, q, v, t, None)?;
                            d.ddq[0]
                        }
                        1 => {
                            rnea(m, d, q, v, t, None)?;
                            d.tau[0]
                        }
                        _ => {
                            crba(m, d, q)?;
                            d.mass_matrix[(0, 0)]
                        }
                    };
                }
                let (wall, cpu) = (t0.elapsed().as_secs_f64(), thread_cpu_seconds() - c0);
                Ok((wall, cpu, std::hint::black_box(sum)))
            })
        })
    })
}

/// CPU seconds the calling thread has used (CLOCK_THREAD_CPUTIME_ID; NaN where the clock is missing).
#[cfg(unix)]
fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes one timespec through a valid pointer to a local.
    if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) } != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

#[cfg(not(unix))]
fn thread_cpu_seconds() -> f64 {
    f64::NAN
}
