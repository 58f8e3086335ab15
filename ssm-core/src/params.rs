//! Technique parameters: declared once as constants, set from strings by the
//! CLI and by sweeps, read back typed by the technique.

use std::collections::BTreeMap;
use std::fmt;

/// The type, default and valid range of one parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// `true` or `false`.
    Bool {
        /// Default value.
        default: bool,
    },
    /// An integer in `[min, max]`.
    Int {
        /// Default value.
        default: i64,
        /// Smallest allowed.
        min: i64,
        /// Largest allowed.
        max: i64,
    },
    /// A finite number in `[min, max]`.
    Float {
        /// Default value.
        default: f64,
        /// Smallest allowed.
        min: f64,
        /// Largest allowed.
        max: f64,
    },
    /// One of a fixed set of words.
    Choice {
        /// Default value; one of `options`.
        default: &'static str,
        /// The allowed words.
        options: &'static [&'static str],
    },
}

/// One parameter of a technique: name, kind (type, default, range) and one line of doc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// Name used on the command line (`--set mine.kernel=15`).
    pub name: &'static str,
    /// Type, default and range.
    pub kind: ParamKind,
    /// One line: what it controls, with units.
    pub doc: &'static str,
}

impl ParamSpec {
    /// The default value.
    #[must_use]
    pub fn default_value(&self) -> ParamValue {
        match self.kind {
            ParamKind::Bool { default } => ParamValue::Bool(default),
            ParamKind::Int { default, .. } => ParamValue::Int(default),
            ParamKind::Float { default, .. } => ParamValue::Float(default),
            ParamKind::Choice { default, .. } => ParamValue::Choice(default),
        }
    }

    /// The type and range as text, e.g. `int in [32, 2048]` or `one of f16|f32`.
    #[must_use]
    pub fn range_text(&self) -> String {
        match self.kind {
            ParamKind::Bool { .. } => "bool".into(),
            ParamKind::Int { min, max, .. } => format!("int in [{min}, {max}]"),
            ParamKind::Float { min, max, .. } => format!("float in [{min}, {max}]"),
            ParamKind::Choice { options, .. } => format!("one of {}", options.join("|")),
        }
    }

    /// Parses `text` as a value of this parameter, checking its range.
    ///
    /// # Errors
    /// [`ParamError::Invalid`] or [`ParamError::OutOfRange`].
    pub fn parse(&self, technique: &str, text: &str) -> Result<ParamValue, ParamError> {
        let invalid =
            || ParamError::Invalid { technique: technique.into(), name: self.name.into(), value: text.into(), expected: self.range_text() };
        let out_of_range =
            || ParamError::OutOfRange { technique: technique.into(), name: self.name.into(), value: text.into(), range: self.range_text() };
        let text = text.trim();
        match self.kind {
            ParamKind::Bool { .. } => match text {
                "true" | "1" | "on" | "yes" => Ok(ParamValue::Bool(true)),
                "false" | "0" | "off" | "no" => Ok(ParamValue::Bool(false)),
                _ => Err(invalid()),
            },
            ParamKind::Int { min, max, .. } => {
                let value: i64 = text.parse().map_err(|_| invalid())?;
                if (min..=max).contains(&value) { Ok(ParamValue::Int(value)) } else { Err(out_of_range()) }
            }
            ParamKind::Float { min, max, .. } => {
                let value: f64 = text.parse().map_err(|_| invalid())?;
                if !value.is_finite() {
                    return Err(invalid());
                }
                if (min..=max).contains(&value) { Ok(ParamValue::Float(value)) } else { Err(out_of_range()) }
            }
            ParamKind::Choice { options, .. } => options.iter().find(|o| **o == text).map(|o| ParamValue::Choice(o)).ok_or_else(invalid),
        }
    }
}

/// A parameter's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    /// A bool.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
    /// A choice.
    Choice(&'static str),
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Bool(v) => write!(f, "{v}"),
            Self::Int(v) => write!(f, "{v}"),
            Self::Float(v) => write!(f, "{v}"),
            Self::Choice(v) => f.write_str(v),
        }
    }
}

