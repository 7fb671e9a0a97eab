//! Sensor models and `measure`: a simulated run turned into the telemetry a spacecraft would send down.
//!
//! Each sensor samples the recorded run at its own rate, optionally late by a fixed latency, and adds its
//! errors (one module per sensor, each citing its model). Random numbers come from a seeded ChaCha8
//! stream per sensor, so a seed reproduces a run on every machine.
//!
//! Resampling rule (no interpolation, so that no interpolation error is mixed into the sensor errors):
//! the run's samples must be evenly spaced (a fixed-step run), each sensor's period must be a whole
//! multiple of that spacing and its latency a whole number of spacings (both to 1e-6 of a spacing); a rate
//! above the run's sample rate, or one whose period does not divide into it, is an error naming the
//! sensor's key. Sample j of a sensor is the run's state at t₀ + j·P, stamped t₀ + j·P + latency; stamps
//! past the end of the run are not produced.

mod encoder;
mod fields;
mod force_torque;
mod gyro;
mod navigation;
mod rate_smoother;
mod rng;
mod star_tracker;
mod tachometer;

pub use encoder::EncoderConfig;
pub use force_torque::ForceTorqueConfig;
pub use gyro::{GyroConfig, FLAT_REGION_FACTOR, GAUSS_MARKOV_PEAK};
pub use navigation::{NavQuantity, NavigationConfig};
pub use rate_smoother::{smooth_rates, SmoothedRates};
pub use rng::GaussianRng;
pub use star_tracker::StarTrackerConfig;
pub use tachometer::TachometerConfig;

use crate::error::{FfError, Result};
use crate::model::{JointType, Model};
use fields::{show, Fields};
use serde_norway::Value;

/// Tolerance, in sample spacings, on the evenness of the run and on periods and latencies being whole
/// numbers of spacings.
pub const GRID_TOLERANCE: f64 = 1e-6;

/// One sensor's kind and error parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum SensorKind {
    /// Three-axis rate gyro on the base.
    Gyro(GyroConfig),
    /// Star tracker (base attitude).
    StarTracker(StarTrackerConfig),
    /// Joint encoders.
    Encoder(EncoderConfig),
    /// Joint (wheel) tachometers.
    Tachometer(TachometerConfig),
    /// Base linear velocity or position.
    Navigation(NavigationConfig),
    /// Six-axis force/torque sensor at a joint.
    ForceTorque(ForceTorqueConfig),
}

/// A configured sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// Its name (unique in a sensor set; names its output columns' random stream and error messages).
    pub name: String,
    /// Sample rate [Hz]; None: every sample of the run.
    pub rate: Option<f64>,
    /// Delay between the instant measured and its time stamp [s].
    pub latency: f64,
    /// What it measures and its errors.
    pub kind: SensorKind,
}

/// The recorded run that sensors sample, row-major: `q` is T × nq, `v` and `ddq` T × nv.
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    /// Times [s], evenly spaced.
    pub t: &'a [f64],
    /// Configurations.
    pub q: &'a [f64],
    /// Velocities (base twist in the base frame).
    pub v: &'a [f64],
    /// Accelerations, when recorded (needed by force/torque sensors).
    pub ddq: Option<&'a [f64]>,
    /// Length of one configuration.
    pub nq: usize,
    /// Length of one velocity.
    pub nv: usize,
}

/// One sensor's output: time stamps and named columns (telemetry names: `q.<label>`, `v.<label>`, or
/// `ft.<sensor>.<fx…mz>`).
#[derive(Clone, Debug, PartialEq)]
pub struct Stream {
    /// The sensor's name.
    pub sensor: String,
    /// Column names.
    pub columns: Vec<String>,
    /// Time stamps [s] (the measured instant plus the latency).
    pub t: Vec<f64>,
    /// Values, len(t) × len(columns), row-major.
    pub values: Vec<f64>,
    /// Per-column standard deviation of the white, zero-mean part of the rate errors (gyro, tachometer,
    /// base velocity; empty for other sensors): what identification's errors-in-variables removal needs.
    pub white_sigma: Vec<f64>,
    /// Sample period [s].
    pub period: f64,
}

