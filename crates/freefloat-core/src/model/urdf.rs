//! URDF reading and writing.
//!
//! Reading: the root link becomes the base (its joint to the inertial frame is chosen by the caller:
//! free, planar or fixed); joints are taken depth-first, children in document order. Massive links
//! on fixed joints stay separate bodies (a grasped target must keep its own parameters); a massless
//! leaf link on a fixed joint (tool points, sensor frames) becomes a `Frame`.
//!
//! Body tags (wheel, known, target, ...) are written as `<freefloat tags="..."/>` inside each link and read
//! back, so a URDF written by freefloat (e.g. `identified.urdf`) feeds every command again with its known
//! bodies; other URDF tools skip the element.

use super::{BodySpec, JointLimits, JointType, Model, ModelBuilder};
use crate::error::{FfError, Result};
use crate::spatial::{rot_to_rpy, rpy_to_rot, Inertia, Se3, M3, V3};
use std::collections::HashMap;
use std::fmt::Write;

struct LinkInfo<'a> {
    node: roxmltree::Node<'a, 'a>,
    inertia: Inertia,
    tags: Vec<String>,
}

/// freefloat's body tags (wheel, known, ...) in a link: `<freefloat tags="wheel known"/>`. Other URDF readers
/// ignore an element they do not know, so the file stays a plain URDF for them.
fn link_tags(link: roxmltree::Node) -> Vec<String> {
    link.children()
        .filter(|n| n.is_element() && n.tag_name().name() == "freefloat")
        .filter_map(|n| n.attribute("tags"))
        .flat_map(|t| t.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .collect()
}

struct JointInfo<'a> {
    node: roxmltree::Node<'a, 'a>,
    name: String,
    kind: JointType,
    parent: String,
    child: String,
    placement: Se3,
    axis: V3,
    limits: JointLimits,
}

