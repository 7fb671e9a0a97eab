//! Whether a dual-inertia parameter vector `v = [I11, I12, I13, I22, I23, I33, m]` (Valverde 2018, §4.1) is the
//! mass and inertia of some rigid body: positive mass, a positive-definite inertia about the centre of mass, and
//! principal moments that satisfy the triangle inequalities `λi ≤ λj + λk` (each principal moment is
//! `∫(ρj² + ρk²) dm`, so no one exceeds the sum of the other two). An adaptive estimate may be anything, and the
//! truth of the thesis' ch. 4 example (eigenvalues 1.361, 3.842, 8.797) fails the triangle test: this reports,
//! it rejects nothing.

use super::regressor::V7;
use crate::spatial::M3;

/// What [`realisability`] found; each flag says whether one condition holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Realisability {
    /// Principal moments of inertia (eigenvalues of Ī), ascending; NaN when `v` has non-finite entries.
    pub eigenvalues: [f64; 3],
    /// Every entry of `v` is finite.
    pub finite: bool,
    /// `m > 0`.
    pub mass_positive: bool,
    /// Ī positive definite (every eigenvalue > 0).
    pub positive_definite: bool,
    /// `λ_max ≤ λ_a + λ_b` for the two other eigenvalues (the binding one of the three inequalities), within
    /// a round-off tolerance of 1e-12 × the largest moment.
    pub triangle_inequality: bool,
    /// `λ_a + λ_b − λ_max`: ≥ 0 when the triangle inequality holds (how far from failing it is).
    pub triangle_margin: f64,
}

impl Realisability {
    /// All conditions hold: some rigid body has these mass properties.
    pub fn is_realisable(&self) -> bool {
        self.finite && self.mass_positive && self.positive_definite && self.triangle_inequality
    }
    /// Whether the estimate can be used as a dual inertia at all (`m > 0`, Ī > 0: `H(M)` invertible, Lemma 3);
    /// the triangle inequality is not needed for that.
    pub fn is_admissible(&self) -> bool {
        self.finite && self.mass_positive && self.positive_definite
    }
    /// The conditions that fail, in words (empty when realisable).
    pub fn failures(&self) -> Vec<String> {
        let [l1, l2, l3] = self.eigenvalues;
        let mut out = Vec::new();
        if !self.finite {
            out.push("has non-finite entries".to_string());
            return out;
        }
        if !self.mass_positive {
            out.push("mass is not positive".to_string());
        }
        if !self.positive_definite {
            out.push(format!("inertia is not positive definite (eigenvalues {l1:.4}, {l2:.4}, {l3:.4})"));
        }
        if !self.triangle_inequality {
            out.push(format!("principal moments violate the triangle inequality ({l3:.4} > {l1:.4} + {l2:.4})"));
        }
        out
    }
}

/// The inertia Ī of `v` (symmetric 3×3).
pub fn inertia_matrix(v: &V7) -> M3 {
    M3::new(v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5])
}

/// Test `v = [I11, I12, I13, I22, I23, I33, m]` for physical realisability (see the module comment).
pub fn realisability(v: &V7) -> Realisability {
    let finite = v.iter().all(|x| x.is_finite());
    if !finite {
        return Realisability {
            eigenvalues: [f64::NAN; 3],
            finite,
            mass_positive: false,
            positive_definite: false,
            triangle_inequality: false,
            triangle_margin: f64::NAN,
        };
    }
    let mut ev: Vec<f64> = inertia_matrix(v).symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(|a, b| a.total_cmp(b));
    let (l1, l2, l3) = (ev[0], ev[1], ev[2]);
    let margin = l1 + l2 - l3;
    let tol = 1e-12 * l3.abs().max(l1.abs());
    Realisability {
        eigenvalues: [l1, l2, l3],
        finite,
        mass_positive: v[6] > 0.0,
        positive_definite: l1 > 0.0,
        triangle_inequality: margin >= -tol,
        triangle_margin: margin,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_truth_is_positive_definite_but_not_realisable() {
        // Valverde 2018 §4.5: Ī = [[5,2,3],[2,5,1],[3,1,4]], m = 10
        let r = realisability(&V7::from_column_slice(&[5.0, 2.0, 3.0, 5.0, 1.0, 4.0, 10.0]));
        assert!(r.mass_positive && r.positive_definite && !r.triangle_inequality);
        assert!(r.is_admissible() && !r.is_realisable());
        // principal moments of the ch. 4 truth [5, 2, 3, 5, 1, 4, 10] (numpy eigvalsh, 4 digits): 1.361, 3.842, 8.797
        for (a, b) in r.eigenvalues.iter().zip([1.361, 3.842, 8.797]) {
            assert!((a - b).abs() < 1e-3, "{a} vs {b}");
        }
        assert_eq!(r.failures().len(), 1);
    }

    #[test]
    fn solid_box_is_realisable_and_a_lamina_is_on_the_boundary() {
        // box a×b×c of mass m: I = m/12 diag(b²+c², a²+c², a²+b²)
        let (m, a, b, c) = (3.0, 1.0, 2.0, 0.5);
        let i = [m / 12.0 * (b * b + c * c), m / 12.0 * (a * a + c * c), m / 12.0 * (a * a + b * b)];
        let r = realisability(&V7::from_column_slice(&[i[0], 0.0, 0.0, i[1], 0.0, i[2], m]));
        assert!(r.is_realisable(), "{:?}", r);
        // thin plate (c = 0): I3 = I1 + I2 exactly, still realisable
        let i = [m / 12.0 * b * b, m / 12.0 * a * a, m / 12.0 * (a * a + b * b)];
        let r = realisability(&V7::from_column_slice(&[i[0], 0.0, 0.0, i[1], 0.0, i[2], m]));
        assert!(r.triangle_inequality && r.triangle_margin.abs() < 1e-12);
    }

    #[test]
    fn each_failure_is_named() {
        let r = realisability(&V7::zeros());
        assert!(!r.mass_positive && !r.positive_definite && r.failures().len() >= 2);
        let r = realisability(&V7::from_column_slice(&[1.0, 0.0, 0.0, 1.0, 0.0, -1.0, 1.0]));
        assert!(!r.positive_definite && r.mass_positive);
        let r = realisability(&V7::from_column_slice(&[f64::NAN, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0]));
        assert!(!r.finite && !r.is_realisable() && r.failures()[0].contains("non-finite"));
    }
}
