//! MJCF (MuJoCo XML) writing.
//!
//! The writer lives here, beside the URDF writer, because it needs the same engine quantities
//! (centre of mass and inertia about it, `Inertia::com` / `Inertia::i_com`) and formats numbers the
//! same way (`{:?}`: the shortest decimal that reads back to the same f64, so inertias survive the
//! trip at full precision). Reading MJCF is done in Python through MuJoCo's own compiler
//! (`freefloat.io.mujoco`): MJCF's meaning (default classes, angle units, five ways to write an
//! orientation, inertia from geoms, `fusestatic`) is whatever that compiler decides, so the one
//! faithful reader is the compiler itself, not a second copy of its rules.
//!
//! What is written, and why:
//! - the compiler options that keep the file's numbers as they are: `angle="radian"`,
//!   `inertiafromgeom="false"` (inertia from `<inertial>`, never from geoms), `balanceinertia="false"`
//!   (no silent change of an inertia), `fusestatic="false"` (a body on a fixed joint, or the jointless
//!   base of a fixed-base robot, keeps its own body), `boundmass`/`boundinertia` 0;
//! - gravity zero unless asked for (the model's own gravity is then written), RK4 with a 1 ms step;
//! - the base as a body with a `<freejoint>` named like the model's base joint (`root_joint`), or no
//!   joint for a fixed base; each joint as `hinge` (revolute), `slide` (prismatic), `ball`
//!   (spherical), none (fixed), a hinge then a slide on the same axis (cylindrical), two hinges
//!   (universal: MuJoCo rotates the second axis with the first, as freefloat does);
//! - each body's inertial as `pos` (centre of mass) + `fullinertia` (about the centre of mass, body
//!   axes), so MuJoCo diagonalises it itself;
//! - joint limits as `range` with `limited="false"`: kept for reference but not enforced, because the
//!   engine does not enforce them either (an enforced limit would add constraint forces);
//! - a `motor` per 1-DoF joint (gear 1, unlimited), so `ctrl` applies joint torques/forces;
//! - frames as `site`s; body tags as `<custom><text name="freefloat.tags.BODY" data="t1 t2"/>`, read
//!   back by `Model.from_mjcf` so wheels and known bodies survive the round trip (and the names of fixed
//!   joints, which have no MJCF element, as `freefloat.fixed_joint.BODY`).
//!
//! A body MuJoCo would refuse (a moving body with no mass, or an inertia that is not physical: MuJoCo
//! checks positivity and the triangle inequality) is refused here with the body's name.

use super::{check_physical, JointType, Model};
use crate::error::{FfError, Result};
use crate::spatial::{quat_from_rot, Se3, V3};
use std::fmt::Write;

fn fmt3(v: &V3) -> String {
    format!("{:?} {:?} {:?}", v.x, v.y, v.z)
}

/// MuJoCo's quaternion order is (w, x, y, z); the engine's is (x, y, z, w).
fn quat_wxyz(p: &Se3) -> String {
    let q = quat_from_rot(&p.rot);
    format!("{:?} {:?} {:?} {:?}", q[3], q[0], q[1], q[2])
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Write a model as MJCF. `with_gravity`: write the model's gravity (otherwise zero gravity, the
/// orbital case). Planar bases have no single MuJoCo joint and are refused.
pub fn to_mjcf_string(m: &Model, with_gravity: bool) -> Result<String> {
    if m.joint_types[0] == JointType::Planar {
        return Err(FfError::Model(
            "MJCF export supports free and fixed bases; this model's base is planar (load it with base='free')".into(),
        ));
    }
    // MuJoCo refuses non-physical inertia on any body and zero mass on a moving body: say which one.
    for i in 0..m.nbodies() {
        let name = &m.body_names[i];
        let moving = m.joint_types[i] != JointType::Fixed && m.joint_types[i] != JointType::FixedBase;
        if moving && m.inertias[i].mass <= 0.0 {
            return Err(FfError::Model(format!(
                "body '{name}' moves (joint '{}') but has no mass; MuJoCo refuses moving bodies without mass",
                m.joint_names[i]
            )));
        }
        if m.inertias[i].mass > 0.0 {
            check_physical(name, &m.inertias[i]).map_err(|e| {
                FfError::Model(format!(
                    "{e}; MuJoCo refuses such a body (it checks positivity and the triangle inequality). \
                     Export a physically consistent variant of the model (for the Naveen, Shah, Misra robot: \
                     naveen_dual_arm_consistent)"
                ))
            })?;
        }
    }
    let mut children: Vec<Vec<usize>> = vec![vec![]; m.nbodies()];
    for i in 1..m.nbodies() {
        children[m.parents[i].expect("non-base bodies have parents")].push(i);
    }
    let g = if with_gravity { m.gravity } else { V3::zeros() };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<!-- written by freefloat from model '{}'; base joint: {} -->",
        xml_escape(&m.name),
        m.joint_types[0].name()
    );
    let _ = writeln!(s, "<mujoco model=\"{}\">", xml_escape(&m.name));
    let _ = writeln!(
        s,
        "  <compiler angle=\"radian\" inertiafromgeom=\"false\" balanceinertia=\"false\" fusestatic=\"false\" \
         boundmass=\"0\" boundinertia=\"0\" autolimits=\"false\"/>"
    );
    let _ = writeln!(s, "  <option gravity=\"{}\" integrator=\"RK4\" timestep=\"0.001\"/>", fmt3(&g));
    let _ = writeln!(s, "  <worldbody>");
    write_body(&mut s, m, &children, 0, 2);
    let _ = writeln!(s, "  </worldbody>");
    let motors: Vec<usize> =
        (1..m.nbodies()).filter(|&i| matches!(m.joint_types[i], JointType::Revolute | JointType::Prismatic)).collect();
    if !motors.is_empty() {
        let _ = writeln!(s, "  <actuator>");
        for i in motors {
            let j = xml_escape(&m.joint_names[i]);
            let _ = writeln!(s, "    <motor name=\"{j}\" joint=\"{j}\" gear=\"1\" ctrllimited=\"false\"/>");
        }
        let _ = writeln!(s, "  </actuator>");
    }
    let tagged: Vec<usize> = (0..m.nbodies()).filter(|&i| !m.tags[i].is_empty()).collect();
    // A fixed joint has no MJCF element: its name travels in a custom text like the tags.
    let fixed: Vec<usize> = (1..m.nbodies()).filter(|&i| m.joint_types[i] == JointType::Fixed).collect();
    if !tagged.is_empty() || !fixed.is_empty() {
        let _ = writeln!(s, "  <custom>");
        for &i in &fixed {
            let _ = writeln!(
                s,
                "    <text name=\"freefloat.fixed_joint.{}\" data=\"{}\"/>",
                xml_escape(&m.body_names[i]),
                xml_escape(&m.joint_names[i])
            );
        }
        for i in tagged {
            let _ = writeln!(
                s,
                "    <text name=\"freefloat.tags.{}\" data=\"{}\"/>",
                xml_escape(&m.body_names[i]),
                xml_escape(&m.tags[i].join(" "))
            );
        }
        let _ = writeln!(s, "  </custom>");
    }
    let _ = writeln!(s, "</mujoco>");
    Ok(s)
}