/// `allow_nonphysical` exempts every link from the physical-consistency check (many published URDFs
/// carry dummy links with degenerate inertia); finite values and mass ≥ 0 are still required.
pub fn from_urdf_str(text: &str, source_name: &str, base: JointType, allow_nonphysical: bool) -> Result<Model> {
    let doc = roxmltree::Document::parse(text).map_err(|e| FfError::ModelFile {
        source_name: source_name.to_string(),
        line: Some(e.pos().row as usize),
        msg: format!("not well-formed XML: {e}"),
    })?;
    let err = |node: roxmltree::Node, msg: String| FfError::ModelFile {
        source_name: source_name.to_string(),
        line: Some(doc.text_pos_at(node.range().start).row as usize),
        msg,
    };
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(err(robot, format!("root element is <{}>, expected <robot>", robot.tag_name().name())));
    }
    let robot_name = robot.attribute("name").unwrap_or("robot");

    let mut links: HashMap<String, LinkInfo> = HashMap::new();
    let mut link_order: Vec<String> = vec![];
    let mut joints: Vec<JointInfo> = vec![];
    for node in robot.children().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "link" => {
                let name = attr(node, "name").map_err(|m| err(node, m))?;
                let inertia = link_inertia(node).map_err(|(n, m)| err(n, format!("link '{name}': {m}")))?;
                let tags = link_tags(node);
                if links.insert(name.to_string(), LinkInfo { node, inertia, tags }).is_some() {
                    return Err(err(node, format!("link '{name}' is defined twice")));
                }
                link_order.push(name.to_string());
            }
            "joint" => joints.push(parse_joint(node).map_err(|(n, m)| err(n, m))?),
            _ => {} // materials, transmissions, gazebo tags: not dynamics
        }
    }
    // Topology: every joint's links must exist; every link has at most one parent joint.
    let mut parent_of: HashMap<&str, usize> = HashMap::new();
    for (k, j) in joints.iter().enumerate() {
        for l in [&j.parent, &j.child] {
            if !links.contains_key(l) {
                return Err(err(j.node, format!("joint '{}' refers to link '{l}', which is not defined", j.name)));
            }
        }
        if parent_of.insert(j.child.as_str(), k).is_some() {
            return Err(err(j.node, format!("link '{}' is the child of two joints", j.child)));
        }
    }
    let roots: Vec<&String> = link_order.iter().filter(|l| !parent_of.contains_key(l.as_str())).collect();
    if roots.len() != 1 {
        return Err(FfError::ModelFile {
            source_name: source_name.to_string(),
            line: None,
            msg: format!(
                "expected exactly one root link (a link that is no joint's child), found {}: {:?}",
                roots.len(),
                roots
            ),
        });
    }
    let root = roots[0].clone();
    let root_info = &links[&root];
    let mut b = ModelBuilder::new(robot_name, &root, base, root_info.inertia)?;
    b.set_base_allow_nonphysical(allow_nonphysical);
    b.set_base_tags(root_info.tags.clone());

    // Depth-first, children in document order.
    let mut stack: Vec<(usize, usize)> = vec![]; // (joint index, parent body index)
    let push_children = |link: &str, body: usize, stack: &mut Vec<(usize, usize)>| {
        let kids: Vec<usize> = (0..joints.len()).filter(|&k| joints[k].parent == link).collect();
        for &k in kids.iter().rev() {
            stack.push((k, body));
        }
    };
    push_children(&root, 0, &mut stack);
    let mut visited = 1usize;
    // Placement of each link's frame in the body it is carried by (for links that became frames).
    while let Some((k, parent_body)) = stack.pop() {
        let j = &joints[k];
        let child = &links[&j.child];
        visited += 1;
        let is_leaf = !joints.iter().any(|o| o.parent == j.child);
        if j.kind == JointType::Fixed && child.inertia.mass == 0.0 && is_leaf {
            b.add_frame(&j.child, parent_body, j.placement).map_err(|e| err(j.node, e.to_string()))?;
            continue;
        }
        let spec = BodySpec {
            name: j.child.clone(),
            parent: parent_body,
            joint_name: j.name.clone(),
            joint_type: j.kind,
            axis: j.axis,
            axis2: V3::z(), // URDF has no universal joint
            placement: j.placement,
            inertia: child.inertia,
            limits: j.limits,
            tags: child.tags.clone(),
            allow_nonphysical,
        };
        let idx = b.add_body(spec).map_err(|e| err(j.node, e.to_string()))?;
        push_children(&j.child, idx, &mut stack);
    }
    if visited != links.len() {
        return Err(FfError::ModelFile {
            source_name: source_name.to_string(),
            line: None,
            msg: format!(
                "{} link(s) are not connected to the root '{root}' (the joint graph has a cycle)",
                links.len() - visited
            ),
        });
    }
    b.build().map_err(|e| match e {
        FfError::Inertia { ref body, .. } => {
            err(links[body].node, format!("{e} (to load a file with such links anyway, pass allow_nonphysical=True)"))
        }
        other => FfError::ModelFile { source_name: source_name.to_string(), line: None, msg: other.to_string() },
    })
}

type NodeErr<'a> = (roxmltree::Node<'a, 'a>, String);

fn attr<'a>(node: roxmltree::Node<'a, 'a>, name: &str) -> std::result::Result<&'a str, String> {
    node.attribute(name).ok_or_else(|| format!("<{}> has no '{name}' attribute", node.tag_name().name()))
}

fn child<'a>(node: roxmltree::Node<'a, 'a>, tag: &str) -> Option<roxmltree::Node<'a, 'a>> {
    node.children().find(|n| n.is_element() && n.tag_name().name() == tag)
}

fn numbers<'a>(node: roxmltree::Node<'a, 'a>, name: &str, default: [f64; 3]) -> std::result::Result<V3, NodeErr<'a>> {
    let Some(s) = node.attribute(name) else { return Ok(V3::from(default)) };
    let vals: std::result::Result<Vec<f64>, _> = s.split_whitespace().map(str::parse::<f64>).collect();
    match vals {
        Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => Ok(V3::new(v[0], v[1], v[2])),
        _ => Err((node, format!("attribute {name}=\"{s}\" must be three finite numbers"))),
    }
}