/// A bad parameter name or value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// The technique has no parameter of this name.
    #[error("technique `{technique}` has no parameter `{name}`; its parameters are: {known}")]
    Unknown {
        /// Technique name.
        technique: String,
        /// Name given.
        name: String,
        /// Names that exist.
        known: String,
    },
    /// The value does not parse as the parameter's type.
    #[error("{technique}.{name}: `{value}` is not a valid value; expected {expected}")]
    Invalid {
        /// Technique name.
        technique: String,
        /// Parameter name.
        name: String,
        /// Text given.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// The value parses but is outside the allowed range.
    #[error("{technique}.{name}: {value} is out of range; expected {range}")]
    OutOfRange {
        /// Technique name.
        technique: String,
        /// Parameter name.
        name: String,
        /// Text given.
        value: String,
        /// The allowed range.
        range: String,
    },
    /// A technique read its own parameter with the wrong type: a bug in the technique.
    #[error("technique `{technique}` read parameter `{name}` as {wanted}, but it is declared otherwise")]
    WrongType {
        /// Technique name.
        technique: String,
        /// Parameter name.
        name: String,
        /// Type asked for.
        wanted: &'static str,
    },
}

/// A complete set of values for one technique's parameters: every declared
/// parameter has a value (its default until set).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamValues {
    technique: &'static str,
    specs: &'static [ParamSpec],
    values: BTreeMap<&'static str, ParamValue>,
}

impl ParamValues {
    /// Every parameter at its default.
    #[must_use]
    pub fn defaults(technique: &'static str, specs: &'static [ParamSpec]) -> Self {
        Self { technique, specs, values: specs.iter().map(|s| (s.name, s.default_value())).collect() }
    }

    /// Sets `name` from text.
    ///
    /// # Errors
    /// [`ParamError::Unknown`], [`ParamError::Invalid`] or [`ParamError::OutOfRange`].
    pub fn set(&mut self, name: &str, text: &str) -> Result<(), ParamError> {
        let spec = self.specs.iter().find(|s| s.name == name).ok_or_else(|| ParamError::Unknown {
            technique: self.technique.into(),
            name: name.into(),
            known: if self.specs.is_empty() { "(none)".into() } else { self.specs.iter().map(|s| s.name).collect::<Vec<_>>().join(", ") },
        })?;
        let value = spec.parse(self.technique, text)?;
        self.values.insert(spec.name, value);
        Ok(())
    }

    fn get(&self, name: &str, wanted: &'static str) -> Result<ParamValue, ParamError> {
        self.values.get(name).copied().ok_or_else(|| ParamError::WrongType { technique: self.technique.into(), name: name.into(), wanted })
    }

    fn wrong(&self, name: &str, wanted: &'static str) -> ParamError {
        ParamError::WrongType { technique: self.technique.into(), name: name.into(), wanted }
    }

    /// A bool parameter.
    ///
    /// # Errors
    /// [`ParamError::WrongType`] if `name` is not a declared bool.
    pub fn bool(&self, name: &str) -> Result<bool, ParamError> {
        match self.get(name, "bool")? {
            ParamValue::Bool(v) => Ok(v),
            _ => Err(self.wrong(name, "bool")),
        }
    }

    /// An int parameter.
    ///
    /// # Errors
    /// [`ParamError::WrongType`] if `name` is not a declared int.
    pub fn int(&self, name: &str) -> Result<i64, ParamError> {
        match self.get(name, "int")? {
            ParamValue::Int(v) => Ok(v),
            _ => Err(self.wrong(name, "int")),
        }
    }

    /// A float parameter.
    ///
    /// # Errors
    /// [`ParamError::WrongType`] if `name` is not a declared float.
    pub fn float(&self, name: &str) -> Result<f64, ParamError> {
        match self.get(name, "float")? {
            ParamValue::Float(v) => Ok(v),
            _ => Err(self.wrong(name, "float")),
        }
    }

    /// A choice parameter.
    ///
    /// # Errors
    /// [`ParamError::WrongType`] if `name` is not a declared choice.
    pub fn choice(&self, name: &str) -> Result<&'static str, ParamError> {
        match self.get(name, "choice")? {
            ParamValue::Choice(v) => Ok(v),
            _ => Err(self.wrong(name, "choice")),
        }
    }

    /// The technique these values belong to.
    #[must_use]
    pub fn technique(&self) -> &'static str {
        self.technique
    }

    /// Every (name, value), in declaration order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, ParamValue)> + '_ {
        self.specs.iter().filter_map(|s| self.values.get(s.name).map(|v| (s.name, *v)))
    }
}

