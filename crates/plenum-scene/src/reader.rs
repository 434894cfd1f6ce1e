//! Typed, located access to a parsed TOML document. Each table is opened with the list of
//! fields it allows, so a misspelt key is caught at once with a suggestion, and every value is
//! checked where it stands: a wrong type, a NaN or a negative radius points at its own text.

use crate::diagnostics::{did_you_mean, SceneError};
use plenum_core::math::Vec3;
use std::ops::Range;
use std::path::Path;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

pub type Value<'s> = Spanned<DeValue<'s>>;
pub type Result<T> = std::result::Result<T, SceneError>;

/// The text being read, for locating errors.
#[derive(Clone, Copy)]
pub struct Source<'s> {
    pub path: &'s Path,
    pub text: &'s str,
}

impl<'s> Source<'s> {
    pub fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::at(self.path, self.text, span, message)
    }

    /// A value as a table with the given fields; `what` names it in messages.
    pub fn table<'a>(
        &self,
        value: &'a Value<'s>,
        what: &str,
        allowed: &[&'static str],
    ) -> Result<Fields<'a, 's>> {
        let DeValue::Table(table) = value.get_ref() else {
            return Err(self.error(
                value.span(),
                format!(
                    "expected a table for {what}, found {}",
                    describe(value.get_ref())
                ),
            ));
        };
        Fields::new(*self, table, value.span(), what, allowed)
    }

    pub fn number(&self, v: &Value<'s>) -> Result<f64> {
        let n = match v.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f64),
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            other => {
                return Err(self.error(
                    v.span(),
                    format!("expected a number, found {}", describe(other)),
                ))
            }
        };
        match n {
            Some(n) if n.is_finite() => Ok(n),
            _ => Err(self.error(
                v.span(),
                format!("expected a finite number, found `{}`", &self.text[v.span()]),
            )),
        }
    }

    pub fn array<'a>(&self, v: &'a Value<'s>, what: &str) -> Result<&'a [Value<'s>]> {
        match v.get_ref() {
            DeValue::Array(a) => Ok(a),
            other => Err(self.error(
                v.span(),
                format!("expected {what}, found {}", describe(other)),
            )),
        }
    }

    /// `[x, y, z]`.
    pub fn vec3(&self, v: &Value<'s>) -> Result<Vec3> {
        let [x, y, z] = self.numbers::<3>(v, "an array of 3 numbers [x, y, z]")?;
        Ok(Vec3::new(x, y, z))
    }

    /// An array of exactly N numbers.
    pub fn numbers<const N: usize>(&self, v: &Value<'s>, what: &str) -> Result<[f64; N]> {
        let items = self.array(v, what)?;
        if items.len() != N {
            return Err(self.error(
                v.span(),
                format!("expected {what}, found {} element(s)", items.len()),
            ));
        }
        let mut out = [0.0; N];
        for (o, item) in out.iter_mut().zip(items) {
            *o = self.number(item)?;
        }
        Ok(out)
    }

    pub fn string<'a>(&self, v: &'a Value<'s>) -> Result<&'a str> {
        match v.get_ref() {
            DeValue::String(s) => Ok(s),
            other => Err(self.error(
                v.span(),
                format!("expected a string, found {}", describe(other)),
            )),
        }
    }

    pub fn index(&self, v: &Value<'s>) -> Result<u32> {
        match v.get_ref() {
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .and_then(|i| u32::try_from(i).ok())
                .ok_or_else(|| self.error(v.span(), "expected a vertex index (0 or more)")),
            other => Err(self.error(
                v.span(),
                format!("expected a vertex index, found {}", describe(other)),
            )),
        }
    }
}

/// "a string", "an array", …: the TOML type of a value, for messages.
pub fn describe(v: &DeValue) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

/// One TOML table whose keys have been checked against the fields it allows.
pub struct Fields<'a, 's> {
    pub src: Source<'s>,
    table: &'a DeTable<'s>,
    /// The table's own span, for "missing field" errors.
    pub span: Range<usize>,
    what: String,
}

