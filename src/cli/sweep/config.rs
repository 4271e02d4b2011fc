//! The sweep file (TOML): what to vary, parsed and validated completely before any work starts.
//!
//! ```toml
//! scenes = ["city", "ramp-up"]        # bundled / built-in names or scene .toml files
//! rigs = ["lux-roof-4"]               # presets or rig .toml files
//! seeds = [0, 1, 2]                   # or { from = 0, to = 9 } (step 1)
//! methods = ["nitsch", "ransac"]
//! frames = 1                          # frames per configuration, 1 ..= 100 (default 1)
//! speed_m_per_s = 0.0                 # ego speed (default 0: standing)
//! ideal = false                       # measurement effects off (default false)
//! body = "rig"                        # "rig" (default): the whole rig moves as one body; or a sensor name
//!
//! [mount]                             # any of x_m y_m z_m roll_deg pitch_deg yaw_deg
//! z_m = { from = 1.2, to = 2.2, step = 0.1 }
//! pitch_deg = [-6.0, -4.0, -2.0, 0.0, 2.0]
//!
//! [sensor]                            # fields of the sensor spec (as in a rig file's `spec`)
//! frequency_hz = [12.5, 25.0]
//! ```
//!
//! The weather is swept either as a list of kinds, `weather = ["clear", "fog:visibility_m=50",
//! "snow:rate_mm_h=2"]` (top level, before any table; column `weather`), or over one kind's
//! parameter, a numeric axis to plot against: `[weather]` with `kind = "fog"` and
//! `visibility_m = { from = 20, to = 200, step = 20 }` (column `weather.visibility_m`); see
//! `sim::effects::weather` for the kinds and ranges.
//!
//! A value list is a TOML array, or a range table `{ from, to, step }` (inclusive of `to` where
//! the steps land on it; `step` defaults to 1). Mount values follow the manifest's `mount` (metres,
//! degrees, ISO 8855, +pitch = down); see [`super::expand`] for what they mean for a whole rig.

use std::collections::BTreeMap;

use anyhow::{Context, bail};
use serde::Deserialize;

/// The mount parameters, in column order.
pub const MOUNT_PARAMS: [&str; 6] = ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"];

/// Largest product of a sweep without `--allow-large`.
pub const MAX_CONFIGURATIONS: u64 = 10_000_000;

/// Largest number of values one list or range may hold.
pub const MAX_VALUES: usize = 1_000_000;

/// The weather axis's column name.
pub const WEATHER_AXIS: &str = "weather";

/// Largest number of frames per configuration.
pub const MAX_FRAMES: usize = 100;

/// The sweep file as written.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    scenes: Vec<String>,
    rigs: Vec<String>,
    seeds: RawValues,
    methods: Vec<String>,
    #[serde(default = "one")]
    frames: usize,
    #[serde(default)]
    speed_m_per_s: f32,
    #[serde(default)]
    ideal: bool,
    #[serde(default = "rig_body")]
    body: String,
    #[serde(default)]
    mount: BTreeMap<String, RawValues>,
    #[serde(default)]
    sensor: BTreeMap<String, RawValues>,
    #[serde(default)]
    weather: Option<RawWeather>,
    /// Keys without their unit: refused as a scan spec refuses them.
    #[serde(default)]
    speed: Option<serde::de::IgnoredAny>,
    #[serde(default)]
    yaw_rate: Option<serde::de::IgnoredAny>,
}

/// The sweep's weather: a list of specs or one kind with its parameter's values.
#[derive(Deserialize, Debug)]
#[serde(untagged)]
enum RawWeather {
    Specs(Vec<String>),
    Swept(BTreeMap<String, toml::Value>),
}

fn one() -> usize {
    1
}

fn rig_body() -> String {
    "rig".to_string()
}

/// A list of values or a range table.
#[derive(Deserialize, Debug)]
#[serde(untagged)]
enum RawValues {
    List(Vec<toml::Value>),
    Range(RawRange),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RawRange {
    from: toml::Value,
    to: toml::Value,
    step: Option<toml::Value>,
}

/// One swept parameter: its column name and its values (JSON numbers, strings or booleans).
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Column name: a mount parameter (`z_m`) or `sensor.<field>`.
    pub name: String,
    /// The values, in the file's order.
    pub values: Vec<serde_json::Value>,
}

