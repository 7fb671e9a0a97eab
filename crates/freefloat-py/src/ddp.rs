//! DDP bindings (Valverde 2018, ch. 8): build a floating-robot optimal-control problem from cost
//! descriptions (dicts), solve it with DDP or its feasibility-driven variant, get the trajectory, gains and
//! per-iteration history back; plus the screw reference and the continuous end-effector dual quaternion.

use crate::batch::model_arg;
use crate::errors::{guard, input_err};
use freefloat_core::control::ddp::costs::{frame_dual_quat, CostTerm, KeepOut, Residual, Weights};
use freefloat_core::control::ddp::reference::screw_reference;
use freefloat_core::control::ddp::{
    ActionModel, DdpOptions, FloatingRobot, IterInfo, Mpc, MpcOptions, Policy, RegOptions, Solver, StopReason, Variant,
};
use freefloat_core::dualquat::DualQuat;
use freefloat_core::spatial::{rot_from_quat, Se3, V3};
use freefloat_core::{FfError, Model};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

fn rows(name: &str, a: &PyReadonlyArray2<f64>, cols: usize) -> PyResult<Vec<Vec<f64>>> {
    let s = a.shape();
    if s[1] != cols || s[0] == 0 {
        return Err(input_err(format!("argument `{name}`: expected shape (M, {cols}) with M >= 1, got {s:?}")));
    }
    let v = a.as_array();
    let out: Vec<Vec<f64>> = (0..s[0]).map(|i| v.row(i).iter().copied().collect()).collect();
    if out.iter().flatten().any(|x| !x.is_finite()) {
        return Err(input_err(format!("argument `{name}`: non-finite entries")));
    }
    Ok(out)
}

fn get<'py, T: FromPyObject<'py>>(d: &Bound<'py, PyDict>, ctx: &str, key: &str) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v.extract::<T>().map(Some).map_err(|e| input_err(format!("{ctx}: key `{key}`: {e}"))),
    }
}

fn need<'py, T: FromPyObject<'py>>(d: &Bound<'py, PyDict>, ctx: &str, key: &str) -> PyResult<T> {
    get(d, ctx, key)?.ok_or_else(|| input_err(format!("{ctx}: missing key `{key}`")))
}

fn frame(m: &Model, name: &str) -> PyResult<(usize, Se3)> {
    m.frame_or_body(name).map_err(crate::errors::to_py)
}

fn cost_term(m: &Model, d: &Bound<'_, PyDict>, i: usize) -> PyResult<CostTerm> {
    let name: String = get(d, &format!("cost {i}"), "name")?.unwrap_or_else(|| format!("cost{i}"));
    let ctx = format!("cost '{name}'");
    let kind: String = need(d, &ctx, "kind")?;
    let nx = m.nq + m.nv;
    let reference: Option<PyReadonlyArray2<f64>> = get(d, &ctx, "reference")?;
    let residual = match kind.as_str() {
        "frame_placement" => {
            let (body, placement) = frame(m, &need::<String>(d, &ctx, "frame")?)?;
            let r = reference.ok_or_else(|| input_err(format!("{ctx}: missing key `reference` ((M, 7) poses)")))?;
            let refs = rows(&format!("{name}.reference"), &r, 7)?
                .iter()
                .map(|p| {
                    let mut q = [p[3], p[4], p[5], p[6]];
                    freefloat_core::spatial::quat_normalize(&mut q);
                    Se3::new(rot_from_quat(&q), V3::new(p[0], p[1], p[2]))
                })
                .collect();
            Residual::FramePlacement { body, placement, refs }
        }
        "frame_dq" => {
            let (body, placement) = frame(m, &need::<String>(d, &ctx, "frame")?)?;
            let r = reference
                .ok_or_else(|| input_err(format!("{ctx}: missing key `reference` ((M, 8) dual quaternions)")))?;
            let refs = rows(&format!("{name}.reference"), &r, 8)?
                .iter()
                .map(|p| [p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]])
                .collect();
            let nearest_sign = match get::<String>(d, &ctx, "sign")?.as_deref() {
                None | Some("literal") => false,
                Some("nearest") => true,
                Some(other) => {
                    return Err(input_err(format!("{ctx}: key `sign`: expected 'literal' or 'nearest', got '{other}'")))
                }
            };
            Residual::FrameDualQuat { body, placement, refs, nearest_sign }
        }
        "state" => {
            let refs = match reference {
                Some(r) => rows(&format!("{name}.reference"), &r, nx)?,
                None => {
                    let mut x = m.neutral();
                    x.extend(std::iter::repeat_n(0.0, m.nv));
                    vec![x]
                }
            };
            Residual::State { refs }
        }
        "control" => {
            let refs = match reference {
                Some(r) => rows(&format!("{name}.reference"), &r, m.nv)?,
                None => vec![vec![0.0; m.nv]],
            };
            Residual::Control { refs }
        }
        other => {
            return Err(input_err(format!(
                "{ctx}: key `kind`: expected 'frame_placement', 'frame_dq', 'state' or 'control', got '{other}'"
            )))
        }
    };
    let weights = if let Some(w) = get::<Vec<f64>>(d, &ctx, "weights")? {
        Weights::constant(w)
    } else {
        let s: Vec<f64> = need(d, &ctx, "weights_start")?;
        let mm: Vec<f64> = need(d, &ctx, "weights_medium")?;
        let e: Vec<f64> = need(d, &ctx, "weights_end")?;
        let b: Vec<usize> = need(d, &ctx, "breakpoints")?;
        let b: [usize; 4] =
            b.try_into().map_err(|_| input_err(format!("{ctx}: key `breakpoints`: need 4 iteration numbers")))?;
        Weights::scheduled(s, mm, e, b)
    }
    .map_err(|e| input_err(format!("{ctx}: {e}")))?;
    Ok(CostTerm { name, residual, weights })
}

