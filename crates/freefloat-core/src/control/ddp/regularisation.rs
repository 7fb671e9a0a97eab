//! Levenberg–Marquardt regularisation of the control Hessian, `Q̃uu = Quu + λ I`, with the schedule of
//! Tassa's iLQG code that Valverde 2018 (ch. 8) modified: a multiplicative factor 1.6 on a running
//! "speed" dλ, so that repeated failures raise λ geometrically faster and repeated successes lower it
//! geometrically faster.

use crate::error::{FfError, Result};

/// Parameters of the λ schedule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegOptions {
    /// λ at the first iteration (Tassa: 1).
    pub init: f64,
    /// Below this λ is set to zero on a decrease, and a raise starts from here (Tassa: 1e-6).
    pub min: f64,
    /// Above this the solve stops: the problem cannot be made locally convex (Tassa: 1e10).
    pub max: f64,
    /// The factor (Tassa and Valverde 2018: 1.6).
    pub factor: f64,
}

impl Default for RegOptions {
    fn default() -> Self {
        RegOptions { init: 1.0, min: 1e-6, max: 1e10, factor: 1.6 }
    }
}

impl RegOptions {
    /// Check the parameters: finite, `0 ≤ init`, `0 < min ≤ max`, `factor > 1`.
    pub fn validate(&self) -> Result<()> {
        let ok = self.init.is_finite()
            && self.init >= 0.0
            && self.min > 0.0
            && self.max.is_finite()
            && self.min <= self.max
            && self.factor.is_finite()
            && self.factor > 1.0;
        if ok {
            Ok(())
        } else {
            Err(FfError::arg(
                "regularisation",
                format!("need 0 <= init, 0 < min <= max (finite) and factor > 1, got {self:?}"),
            ))
        }
    }
}

/// The current λ and its speed dλ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Regularisation {
    /// λ added to the diagonal of Quu.
    pub lambda: f64,
    /// Multiplicative speed dλ.
    pub dlambda: f64,
    opts: RegOptions,
}

impl Regularisation {
    /// Start at `opts.init` with dλ = 1.
    pub fn new(opts: RegOptions) -> Regularisation {
        Regularisation { lambda: opts.init, dlambda: 1.0, opts }
    }
    /// After a failed backward pass or a rejected step: `dλ ← max(f·dλ, f)`, `λ ← max(λ·dλ, λmin)`.
    /// Returns false if λ went above the maximum (the caller stops).
    pub fn increase(&mut self) -> bool {
        let f = self.opts.factor;
        self.dlambda = (self.dlambda * f).max(f);
        self.lambda = (self.lambda * self.dlambda).max(self.opts.min);
        self.lambda <= self.opts.max
    }
    /// After an accepted step: `dλ ← min(dλ/f, 1/f)`, `λ ← λ·dλ` (0 once λ is not above λmin).
    pub fn decrease(&mut self) {
        let f = self.opts.factor;
        self.dlambda = (self.dlambda / f).min(1.0 / f);
        self.lambda = if self.lambda > self.opts.min { self.lambda * self.dlambda } else { 0.0 };
    }
    /// The largest λ allowed.
    pub fn max(&self) -> f64 {
        self.opts.max
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follows_the_1_6_schedule() {
        let mut r = Regularisation::new(RegOptions::default());
        assert!(r.increase());
        assert_eq!((r.lambda, r.dlambda), (1.6, 1.6));
        assert!(r.increase());
        assert!((r.dlambda - 2.56).abs() < 1e-15 && (r.lambda - 1.6 * 2.56).abs() < 1e-12);
        r.decrease();
        assert!((r.dlambda - 1.0 / 1.6).abs() < 1e-15);
        assert!((r.lambda - 1.6 * 2.56 / 1.6).abs() < 1e-12);
        r.decrease();
        assert!((r.dlambda - 1.0 / 2.56).abs() < 1e-15);
        // Down to zero once at or below λmin, and a raise from zero starts at λmin.
        let mut r = Regularisation::new(RegOptions { init: 1e-6, ..Default::default() });
        r.decrease();
        assert_eq!(r.lambda, 0.0);
        r.increase();
        assert_eq!(r.lambda, 1e-6);
        // Past the maximum the caller is told to stop.
        let mut r = Regularisation::new(RegOptions { init: 1e9, ..Default::default() });
        let mut n = 0;
        while r.increase() {
            n += 1;
        }
        assert!(n < 5 && r.lambda > 1e10);
    }

    #[test]
    fn rejects_bad_options() {
        assert!(RegOptions { factor: 1.0, ..Default::default() }.validate().is_err());
        assert!(RegOptions { init: f64::NAN, ..Default::default() }.validate().is_err());
        assert!(RegOptions { min: 0.0, ..Default::default() }.validate().is_err());
        assert!(RegOptions::default().validate().is_ok());
    }
}
