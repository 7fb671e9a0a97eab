//! `simulate_many`: B independent simulations of one robot (different initial states, inertial parameters or
//! torque tables) in one call, spread over the cores. Members share nothing mutable: each gets its own `Data`
//! and stepper (inside `simulate`), so the runs are exactly those of B separate `simulate` calls, whatever the
//! number of threads. A member that fails is reported by its index and the others are kept.

use super::{simulate, Hold, Inputs, SimOptions, TorqueSource, Trajectory};
use crate::error::{FfError, Result};
use crate::interrupt::{supervise, Hook};
use crate::model::Model;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// One argument of a batch: `rows` rows of `data.len() / rows` numbers (row-major). `rows == 1` is shared by every
/// member (broadcast); otherwise `rows` is the batch size.
#[derive(Clone, Copy, Debug)]
pub struct Stacked<'a> {
    /// The numbers, `rows` rows back to back.
    pub data: &'a [f64],
    /// Number of rows (1: one value for all members).
    pub rows: usize,
}

impl<'a> Stacked<'a> {
    /// One row shared by all members.
    pub fn shared(data: &'a [f64]) -> Self {
        Stacked { data, rows: 1 }
    }

    fn row(&self, k: usize) -> &'a [f64] {
        let w = self.data.len() / self.rows.max(1);
        let k = if self.rows == 1 { 0 } else { k };
        &self.data[k * w..(k + 1) * w]
    }
}

/// What varies between the members of a batch (each field is one row for all, or one row per member).
#[derive(Clone, Copy, Debug)]
pub struct BatchSpec<'a> {
    /// Initial configurations (nq per row).
    pub q0: Stacked<'a>,
    /// Initial velocities (nv per row).
    pub v0: Stacked<'a>,
    /// Inertial parameters (10 per body, `Model::with_parameters` order), or `None`: the model's own.
    pub params: Option<Stacked<'a>>,
    /// Generalized-force tables (T × nv per row, read at `torque_times`), or `None`: no forces.
    pub torques: Option<Stacked<'a>>,
    /// Sample times of the torque tables (T, shared by all members).
    pub torque_times: Option<&'a [f64]>,
    /// How the tables are read between samples.
    pub hold: Hold,
}

/// The batch size of `spec`: every stacked argument has 1 row (shared) or the same number B of rows, and each row
/// has the width the model needs. Errors name the argument.
pub fn batch_size(m: &Model, spec: &BatchSpec) -> Result<usize> {
    let nparams = 10 * m.nbodies();
    let ntimes = spec.torque_times.map(|t| t.len());
    let mut args: Vec<(&str, Stacked, usize)> = vec![("q0", spec.q0, m.nq), ("v0", spec.v0, m.nv)];
    if let Some(p) = spec.params {
        args.push(("params", p, nparams));
    }
    if let Some(t) = spec.torques {
        let times = ntimes.ok_or_else(|| FfError::arg("torque_times", "a torque table needs its sample times"))?;
        args.push(("torques", t, times * m.nv));
    }
    let mut b: Option<(usize, &str)> = None;
    for (name, s, width) in &args {
        if s.rows == 0 {
            return Err(FfError::arg(name, "the batch is empty (0 members): give at least one row"));
        }
        if s.data.len() != s.rows * width {
            return Err(FfError::arg(
                name,
                format!("expected {} rows of {width} numbers, got {} numbers", s.rows, s.data.len()),
            ));
        }
        if s.rows > 1 {
            match b {
                None => b = Some((s.rows, name)),
                Some((r, first)) if r != s.rows => {
                    return Err(FfError::arg(
                        name,
                        format!(
                            "has {} members but `{first}` has {r}: batched arguments must have the same size",
                            s.rows
                        ),
                    ))
                }
                _ => {}
            }
        }
    }
    Ok(b.map(|(r, _)| r).unwrap_or(1))
}