fn cost_list(m: &Model, l: &Bound<'_, PyList>) -> PyResult<Vec<CostTerm>> {
    let mut out = vec![];
    for (i, item) in l.iter().enumerate() {
        let d = item.downcast::<PyDict>().map_err(|_| input_err(format!("cost {i}: expected a dict")))?;
        out.push(cost_term(m, d, i)?);
    }
    Ok(out)
}

fn parse_options(d: Option<&Bound<'_, PyDict>>) -> PyResult<(DdpOptions, bool)> {
    let mut o = DdpOptions::default();
    let Some(d) = d else { return Ok((o, false)) };
    let ctx = "options";
    for key in d.keys() {
        let k: String = key.extract()?;
        let known = [
            "variant",
            "second_order",
            "max_iter",
            "alphas",
            "best_alpha",
            "accept_ratio",
            "reg_init",
            "reg_min",
            "reg_max",
            "reg_factor",
            "tol_expected",
            "tol_cost",
            "refresh_gains",
        ];
        if !known.contains(&k.as_str()) {
            return Err(input_err(format!("options: unknown key `{k}` (known: {})", known.join(", "))));
        }
    }
    if let Some(v) = get::<String>(d, ctx, "variant")? {
        o.variant = match v.as_str() {
            "ddp" => Variant::Ddp,
            "fddp" => Variant::Fddp,
            other => return Err(input_err(format!("options: key `variant`: expected 'ddp' or 'fddp', got '{other}'"))),
        };
    }
    if let Some(v) = get(d, ctx, "second_order")? {
        o.second_order = v;
    }
    if let Some(v) = get(d, ctx, "max_iter")? {
        o.max_iter = v;
    }
    if let Some(v) = get(d, ctx, "alphas")? {
        o.alphas = v;
    }
    if let Some(v) = get(d, ctx, "best_alpha")? {
        o.best_alpha = v;
    }
    if let Some(v) = get(d, ctx, "accept_ratio")? {
        o.accept_ratio = v;
    }
    let mut reg = RegOptions::default();
    if let Some(v) = get(d, ctx, "reg_init")? {
        reg.init = v;
    }
    if let Some(v) = get(d, ctx, "reg_min")? {
        reg.min = v;
    }
    if let Some(v) = get(d, ctx, "reg_max")? {
        reg.max = v;
    }
    if let Some(v) = get(d, ctx, "reg_factor")? {
        reg.factor = v;
    }
    o.reg = reg;
    if let Some(v) = get(d, ctx, "tol_expected")? {
        o.tol_expected = v;
    }
    if let Some(v) = get(d, ctx, "tol_cost")? {
        o.tol_cost = v;
    }
    let refresh = get(d, ctx, "refresh_gains")?.unwrap_or(false);
    Ok((o, refresh))
}

