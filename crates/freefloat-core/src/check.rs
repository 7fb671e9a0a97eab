//! The one argument check of the engine (the contract of every public entry point).
//!
//! Every public algorithm calls [`check_args`] once, at entry, before touching its buffers: sizes of
//! `q`, `v`, the other nv-vectors (`a`, `tau`, `ddq`), `fext` (nbodies × 6), masks (one flag per body),
//! finiteness of every number, unit quaternions in `q`, and that the `Data` was made for this `Model`.
//! The checks are O(nq + nv + nbodies) and never run inside a per-body loop; algorithms that call one
//! another use the unchecked `pub(crate)` cores, so an RK4 stage checks once.
//!
//! Messages name the argument and give the expected and the actual value
//! (`argument `tau`: expected 15 entries, got 14`); the Python layer passes them on unchanged.

use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;

/// Tolerance on the norm of a quaternion in `q`: within it the quaternion is normalised silently
/// (round-off), beyond it rejected (almost always a wrong layout, e.g. `w` first).
pub const QUATERNION_TOLERANCE: f64 = 1e-6;

/// Check that a slice has `expected` entries, all finite.
pub fn check_vec(name: &str, x: &[f64], expected: usize) -> Result<()> {
    if x.len() != expected {
        return Err(FfError::arg(name, format!("expected {expected} entries, got {}", x.len())));
    }
    check_finite(name, x)
}

/// Check the length of an output slice.
pub fn check_len(name: &str, len: usize, expected: usize) -> Result<()> {
    if len != expected {
        return Err(FfError::arg(name, format!("expected {expected} entries, got {len}")));
    }
    Ok(())
}

/// Check that every entry of a slice is finite (names the first entry that is not).
#[inline]
pub fn check_finite(name: &str, x: &[f64]) -> Result<()> {
    // one branch-free pass: `v * 0` is 0 for a finite v and NaN otherwise; sixteen independent lanes (four AVX2
    // vectors) so that the sums vectorise and no add waits on the one before (with four lanes, one vector, each
    // add waited for the last: a scan of the identification's v and h ran at about one entry per cycle). The
    // position is looked up only on failure.
    const L: usize = 16;
    let mut acc = [0.0f64; L];
    let chunks = x.chunks_exact(L);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..L {
            acc[k] += c[k] * 0.0;
        }
    }
    // what is left (all of a short argument such as one sample's q) four at a time, then one at a time
    let quads = rest.chunks_exact(4);
    let tail = quads.remainder();
    for c in quads {
        for k in 0..4 {
            acc[k] += c[k] * 0.0;
        }
    }
    for (k, v) in tail.iter().enumerate() {
        acc[k] += v * 0.0;
    }
    if acc.iter().sum::<f64>() == 0.0 {
        return Ok(());
    }
    match x.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(FfError::arg(name, format!("entry {i} is {} (must be finite)", x[i]))),
        None => Ok(()),
    }
}

/// Check that a `Data` was made (by `Data::new`) for this `Model` or for a clone of it.
#[inline]
pub fn check_data(m: &Model, d: &Data) -> Result<()> {
    if d.model_id() != m.id() {
        return Err(FfError::arg(
            "data",
            format!(
                "this Data was made for another model (model id {}, expected {} of model '{}'); make one with Data::new(&model)",
                d.model_id(),
                m.id(),
                m.name
            ),
        ));
    }
    if !d.sized_for(m) {
        return Err(FfError::arg(
            "data",
            format!("a buffer of this Data was resized; make a new one with Data::new(&model) for model '{}'", m.name),
        ));
    }
    Ok(())
}

/// Check a configuration: nq finite entries, every quaternion of unit norm within
/// [`QUATERNION_TOLERANCE`]. Returns whether some quaternion needs normalising (norm not exactly 1).
pub fn check_q(m: &Model, q: &[f64]) -> Result<bool> {
    check_vec("q", q, m.nq)?;
    let mut needs_fix = false;
    for &(i, s) in m.quaternions() {
        {
            let n = q[s..s + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
            if (n - 1.0).abs() > QUATERNION_TOLERANCE {
                return Err(FfError::arg(
                    "q",
                    format!(
                        "the quaternion of joint '{}' (q[{}..{}], order x y z w) has norm {n:.6}; it must be a unit quaternion",
                        m.joint_names[i],
                        s,
                        s + 4
                    ),
                ));
            }
            needs_fix |= n != 1.0;
        }
    }
    Ok(needs_fix)
}

/// Check optional external forces: nbodies × 6 finite numbers (body-frame wrenches).
pub fn check_fext(m: &Model, fext: Option<&[f64]>) -> Result<()> {
    match fext {
        Some(f) => check_vec("fext", f, 6 * m.nbodies()),
        None => Ok(()),
    }
}

/// Check a per-body mask (one flag per joint, in body order).
pub fn check_mask(m: &Model, name: &str, mask: &[bool]) -> Result<()> {
    let n = m.nbodies();
    if mask.len() != n {
        return Err(FfError::arg(name, format!("expected {n} flags (one per joint), got {}", mask.len())));
    }
    Ok(())
}

/// Check a body index.
pub fn check_body(m: &Model, name: &str, body: usize) -> Result<()> {
    let n = m.nbodies();
    if body >= n {
        return Err(FfError::arg(name, format!("body index {body} out of range (model '{}' has {n} bodies)", m.name)));
    }
    Ok(())
}

/// Check the shape of an output matrix.
pub fn check_shape(name: &str, rows: usize, cols: usize, expected: (usize, usize)) -> Result<()> {
    if (rows, cols) != expected {
        return Err(FfError::arg(name, format!("output must be {} × {}, got {rows} × {cols}", expected.0, expected.1)));
    }
    Ok(())
}

/// The arguments of one call, each optional; [`check_args`] checks those present.
#[derive(Clone, Copy, Default)]
pub struct Args<'a> {
    /// Configuration (nq).
    pub q: Option<&'a [f64]>,
    /// Generalized velocity (nv).
    pub v: Option<&'a [f64]>,
    /// Further nv-vectors with their argument names (`a`, `tau`, `ddq`; at most three).
    pub nv_vectors: [Option<(&'static str, &'a [f64])>; 3],
    /// External forces (nbodies × 6).
    pub fext: Option<&'a [f64]>,
    /// A per-body mask with its argument name (`prescribed`, `locked`).
    pub mask: Option<(&'static str, &'a [bool])>,
}