/// Simulate every member of `spec` with `opts` on up to `threads` threads (0: one per core). The outer `Err` is a
/// problem with the batch itself (sizes, empty batch); member k's own failure is the k-th entry's `Err`, with "member
/// k" in its message, and does not stop the others. `stop` (e.g. raised by [`simulate_many_interruptible`] on
/// Ctrl-C) ends the running members within ~20 ms (each `Err(Interrupted)` with its samples so far as the partial
/// trajectory) and makes the members that have not started return `Err(Interrupted)` without one.
pub fn simulate_many(
    m: &Model,
    spec: &BatchSpec,
    opts: &SimOptions,
    threads: usize,
    stop: Option<&AtomicBool>,
) -> Result<Vec<Result<Trajectory>>> {
    let b = batch_size(m, spec)?;
    let cores = crate::threads::available_cores();
    let threads = if threads == 0 { cores } else { threads }.clamp(1, b);
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<Result<Trajectory>>>> = (0..b).map(|_| Mutex::new(None)).collect();
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        if k >= b {
            break;
        }
        let r = if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            Err(FfError::interrupted(format!("member {k}: stopped before it started")))
        } else {
            run_member(m, spec, opts, k, stop)
        };
        let r = r.map_err(|e| in_member(e, k));
        *slots[k].lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
    };
    if threads == 1 {
        work();
    } else {
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(work);
            }
        });
    }
    Ok(slots
        .into_iter()
        .enumerate()
        .map(|(k, s)| {
            s.into_inner()
                .unwrap_or_else(|p| p.into_inner())
                .unwrap_or_else(|| Err(in_member(FfError::Numerical("did not run".into()), k)))
        })
        .collect())
}

/// [`simulate_many`] with Ctrl-C: the calling thread polls `hook` (at most every `POLL_INTERVAL`) while the
/// members run; its `false` stops them all (see `stop` above). Returns the members' results and whether the batch
/// was stopped.
pub fn simulate_many_interruptible(
    m: &Model,
    spec: &BatchSpec,
    opts: &SimOptions,
    threads: usize,
    mut hook: Option<Hook>,
) -> Result<(Vec<Result<Trajectory>>, bool)> {
    if hook.is_none() {
        return Ok((simulate_many(m, spec, opts, threads, None)?, false));
    }
    batch_size(m, spec)?;
    let stop = AtomicBool::new(false);
    let (results, finished) = std::thread::scope(|s| {
        let h = s.spawn(|| simulate_many(m, spec, opts, threads, Some(&stop)));
        let finished = supervise(&mut hook, &stop, std::slice::from_ref(&h), || 0.0);
        (h.join().expect("batch simulation panicked"), finished)
    });
    Ok((results?, !finished))
}

fn run_member(
    m: &Model,
    spec: &BatchSpec,
    opts: &SimOptions,
    k: usize,
    stop: Option<&AtomicBool>,
) -> Result<Trajectory> {
    // A panic inside one member must not take the batch (or the thread pool) down with it.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let own;
        let model = match spec.params {
            Some(p) => {
                own = m.with_parameters(p.row(k))?;
                &own
            }
            None => m,
        };
        let torques = match (spec.torques, spec.torque_times) {
            (Some(t), Some(times)) => TorqueSource::table(times.to_vec(), t.row(k).to_vec(), m.nv, spec.hold)?,
            _ => TorqueSource::Zero,
        };
        // the member polls the batch's stop flag like a Ctrl-C hook (at most every 20 ms)
        let mut watch = |_: f64| !stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let hook: Option<Hook> = if stop.is_some() { Some(&mut watch) } else { None };
        simulate(model, spec.q0.row(k), spec.v0.row(k), opts, Inputs { torques, ..Default::default() }, hook)
    }))
    .unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(FfError::Numerical(format!("internal error (please report it): {what}")))
    })
}

/// Prefix an error with the member it came from.
fn in_member(e: FfError, k: usize) -> FfError {
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("member {k}: {msg}") },
        FfError::Numerical(msg) => FfError::Numerical(format!("member {k}: {msg}")),
        FfError::Model(msg) => FfError::Model(format!("member {k}: {msg}")),
        // a stop keeps its partial trajectory (and already names the member when it had not started)
        FfError::Interrupted { msg, partial } if !msg.starts_with("member ") => {
            FfError::Interrupted { msg: format!("member {k}: {msg}"), partial }
        }
        e @ FfError::Interrupted { .. } => e,
        other => FfError::Numerical(format!("member {k}: {other}")),
    }
}