/// Work of one sensor over one run (internal).
pub(crate) struct SensorRun<'a> {
    pub(crate) m: &'a Model,
    pub(crate) s: &'a Samples<'a>,
    pub(crate) idx: &'a [usize],
    pub(crate) period: f64,
    pub(crate) ctx: String,
    pub(crate) name: String,
    pub(crate) columns: Vec<String>,
    pub(crate) values: Vec<f64>,
    pub(crate) white_sigma: Vec<f64>,
}

/// Read a `sensors:` list (YAML or JSON text: a list of mappings, or a mapping with a `sensors` list).
/// Each entry has `type` (gyro, star_tracker, encoder, tachometer, base_velocity, base_position,
/// force_torque), optional `name` (default: the type), `rate` [Hz], `latency` [s], and its sensor's keys.
/// Unknown keys, negative noise, a non-positive rate, duplicate names: errors naming the key.
pub fn parse_sensors(text: &str) -> Result<Vec<Sensor>> {
    let doc: Value =
        serde_norway::from_str(text).map_err(|e| FfError::arg("sensors", format!("not YAML/JSON: {e}")))?;
    let list = match doc {
        Value::Sequence(s) => s,
        Value::Mapping(mut m) => match m.remove(Value::String("sensors".into())) {
            Some(Value::Sequence(s)) => s,
            Some(other) => {
                return Err(FfError::arg("sensors", format!("expected a list of sensors, got {}", show(&other))))
            }
            None => {
                return Err(FfError::arg("sensors", "expected a list of sensors (or a mapping with a `sensors:` list)"))
            }
        },
        other => return Err(FfError::arg("sensors", format!("expected a list of sensors, got {}", show(&other)))),
    };
    let mut out: Vec<Sensor> = Vec::with_capacity(list.len());
    for (i, item) in list.into_iter().enumerate() {
        let map = match item {
            Value::Mapping(m) => m,
            other => {
                return Err(FfError::arg(&format!("sensors[{i}]"), format!("expected a mapping, got {}", show(&other))))
            }
        };
        let mut f = Fields::new(map, format!("sensors[{i}]"));
        let ty = f.string("type")?.ok_or_else(|| {
            FfError::arg(&format!("sensors[{i}].type"), format!("missing (one of: {})", TYPES.join(", ")))
        })?;
        let name = f.string("name")?.unwrap_or_else(|| ty.clone());
        f.ctx = format!("sensors.{name}");
        let rate = f.positive("rate", "Hz")?;
        let latency = f.nonneg("latency", 0.0, "s")?;
        let kind = match ty.as_str() {
            "gyro" => SensorKind::Gyro(GyroConfig::parse(&mut f)?),
            "star_tracker" => SensorKind::StarTracker(StarTrackerConfig::parse(&mut f)?),
            "encoder" => SensorKind::Encoder(EncoderConfig::parse(&mut f)?),
            "tachometer" => SensorKind::Tachometer(TachometerConfig::parse(&mut f)?),
            "base_velocity" => SensorKind::Navigation(NavigationConfig::parse(&mut f, NavQuantity::Velocity)?),
            "base_position" => SensorKind::Navigation(NavigationConfig::parse(&mut f, NavQuantity::Position)?),
            "force_torque" => SensorKind::ForceTorque(ForceTorqueConfig::parse(&mut f)?),
            other => {
                return Err(FfError::arg(
                    &format!("sensors[{i}].type"),
                    format!("unknown sensor type '{other}' (known: {})", TYPES.join(", ")),
                ))
            }
        };
        f.finish()?;
        if out.iter().any(|s| s.name == name) {
            return Err(FfError::arg(
                &format!("sensors[{i}].name"),
                format!("'{name}' names two sensors (names must be unique)"),
            ));
        }
        out.push(Sensor { name, rate, latency, kind });
    }
    Ok(out)
}