fn info_dict<'py>(py: Python<'py>, i: &IterInfo) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iter", i.iter)?;
    d.set_item("cost", i.cost)?;
    d.set_item("alpha", i.alpha)?;
    d.set_item("lambda", i.lambda)?;
    d.set_item("expected", i.expected)?;
    d.set_item("reduction", i.reduction)?;
    d.set_item("accepted", i.accepted)?;
    d.set_item("gap", i.gap)?;
    d.set_item("rollouts", i.rollouts)?;
    d.set_item("backward_passes", i.backward_passes)?;
    Ok(d)
}

/// The robot action model of a problem description (shared by `ddp_solve` and `DdpMpc`).
fn build_robot(
    model: &Bound<'_, PyAny>,
    dt: f64,
    horizon: usize,
    running: &Bound<'_, PyList>,
    terminal: &Bound<'_, PyList>,
    keep_out: Option<&Bound<'_, PyList>>,
    rate_joints: Option<Vec<String>>,
) -> PyResult<FloatingRobot> {
    let mb = model_arg(model)?;
    let m: Model = (*mb.get().inner).clone();
    let run_terms = cost_list(&m, running)?;
    let term_terms = cost_list(&m, terminal)?;
    let mut kos = vec![];
    if let Some(l) = keep_out {
        for (i, item) in l.iter().enumerate() {
            let d = item.downcast::<PyDict>().map_err(|_| input_err(format!("keep_out {i}: expected a dict")))?;
            let ctx = format!("keep_out {i}");
            let joint: String = need(d, &ctx, "joint")?;
            let j = m
                .joint_names
                .iter()
                .position(|n| *n == joint)
                .ok_or_else(|| input_err(format!("{ctx}: key `joint`: no joint '{joint}'")))?;
            if m.nvs[j] != 1 {
                return Err(input_err(format!("{ctx}: key `joint`: '{joint}' is not a one-coordinate joint")));
            }
            kos.push(KeepOut {
                iq: m.idx_q[j],
                iv: m.idx_v[j],
                center: need(d, &ctx, "center")?,
                width: need(d, &ctx, "width")?,
                height: need(d, &ctx, "height")?,
            });
        }
    }
    // Rate-driven joints: named, and they must be the model's last ones (a massless tail: the thesis' wrist).
    let k = rate_joints.as_ref().map_or(0, |v| v.len());
    if let Some(names) = &rate_joints {
        let n = m.nbodies();
        if k >= n || m.joint_names[n - k..] != names[..] {
            return Err(input_err(format!(
                "argument `rate_joints`: the rate-driven joints must be the model's last joints, in order (a massless \
                 tail after the base); got {names:?}, the model's joints are {:?}",
                &m.joint_names[1..]
            )));
        }
    }
    let mut robot = guard(|| FloatingRobot::new(m, dt, horizon, run_terms, term_terms, kos))?;
    guard(|| robot.set_rate_driven(k))?;
    Ok(robot)
}

fn check_x0(x0: &[f64], nx: usize) -> PyResult<()> {
    if x0.len() != nx {
        return Err(input_err(format!("argument `x0`: expected {nx} entries (nq + nv), got {}", x0.len())));
    }
    if x0.iter().any(|v| !v.is_finite()) {
        return Err(input_err("argument `x0`: non-finite entries (NaN or inf) in the initial state"));
    }
    Ok(())
}

