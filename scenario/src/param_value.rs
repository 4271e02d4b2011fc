//! Values of a scene family's named parameters, as a scene file's `[params]` table holds them.

/// A parameter value for [`Scenario::param`]: a number, an integer, a flag or a word, as in the
/// `[params]` table of a scene file.
/// In a [`crate::ScanSpec`] file it is the plain TOML or JSON value.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// A flag.
    Bool(bool),
    /// An integer (counts, e.g. `objects` of `flat`).
    Int(i64),
    /// A real number (most parameters: `slope_deg`, `depth_m`, ...).
    Float(f64),
    /// A word (e.g. `sides = "railings"` of `ramp`).
    Text(String),
}

impl From<f64> for ParamValue {
    fn from(v: f64) -> Self {
        Self::Float(v)
    }
}
impl From<f32> for ParamValue {
    fn from(v: f32) -> Self {
        Self::Float(f64::from(v))
    }
}
impl From<i64> for ParamValue {
    fn from(v: i64) -> Self {
        Self::Int(v)
    }
}
impl From<i32> for ParamValue {
    fn from(v: i32) -> Self {
        Self::Int(i64::from(v))
    }
}
impl From<u32> for ParamValue {
    fn from(v: u32) -> Self {
        Self::Int(i64::from(v))
    }
}
impl From<bool> for ParamValue {
    fn from(v: bool) -> Self {
        Self::Bool(v)
    }
}
impl From<&str> for ParamValue {
    fn from(v: &str) -> Self {
        Self::Text(v.to_string())
    }
}
impl From<String> for ParamValue {
    fn from(v: String) -> Self {
        Self::Text(v)
    }
}

impl ParamValue {
    pub(crate) fn to_toml(&self) -> toml::Value {
        match self {
            Self::Float(v) => toml::Value::Float(*v),
            Self::Int(v) => toml::Value::Integer(*v),
            Self::Bool(v) => toml::Value::Boolean(*v),
            Self::Text(v) => toml::Value::String(v.clone()),
        }
    }
}