fn write_body(s: &mut String, m: &Model, children: &[Vec<usize>], i: usize, depth: usize) {
    let ind = "  ".repeat(depth);
    let p = &m.placements[i];
    let name = xml_escape(&m.body_names[i]);
    if i == 0 && m.joint_types[0] == JointType::Free {
        // The free joint's own coordinates place the base: the body sits at the origin at qpos0.
        let _ = writeln!(s, "{ind}<body name=\"{name}\">");
    } else {
        let _ = writeln!(s, "{ind}<body name=\"{name}\" pos=\"{}\" quat=\"{}\">", fmt3(&p.trans), quat_wxyz(p));
    }
    let jn = xml_escape(&m.joint_names[i]);
    let l = &m.limits[i];
    let range = match (l.lower, l.upper) {
        (Some(a), Some(b)) => format!(" range=\"{a:?} {b:?}\" limited=\"false\""),
        _ => String::new(),
    };
    let ax = fmt3(&m.axes[i]);
    match m.joint_types[i] {
        JointType::Free => {
            let _ = writeln!(s, "{ind}  <freejoint name=\"{jn}\"/>");
        }
        JointType::Revolute => {
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}\" type=\"hinge\" axis=\"{ax}\"{range}/>");
        }
        JointType::Prismatic => {
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}\" type=\"slide\" axis=\"{ax}\"{range}/>");
        }
        JointType::Spherical => {
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}\" type=\"ball\"/>");
        }
        JointType::Cylindrical => {
            // q = [θ, d]: MuJoCo orders a body's coordinates by its joints, hinge first.
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}.theta\" type=\"hinge\" axis=\"{ax}\"/>");
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}.d\" type=\"slide\" axis=\"{ax}\"/>");
        }
        JointType::Universal => {
            // MuJoCo applies a body's joints in order and carries the second axis with the first
            // rotation: R = R(a1, θ1) R(a2, θ2), the engine's universal joint.
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}.theta1\" type=\"hinge\" axis=\"{ax}\"/>");
            let _ = writeln!(s, "{ind}  <joint name=\"{jn}.theta2\" type=\"hinge\" axis=\"{}\"/>", fmt3(&m.axes2[i]));
        }
        JointType::Fixed | JointType::FixedBase | JointType::Planar => {}
    }
    let inr = &m.inertias[i];
    if inr.mass > 0.0 {
        let ic = inr.i_com();
        let _ = writeln!(
            s,
            "{ind}  <inertial pos=\"{}\" mass=\"{:?}\" fullinertia=\"{:?} {:?} {:?} {:?} {:?} {:?}\"/>",
            fmt3(&inr.com()),
            inr.mass,
            ic[(0, 0)],
            ic[(1, 1)],
            ic[(2, 2)],
            ic[(0, 1)],
            ic[(0, 2)],
            ic[(1, 2)]
        );
    }
    for f in m.frames.iter().filter(|f| f.body == i) {
        let _ = writeln!(
            s,
            "{ind}  <site name=\"{}\" pos=\"{}\" quat=\"{}\"/>",
            xml_escape(&f.name),
            fmt3(&f.placement.trans),
            quat_wxyz(&f.placement)
        );
    }
    for &c in &children[i] {
        write_body(s, m, children, c, depth + 1);
    }
    let _ = writeln!(s, "{ind}</body>");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::builtin;

    #[test]
    fn writes_free_joint_full_precision_and_refuses_nonphysical_bodies() {
        let m = builtin::load("naveen_dual_arm_consistent").unwrap();
        let s = to_mjcf_string(&m, false).unwrap();
        assert!(s.contains("<freejoint name=\"root_joint\"/>"));
        assert!(s.contains("fusestatic=\"false\"") && s.contains("gravity=\"0.0 0.0 0.0\""));
        // the shortest round-trip decimal of each mass: parsing it back gives the same f64
        for i in 0..m.nbodies() {
            assert!(s.contains(&format!("mass=\"{:?}\"", m.inertias[i].mass)));
        }
        let bad = builtin::load("naveen_dual_arm").unwrap();
        let e = to_mjcf_string(&bad, false).unwrap_err().to_string();
        assert!(e.contains("'L1'") && e.contains("MuJoCo refuses"), "{e}");
    }
}
