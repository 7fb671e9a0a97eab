//! The project's own YAML model format (docs/model_format.md), including modified Denavit-Hartenberg
//! rows as the seeds write them.

use super::{BodySpec, JointLimits, JointType, Model, ModelBuilder};
use crate::error::{FfError, Result};
use crate::spatial::{rot_from_quat, rotation_about_axis, rpy_to_rot, Inertia, Se3, M3, V3};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    name: String,
    #[allow(dead_code)]
    description: Option<String>,
    base: Option<String>,
    gravity: Option<[f64; 3]>,
    angles: Option<String>,
    bodies: Vec<BodyYaml>,
    frames: Option<Vec<FrameYaml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyYaml {
    name: String,
    parent: Option<String>,
    joint: Option<JointYaml>,
    origin: Option<OriginYaml>,
    mdh: Option<MdhYaml>,
    inertial: Option<InertialYaml>,
    tags: Option<Vec<String>>,
    #[serde(default)]
    allow_nonphysical: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointYaml {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    axis: Option<[f64; 3]>,
    /// Second axis of a universal joint (required there, rejected elsewhere).
    axis2: Option<[f64; 3]>,
    limits: Option<LimitsYaml>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct LimitsYaml {
    lower: Option<f64>,
    upper: Option<f64>,
    velocity: Option<f64>,
    effort: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OriginYaml {
    xyz: Option<[f64; 3]>,
    rpy: Option<[f64; 3]>,
    /// Unit quaternion (x, y, z, w), an alternative to `rpy` that is exact for any rotation (the MJCF
    /// reader writes it: no Euler-angle round trip, no gimbal-lock loss).
    quat: Option<[f64; 4]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MdhYaml {
    #[serde(default)]
    alpha: f64,
    #[serde(default)]
    a: f64,
    #[serde(default)]
    d: f64,
    #[serde(default)]
    theta: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InertialYaml {
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    inertia: Option<InertiaYaml>,
    inertia_origin: Option<InertiaYaml>,
    params: Option<Vec<f64>>,
}

/// An inertia written either way the format allows. Deserialized by hand (not `#[serde(untagged)]`) so that a
/// block of the wrong shape is answered with the key and the two accepted forms, instead of serde's "data did not
/// match any variant of untagged enum", and a typo inside the mapping form is still an unknown-field error.
enum InertiaYaml {
    Principal([f64; 3]),
    Full(InertiaMap),
}

const INERTIA_FORMS: &str =
    "the principal moments [Ixx, Iyy, Izz] or a mapping {xx, yy, zz, xy, xz, yz} (xy, xz, yz default to 0)";

impl<'de> Deserialize<'de> for InertiaYaml {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = InertiaYaml;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(INERTIA_FORMS)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<Self::Value, A::Error> {
                let mut out = [0.0; 3];
                for (i, x) in out.iter_mut().enumerate() {
                    *x = seq.next_element()?.ok_or_else(|| {
                        serde::de::Error::custom(format!("expected {INERTIA_FORMS}; the list has {i} entries"))
                    })?;
                }
                if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    return Err(serde::de::Error::custom(format!(
                        "expected {INERTIA_FORMS}; the list has more than 3 entries"
                    )));
                }
                Ok(InertiaYaml::Principal(out))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> std::result::Result<Self::Value, A::Error> {
                InertiaMap::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(InertiaYaml::Full)
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InertiaMap {
    xx: f64,
    yy: f64,
    zz: f64,
    #[serde(default)]
    xy: f64,
    #[serde(default)]
    xz: f64,
    #[serde(default)]
    yz: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameYaml {
    name: String,
    body: String,
    origin: Option<OriginYaml>,
}

impl InertiaYaml {
    fn matrix(&self) -> M3 {
        match self {
            InertiaYaml::Principal(d) => M3::from_diagonal(&V3::new(d[0], d[1], d[2])),
            InertiaYaml::Full(m) => M3::new(m.xx, m.xy, m.xz, m.xy, m.yy, m.yz, m.xz, m.yz, m.zz),
        }
    }
}

/// Parse a YAML model from text. `source_name` (a path, or "<string>") is used in error messages.
pub fn from_yaml_str(text: &str, source_name: &str) -> Result<Model> {
    let spec: FileSpec = serde_norway::from_str(text).map_err(|e| FfError::ModelFile {
        source_name: source_name.to_string(),
        line: e.location().map(|l| l.line()),
        msg: with_suggestion(&e.to_string()),
    })?;
    Loader { text, source_name }.build(spec)
}

struct Loader<'a> {
    text: &'a str,
    source_name: &'a str,
}

impl Loader<'_> {
    /// Error located at the line where `name: <key>` first appears (the offending body or frame).
    fn err_at(&self, key: &str, msg: String) -> FfError {
        let line = self.text.lines().position(|l| {
            let t = l.trim_start().trim_start_matches("- ").trim_start_matches('{');
            t.starts_with("name:")
                && t["name:".len()..].trim().trim_matches(|c| c == '"' || c == '\'' || c == ',').starts_with(key)
        });
        FfError::ModelFile { source_name: self.source_name.to_string(), line: line.map(|l| l + 1), msg }
    }

    fn build(&self, spec: FileSpec) -> Result<Model> {
        let deg = match spec.angles.as_deref().unwrap_or("rad") {
            "rad" => false,
            "deg" => true,
            other => return Err(self.err_at(&spec.name, format!("angles must be 'rad' or 'deg', got '{other}'"))),
        };
        let ang = |x: f64| if deg { x.to_radians() } else { x };
        let base_kind = spec.base.as_deref().unwrap_or("free");
        let base_joint = JointType::base_from_name(base_kind).ok_or_else(|| {
            self.err_at(&spec.name, format!("base must be one of free, planar, fixed; got '{base_kind}'"))
        })?;
        let Some(base) = spec.bodies.first() else {
            return Err(self.err_at(&spec.name, "the model has no bodies".into()));
        };
        if base.parent.is_some() || base.joint.is_some() || base.origin.is_some() || base.mdh.is_some() {
            return Err(self.err_at(
                &base.name,
                format!("the first body '{}' is the base: it takes no parent, joint, origin or mdh", base.name),
            ));
        }
        let mut b = ModelBuilder::new(&spec.name, &base.name, base_joint, self.inertia(base)?)?;
        b.set_base_tags(base.tags.clone().unwrap_or_default());
        b.set_base_allow_nonphysical(base.allow_nonphysical);
        if let Some(g) = spec.gravity {
            b.set_gravity(V3::from(g));
        }
        for body in &spec.bodies[1..] {
            let parent_name = body.parent.as_deref().ok_or_else(|| {
                self.err_at(&body.name, format!("body '{}' has no parent (only the first body is the base)", body.name))
            })?;
            let parent = b.body_index(parent_name).ok_or_else(|| {
                self.err_at(
                    &body.name,
                    format!("body '{}': parent '{parent_name}' is not a body listed before it", body.name),
                )
            })?;
            let joint = body
                .joint
                .as_ref()
                .ok_or_else(|| self.err_at(&body.name, format!("body '{}' has no joint", body.name)))?;
            let jt = JointType::child_from_name(&joint.kind).ok_or_else(|| {
                self.err_at(
                    &body.name,
                    format!(
                        "body '{}': unknown joint type '{}' (expected revolute, prismatic, fixed, spherical, cylindrical or universal)",
                        body.name, joint.kind
                    ),
                )
            })?;
            let mut placement = Se3::identity();
            if let Some(o) = &body.origin {
                placement = origin_se3(o, &ang)
                    .map_err(|m| self.err_at(&body.name, format!("body '{}': origin: {m}", body.name)))?;
            }
            let mut axis = joint.axis.map(V3::from).unwrap_or_else(V3::z);
            if let Some(dh) = &body.mdh {
                // Craig's modified DH: Rx(alpha) Tx(a) Rz(theta) Tz(d); the joint axis is the new z.
                let rx = Se3::new(rotation_about_axis(&V3::x(), ang(dh.alpha)), V3::zeros());
                let tx = Se3::new(M3::identity(), V3::new(dh.a, 0.0, 0.0));
                let rz = Se3::new(rotation_about_axis(&V3::z(), ang(dh.theta)), V3::new(0.0, 0.0, dh.d));
                placement = placement.compose(&rx).compose(&tx).compose(&rz);
                if let Some(a) = joint.axis {
                    if (V3::from(a).normalize() - V3::z()).norm() > 1e-12 {
                        return Err(self.err_at(
                            &body.name,
                            format!(
                                "body '{}': with mdh the joint axis is z; remove `axis` or set it to [0, 0, 1]",
                                body.name
                            ),
                        ));
                    }
                }
                axis = V3::z();
            }
            let axis2 = match (jt, joint.axis2) {
                (JointType::Universal, Some(a)) => V3::from(a),
                (JointType::Universal, None) => {
                    return Err(self.err_at(
                        &body.name,
                        format!(
                            "body '{}': a universal joint needs `axis2`, the second rotation axis (e.g. axis: [1, 0, 0], axis2: [0, 1, 0])",
                            body.name
                        ),
                    ))
                }
                (_, Some(_)) => {
                    return Err(self.err_at(
                        &body.name,
                        format!("body '{}': `axis2` is only meaningful for a universal joint, not {}", body.name, jt.name()),
                    ))
                }
                (_, None) => V3::z(),
            };
            let l = joint.limits.as_ref();
            let ang_lim = |x: Option<f64>| if jt == JointType::Revolute { x.map(ang) } else { x };
            let limits = JointLimits {
                lower: ang_lim(l.and_then(|l| l.lower)),
                upper: ang_lim(l.and_then(|l| l.upper)),
                velocity: ang_lim(l.and_then(|l| l.velocity)),
                effort: l.and_then(|l| l.effort),
            };
            if let (Some(lo), Some(hi)) = (limits.lower, limits.upper) {
                if lo > hi {
                    return Err(
                        self.err_at(&body.name, format!("body '{}': joint lower limit {lo} > upper {hi}", body.name))
                    );
                }
            }
            let spec_b = BodySpec {
                name: body.name.clone(),
                parent,
                joint_name: joint.name.clone().unwrap_or_else(|| format!("{}_joint", body.name)),
                joint_type: jt,
                axis,
                axis2,
                placement,
                inertia: self.inertia(body)?,
                limits,
                tags: body.tags.clone().unwrap_or_default(),
                allow_nonphysical: body.allow_nonphysical,
            };
            b.add_body(spec_b).map_err(|e| self.relocate(&body.name, e))?;
        }
        for f in spec.frames.unwrap_or_default() {
            let body = b
                .body_index(&f.body)
                .ok_or_else(|| self.err_at(&f.name, format!("frame '{}': body '{}' does not exist", f.name, f.body)))?;
            let pl = match f.origin.as_ref() {
                Some(o) => {
                    origin_se3(o, &ang).map_err(|m| self.err_at(&f.name, format!("frame '{}': origin: {m}", f.name)))?
                }
                None => Se3::default(),
            };
            b.add_frame(&f.name, body, pl)?;
        }
        b.build().map_err(|e| match &e {
            FfError::Inertia { body, .. } => self.relocate(&body.clone(), e),
            _ => FfError::ModelFile { source_name: self.source_name.to_string(), line: None, msg: e.to_string() },
        })
    }

    fn relocate(&self, body: &str, e: FfError) -> FfError {
        self.err_at(body, e.to_string())
    }

    fn inertia(&self, body: &BodyYaml) -> Result<Inertia> {
        let Some(i) = &body.inertial else { return Ok(Inertia::zero()) };
        let bad = |msg: &str| self.err_at(&body.name, format!("body '{}': inertial: {msg}", body.name));
        if let Some(p) = &i.params {
            if i.mass.is_some() || i.com.is_some() || i.inertia.is_some() || i.inertia_origin.is_some() {
                return Err(bad("give either `params` or mass/com/inertia, not both"));
            }
            if p.len() != 10 {
                return Err(bad(&format!(
                    "params needs 10 numbers [m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz], got {}",
                    p.len()
                )));
            }
            return Ok(Inertia::from_params(p));
        }
        let mass = i.mass.ok_or_else(|| bad("missing `mass`"))?;
        let com = V3::from(i.com.unwrap_or([0.0; 3]));
        match (&i.inertia, &i.inertia_origin) {
            (Some(ic), None) => Ok(Inertia::from_com(mass, com, ic.matrix())),
            (None, Some(io)) => Ok(Inertia { mass, h: com * mass, i_o: io.matrix() }),
            (None, None) => Ok(Inertia::from_com(mass, com, M3::zeros())),
            (Some(_), Some(_)) => Err(bad("give `inertia` (about the CoM) or `inertia_origin`, not both")),
        }
    }
}

/// serde's unknown-field message ("unknown field `mas`, expected one of `mass`, `com`") with the closest valid
/// key named first: "unknown field `mas` (did you mean `mass`?), expected one of ...".
fn with_suggestion(msg: &str) -> String {
    let Some(start) = msg.find("unknown field `") else { return msg.to_string() };
    let rest = &msg[start + "unknown field `".len()..];
    let Some(end) = rest.find('`') else { return msg.to_string() };
    let key = &rest[..end];
    let valid: Vec<&str> = rest[end + 1..].split('`').skip(1).step_by(2).collect();
    let best = valid
        .iter()
        .map(|v| (edit_distance(&key.to_lowercase(), &v.to_lowercase()), *v))
        .filter(|(d, v)| *d <= (v.len().max(key.len()) / 3).max(1))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((_, v)) => {
            let at = start + "unknown field `".len() + end + 1;
            format!("{} (did you mean `{v}`?){}", &msg[..at], &msg[at..])
        }
        None => msg.to_string(),
    }
}

/// Levenshtein distance (insertions, deletions, substitutions), on characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

fn origin_se3(o: &OriginYaml, ang: &dyn Fn(f64) -> f64) -> std::result::Result<Se3, String> {
    let xyz = V3::from(o.xyz.unwrap_or([0.0; 3]));
    if let Some(q) = o.quat {
        if o.rpy.is_some() {
            return Err("give `rpy` or `quat`, not both".into());
        }
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !n.is_finite() || (n - 1.0).abs() > 1e-6 {
            return Err(format!("`quat` [x, y, z, w] must be a unit quaternion, its norm is {n}"));
        }
        let u = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
        return Ok(Se3::new(rot_from_quat(&u), xyz));
    }
    let rpy = o.rpy.map(|r| V3::new(ang(r[0]), ang(r[1]), ang(r[2]))).unwrap_or_else(V3::zeros);
    Ok(Se3::new(rpy_to_rot(&rpy), xyz))
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "name: t\nbodies:\n  - name: base\n    inertial: {mass: 10, inertia: [1, 1, 1]}\n";

    fn err(text: &str) -> String {
        match from_yaml_str(text, "t.yaml") {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        }
    }

    #[test]
    fn unknown_key_names_the_closest_valid_key() {
        let e = err(&BASE.replace("mass:", "mas:"));
        assert!(e.contains("unknown field `mas` (did you mean `mass`?)"), "{e}");
        let e = err(&BASE.replace("inertial:", "inertal:"));
        assert!(e.contains("did you mean `inertial`?"), "{e}");
        let e = err(&format!("{BASE}    zzzzzz: 1\n"));
        assert!(e.contains("unknown field `zzzzzz`") && !e.contains("did you mean"), "{e}");
    }

    #[test]
    fn inertia_of_the_wrong_shape_names_the_key_and_the_accepted_forms() {
        for bad in ["inertia: [1, 1]", "inertia: [1, 1, 1, 1]", "inertia: 5", "inertia: abc"] {
            let e = err(&BASE.replace("inertia: [1, 1, 1]", bad));
            assert!(e.contains("inertia") && e.contains("[Ixx, Iyy, Izz]"), "{bad}: {e}");
            assert!(!e.contains("untagged"), "{bad}: {e}");
        }
        let e = err(&BASE.replace("inertia: [1, 1, 1]", "inertia: {xx: 1, yy: 1, zz: 1, x_y: 0}"));
        assert!(e.contains("unknown field `x_y` (did you mean `xy`?)"), "{e}");
        assert!(from_yaml_str(&BASE.replace("[1, 1, 1]", "{xx: 1, yy: 2, zz: 3, xy: 0.1}"), "t").is_ok());
    }
}
