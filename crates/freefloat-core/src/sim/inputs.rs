//! What drives a simulation: torque sources, a sampled controller, prescribed joint motion.

use crate::error::{FfError, Result};

/// How a torque table is read between its samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hold {
    /// Zero-order hold: the last sample at or before t.
    Zoh,
    /// Linear interpolation between samples (held constant beyond the table).
    Linear,
}

/// When the torque source is read during an integration step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum InputTiming {
    /// Read once per step, at the step's start, and held through its stages (the default): a
    /// zero-order-hold table switching on a step boundary acts from exactly that boundary, and a
    /// torque function is sampled like a digital controller running at the step rate. The actuator
    /// command shaping (joint limits, wheel saturation) happens at the same instant. A linearly
    /// interpolated table is still read at every stage (it is continuous in time).
    #[default]
    PerStep,
    /// Read at every Runge-Kutta stage time (t + c_s h): for a smooth function of (t, q, v) this
    /// keeps the integrator's order; a zero-order-hold switch on a step boundary then gets the last
    /// stage's weight (1/6 with RK4) of the new value in the step before it.
    Stage,
}

/// `f(t, q, v, out)`: generalized forces (nv) at time t and state (q, v).
pub type TorqueFn<'a> = Box<dyn FnMut(f64, &[f64], &[f64], &mut [f64]) -> Result<()> + 'a>;

/// Generalized forces (length nv; for a free base the first six are the base-frame thruster
/// wrench [force; torque]) as a function of time and state.
pub enum TorqueSource<'a> {
    /// No forces.
    Zero,
    /// `values` is T × nv, row-major, sampled at increasing `times`.
    Table {
        /// Sample times (s), strictly increasing.
        times: Vec<f64>,
        /// T × nv values, row-major.
        values: Vec<f64>,
        /// How values are held between samples.
        hold: Hold,
    },
    /// A function of time and state.
    Function(TorqueFn<'a>),
}

