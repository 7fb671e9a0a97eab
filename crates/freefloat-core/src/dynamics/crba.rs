use crate::data::Data;
use crate::kinematics::{composite_inertias, forward_kinematics};
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// Joint-space inertia matrix by the composite-rigid-body algorithm, into `d.mass_matrix` (full,
/// symmetric). Column block i is `Sⱼᵀ ʲX*ᵢ Icᵢ Sᵢ` for i and every ancestor j of i.
pub fn crba(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics(m, d, q);
    composite_inertias(m, d);
    d.mass_matrix.fill(0.0);
    let mut f = [Force::ZERO; 6];
    for i in 0..m.nbodies() {
        let ni = m.nvs[i];
        if ni == 0 {
            continue;
        }
        for (c, fc) in f.iter_mut().enumerate().take(ni) {
            *fc = d.ic[i].mul_motion(&Motion::from_v6(&m.subspaces[i].column(c).into_owned()));
        }
        let ci = m.idx_v[i];
        let mut j = i;
        loop {
            let sj = &m.subspaces[j];
            let cj = m.idx_v[j];
            for c in 0..ni {
                let f6 = f[c].to_v6();
                for r in 0..m.nvs[j] {
                    let x = sj.column(r).dot(&f6);
                    d.mass_matrix[(cj + r, ci + c)] = x;
                    d.mass_matrix[(ci + c, cj + r)] = x;
                }
            }
            let Some(p) = m.parents[j] else { break };
            for fc in f.iter_mut().take(ni) {
                *fc = d.li_mi[j].act_force(fc);
            }
            j = p;
        }
    }
}