/// Solve a floating-robot optimal-control problem by DDP (Valverde 2018, ch. 8).
///
/// State `x = [q; v]` (nq + nv), control `u = τ` (nv: base force and torque in the base frame, then joint
/// torques), semi-implicit Euler steps of `dt` over `horizon` nodes. `running` / `terminal`: lists of cost
/// dicts with keys `name`, `kind` ('frame_placement' with `frame` and `reference` (M, 7) [p, quat xyzw];
/// 'frame_dq' with `frame`, `reference` (M, 8) thesis-layout dual quaternions and optional `sign` ('literal',
/// the thesis' q_G − q_D, or 'nearest': q_G − s q_D with s the sign of q_G,r · q_D,r); 'state' with optional
/// `reference` (M, nx); 'control' with optional `reference` (M, nu)), and `weights` (one per residual
/// entry) or `weights_start`/`weights_medium`/`weights_end` + `breakpoints` [i1, i2, i3, i4] (Table 8.2
/// schedule). M is 1 or one per node. Cost = Σ w r² (no ½, no Δt). `keep_out`: dicts with `joint`,
/// `center`, `width`, `height` (rad). `us0`: (horizon, nu); `xs0`: optional (horizon + 1, nx) initial
/// states (feasibility-driven variant). `options`: variant ('ddp'/'fddp'), second_order, max_iter, alphas,
/// best_alpha, accept_ratio, reg_init, reg_min, reg_max, reg_factor, tol_expected, tol_cost.
/// `callback(info: dict)` is called after every iteration; returning False stops (so does Ctrl-C), keeping
/// the best iterate. Returns a dict: xs, us, gains (horizon, nu, ndx), cost, initial_cost, iterations, stop,
/// stop_message, history (list of dicts), gap, timings (seconds and calls of the derivative, backward-pass
/// and rollout blocks). Option `refresh_gains` (default False): recompute the gains at the returned iterate
/// (one more derivative evaluation and backward pass), as closed-loop use of the policy needs.
/// `rate_joints`: names of the model's last joints to drive by their rates (a massless tail, the thesis' wrist of
/// eq. (8.51)): their bodies' inertia is ignored and their controls are joint rates, not torques.
#[pyfunction]
#[pyo3(signature = (model, x0, dt, horizon, running, terminal, us0, keep_out = None, xs0 = None, options = None, callback = None, rate_joints = None))]
#[allow(clippy::too_many_arguments)]
pub fn ddp_solve<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    x0: Vec<f64>,
    dt: f64,
    horizon: usize,
    running: &Bound<'py, PyList>,
    terminal: &Bound<'py, PyList>,
    us0: PyReadonlyArray2<'py, f64>,
    keep_out: Option<&Bound<'py, PyList>>,
    xs0: Option<PyReadonlyArray2<'py, f64>>,
    options: Option<&Bound<'py, PyDict>>,
    callback: Option<Bound<'py, PyAny>>,
    rate_joints: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut robot = build_robot(model, dt, horizon, running, terminal, keep_out, rate_joints)?;
    let (nx, nu) = (robot.nx(), robot.nu());
    check_x0(&x0, nx)?;
    let s = us0.shape();
    if s != [horizon, nu] {
        return Err(input_err(format!("argument `us0`: expected shape ({horizon}, {nu}), got {s:?}")));
    }
    let us_flat: Vec<f64> = us0.as_array().iter().copied().collect();
    let xs_flat: Option<Vec<f64>> = match &xs0 {
        None => None,
        Some(a) => {
            if a.shape() != [horizon + 1, nx] {
                return Err(input_err(format!(
                    "argument `xs0`: expected shape ({}, {nx}), got {:?}",
                    horizon + 1,
                    a.shape()
                )));
            }
            Some(a.as_array().iter().copied().collect())
        }
    };
    let (opts, refresh) = parse_options(options)?;
    let mut solver = guard(|| Solver::new(&robot, opts))?;
    let mut py_err: Option<PyErr> = None;
    let mut interrupted = false;
    let mut cb = |info: &IterInfo| -> bool {
        if let Err(e) = py.check_signals() {
            let _ = e;
            interrupted = true;
            return false;
        }
        if let Some(f) = &callback {
            let r = info_dict(py, info).and_then(|d| f.call1((d,)));
            match r {
                Ok(v) => {
                    if let Ok(false) = v.extract::<bool>() {
                        return false;
                    }
                }
                Err(e) => {
                    if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                        interrupted = true;
                    } else {
                        py_err = Some(e);
                    }
                    return false;
                }
            }
        }
        true
    };
    let sol = guard(|| solver.solve(&mut robot, &x0, &us_flat, xs_flat.as_deref(), &mut cb))?;
    if let Some(e) = py_err {
        return Err(e);
    }
    let out = PyDict::new(py);
    let n = horizon;
    let ndx = 2 * nu;
    let xs = PyArray2::from_vec2(py, &sol.xs).map_err(|e| input_err(e.to_string()))?;
    let us = PyArray2::from_vec2(py, &sol.us).map_err(|e| input_err(e.to_string()))?;
    let mut gains_flat: Vec<f64> = sol.gains.concat();
    if refresh {
        // Gains at the returned iterate (closed-loop use), not at the one before the last step.
        let lambda = sol.history.last().map(|i| i.lambda).filter(|l| l.is_finite()).unwrap_or(0.0);
        if let Some(g) = guard(|| solver.refresh_gains(&mut robot, lambda))? {
            gains_flat = g.concat();
        }
    }
    let gains = PyArray1::from_vec(py, gains_flat).reshape([n, nu, ndx])?;
    out.set_item("xs", xs)?;
    out.set_item("us", us)?;
    out.set_item("gains", gains)?;
    out.set_item("cost", sol.cost)?;
    out.set_item("initial_cost", sol.initial_cost)?;
    out.set_item("iterations", sol.iterations)?;
    let stop = match (&sol.stop, interrupted) {
        (StopReason::Interrupted, true) => "interrupted",
        (StopReason::Interrupted, false) => "stopped_by_callback",
        (StopReason::Converged, _) => "converged",
        (StopReason::CostTolerance, _) => "cost_tolerance",
        (StopReason::MaxIterations, _) => "max_iterations",
        (StopReason::RegularisationLimit, _) => "regularisation_limit",
        (StopReason::Failed(_), _) => "failed",
    };
    out.set_item("stop", stop)?;
    out.set_item("stop_message", sol.stop.describe())?;
    let hist = PyList::empty(py);
    for h in &sol.history {
        hist.append(info_dict(py, h)?)?;
    }
    out.set_item("history", hist)?;
    out.set_item("gap", sol.gap)?;
    let t = PyDict::new(py);
    let tm = sol.timings;
    t.set_item("calc_diff_s", tm.calc_diff_s)?;
    t.set_item("calc_diff_calls", tm.calc_diff_calls)?;
    t.set_item("backward_s", tm.backward_s)?;
    t.set_item("backward_calls", tm.backward_calls)?;
    t.set_item("forward_s", tm.forward_s)?;
    t.set_item("forward_calls", tm.forward_calls)?;
    out.set_item("timings", t)?;
    Ok(out)
}