fn number<'a>(node: roxmltree::Node<'a, 'a>, name: &str) -> std::result::Result<Option<f64>, NodeErr<'a>> {
    match node.attribute(name) {
        None => Ok(None),
        Some(s) => match s.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => {
                Err((node, format!("attribute {name}=\"{s}\" of <{}> is not a finite number", node.tag_name().name())))
            }
        },
    }
}

fn origin<'a>(node: roxmltree::Node<'a, 'a>) -> std::result::Result<Se3, NodeErr<'a>> {
    match child(node, "origin") {
        None => Ok(Se3::identity()),
        Some(o) => Ok(Se3::new(rpy_to_rot(&numbers(o, "rpy", [0.0; 3])?), numbers(o, "xyz", [0.0; 3])?)),
    }
}

fn link_inertia<'a>(link: roxmltree::Node<'a, 'a>) -> std::result::Result<Inertia, NodeErr<'a>> {
    let Some(inertial) = child(link, "inertial") else { return Ok(Inertia::zero()) };
    let frame = origin(inertial)?;
    let mass_node = child(inertial, "mass").ok_or((inertial, "<inertial> has no <mass>".to_string()))?;
    let mass = number(mass_node, "value")?.ok_or((mass_node, "<mass> has no value".to_string()))?;
    let i = match child(inertial, "inertia") {
        None => M3::zeros(),
        Some(n) => {
            let g = |k: &str| number(n, k).map(|x| x.unwrap_or(0.0));
            let (xx, xy, xz, yy, yz, zz) = (g("ixx")?, g("ixy")?, g("ixz")?, g("iyy")?, g("iyz")?, g("izz")?);
            M3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
        }
    };
    // URDF gives the inertia about the CoM in the <inertial><origin> axes; rotate it to link axes.
    let ic = frame.rot * i * frame.rot.transpose();
    Ok(Inertia::from_com(mass, frame.trans, ic))
}

fn parse_joint<'a>(node: roxmltree::Node<'a, 'a>) -> std::result::Result<JointInfo<'a>, NodeErr<'a>> {
    let name = attr(node, "name").map_err(|m| (node, m))?.to_string();
    let t = attr(node, "type").map_err(|m| (node, m))?;
    let kind = match t {
        "revolute" | "continuous" => JointType::Revolute,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "floating" | "planar" => {
            return Err((
                node,
                format!("joint '{name}': type '{t}' is only supported for the base (choose it with base=...)"),
            ))
        }
        other => return Err((node, format!("joint '{name}': unknown joint type '{other}'"))),
    };
    let link_ref = |tag: &str| -> std::result::Result<String, NodeErr<'a>> {
        let n = child(node, tag).ok_or((node, format!("joint '{name}' has no <{tag}>")))?;
        Ok(attr(n, "link").map_err(|m| (n, m))?.to_string())
    };
    let axis = match child(node, "axis") {
        Some(a) => numbers(a, "xyz", [1.0, 0.0, 0.0])?,
        None => V3::x(), // URDF default
    };
    if matches!(kind, JointType::Revolute | JointType::Prismatic) && !(axis.norm() > 1e-12) {
        return Err((node, format!("joint '{name}': axis has zero length")));
    }
    let mut limits = JointLimits::default();
    if let Some(l) = child(node, "limit") {
        limits.lower = number(l, "lower")?;
        limits.upper = number(l, "upper")?;
        limits.velocity = number(l, "velocity")?;
        limits.effort = number(l, "effort")?;
        if t == "continuous" {
            limits.lower = None;
            limits.upper = None;
        }
    }
    let (parent, child_link) = (link_ref("parent")?, link_ref("child")?);
    Ok(JointInfo {
        node,
        name,
        kind,
        parent,
        child: child_link,
        placement: origin(node)?,
        axis: if axis.norm() > 0.0 { axis.normalize() } else { axis },
        limits,
    })
}

fn fmt3(v: &V3) -> String {
    format!("{:?} {:?} {:?}", v.x, v.y, v.z)
}