/// A validated sweep: every list expanded, every name known.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// Scene names or files.
    pub scenes: Vec<String>,
    /// Rig names or files.
    pub rigs: Vec<String>,
    /// Seeds of the scenes, the scan noise and RANSAC.
    pub seeds: Vec<u64>,
    /// Method names.
    pub methods: Vec<String>,
    /// Frames per configuration.
    pub frames: usize,
    /// Ego speed, metres per second.
    pub speed_m_per_s: f32,
    /// Measurement effects off.
    pub ideal: bool,
    /// `"rig"` or the name of the sensor the mount and sensor parameters apply to.
    pub body: String,
    /// Mount axes, in [`MOUNT_PARAMS`] order.
    pub mount: Vec<Axis>,
    /// Sensor spec axes (`sensor.<field>`), sorted by name.
    pub sensor: Vec<Axis>,
    /// The weather axis (column `weather`, values as `fog:visibility_m=50`), if swept.
    pub weather: Option<Axis>,
}

impl Sweep {
    /// Parses a sweep file's text (structure and value lists only; names are checked by
    /// [`super::expand::Space::new`]). `source` names the file in messages.
    pub fn parse(text: &str, source: &str) -> anyhow::Result<Sweep> {
        let raw: RawSweep = toml::from_str(text).with_context(|| format!("{source}: not a valid sweep file"))?;
        let nonempty = |field: &str, v: &[String]| -> anyhow::Result<()> {
            if v.is_empty() {
                bail!("{source}: `{field}` is empty; list at least one");
            }
            if let Some(d) = v.iter().enumerate().find_map(|(i, x)| v[..i].contains(x).then_some(x)) {
                bail!("{source}: `{field}` lists `{d}` twice");
            }
            if let Some(bad) = v.iter().find(|x| x.is_empty() || x.contains([',', '"', '\n', '\r'])) {
                bail!("{source}: `{field}` entry `{bad}`: names may not be empty or hold commas, quotes or newlines");
            }
            Ok(())
        };
        for (key, given) in [("speed", raw.speed.is_some()), ("yaw_rate", raw.yaw_rate.is_some())] {
            if given {
                bail!("{source}: {}", groundtruth_scenario::spec::unitless_key(key));
            }
        }
        nonempty("scenes", &raw.scenes)?;
        nonempty("rigs", &raw.rigs)?;
        nonempty("methods", &raw.methods)?;
        if raw.frames == 0 || raw.frames > MAX_FRAMES {
            bail!("{source}: `frames` = {}: allowed 1 ..= {MAX_FRAMES}", raw.frames);
        }
        if !raw.speed_m_per_s.is_finite() || raw.speed_m_per_s.abs() > 100.0 {
            bail!("{source}: `speed_m_per_s` = {}: allowed -100 ..= 100", raw.speed_m_per_s);
        }
        if raw.body.trim().is_empty() {
            bail!("{source}: `body` is empty: \"rig\" or a sensor name");
        }
        let seed_values = expand("seeds", &raw.seeds, source)?;
        let seeds = seed_values
            .iter()
            .map(|v| v.as_u64().with_context(|| format!("{source}: `seeds` value {v}: seeds are integers >= 0")))
            .collect::<anyhow::Result<Vec<u64>>>()?;
        let mut mount = Vec::new();
        for name in raw.mount.keys() {
            if !MOUNT_PARAMS.contains(&name.as_str()) {
                bail!("{source}: unknown mount parameter `mount.{name}`; known: {}", MOUNT_PARAMS.join(", "));
            }
        }
        for name in MOUNT_PARAMS {
            if let Some(values) = raw.mount.get(name) {
                let field = format!("mount.{name}");
                let values = expand(&field, values, source)?;
                if let Some(v) = values.iter().find(|v| !v.is_number()) {
                    bail!("{source}: `{field}` value {v}: mount values are numbers");
                }
                mount.push(Axis { name: name.to_string(), values });
            }
        }
        let mut sensor = Vec::new();
        for (name, values) in &raw.sensor {
            let field = format!("sensor.{name}");
            if name.is_empty() || name.contains([',', '"', '\n']) || name == "model" {
                bail!("{source}: `{field}`: not a sensor parameter");
            }
            sensor.push(Axis { name: field.clone(), values: expand(&field, values, source)? });
        }
        let weather = match raw.weather {
            None => None,
            Some(RawWeather::Specs(list)) => {
                if list.is_empty() {
                    bail!("{source}: `weather` is an empty list; give at least one (e.g. \"clear\")");
                }
                let mut values = Vec::new();
                for spec in &list {
                    let w = sim::effects::weather::Weather::parse(spec)
                        .with_context(|| format!("{source}: `weather` entry `{spec}`"))?;
                    let v = serde_json::Value::from(w.spec());
                    if values.contains(&v) {
                        bail!("{source}: `weather` lists `{spec}` twice");
                    }
                    values.push(v);
                }
                Some(Axis { name: WEATHER_AXIS.to_string(), values })
            }
            Some(RawWeather::Swept(table)) => Some(weather_axis(&table, source)?),
        };
        Ok(Sweep {
            scenes: raw.scenes,
            rigs: raw.rigs,
            seeds,
            methods: raw.methods,
            frames: raw.frames,
            speed_m_per_s: raw.speed_m_per_s,
            ideal: raw.ideal,
            body: raw.body,
            mount,
            sensor,
            weather,
        })
    }