/// Three-phase screw reference (Valverde 2018, §8.7): hold `start` (8, thesis layout [real w x y z, dual
/// w x y z]) for `t_hold`, then `start · exp(½ θ̂ ŝ)` with `ŝ = axis + ε moment` (start-frame coordinates),
/// `θ = angle·τ/t_move`, `d = advance·τ/t_move` for `t_move` seconds, then hold; sampled at k·dt,
/// k = 0..=n. Returns (n + 1, 8); never properised.
#[pyfunction]
#[pyo3(signature = (start, axis, moment, angle, advance, t_hold, t_move, dt, n))]
#[allow(clippy::too_many_arguments)]
pub fn ddp_screw_reference<'py>(
    py: Python<'py>,
    start: [f64; 8],
    axis: [f64; 3],
    moment: [f64; 3],
    angle: f64,
    advance: f64,
    t_hold: f64,
    t_move: f64,
    dt: f64,
    n: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let s = DualQuat::from_slice(&start);
    let r = guard(|| screw_reference(&s, &V3::from(axis), &V3::from(moment), angle, advance, t_hold, t_move, dt, n))?;
    let rows: Vec<Vec<f64>> = r.iter().map(|q| q.to_array().to_vec()).collect();
    PyArray2::from_vec2(py, &rows).map_err(|e| input_err(e.to_string()))
}

/// The frame's pose as a dual quaternion (thesis layout), composed along the chain so that it is continuous
/// along a trajectory (never properised), for each row of `qs` (M, nq). Returns (M, 8).
#[pyfunction]
pub fn ddp_frame_dual_quats<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    qs: PyReadonlyArray2<'py, f64>,
    frame_name: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mb = model_arg(model)?;
    let pm = mb.get();
    let m = &pm.inner;
    let (body, placement) = frame(m, frame_name)?;
    let q = rows("qs", &qs, m.nq)?;
    let out = pm.with_data(|m, d| -> Result<Vec<Vec<f64>>, FfError> {
        let mut rows = vec![];
        for qi in &q {
            freefloat_core::kinematics::forward_kinematics(m, d, qi)?;
            let o = d.o_mi[body].compose(&placement);
            rows.push(frame_dual_quat(m, qi, body, &placement, &o)?.to_array().to_vec());
        }
        Ok(rows)
    });
    let out = guard(|| out)?;
    PyArray2::from_vec2(py, &out).map_err(|e| input_err(e.to_string()))
}

