//! `freefloat.Environment`: the orbital environment of `freefloat_core::environment` (central-body gravity and
//! orbit, gravity gradient, J2, constant disturbance) as a Python object handed to `simulate(environment=...)`.
//! Only conversion and validation here.

use crate::errors::{guard, input_err};
use crate::model::PyModel;
use freefloat_core::environment::{self as env, Axes, CentralBody, Disturbance, Elements, Environment, Orbit};
use freefloat_core::spatial::V3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

fn v3(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<V3> {
    let v: Vec<f64> = obj
        .py()
        .import("numpy")?
        .call_method1("asarray", (obj, "float64"))
        .and_then(|a| a.call_method0("ravel"))
        .and_then(|a| a.call_method0("tolist"))
        .and_then(|a| a.extract())
        .map_err(|_| input_err(format!("argument `{name}`: expected 3 numbers")))?;
    if v.len() != 3 {
        return Err(input_err(format!("argument `{name}`: expected 3 numbers, got {}", v.len())));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(input_err(format!("argument `{name}`: entry {i} is {} (must be finite)", v[i])));
    }
    Ok(V3::new(v[0], v[1], v[2]))
}

/// Two float arrays.
type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// A `freefloat.Model` (or its engine model).
fn as_model<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyRef<'py, PyModel>> {
    if let Ok(m) = obj.extract::<PyRef<'py, PyModel>>() {
        return Ok(m);
    }
    obj.getattr("_core")
        .and_then(|c| c.extract::<PyRef<'py, PyModel>>())
        .map_err(|_| input_err("argument `model`: expected a freefloat.Model"))
}

/// The orbital environment of a simulation; every effect is off unless asked for.
///
/// Orbit (of the system's centre of mass at t = 0, about a central body; the Earth by default): give either
/// `altitude` or `semi_major_axis` (m) with `eccentricity`, `inclination`, `raan`, `arg_periapsis` and
/// `true_anomaly` (radians), or an inertial `position` and `velocity` (m, m/s, from the body's centre).
/// `mu` (m³/s²), `radius` (m) and `j2_coefficient` override the Earth's constants. With an orbit the
/// simulator's world frame is a free-falling frame with inertial axes whose origin follows the orbit
/// (starting at the system's centre of mass), so `q` keeps metre-sized positions.
///
/// `gravity_gradient=True` applies the tidal force and gravity-gradient torque to every body; `j2=True` adds
/// J2 to the orbit and its differential part to every body. A constant disturbance wrench
/// (`disturbance_force`, `disturbance_torque`, N and N·m about the centre of mass of body
/// `disturbance_body`, the base by default) is given in `disturbance_axes` "inertial" or "body".
#[pyclass(name = "Environment", module = "freefloat", frozen)]
#[derive(Clone, Copy)]
pub struct PyEnvironment {
    pub inner: Environment,
}