    /// Every swept parameter axis: mount axes, then sensor axes, then the weather.
    pub fn axes(&self) -> impl Iterator<Item = &Axis> {
        self.mount.iter().chain(&self.sensor).chain(&self.weather)
    }

    /// The sweep as canonical JSON (lists expanded): equal sweeps give equal text.
    pub fn canonical(&self) -> serde_json::Value {
        let axes: Vec<serde_json::Value> =
            self.axes().map(|a| serde_json::json!({"name": a.name, "values": a.values})).collect();
        serde_json::json!({
            "scenes": self.scenes,
            "rigs": self.rigs,
            "seeds": self.seeds,
            "methods": self.methods,
            "frames": self.frames,
            "speed_m_per_s": self.speed_m_per_s,
            "ideal": self.ideal,
            "body": self.body,
            "axes": axes,
        })
    }
}

/// `[weather]` with `kind` and one parameter's values: the axis `weather.<parameter>`.
fn weather_axis(table: &BTreeMap<String, toml::Value>, source: &str) -> anyhow::Result<Axis> {
    let kind = match table.get("kind") {
        Some(toml::Value::String(k)) => k.clone(),
        _ => bail!("{source}: `weather.kind`: give the kind swept (fog, rain or snow) as a string"),
    };
    let params: Vec<(&String, &toml::Value)> = table.iter().filter(|(k, _)| k.as_str() != "kind").collect();
    let [(name, raw)] = params.as_slice() else {
        bail!("{source}: `[weather]`: give `kind` and the values of exactly one of its parameters");
    };
    let field = format!("weather.{name}");
    let raw: RawValues =
        toml::Value::clone(raw).try_into().with_context(|| format!("{source}: `{field}`: a list or a range table"))?;
    let values = expand(&field, &raw, source)?;
    for v in &values {
        sim::effects::weather::Weather::parse(&format!("{kind}:{name}={v}"))
            .with_context(|| format!("{source}: `{field}` value {v}"))?;
    }
    Ok(Axis { name: format!("{WEATHER_AXIS}.{kind}.{name}"), values })
}

/// A TOML value as JSON (numbers, strings and booleans only).
fn to_json(field: &str, v: &toml::Value, source: &str) -> anyhow::Result<serde_json::Value> {
    Ok(match v {
        toml::Value::Integer(i) => serde_json::Value::from(*i),
        toml::Value::Float(f) if f.is_finite() => serde_json::Value::from(*f),
        toml::Value::String(s) if !s.contains([',', '"', '\n', '\r']) => serde_json::Value::from(s.clone()),
        toml::Value::Boolean(b) => serde_json::Value::from(*b),
        other => bail!("{source}: `{field}` value {other}: allowed finite numbers, plain strings or booleans"),
    })
}