fn rows3(name: &str, a: &PyReadonlyArray2<f64>, cols: usize, n: usize) -> PyResult<Vec<Vec<f64>>> {
    let r = rows(name, a, cols)?;
    if r.len() != n {
        return Err(input_err(format!("argument `{name}`: expected {n} rows, got {}", r.len())));
    }
    Ok(r)
}

/// The feedback policy of a DDP solution (Valverde 2018, eq. (8.45) with α = 1 on the measured state):
/// `control(k, x)` = `us[k] + gains[k] (x ⊖ xs[k])`, the state error in the tangent space (base twist, joint
/// angles, velocities), as the backward pass linearised it; `feedback=False` gives the open-loop `us[k]`.
/// Nodes past the end use the last one. `xs` (N + 1, nq + nv), `us` (N, nv), `gains` (N, nv, 2 nv).
#[pyclass(name = "DdpPolicy", module = "freefloat._core")]
pub struct PyDdpPolicy {
    robot: FloatingRobot,
    policy: Policy,
    out: Vec<f64>,
}

#[pymethods]
impl PyDdpPolicy {
    #[new]
    fn new(
        model: &Bound<'_, PyAny>,
        xs: PyReadonlyArray2<'_, f64>,
        us: PyReadonlyArray2<'_, f64>,
        gains: numpy::PyReadonlyArray3<'_, f64>,
    ) -> PyResult<Self> {
        let mb = model_arg(model)?;
        let m: Model = (*mb.get().inner).clone();
        let (nx, nu) = (m.nq + m.nv, m.nv);
        let us_r = rows("us", &us, nu)?;
        let n = us_r.len();
        let xs_r = rows3("xs", &xs, nx, n + 1)?;
        let g = gains.as_array();
        if g.shape() != [n, nu, 2 * nu] {
            return Err(input_err(format!(
                "argument `gains`: expected shape ({n}, {nu}, {}), got {:?}",
                2 * nu,
                g.shape()
            )));
        }
        let gains_r: Vec<Vec<f64>> =
            (0..n).map(|k| g.index_axis(numpy::ndarray::Axis(0), k).iter().copied().collect()).collect();
        let robot = guard(|| FloatingRobot::new(m, 1.0, n, vec![], vec![], vec![]))?;
        let policy = guard(|| Policy::new(xs_r, us_r, gains_r, nx, 2 * nu, nu))?;
        Ok(PyDdpPolicy { robot, policy, out: vec![0.0; nu] })
    }

    /// Control (nv,) at node k for the measured state x = [q; v].
    #[pyo3(signature = (k, x, feedback = true))]
    fn control<'py>(
        &mut self,
        py: Python<'py>,
        k: usize,
        x: Vec<f64>,
        feedback: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (robot, policy, out) = (&self.robot, &mut self.policy, &mut self.out);
        guard(|| policy.control(robot, k, &x, feedback, out))?;
        Ok(PyArray1::from_slice(py, out))
    }

    /// Number of nodes N.
    fn __len__(&self) -> usize {
        self.policy.len()
    }
}

/// Receding-horizon DDP (model-predictive control) over a task: the problem description of `ddp_solve`
/// (model, dt, task horizon N, running/terminal costs, keep_out; scheduled weights frozen at their End column).
/// `control(k, x)` re-solves the window of `mpc_horizon` nodes starting at task node k from the measured state
/// every `replan` nodes (warm-started by the previous window shifted in time; the first window by
/// `guess_xs`/`guess_us` over the whole task if given, else zero controls), and in between applies that
/// window's feedback policy. `options` as in `ddp_solve` (per re-plan; `max_iter` is the re-plan budget);
/// `first_max_iter` bounds the first solve. `shrink`: no window reaches past the task's last node (the
/// terminal cost lands on the task's end, a deadline); off, every window has `mpc_horizon` nodes. `stats()`: re-plans, iterations, solve time, slowest re-plan,
/// troubled re-plans, last stop reason, the cost, wall time and iterations of each re-plan (`replan_costs`,
/// `replan_times_s`, `replan_iterations`; the first re-plan included). `rate_joints` as in `ddp_solve`.
#[pyclass(name = "DdpMpc", module = "freefloat._core")]
pub struct PyDdpMpc {
    mpc: Mpc,
    out: Vec<f64>,
}