impl<'a> Args<'a> {
    /// Arguments of a call taking a configuration.
    pub fn q(q: &'a [f64]) -> Self {
        Args { q: Some(q), ..Default::default() }
    }
    /// Arguments of a call taking a configuration and a velocity.
    pub fn qv(q: &'a [f64], v: &'a [f64]) -> Self {
        Args { q: Some(q), v: Some(v), ..Default::default() }
    }
    /// Add an nv-vector named `name` (at most three; a fourth replaces the third).
    pub fn nv(mut self, name: &'static str, x: &'a [f64]) -> Self {
        let slot = self.nv_vectors.iter().position(|s| s.is_none()).unwrap_or(self.nv_vectors.len() - 1);
        self.nv_vectors[slot] = Some((name, x));
        self
    }
    /// Add optional external forces.
    pub fn fext(mut self, fext: Option<&'a [f64]>) -> Self {
        self.fext = fext;
        self
    }
    /// Add a per-body mask named `name`.
    pub fn mask(mut self, name: &'static str, mask: &'a [bool]) -> Self {
        self.mask = Some((name, mask));
        self
    }
}

/// The shared check of every public entry point: `Data` belongs to `Model` (when given), then `q`,
/// `v`, the nv-vectors, `fext` and the mask, in that order (the first problem is reported). Returns
/// whether `q` needs its quaternions normalised (see [`with_unit_q`]).
pub fn check_args(m: &Model, d: Option<&Data>, args: &Args) -> Result<bool> {
    if let Some(d) = d {
        check_data(m, d)?;
    }
    let needs_fix = match args.q {
        Some(q) => check_q(m, q)?,
        None => false,
    };
    if let Some(v) = args.v {
        check_vec("v", v, m.nv)?;
    }
    for (name, x) in args.nv_vectors.iter().flatten() {
        check_vec(name, x, m.nv)?;
    }
    check_fext(m, args.fext)?;
    if let Some((name, mask)) = args.mask {
        check_mask(m, name, mask)?;
    }
    Ok(needs_fix)
}

/// Run `f` with `q` whose quaternions have exactly unit norm: `q` itself when `needs_fix` is false,
/// else a normalised copy in `d.qbuf` (no allocation once `d.qbuf` has nq capacity, as `Data::new`
/// gives it).
#[inline]
pub(crate) fn with_unit_q<T>(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    needs_fix: bool,
    f: impl FnOnce(&mut Data, &[f64]) -> T,
) -> T {
    if !needs_fix {
        return f(d, q);
    }
    let mut buf = std::mem::take(&mut d.qbuf);
    normalized_into(m, q, &mut buf);
    let r = f(d, &buf);
    d.qbuf = buf;
    r
}

/// Copy `q` into `buf` with every quaternion normalised (q already checked).
pub(crate) fn normalized_into(m: &Model, q: &[f64], buf: &mut Vec<f64>) {
    buf.clear();
    buf.extend_from_slice(q);
    for &(_, s) in m.quaternions() {
        crate::spatial::quat_normalize(&mut buf[s..s + 4]);
    }
}

/// `Model::checked_q` is defined here, not in `model`, so that `model` does not import the check that imports it.
impl Model {
    /// Check `q` (size, finiteness, unit quaternions: `check::check_q`) and return it with every
    /// quaternion normalised (a copy in `buf` only when one was off by round-off).
    /// Policy: a quaternion whose norm is off by more than 1e-6 is rejected, not silently fixed,
    /// because such an input almost always means a wrong layout (e.g. w first) rather than round-off.
    pub fn checked_q<'a>(&self, q: &'a [f64], buf: &'a mut Vec<f64>) -> Result<&'a [f64]> {
        if !check_q(self, q)? {
            return Ok(q);
        }
        normalized_into(self, q, buf);
        Ok(&buf[..])
    }
}

#[cfg(test)]
mod tests {
    use super::check_finite;

    #[test]
    fn check_finite_names_the_first_bad_entry_in_every_lane_and_tail() {
        // every length around the 16- and 4-lane blocks, every position, each kind of non-finite value
        for n in 0..40 {
            let ok: Vec<f64> = (0..n).map(|k| if k % 3 == 0 { f64::MAX } else { -(k as f64) - 0.5 }).collect();
            assert!(check_finite("x", &ok).is_ok(), "n = {n}");
            for i in 0..n {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut x = ok.clone();
                    x[i] = bad;
                    if i + 1 < n {
                        x[n - 1] = f64::NAN; // a later one too: the first is named
                    }
                    let e = check_finite("x", &x).unwrap_err().to_string();
                    assert!(e.contains(&format!("entry {i} is")), "n = {n}, i = {i}: {e}");
                }
            }
        }
    }
}
