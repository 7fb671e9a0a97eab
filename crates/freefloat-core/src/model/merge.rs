//! Smaller models with the same dynamics: welded leaves merged into their parents, for algorithms that take only
//! moving joints (the DDP robot model of Valverde 2018 ch. 8, say), and a model cut to its leading bodies (a
//! massless tail, such as that model's rate-driven wrist, dropped).

use super::{Frame, JointType, Model};
use crate::error::{FfError, Result};

impl Model {
    /// A copy in which every leaf body on a fixed joint (a grasped target, a tool) is merged into its parent: its
    /// inertia is expressed in the parent frame and added to the parent's (Featherstone, RBDA eq. 2.63, the
    /// composite of two bodies), and a frame with the leaf's name keeps its place (frames on the leaf move to the
    /// parent with it). The joint-space dynamics are the same to round-off: a welded leaf only adds inertia to its
    /// parent. A leaf that carries its own leaf is not merged (only leaves, one level). A new layout identity: a
    /// `Data` of this model is not one of the merged one.
    pub fn with_fixed_leaves_merged(&self) -> Result<Model> {
        let n = self.nbodies();
        let merged: Vec<bool> =
            (0..n).map(|i| i > 0 && self.joint_types[i] == JointType::Fixed && self.children[i].is_empty()).collect();
        if !merged.iter().any(|&x| x) {
            return Ok(self.clone());
        }
        let mut m = self.clone();
        let new_index = kept_index(&merged);
        let mut inertias = self.inertias.clone();
        let mut frames: Vec<Frame> = Vec::new();
        for i in (0..n).filter(|&i| merged[i]) {
            let p = self.parents[i].ok_or_else(|| FfError::Model("a merged body must have a parent".into()))?;
            inertias[p] = inertias[p].add(&self.inertias[i].transformed(&self.placements[i]));
            frames.push(Frame { name: self.body_names[i].clone(), body: new_index[p], placement: self.placements[i] });
        }
        for f in &self.frames {
            if merged[f.body] {
                let p = self.parents[f.body].unwrap_or(0);
                let placement = self.placements[f.body].compose(&f.placement);
                frames.push(Frame { name: f.name.clone(), body: new_index[p], placement });
            } else {
                frames.push(Frame { name: f.name.clone(), body: new_index[f.body], placement: f.placement });
            }
        }
        m.inertias = inertias;
        m.drop_bodies(&merged);
        m.frames = frames;
        m.finalize()?;
        m.id = super::next_model_id();
        Ok(m)
    }

    /// The model of its first `n` bodies: the last `nbodies − n` bodies (a subtree closed under descendants, since
    /// every parent precedes its children) and the frames on them are dropped, the rest keeps its layout (q and v
    /// of the kept joints are the leading entries of the full model's). The dynamics of the rest equal the full
    /// model's when the dropped bodies are massless: what the DDP robot of Valverde 2018 ch. 8 needs for its
    /// massless wrist driven by Euler-angle rates (§8.4, eq. (8.51)). A new layout identity.
    pub fn leading_bodies(&self, n: usize) -> Result<Model> {
        if n == 0 || n > self.nbodies() {
            return Err(FfError::arg("n", format!("keep between 1 and {} bodies, got {n}", self.nbodies())));
        }
        if n == self.nbodies() {
            return Ok(self.clone());
        }
        let mut m = self.clone();
        m.drop_bodies(&(0..self.nbodies()).map(|i| i >= n).collect::<Vec<_>>());
        m.frames.retain(|f| f.body < n);
        m.finalize()?;
        m.id = super::next_model_id();
        Ok(m)
    }

    /// Remove the bodies with `drop[i]` from every per-body list and renumber the parents of the rest (which must
    /// not be dropped bodies: callers drop leaves or whole tails). The frames and the derived layout are the
    /// caller's to redo (`finalize`).
    fn drop_bodies(&mut self, drop: &[bool]) {
        let new_index = kept_index(drop);
        macro_rules! keep_all {
            ($($f:ident),*) => { $( {
                let mut j = 0;
                self.$f.retain(|_| {
                    j += 1;
                    !drop[j - 1]
                });
            } )* };
        }
        keep_all!(
            body_names,
            joint_names,
            parents,
            joint_types,
            axes,
            axes2,
            placements,
            inertias,
            limits,
            tags,
            allow_nonphysical
        );
        for p in self.parents.iter_mut() {
            *p = p.map(|x| new_index[x]);
        }
    }
}