#[pymethods]
impl PyDdpMpc {
    #[new]
    #[pyo3(signature = (model, dt, horizon, running, terminal, mpc_horizon, replan, keep_out = None, options = None, first_max_iter = 50, guess_xs = None, guess_us = None, shrink = false, rate_joints = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        model: &Bound<'_, PyAny>,
        dt: f64,
        horizon: usize,
        running: &Bound<'_, PyList>,
        terminal: &Bound<'_, PyList>,
        mpc_horizon: usize,
        replan: usize,
        keep_out: Option<&Bound<'_, PyList>>,
        options: Option<&Bound<'_, PyDict>>,
        first_max_iter: usize,
        guess_xs: Option<PyReadonlyArray2<'_, f64>>,
        guess_us: Option<PyReadonlyArray2<'_, f64>>,
        shrink: bool,
        rate_joints: Option<Vec<String>>,
    ) -> PyResult<Self> {
        let robot = build_robot(model, dt, horizon, running, terminal, keep_out, rate_joints)?;
        let (nx, nu) = (robot.nx(), robot.nu());
        let (solver, _) = parse_options(options)?;
        let guess = match (guess_xs, guess_us) {
            (Some(x), Some(u)) => Some((rows3("guess_xs", &x, nx, horizon + 1)?, rows3("guess_us", &u, nu, horizon)?)),
            (None, None) => None,
            _ => return Err(input_err("give both `guess_xs` and `guess_us`, or neither")),
        };
        let opts = MpcOptions { horizon: mpc_horizon, replan, solver, first_max_iter, shrink };
        let mpc = guard(|| Mpc::new(&robot, opts, guess))?;
        Ok(PyDdpMpc { mpc, out: vec![0.0; nu] })
    }

    /// Control (nv,) at task node k for the measured state x = [q; v] (re-plans when due; Ctrl-C is checked
    /// between re-plans by the caller's loop).
    fn control<'py>(&mut self, py: Python<'py>, k: usize, x: Vec<f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (mpc, out) = (&mut self.mpc, &mut self.out);
        guard(|| mpc.control(k, &x, out))?;
        Ok(PyArray1::from_slice(py, out))
    }

    /// Replace the model's inertial parameters P (nbodies, 10), as `Model.parameters()` of the model the
    /// controller was built on: the next re-plan optimises on them (until then the current window's policy
    /// runs). For a controller that follows an online estimate of the plant.
    fn set_parameters(&mut self, params: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let nb = self.mpc.model().nbodies();
        if params.shape() != [nb, 10] {
            return Err(input_err(format!("argument `P`: expected shape ({nb}, 10), got {:?}", params.shape())));
        }
        let flat: Vec<f64> = params.as_array().iter().copied().collect();
        let mpc = &mut self.mpc;
        guard(|| mpc.set_parameters(&flat))
    }

    /// What the controller did so far (dict).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.mpc.stats;
        let d = PyDict::new(py);
        d.set_item("replans", s.replans)?;
        d.set_item("iterations", s.iterations)?;
        d.set_item("solve_time_s", s.solve_time_s)?;
        d.set_item("max_replan_s", s.max_replan_s)?;
        d.set_item("troubled_replans", s.troubled)?;
        d.set_item("last_stop", s.last_stop.clone())?;
        d.set_item("replan_costs", s.costs.clone())?;
        d.set_item("replan_times_s", s.times.clone())?;
        d.set_item("replan_iterations", s.replan_iterations.clone())?;
        d.set_item("model_updates", s.model_updates)?;
        d.set_item("horizon", self.mpc.options().horizon)?;
        d.set_item("replan", self.mpc.options().replan)?;
        Ok(d)
    }
}