impl TorqueSource<'_> {
    /// A table of `times.len()` × `nv` values (checked: sizes, strictly increasing times, finite).
    pub fn table(times: Vec<f64>, values: Vec<f64>, nv: usize, hold: Hold) -> Result<Self> {
        if times.is_empty() || values.len() != times.len() * nv {
            return Err(FfError::arg(
                "torques",
                format!("expected a ({}, {nv}) table, got {} values", times.len(), values.len()),
            ));
        }
        if let Some(k) = times.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(FfError::arg(
                "torque_times",
                format!("times must increase strictly; row {} is not after row {k}", k + 1),
            ));
        }
        if let Some(k) = values.iter().chain(&times).position(|x| !x.is_finite()) {
            return Err(FfError::arg("torques", format!("entry {k} is not finite")));
        }
        Ok(TorqueSource::Table { times, values, hold })
    }

    /// Whether this source is read at every stage regardless of the timing (a linear table).
    pub(crate) fn continuous(&self) -> bool {
        matches!(self, TorqueSource::Table { hold: Hold::Linear, .. })
    }

    /// The first table sample time strictly after `t` (infinity for other sources): the adaptive
    /// stepper lands there so that a held switch acts from its exact time.
    pub(crate) fn next_switch(&self, t: f64) -> f64 {
        match self {
            TorqueSource::Table { times, hold: Hold::Zoh, .. } => {
                let k = times.partition_point(|&x| x <= t + 1e-12 * t.abs().max(1.0));
                times.get(k).copied().unwrap_or(f64::INFINITY)
            }
            _ => f64::INFINITY,
        }
    }

    /// Forces at time `t` and state (q, v) into `out` (nv; a table's row length is checked).
    pub fn eval(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<()> {
        self.eval_near(t, q, v, out, &mut 0)
    }

    /// `eval` for a reader that moves along the table (the simulator): `row` is the table row found by the last
    /// read, updated to this one's; the row of `t` is looked for from there (a stage is at most a few rows away)
    /// instead of by a binary search over the whole table every time. Any `row` gives the same result.
    pub(crate) fn eval_near(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64], row: &mut usize) -> Result<()> {
        match self {
            TorqueSource::Zero => out.fill(0.0),
            TorqueSource::Function(f) => {
                f(t, q, v, out)?;
                if let Some(k) = out.iter().position(|x| !x.is_finite()) {
                    return Err(FfError::Numerical(format!(
                        "torque function returned a non-finite value at entry {k}, t = {t}"
                    )));
                }
            }
            TorqueSource::Table { times, values, hold } => {
                let nv = out.len();
                if values.len() != times.len() * nv {
                    return Err(FfError::arg(
                        "out",
                        format!(
                            "the torque table has rows of {} entries, got an output of {nv}",
                            values.len() / times.len().max(1)
                        ),
                    ));
                }
                let k = last_at_or_before(times, t + 1e-12 * t.abs().max(1.0), row);
                let row = |k: usize| &values[k * nv..(k + 1) * nv];
                if *hold == Hold::Zoh || k + 1 >= times.len() || t <= times[0] {
                    out.copy_from_slice(row(k));
                } else {
                    let s = (t - times[k]) / (times[k + 1] - times[k]);
                    for ((o, a), b) in out.iter_mut().zip(row(k)).zip(row(k + 1)) {
                        *o = (1.0 - s) * a + s * b;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Index of the last of the strictly increasing, non-empty `times` at or before `x` (0 if none is): what
/// `times.partition_point(|&s| s <= x).saturating_sub(1)` returns, searched from `hint` (set to the answer) a few
/// rows either way, then by that binary search (tables can be long) when the answer is farther.
fn last_at_or_before(times: &[f64], x: f64, hint: &mut usize) -> usize {
    let mut k = (*hint).min(times.len() - 1);
    let mut moves = 0;
    loop {
        if times[k] > x && k > 0 {
            k -= 1;
        } else if k + 1 < times.len() && times[k + 1] <= x {
            k += 1;
        } else {
            break;
        }
        moves += 1;
        if moves > 8 {
            k = times.partition_point(|&s| s <= x).saturating_sub(1);
            break;
        }
    }
    *hint = k;
    k
}

/// A controller sampled every `period` seconds; its output (generalized forces, length nv) is held
/// until the next sample and added to the torque source.
pub struct Controller<'a> {
    /// Sampling period (s).
    pub period: f64,
    /// `f(t, q, v, out)`: the controller's output (nv).
    pub f: TorqueFn<'a>,
}

/// `f(t, q, v, a)`: prescribed configuration, velocity and acceleration at time t.
pub type PrescriptionFn<'a> = Box<dyn FnMut(f64, &mut [f64], &mut [f64], &mut [f64]) -> Result<()> + 'a>;

/// Joints (given by their child body index) that follow a prescribed motion. `f(t, q, v, a)` fills
/// full-length q (nq), v and a (nv); only the prescribed joints' entries are read.
pub struct Prescription<'a> {
    /// Child body index of each prescribed joint.
    pub bodies: Vec<usize>,
    /// The prescribed motion.
    pub f: PrescriptionFn<'a>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_from_a_hint_finds_what_the_binary_search_finds() {
        let times: Vec<f64> = (0..40).map(|k| 0.5 * k as f64 + 0.01 * (k * k) as f64).collect();
        let xs: Vec<f64> = (-30..300).map(|j| 0.1 * j as f64).chain([times[5], times[39], 1e9, -1e9]).collect();
        for start in [0, 3, 17, 39, 1000] {
            let mut hint = start;
            // forwards, backwards and jumping about
            for &x in xs.iter().chain(xs.iter().rev()).chain(xs.iter().step_by(37)) {
                let want = times.partition_point(|&s| s <= x).saturating_sub(1);
                assert_eq!(last_at_or_before(&times, x, &mut hint), want, "x = {x}, from {start}");
                assert_eq!(hint, want);
            }
        }
        let one = [2.0];
        assert_eq!(last_at_or_before(&one, 1.0, &mut 5), 0);
        assert_eq!(last_at_or_before(&one, 3.0, &mut 0), 0);
    }
}
