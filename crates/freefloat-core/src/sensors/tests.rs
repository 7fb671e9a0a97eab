use super::*;
use crate::model::builtin;

fn still(m: &Model, n: usize, dt: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let mut q = vec![0.0; n * m.nq];
    for k in 0..n {
        q[k * m.nq + 6] = 1.0;
    }
    (t, q, vec![0.0; n * m.nv])
}

fn model() -> Model {
    builtin::load(builtin::names()[0]).unwrap()
}

#[test]
fn bad_inputs_name_the_key() {
    let err = |y: &str| parse_sensors(y).unwrap_err().to_string();
    assert!(err("- {type: gyro, noise_density: -1}").contains("sensors.gyro.noise_density"));
    assert!(err("- {type: gyro, rate: 0}").contains("sensors.gyro.rate"));
    assert!(err("- {type: gyro, rate: -5}").contains("sensors.gyro.rate"));
    assert!(err("- {type: gyro, noise_densty: 1}").contains("sensors.gyro.noise_densty"));
    assert!(err("- {type: sonar}").contains("sensors[0].type"));
    assert!(err("- {type: gyro}\n- {type: gyro}").contains("sensors[1].name"));
    let m = model();
    let (t, q, v) = still(&m, 11, 0.1);
    let s = Samples { t: &t, q: &q, v: &v, ddq: None, nq: m.nq, nv: m.nv };
    let e = |y: &str| measure(&m, &s, &parse_sensors(y).unwrap(), 0).unwrap_err().to_string();
    assert!(e("- {type: gyro, rate: 20}").contains("above the run's sample rate"), "{}", e("- {type: gyro, rate: 20}"));
    assert!(e("- {type: gyro, rate: 3}").contains("does not divide"));
    assert!(e("- {type: gyro, latency: 0.05}").contains("sensors.gyro.latency"));
    assert!(e("- {type: encoder, joints: [nope]}").contains("sensors.encoder.joints"));
    assert!(e("- {type: force_torque, joint: nope}").contains("sensors.force_torque.joint"));
}

#[test]
fn latency_shifts_by_exactly_the_delay() {
    let m = model();
    let n = 101;
    let dt = 0.01;
    let (t, q, mut v) = still(&m, n, dt);
    for k in 0..n {
        for j in 0..m.nv {
            v[k * m.nv + j] = (k as f64 * 0.37 + j as f64).sin();
        }
    }
    let s = Samples { t: &t, q: &q, v: &v, ddq: None, nq: m.nq, nv: m.nv };
    let sens = parse_sensors("- {type: gyro, rate: 20, latency: 0.03}").unwrap();
    let out = &measure(&m, &s, &sens, 1).unwrap()[0];
    assert_eq!(out.period, 0.05);
    for (j, stamp) in out.t.iter().enumerate() {
        let k_true = j * 5;
        assert!((stamp - t[k_true] - 0.03).abs() < 1e-12);
        for a in 0..3 {
            assert_eq!(out.values[j * 3 + a], v[k_true * m.nv + 3 + a]);
        }
    }
    assert_eq!(out.t.len(), 20); // stamps 0.03 … 0.98; 1.03 would be past the end
}
