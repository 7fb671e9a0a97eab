//! The engine's one explicit Runge-Kutta stage loop and its Butcher tableaux.
//!
//! A step works in increments δ of the state's tangent coordinates about the step's start x0: stage s is
//! evaluated at `x0 ⊕ δ_s`, `δ_s = h Σⱼ a_sj k_j`, and the step's increment is `h Σⱼ b_j k_j`. On a Lie group this
//! is Runge-Kutta-Munthe-Kaas (Munthe-Kaas 1999): the stage's rate k_s is its velocity mapped through
//! dexp⁻¹(δ_s), which keeps the method's order; on a vector space ⊕ is + and dexp⁻¹ the identity. The
//! caller's stage function does the ⊕, the evaluation and the dexp⁻¹ (on the configuration space: `config::retract`,
//! the dynamics, `config::dexpinv`), so one loop serves the simulator (`sim`), the concurrent-learning driver
//! (`estimation::concurrent`) and the adaptive controller's closed loop (`control::adaptive`, RK4 and
//! Dormand-Prince).
//!
//! Not used by `dynamics::derivatives::step`: its RK4 differentiates every stage (the stage's Jacobians propagate
//! through `∂δ_s = c_s h ∂K_{s−1}` beside the values), in the derivatives' chart with its tangent map, so its stage
//! loop carries matrices the others do not have.

use crate::error::Result;

/// An explicit Runge-Kutta method: nodes c, lower-triangular a (row s has s entries), weights b.
pub struct Tableau {
    /// Nodes.
    pub c: &'static [f64],
    /// Coefficients, row s = stage s (row 0 empty).
    pub a: &'static [&'static [f64]],
    /// Weights.
    pub b: &'static [f64],
    /// b − b̂ (embedded lower-order weights), for error control.
    pub e: Option<&'static [f64]>,
}

impl Tableau {
    /// Number of stages.
    pub fn stages(&self) -> usize {
        self.c.len()
    }
}

/// The classical fourth-order method.
pub static RK4: Tableau = Tableau {
    c: &[0.0, 0.5, 0.5, 1.0],
    a: &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]],
    b: &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    e: None,
};

/// Dormand & Prince (1980) 5(4), the tableau of MATLAB's ode45 (seventh stage evaluates at the
/// new point; its weight in b is zero).
pub static DOPRI5: Tableau = Tableau {
    c: &[0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0],
    a: &[
        &[],
        &[1.0 / 5.0],
        &[3.0 / 40.0, 9.0 / 40.0],
        &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
        &[19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0],
        &[9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0],
        &[35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
    ],
    b: &[35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0],
    e: Some(&[
        35.0 / 384.0 - 5179.0 / 57600.0,
        0.0,
        500.0 / 1113.0 - 7571.0 / 16695.0,
        125.0 / 192.0 - 393.0 / 640.0,
        -2187.0 / 6784.0 + 92097.0 / 339200.0,
        11.0 / 84.0 - 187.0 / 2100.0,
        -1.0 / 40.0,
    ]),
};

/// `out = h Σⱼ wⱼ kⱼ` over `out.len()` entries (w: a row of the tableau's a, or its b), j ascending, zero weights
/// skipped: the same sums in the same order as the full inner product (adding the skipped ±0 terms to a running sum
/// that starts at +0 changes nothing), bit for bit, and RK4 has one non-zero a per stage.
#[inline]
pub fn increment<K: AsRef<[f64]>>(w: &[f64], h: f64, k: &[K], out: &mut [f64]) {
    out.fill(0.0);
    let n = out.len();
    for (j, &wj) in w.iter().enumerate() {
        if wj == 0.0 {
            continue;
        }
        let kj = &k[j].as_ref()[..n];
        for i in 0..n {
            out[i] += wj * kj[i];
        }
    }
    for o in out.iter_mut() {
        *o *= h;
    }
}

/// One explicit Runge-Kutta step from time `t` with step `h` (module documentation). `k[0]` must already hold the
/// rate at x0 (evaluated with the step's start, or the last stage of the step before when the method has the
/// first-same-as-last property). For s = 1, …, stages − 1: `delta ← h Σⱼ a_sj k_j`, then `stage(s, t + c_s h,
/// delta, k_s)` evaluates the state `x0 ⊕ delta` and writes its rate into `k_s`. On return `delta` holds the
/// step's increment `h Σⱼ b_j k_j`; the caller forms `x0 ⊕ delta`. `k`: one row per stage, each with at least
/// `delta.len()` entries.
pub fn step<K, F>(tab: &Tableau, t: f64, h: f64, k: &mut [K], delta: &mut [f64], mut stage: F) -> Result<()>
where
    K: AsRef<[f64]> + AsMut<[f64]>,
    F: FnMut(usize, f64, &[f64], &mut [f64]) -> Result<()>,
{
    for s in 1..tab.stages() {
        increment(tab.a[s], h, k, delta);
        stage(s, t + tab.c[s] * h, delta, k[s].as_mut())?;
    }
    increment(tab.b, h, k, delta);
    Ok(())
}