/// The new index of each body once the ones with `drop[i]` are removed (`usize::MAX` for those).
fn kept_index(drop: &[bool]) -> Vec<usize> {
    let mut out = vec![usize::MAX; drop.len()];
    let mut k = 0;
    for (i, &d) in drop.iter().enumerate() {
        if !d {
            out[i] = k;
            k += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::data::Data;
    use crate::dynamics::{aba, crba};
    use crate::kinematics::{forward_kinematics, momentum};
    use crate::model::builtin;

    #[test]
    fn merged_model_has_the_same_dynamics_and_keeps_the_frame() {
        let m = builtin::load("zhang2020_3d").unwrap();
        let mm = m.with_fixed_leaves_merged().unwrap();
        assert_eq!(mm.nbodies(), m.nbodies() - 1);
        assert_eq!((mm.nq, mm.nv), (m.nq, m.nv));
        let mut q = m.neutral();
        q[7..13].copy_from_slice(&[0.3, -0.5, 1.0, 0.3, 0.7, -0.2]);
        let v: Vec<f64> = (0..m.nv).map(|k| 0.05 * (k as f64 - 4.0)).collect();
        let tau: Vec<f64> = (0..m.nv).map(|k| 0.7 * (k as f64).sin()).collect();
        let (mut d, mut dm) = (Data::new(&m), Data::new(&mm));
        crba(&m, &mut d, &q).unwrap();
        crba(&mm, &mut dm, &q).unwrap();
        let scale = d.mass_matrix.abs().max();
        assert!((&d.mass_matrix - &dm.mass_matrix).abs().max() < 1e-12 * scale);
        aba(&m, &mut d, &q, &v, &tau, None).unwrap();
        aba(&mm, &mut dm, &q, &v, &tau, None).unwrap();
        for (x, y) in d.ddq.iter().zip(&dm.ddq) {
            assert!((x - y).abs() < 1e-10 * (1.0 + x.abs()), "{x} vs {y}");
        }
        let (h, hm) = (momentum(&m, &mut d, &q, &v).unwrap(), momentum(&mm, &mut dm, &q, &v).unwrap());
        assert!((h.lin - hm.lin).norm() + (h.ang - hm.ang).norm() < 1e-10);
        // the target's frame is where the target body was
        forward_kinematics(&m, &mut d, &q).unwrap();
        forward_kinematics(&mm, &mut dm, &q).unwrap();
        let t = m.body_index("target").unwrap();
        let (fb, fp) = mm.frame_or_body("target").unwrap();
        let placed = dm.o_mi[fb].compose(&fp);
        assert!((placed.trans - d.o_mi[t].trans).norm() < 1e-12);
        assert!((placed.rot - d.o_mi[t].rot).abs().max() < 1e-12);
    }

    #[test]
    fn leading_bodies_have_the_dynamics_of_the_full_model_with_a_vanishing_tail() {
        // the ch. 8 arm with its wrist made nearly massless (1e-9 kg): the base and arm accelerate as the model of
        // the leading bodies says, whatever the wrist does
        let m = builtin::load("valverde_ch8_arm").unwrap();
        let mut p = m.parameters();
        for row in p.iter_mut().skip(4) {
            for x in row.iter_mut() {
                *x *= 1e-8;
            }
        }
        let light = m.with_parameters(&p.concat()).unwrap();
        let lead = m.leading_bodies(4).unwrap();
        assert_eq!((lead.nbodies(), lead.nq, lead.nv), (4, m.nq - 3, m.nv - 3));
        assert!(lead.frame_or_body("ee").is_err(), "the frame on a dropped body goes with it");
        let mut q = m.neutral();
        for (k, x) in q.iter_mut().enumerate().skip(7) {
            *x = 0.4 * (k as f64).sin();
        }
        let v: Vec<f64> = (0..m.nv).map(|k| 0.1 * (k as f64 - 5.0)).collect();
        let mut tau: Vec<f64> = (0..m.nv).map(|k| 0.7 * (k as f64).cos()).collect();
        tau[m.nv - 3..].fill(0.0);
        let (mut d, mut dl) = (Data::new(&light), Data::new(&lead));
        aba(&light, &mut d, &q, &v, &tau, None).unwrap();
        aba(&lead, &mut dl, &q[..lead.nq], &v[..lead.nv], &tau[..lead.nv], None).unwrap();
        for i in 0..lead.nv {
            assert!(
                (d.ddq[i] - dl.ddq[i]).abs() < 1e-6 * (1.0 + dl.ddq[i].abs()),
                "dof {i}: {} vs {}",
                d.ddq[i],
                dl.ddq[i]
            );
        }
        assert!(m.leading_bodies(0).is_err() && m.leading_bodies(8).is_err());
    }
}