/// Write a model as URDF. The base joint (free/planar/fixed) has no URDF form: it is recorded in a
/// comment and chosen again when loading. Spherical joints have no URDF form either: an error.
pub fn to_urdf_string(m: &Model) -> Result<String> {
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(s, "<!-- written by freefloat; base joint: {} -->", m.joint_types[0].name());
    let _ = writeln!(s, "<robot name=\"{}\">", xml_escape(&m.name));
    for i in 0..m.nbodies() {
        let inr = &m.inertias[i];
        let _ = writeln!(s, "  <link name=\"{}\">", xml_escape(&m.body_names[i]));
        if !m.tags[i].is_empty() {
            let _ = writeln!(s, "    <freefloat tags=\"{}\"/>", xml_escape(&m.tags[i].join(" ")));
        }
        if inr.mass > 0.0 {
            let ic = inr.i_com();
            let _ = writeln!(s, "    <inertial>\n      <origin xyz=\"{}\" rpy=\"0 0 0\"/>", fmt3(&inr.com()));
            let _ = writeln!(s, "      <mass value=\"{:?}\"/>", inr.mass);
            let _ = writeln!(
                s,
                "      <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>\n    </inertial>",
                ic[(0, 0)], ic[(0, 1)], ic[(0, 2)], ic[(1, 1)], ic[(1, 2)], ic[(2, 2)]
            );
        }
        let _ = writeln!(s, "  </link>");
    }
    for i in 1..m.nbodies() {
        let t = match m.joint_types[i] {
            JointType::Revolute if m.limits[i].lower.is_none() && m.limits[i].upper.is_none() => "continuous",
            JointType::Revolute => "revolute",
            JointType::Prismatic => "prismatic",
            JointType::Fixed => "fixed",
            other => {
                return Err(FfError::Model(format!(
                    "joint '{}' is {}; URDF has no such joint type",
                    m.joint_names[i],
                    other.name()
                )))
            }
        };
        let p = &m.placements[i];
        let _ = writeln!(s, "  <joint name=\"{}\" type=\"{t}\">", xml_escape(&m.joint_names[i]));
        let _ = writeln!(s, "    <parent link=\"{}\"/>", xml_escape(&m.body_names[m.parents[i].unwrap()]));
        let _ = writeln!(s, "    <child link=\"{}\"/>", xml_escape(&m.body_names[i]));
        let _ = writeln!(s, "    <origin xyz=\"{}\" rpy=\"{}\"/>", fmt3(&p.trans), fmt3(&rot_to_rpy(&p.rot)));
        if t != "fixed" {
            let _ = writeln!(s, "    <axis xyz=\"{}\"/>", fmt3(&m.axes[i]));
            // Only the limits the model has; a missing one is not "zero".
            let l = &m.limits[i];
            let attrs: Vec<String> =
                [("lower", l.lower), ("upper", l.upper), ("velocity", l.velocity), ("effort", l.effort)]
                    .iter()
                    .filter_map(|(k, v)| v.map(|x| format!("{k}=\"{x:?}\"")))
                    .collect();
            if !attrs.is_empty() {
                let _ = writeln!(s, "    <limit {}/>", attrs.join(" "));
            }
        }
        let _ = writeln!(s, "  </joint>");
    }
    for f in &m.frames {
        let _ = writeln!(s, "  <link name=\"{}\"/>", xml_escape(&f.name));
        let _ = writeln!(s, "  <joint name=\"{}_fixed\" type=\"fixed\">", xml_escape(&f.name));
        let _ = writeln!(
            s,
            "    <parent link=\"{}\"/>\n    <child link=\"{}\"/>",
            xml_escape(&m.body_names[f.body]),
            xml_escape(&f.name)
        );
        let _ = writeln!(
            s,
            "    <origin xyz=\"{}\" rpy=\"{}\"/>\n  </joint>",
            fmt3(&f.placement.trans),
            fmt3(&rot_to_rpy(&f.placement.rot))
        );
    }
    let _ = writeln!(s, "</robot>");
    Ok(s)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
