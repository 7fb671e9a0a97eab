//! Reading one sensor's block of a `sensors:` list (YAML or JSON) with errors that name the key.

use crate::error::{FfError, Result};
use serde_norway::{Mapping, Value};

/// The keys of one sensor block, read one at a time; `finish` refuses any key that was not read.
pub(crate) struct Fields {
    map: Mapping,
    used: Vec<String>,
    /// `sensors.<name>`: the prefix of every error message.
    pub(crate) ctx: String,
}

impl Fields {
    pub(crate) fn new(map: Mapping, ctx: String) -> Self {
        Fields { map, used: Vec::new(), ctx }
    }

    fn key(&self, k: &str) -> String {
        format!("{}.{k}", self.ctx)
    }

    fn get(&mut self, k: &str) -> Option<Value> {
        self.used.push(k.to_string());
        self.map.get(Value::String(k.to_string())).filter(|v| !v.is_null()).cloned()
    }

    /// An optional string.
    pub(crate) fn string(&mut self, k: &str) -> Result<Option<String>> {
        match self.get(k) {
            None => Ok(None),
            Some(Value::String(s)) => Ok(Some(s)),
            Some(v) => Err(FfError::arg(&self.key(k), format!("expected a name, got {}", show(&v)))),
        }
    }

    fn number(&self, k: &str, v: &Value) -> Result<f64> {
        let x = v.as_f64().ok_or_else(|| FfError::arg(&self.key(k), format!("expected a number, got {}", show(v))))?;
        if !x.is_finite() {
            return Err(FfError::arg(&self.key(k), format!("must be finite, got {x}")));
        }
        Ok(x)
    }

    /// An optional number that must be ≥ 0 (a noise level, a time): `default` when absent.
    pub(crate) fn nonneg(&mut self, k: &str, default: f64, unit: &str) -> Result<f64> {
        match self.get(k) {
            None => Ok(default),
            Some(v) => {
                let x = self.number(k, &v)?;
                if x < 0.0 {
                    return Err(FfError::arg(&self.key(k), format!("must be ≥ 0 {unit}, got {x}")));
                }
                Ok(x)
            }
        }
    }

    /// An optional number that must be ≥ 0 when given.
    pub(crate) fn opt_nonneg(&mut self, k: &str, unit: &str) -> Result<Option<f64>> {
        let present = self.map.get(Value::String(k.to_string())).is_some_and(|v| !v.is_null());
        let x = self.nonneg(k, 0.0, unit)?;
        Ok(present.then_some(x))
    }

    /// An optional number that must be > 0 when given.
    pub(crate) fn positive(&mut self, k: &str, unit: &str) -> Result<Option<f64>> {
        match self.get(k) {
            None => Ok(None),
            Some(v) => {
                let x = self.number(k, &v)?;
                if !(x > 0.0) {
                    return Err(FfError::arg(&self.key(k), format!("must be > 0 {unit}, got {x}")));
                }
                Ok(Some(x))
            }
        }
    }

    /// An optional signed number.
    pub(crate) fn signed(&mut self, k: &str, default: f64) -> Result<f64> {
        match self.get(k) {
            None => Ok(default),
            Some(v) => self.number(k, &v),
        }
    }

    /// Three numbers, or one number meaning the same value on the three axes; `nonneg` refuses
    /// negative entries (noise levels), otherwise any sign (biases).
    pub(crate) fn vec3(&mut self, k: &str, default: [f64; 3], nonneg: bool) -> Result<[f64; 3]> {
        let v = match self.get(k) {
            None => return Ok(default),
            Some(v) => v,
        };
        let out = match &v {
            Value::Sequence(s) if s.len() == 3 => {
                let mut o = [0.0; 3];
                for (i, x) in s.iter().enumerate() {
                    o[i] = self.number(k, x)?;
                }
                o
            }
            Value::Sequence(s) => {
                return Err(FfError::arg(&self.key(k), format!("expected 3 numbers (x, y, z), got {}", s.len())))
            }
            _ => [self.number(k, &v)?; 3],
        };
        if nonneg && out.iter().any(|x| *x < 0.0) {
            return Err(FfError::arg(&self.key(k), format!("must be ≥ 0, got {out:?}")));
        }
        Ok(out)
    }

    /// An optional list of names (a single name is a list of one).
    pub(crate) fn names(&mut self, k: &str) -> Result<Option<Vec<String>>> {
        match self.get(k) {
            None => Ok(None),
            Some(Value::String(s)) => Ok(Some(vec![s])),
            Some(Value::Sequence(s)) => s
                .iter()
                .map(|x| match x {
                    Value::String(n) => Ok(n.clone()),
                    other => Err(FfError::arg(&self.key(k), format!("expected joint names, got {}", show(other)))),
                })
                .collect::<Result<Vec<_>>>()
                .map(Some),
            Some(v) => Err(FfError::arg(&self.key(k), format!("expected a list of names, got {}", show(&v)))),
        }
    }

    /// Refuse every key that no reader asked for (a misspelt key must not be silently ignored).
    pub(crate) fn finish(self) -> Result<()> {
        for (k, _) in self.map.iter() {
            let name = match k {
                Value::String(s) => s.clone(),
                other => show(other),
            };
            if !self.used.contains(&name) {
                let mut known: Vec<&str> = self.used.iter().map(|s| s.as_str()).collect();
                known.sort_unstable();
                known.dedup();
                return Err(FfError::arg(
                    &format!("{}.{name}", self.ctx),
                    format!("unknown key (known: {})", known.join(", ")),
                ));
            }
        }
        Ok(())
    }
}

/// A short rendering of a YAML value for an error message.
pub(crate) fn show(v: &Value) -> String {
    match v {
        Value::Null => "nothing".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("{n}"),
        Value::String(s) => format!("'{s}'"),
        Value::Sequence(s) => format!("a list of {}", s.len()),
        Value::Mapping(_) => "a mapping".into(),
        Value::Tagged(_) => "a tagged value".into(),
    }
}