/// The sensor types `parse_sensors` knows.
pub const TYPES: [&str; 7] =
    ["gyro", "star_tracker", "encoder", "tachometer", "base_velocity", "base_position", "force_torque"];

/// Sample the run `s` of model `m` with every sensor (see the module documentation for the resampling
/// rule), each from its own random stream of `seed`. Returns one stream per sensor, in order.
pub fn measure(m: &Model, s: &Samples, sensors: &[Sensor], seed: u64) -> Result<Vec<Stream>> {
    let n = s.t.len();
    if s.nq != m.nq || s.nv != m.nv {
        return Err(FfError::arg(
            "trajectory",
            format!(
                "rows of {} and {} numbers (q, v), model '{}' has nq = {}, nv = {}",
                s.nq, s.nv, m.name, m.nq, m.nv
            ),
        ));
    }
    crate::check::check_len("trajectory.q", s.q.len(), n * m.nq)?;
    crate::check::check_len("trajectory.v", s.v.len(), n * m.nv)?;
    if let Some(a) = s.ddq {
        crate::check::check_len("trajectory.ddq", a.len(), n * m.nv)?;
    }
    crate::check::check_finite("trajectory.t", s.t)?;
    crate::check::check_finite("trajectory.q", s.q)?;
    crate::check::check_finite("trajectory.v", s.v)?;
    if n < 2 {
        return Err(FfError::arg("trajectory", format!("needs at least 2 samples, got {n}")));
    }
    let dt = (s.t[n - 1] - s.t[0]) / (n - 1) as f64;
    if !(dt > 0.0) {
        return Err(FfError::arg("trajectory.t", "times must increase"));
    }
    for k in 1..n {
        let step = s.t[k] - s.t[k - 1];
        if (step - dt).abs() > GRID_TOLERANCE * dt {
            return Err(FfError::arg(
                "trajectory.t",
                format!(
                    "samples must be evenly spaced (a fixed-step run): step {k} is {} s, the mean step {} s",
                    sig(step),
                    sig(dt)
                ),
            ));
        }
    }
    let mut out = Vec::with_capacity(sensors.len());
    for sensor in sensors {
        let ctx = format!("sensors.{}", sensor.name);
        let every = match sensor.rate {
            None => 1usize,
            Some(rate) => {
                if !(rate > 0.0) || !rate.is_finite() {
                    return Err(FfError::arg(
                        &format!("{ctx}.rate"),
                        format!("must be a positive number of Hz, got {rate}"),
                    ));
                }
                let ratio = 1.0 / (rate * dt);
                if ratio < 1.0 - GRID_TOLERANCE {
                    return Err(FfError::arg(
                        &format!("{ctx}.rate"),
                        format!("{rate} Hz is above the run's sample rate {} Hz (record every integration step, or lower the rate)", sig(1.0 / dt)),
                    ));
                }
                let k = ratio.round();
                if (ratio - k).abs() > GRID_TOLERANCE * k {
                    return Err(FfError::arg(
                        &format!("{ctx}.rate"),
                        format!(
                            "{rate} Hz does not divide the run's sample rate {} Hz (period {} s is {ratio:.6} sample spacings; it must be a whole number — no interpolation is done)",
                            sig(1.0 / dt),
                            sig(1.0 / rate)
                        ),
                    ));
                }
                k as usize
            }
        };
        let lat = sensor.latency / dt;
        let lat_steps = lat.round();
        if !(sensor.latency >= 0.0) || (lat - lat_steps).abs() > GRID_TOLERANCE * lat_steps.max(1.0) {
            return Err(FfError::arg(
                &format!("{ctx}.latency"),
                format!(
                    "{} s must be ≥ 0 and a whole number of the run's sample spacing {} s ({lat:.6} spacings)",
                    sensor.latency,
                    sig(dt)
                ),
            ));
        }
        let lat_steps = lat_steps as usize;
        if lat_steps >= n {
            return Err(FfError::arg(
                &format!("{ctx}.latency"),
                format!("{} s is longer than the run", sensor.latency),
            ));
        }
        let idx: Vec<usize> = (0..).map(|j| j * every).take_while(|&k| k + lat_steps < n).collect();
        let stamps: Vec<f64> = idx.iter().map(|&k| s.t[k + lat_steps]).collect();
        let mut run = SensorRun {
            m,
            s,
            idx: &idx,
            period: every as f64 * dt,
            ctx,
            name: sensor.name.clone(),
            columns: Vec::new(),
            values: Vec::with_capacity(idx.len() * 6),
            white_sigma: Vec::new(),
        };
        let mut rng = GaussianRng::new(seed, &sensor.name);
        match &sensor.kind {
            SensorKind::Gyro(c) => c.run(&mut run, &mut rng)?,
            SensorKind::StarTracker(c) => c.run(&mut run, &mut rng)?,
            SensorKind::Encoder(c) => c.run(&mut run, &mut rng)?,
            SensorKind::Tachometer(c) => c.run(&mut run, &mut rng)?,
            SensorKind::Navigation(c) => c.run(&mut run, &mut rng)?,
            SensorKind::ForceTorque(c) => c.run(&mut run, &mut rng)?,
        }
        out.push(Stream {
            sensor: sensor.name.clone(),
            columns: run.columns,
            t: stamps,
            values: run.values,
            white_sigma: run.white_sigma,
            period: run.period,
        });
    }
    Ok(out)
}