impl fmt::Display for ParamValues {
    /// `name=value` pairs joined by `;`, in declaration order (the `params` column of reports).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut first = true;
        for (name, value) in self.iter() {
            if !first {
                f.write_str(";")?;
            }
            first = false;
            write!(f, "{name}={value}")?;
        }
        Ok(())
    }
}

/// A technique's typed settings: a documented struct whose fields are its
/// parameters. Derive it (`#[derive(Settings)]`, see [`ssm_derive::Settings`]):
/// the string parameters of `ssm list`, `--set` and sweeps are made from the
/// struct, so no name, default or range is written twice.
pub trait Settings: Sized {
    /// The parameters, in field order (flattened settings in place).
    const PARAMS: &'static [ParamSpec];

    /// Reads the settings from a complete set of parameter values.
    ///
    /// # Errors
    /// [`ParamError::WrongType`] when `values` belong to other parameters.
    fn from_params(values: &ParamValues) -> Result<Self, ParamError>;
}

/// An enum parameter: one of a fixed set of words. Derive it
/// (`#[derive(Choice)]`, see [`ssm_derive::Choice`]).
pub trait Choice: Sized + Copy {
    /// The words, in declaration order.
    const OPTIONS: &'static [&'static str];
    /// The first variant.
    const FIRST: Self;

    /// The variant called `word`.
    fn from_name(word: &str) -> Option<Self>;

    /// This variant's word.
    fn name(self) -> &'static str;
}

/// A placeholder for filling arrays of parameters in constant code.
const NO_PARAM: ParamSpec = ParamSpec { name: "", kind: ParamKind::Bool { default: false }, doc: "" };

/// Concatenates parameter lists at compile time (what `#[derive(Settings)]`
/// uses for flattened settings). `N` must be the total length.
///
/// # Panics
/// At compile time, when `N` is not the total length.
#[must_use]
pub const fn concat_params<const N: usize>(parts: &[&[ParamSpec]]) -> [ParamSpec; N] {
    let mut out = [NO_PARAM; N];
    let mut filled = 0;
    let mut part = 0;
    while part < parts.len() {
        let mut index = 0;
        while index < parts[part].len() {
            out[filled] = parts[part][index];
            filled += 1;
            index += 1;
        }
        part += 1;
    }
    assert!(filled == N, "concat_params: N is not the total length");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: &[ParamSpec] = &[
        ParamSpec { name: "size", kind: ParamKind::Int { default: 256, min: 32, max: 2048 }, doc: "map size" },
        ParamSpec { name: "bias", kind: ParamKind::Float { default: 0.5, min: 0.0, max: 4.0 }, doc: "bias" },
        ParamSpec { name: "two_sided", kind: ParamKind::Bool { default: false }, doc: "two-sided" },
        ParamSpec { name: "accumulation", kind: ParamKind::Choice { default: "f32", options: &["f16", "f32"] }, doc: "precision" },
    ];

    #[test]
    fn defaults_set_and_read_back() {
        let mut values = ParamValues::defaults("t", SPECS);
        assert_eq!(values.int("size"), Ok(256));
        values.set("size", "1024").unwrap();
        values.set("two_sided", "true").unwrap();
        values.set("accumulation", "f16").unwrap();
        values.set("bias", "1.5").unwrap();
        assert_eq!(values.to_string(), "size=1024;bias=1.5;two_sided=true;accumulation=f16");
        assert!(matches!(values.float("size"), Err(ParamError::WrongType { .. })));
    }

    #[test]
    fn bad_values_are_typed_errors() {
        let mut values = ParamValues::defaults("t", SPECS);
        assert!(matches!(values.set("sise", "1"), Err(ParamError::Unknown { .. })));
        assert!(matches!(values.set("size", "4096"), Err(ParamError::OutOfRange { .. })));
        assert!(matches!(values.set("size", "big"), Err(ParamError::Invalid { .. })));
        assert!(matches!(values.set("bias", "NaN"), Err(ParamError::Invalid { .. })));
        assert!(matches!(values.set("bias", "inf"), Err(ParamError::Invalid { .. })));
        assert!(matches!(values.set("accumulation", "f64"), Err(ParamError::Invalid { .. })));
        let message = values.set("sise", "1").unwrap_err().to_string();
        assert!(message.contains("size, bias, two_sided, accumulation"), "{message}");
    }
}