/// Expands a list or range into values, refusing empty lists, duplicates, zero or negative steps,
/// reversed ranges and more than [`MAX_VALUES`] values.
fn expand(field: &str, raw: &RawValues, source: &str) -> anyhow::Result<Vec<serde_json::Value>> {
    let values: Vec<serde_json::Value> = match raw {
        RawValues::List(list) => {
            if list.is_empty() {
                bail!("{source}: `{field}` is an empty list; give at least one value");
            }
            if list.len() > MAX_VALUES {
                bail!("{source}: `{field}` lists {} values: allowed at most {MAX_VALUES}", list.len());
            }
            list.iter().map(|v| to_json(field, v, source)).collect::<anyhow::Result<_>>()?
        }
        RawValues::Range(r) => expand_range(field, r, source)?,
    };
    for (i, v) in values.iter().enumerate() {
        if values[..i].iter().any(|w| same_value(v, w)) {
            bail!("{source}: `{field}` holds {v} twice");
        }
    }
    Ok(values)
}

fn same_value(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

fn expand_range(field: &str, r: &RawRange, source: &str) -> anyhow::Result<Vec<serde_json::Value>> {
    let num = |name: &str, v: &toml::Value| -> anyhow::Result<(f64, bool)> {
        match v {
            toml::Value::Integer(i) => Ok((*i as f64, true)),
            toml::Value::Float(f) if f.is_finite() => Ok((*f, false)),
            other => bail!("{source}: `{field}.{name}` = {other}: a range takes finite numbers"),
        }
    };
    let (from, from_int) = num("from", &r.from)?;
    let (to, to_int) = num("to", &r.to)?;
    let (step, step_int) = match &r.step {
        Some(s) => num("step", s)?,
        None => (1.0, true),
    };
    if step <= 0.0 {
        bail!("{source}: `{field}.step` = {step}: the step must be > 0 (a zero step never reaches `to`)");
    }
    if to < from {
        bail!("{source}: `{field}` range {from} .. {to} is reversed: `to` must be >= `from`");
    }
    let n = ((to - from) / step + 1e-9).floor() + 1.0;
    if n > MAX_VALUES as f64 {
        bail!("{source}: `{field}` range {from} .. {to} step {step} holds {n} values: allowed at most {MAX_VALUES}");
    }
    let ints = from_int && to_int && step_int;
    Ok((0..n as usize)
        .map(|k| {
            if ints {
                serde_json::Value::from(from as i64 + k as i64 * step as i64)
            } else {
                // Rounded to 1e-9 so 1.2 + 3 * 0.1 reads 1.5, not 1.5000000000000002.
                let v = ((from + k as f64 * step) * 1e9).round() / 1e9;
                serde_json::Value::from(v)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = "scenes = [\"city\"]\nrigs = [\"lux-roof-4\"]\nseeds = [0]\nmethods = [\"nitsch\"]\n";

    #[test]
    fn ranges_expand_inclusively_and_round() {
        let s = Sweep::parse(
            &format!("{BASE}[mount]\nz_m = {{ from = 1.2, to = 2.2, step = 0.1 }}\npitch_deg = {{ from = -6, to = 2, step = 2 }}\n"),
            "t",
        )
        .unwrap();
        assert_eq!(s.mount[0].name, "z_m");
        assert_eq!(s.mount[0].values.len(), 11);
        assert_eq!(s.mount[0].values[3], serde_json::json!(1.5));
        assert_eq!(s.mount[0].values[10], serde_json::json!(2.2));
        assert_eq!(s.mount[1].values, serde_json::json!([-6, -4, -2, 0, 2]).as_array().unwrap().clone());
    }

    #[test]
    fn bad_files_are_refused_naming_the_field() {
        let cases = [
            ("[mount]\nheight = [1.0]\n", "mount.height"),
            ("[mount]\nz_m = []\n", "empty"),
            ("[mount]\nz_m = { from = 2.0, to = 1.0, step = 0.1 }\n", "reversed"),
            ("[mount]\nz_m = { from = 1.0, to = 2.0, step = 0.0 }\n", "step"),
            ("[mount]\nz_m = [1.0, 1.0]\n", "twice"),
            ("frames = 0\n", "frames"),
            ("colour = 1\n", "colour"),
            ("speed = 3.0\n", "invalid value for `speed`"),
            ("yaw_rate = 0.3\n", "invalid value for `yaw_rate`"),
        ];
        for (extra, needle) in cases {
            let text = if extra.starts_with('[') { format!("{BASE}{extra}") } else { format!("{extra}{BASE}") };
            let e = format!("{:#}", Sweep::parse(&text, "t").unwrap_err());
            assert!(e.contains(needle), "{extra}: {e}");
        }
    }
}