/// `x` to 9 significant digits, shortest form (Rust has no `%g`).
fn sig(x: f64) -> String {
    format!("{x:.8e}").parse::<f64>().map(|y| y.to_string()).unwrap_or_else(|_| x.to_string())
}

/// Round `x` to the nearest multiple of `quantum` (0: unchanged).
#[inline]
pub(crate) fn quantise(x: f64, quantum: f64) -> f64 {
    if quantum > 0.0 {
        quantum * (x / quantum).round()
    } else {
        x
    }
}

/// The base's label in telemetry column names (its body name, as `Model.q_labels`).
pub(crate) fn base_label(m: &Model) -> &str {
    &m.body_names[0]
}

/// Base sensors (gyro, star tracker, navigation) need a free-floating base.
pub(crate) fn require_free_base(m: &Model, ctx: &str, what: &str) -> Result<()> {
    if m.joint_types[0] != JointType::Free {
        return Err(FfError::arg(
            &format!("{ctx}.type"),
            format!("{what} measures a free-floating base; model '{}' has a {} base", m.name, m.joint_types[0].name()),
        ));
    }
    Ok(())
}

/// Bodies of the named one-degree-of-freedom joints (None: all of them), or an error naming the key.
pub(crate) fn joint_list(m: &Model, ctx: &str, names: Option<&[String]>) -> Result<Vec<usize>> {
    let one_dof = |i: usize| i > 0 && matches!(m.joint_types[i], JointType::Revolute | JointType::Prismatic);
    match names {
        None => Ok((1..m.nbodies()).filter(|&i| one_dof(i)).collect()),
        Some(names) => names
            .iter()
            .map(|n| {
                let known = || {
                    (1..m.nbodies())
                        .filter(|&i| one_dof(i))
                        .map(|i| m.joint_names[i].as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                match (1..m.nbodies()).find(|&i| &m.joint_names[i] == n) {
                    Some(i) if one_dof(i) => Ok(i),
                    Some(i) => Err(FfError::arg(
                        &format!("{ctx}.joints"),
                        format!(
                            "joint '{n}' is {} (only revolute and prismatic joints have encoders and tachometers here)",
                            m.joint_types[i].name()
                        ),
                    )),
                    None => Err(FfError::arg(
                        &format!("{ctx}.joints"),
                        format!("'{n}' is not a joint of model '{}' (joints: {})", m.name, known()),
                    )),
                }
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests;