impl<'a, 's> Fields<'a, 's> {
    pub fn new(
        src: Source<'s>,
        table: &'a DeTable<'s>,
        span: Range<usize>,
        what: &str,
        allowed: &[&'static str],
    ) -> Result<Self> {
        for (key, _) in table.iter() {
            let name: &str = key.get_ref();
            if !allowed.contains(&name) {
                let e = src.error(key.span(), format!("unknown field `{name}` in {what}"));
                return Err(match did_you_mean(name, allowed.iter().copied()) {
                    Some(s) => e.with_help(format!("did you mean `{s}`?")),
                    None => e.with_help(format!("expected one of: {}", allowed.join(", "))),
                });
            }
        }
        Ok(Fields {
            src,
            table,
            span,
            what: what.to_string(),
        })
    }

    pub fn get(&self, key: &str) -> Option<&'a Value<'s>> {
        self.table.get(key)
    }

    pub fn required(&self, key: &str) -> Result<&'a Value<'s>> {
        self.get(key).ok_or_else(|| {
            // Point at the table's first line: its header, or its opening brace.
            let start = self.span.start;
            let end = self.src.text[start..]
                .find('\n')
                .map_or(self.src.text.len(), |i| start + i);
            self.src.error(
                start..end,
                format!("missing field `{key}` in {}", self.what),
            )
        })
    }

    pub fn number_or(&self, key: &str, default: f64) -> Result<f64> {
        self.get(key).map_or(Ok(default), |v| self.src.number(v))
    }

    /// A number ≥ 0.
    pub fn non_negative_or(&self, key: &str, default: f64) -> Result<f64> {
        let Some(v) = self.get(key) else {
            return Ok(default);
        };
        let n = self.src.number(v)?;
        if n >= 0.0 {
            Ok(n)
        } else {
            Err(self
                .src
                .error(v.span(), format!("expected {key} ≥ 0, found {n}")))
        }
    }

    /// Exactly one of `keys` is given (or none, when `required` is false): which one.
    pub fn one_of(&self, keys: &[&'static str]) -> Result<Option<&'static str>> {
        let given: Vec<&'static str> = keys
            .iter()
            .copied()
            .filter(|k| self.get(k).is_some())
            .collect();
        match given[..] {
            [] => Ok(None),
            [one] => Ok(Some(one)),
            [_, second, ..] => Err(self.src.error(
                self.get(second).map_or(self.span.clone(), |v| v.span()),
                format!("give only one of {} in {}", keys.join(", "), self.what),
            )),
        }
    }

    /// A number > 0.
    pub fn positive(&self, key: &str, default: Option<f64>) -> Result<f64> {
        let Some(v) = self.get(key) else {
            return match default {
                Some(d) => Ok(d),
                None => self.required(key).map(|_| 0.0),
            };
        };
        let n = self.src.number(v)?;
        if n > 0.0 {
            Ok(n)
        } else {
            Err(self
                .src
                .error(v.span(), format!("expected a positive {key}, found {n}")))
        }
    }

    pub fn vec3(&self, key: &str) -> Result<Option<Vec3>> {
        self.get(key).map(|v| self.src.vec3(v)).transpose()
    }

    pub fn vec3_or(&self, key: &str, default: Vec3) -> Result<Vec3> {
        Ok(self.vec3(key)?.unwrap_or(default))
    }

    pub fn required_vec3(&self, key: &str) -> Result<Vec3> {
        self.src.vec3(self.required(key)?)
    }

    /// A direction: a vector that is not zero.
    pub fn direction(&self, key: &str, default: Option<Vec3>) -> Result<Vec3> {
        let Some(v) = self.get(key) else {
            return match default {
                Some(d) => Ok(d),
                None => self.required(key).map(|_| Vec3::ZERO),
            };
        };
        let d = self.src.vec3(v)?;
        if d.length_squared() > 0.0 {
            Ok(d)
        } else {
            Err(self
                .src
                .error(v.span(), format!("expected a non-zero {key} vector")))
        }
    }

    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => match v.get_ref() {
                DeValue::Boolean(b) => Ok(*b),
                other => Err(self.src.error(
                    v.span(),
                    format!("expected true or false, found {}", describe(other)),
                )),
            },
        }
    }

    pub fn string(&self, key: &str) -> Result<Option<&'a str>> {
        self.get(key).map(|v| self.src.string(v)).transpose()
    }

    /// A non-negative integer.
    pub fn count(&self, key: &str) -> Result<Option<u32>> {
        self.get(key)
            .map(|v| {
                self.src.index(v).map_err(|_| {
                    self.src
                        .error(v.span(), format!("expected a whole number ≥ 0 for {key}"))
                })
            })
            .transpose()
    }
}