#[pymethods]
impl PyEnvironment {
    #[new]
    #[pyo3(signature = (
        *, altitude = None, semi_major_axis = None, eccentricity = 0.0, inclination = 0.0, raan = 0.0,
        arg_periapsis = 0.0, true_anomaly = 0.0, position = None, velocity = None, mu = None, radius = None,
        j2_coefficient = None, gravity_gradient = false, j2 = false, disturbance_force = None,
        disturbance_torque = None, disturbance_axes = "inertial", disturbance_body = 0
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        altitude: Option<f64>,
        semi_major_axis: Option<f64>,
        eccentricity: f64,
        inclination: f64,
        raan: f64,
        arg_periapsis: f64,
        true_anomaly: f64,
        position: Option<Bound<'_, PyAny>>,
        velocity: Option<Bound<'_, PyAny>>,
        mu: Option<f64>,
        radius: Option<f64>,
        j2_coefficient: Option<f64>,
        gravity_gradient: bool,
        j2: bool,
        disturbance_force: Option<Bound<'_, PyAny>>,
        disturbance_torque: Option<Bound<'_, PyAny>>,
        disturbance_axes: &str,
        disturbance_body: usize,
    ) -> PyResult<Self> {
        let e = CentralBody::EARTH;
        let central = CentralBody {
            mu: mu.unwrap_or(e.mu),
            radius: radius.unwrap_or(e.radius),
            j2: j2_coefficient.unwrap_or(e.j2),
        };
        let orbit = match (altitude, semi_major_axis, &position, &velocity) {
            (None, None, None, None) => {
                if mu.is_some() || radius.is_some() {
                    guard(|| central.check())?;
                }
                None
            }
            (Some(_), Some(_), _, _) => {
                return Err(input_err("give either `altitude` or `semi_major_axis`, not both"));
            }
            (alt, sma, None, None) => {
                guard(|| central.check())?;
                let a = match (alt, sma) {
                    (Some(h), _) => {
                        if h.is_nan() || h <= 0.0 || h.is_infinite() {
                            return Err(input_err(format!(
                                "argument `altitude`: the orbit must be above the central body's surface, got {h} m"
                            )));
                        }
                        // the altitude of periapsis: a(1 − e) = radius + altitude
                        (central.radius + h) / (1.0 - eccentricity.clamp(0.0, 0.999_999))
                    }
                    (None, Some(a)) => a,
                    _ => unreachable!(),
                };
                let el = Elements { a, e: eccentricity, i: inclination, raan, argp: arg_periapsis, nu: true_anomaly };
                Some(guard(|| Orbit::from_elements(central, &el))?)
            }
            (None, None, Some(p), Some(v)) => {
                let (p, v) = (v3(p, "position")?, v3(v, "velocity")?);
                Some(guard(|| Orbit::new(central, p, v))?)
            }
            _ => {
                return Err(input_err(
                    "give the orbit as `altitude` or `semi_major_axis` (with elements), or as both `position` and \
                     `velocity`",
                ))
            }
        };
        let axes = match disturbance_axes {
            "inertial" => Axes::Inertial,
            "body" => Axes::Body,
            other => {
                return Err(input_err(format!(
                    "argument `disturbance_axes`: must be 'inertial' or 'body', got '{other}'"
                )))
            }
        };
        let disturbance = match (disturbance_force, disturbance_torque) {
            (None, None) => None,
            (f, t) => Some(Disturbance {
                body: disturbance_body,
                force: f.map(|f| v3(&f, "disturbance_force")).transpose()?.unwrap_or_else(V3::zeros),
                torque: t.map(|t| v3(&t, "disturbance_torque")).transpose()?.unwrap_or_else(V3::zeros),
                axes,
            }),
        };
        if orbit.is_none() && (gravity_gradient || j2) {
            let what = if j2 { "j2" } else { "gravity_gradient" };
            return Err(input_err(format!(
                "argument `{what}`: needs an orbit (`altitude`, `semi_major_axis`, or `position` and `velocity`)"
            )));
        }
        Ok(PyEnvironment { inner: Environment { orbit, gravity_gradient, j2, disturbance } })
    }

    /// True when nothing acts (the simulation is then exactly the environment-free one).
    #[getter]
    fn is_off(&self) -> bool {
        self.inner.is_off()
    }

    /// Whether the tidal force and gravity-gradient torque act on every body.
    #[getter]
    fn gravity_gradient(&self) -> bool {
        self.inner.gravity_gradient
    }

    /// Whether J2 acts.
    #[getter]
    fn j2(&self) -> bool {
        self.inner.j2
    }

    /// Gravitational parameter μ of the central body (m³/s²), or None without an orbit.
    #[getter]
    fn mu(&self) -> Option<f64> {
        self.inner.orbit.map(|o| o.central.mu)
    }

    /// Orbital period of the t = 0 state (s), or None without an orbit.
    #[getter]
    fn period(&self) -> Option<f64> {
        self.inner.orbit.map(|o| o.period())
    }

    /// The system's centre-of-mass orbit at t = 0 as (position, velocity) (inertial, m and m/s), or None.
    #[getter]
    fn orbit_state<'py>(&self, py: Python<'py>) -> Option<Pair<'py>> {
        self.inner
            .orbit
            .map(|o| (PyArray1::from_slice(py, o.position.as_slice()), PyArray1::from_slice(py, o.velocity.as_slice())))
    }

    /// Inertial state `[position, velocity]` (T, 6) of the simulation frame's origin at `times` for a run
    /// from (q0, v0): add a body's local position to get its inertial one. The same propagation as the run.
    fn reference_orbit<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        q0: PyReadonlyArray1<'py, f64>,
        v0: PyReadonlyArray1<'py, f64>,
        times: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q0, v0, times) = (q0.as_slice()?, v0.as_slice()?, times.as_slice()?);
        let model = as_model(model)?;
        let out = guard(|| env::reference_orbit(&self.inner, &model.inner, q0, v0, times))?;
        Ok(PyArray1::from_vec(py, out).reshape([times.len(), 6])?.into_any())
    }

    /// Total external wrench `[force, moment about the frame origin]` (T, 6), inertial axes, that the
    /// environment applies at the samples (times[k], q[k]) of a run that started at (q0, v0).
    fn external_wrenches<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        q0: PyReadonlyArray1<'py, f64>,
        v0: PyReadonlyArray1<'py, f64>,
        times: PyReadonlyArray1<'py, f64>,
        q: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q0, v0, times) = (q0.as_slice()?, v0.as_slice()?, times.as_slice()?);
        let qs: Vec<f64> = q.as_array().iter().copied().collect();
        let model = as_model(model)?;
        let out = guard(|| env::external_wrenches(&self.inner, &model.inner, q0, v0, times, &qs))?;
        Ok(PyArray1::from_vec(py, out).reshape([times.len(), 6])?.into_any())
    }

    fn __repr__(&self) -> String {
        let e = &self.inner;
        let orbit = match &e.orbit {
            None => "no orbit".to_string(),
            Some(o) => {
                let (a, ecc) = o.size_shape();
                format!("a = {a:.1} m, e = {ecc:.6}, mu = {:e}", o.central.mu)
            }
        };
        format!(
            "Environment({orbit}, gravity_gradient={}, j2={}, disturbance={})",
            if e.gravity_gradient { "True" } else { "False" },
            if e.j2 { "True" } else { "False" },
            if e.disturbance.is_some() { "on" } else { "off" }
        )
    }
}
