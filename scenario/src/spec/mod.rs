//! [`ScanSpec`]: the one description of a scan, shared by every front end (the scenario builder,
//! the command line's `scan`, `eval`, `bench`, `dataset` and `sweep`, Python and the test suites),
//! and the one function that turns it into what the scanner needs ([`ScanSpec::setup`]).
//!
//! ```toml
//! scene = "ramp-up"            # a bundled scene, a built-in (`flat-objects`, `fixture-terrain`),
//!                              # a family name, a .toml scene file (user meshes), or scene TOML text
//! # family = "ramp"            # or: a generator family with its default parameters
//! params = { slope_deg = 8.0 } # the family's parameters (optional)
//! seed = 1                     # scene generator and every random draw of the scan
//! rig = "hdl64e-roof"          # a rig preset, a .toml rig file, or rig TOML text
//! mount = { sensor = 0, mode = "absolute", z_m = 1.9, pitch_deg = 1.0 }   # optional
//! frames = 10
//! speed_m_per_s = 10.0         # -100 ..= 100
//! yaw_rate_deg_per_s = 5.0     # -114.59 ..= 114.59 (2 rad/s), or:
//! # waypoints_m = [[0, 0], [40, 0], [60, 20]]   # a path followed at speed_m_per_s (> 0)
//! ideal = false                # measurement effects off
//! noise_scale = 1.5            # x the sensor's range sigma, 0 ..= 10 (optional)
//! dropout = 0.05               # probability a return is lost, 0 ..= 0.9 (optional)
//! intensity_scale = 0.8        # 0 ..= 10 (optional)
//! weather = { kind = "fog", visibility_m = 50.0 }   # default: the scene file's [weather]
//! snow_cover_m = 0.1           # snow lying on the ground, (0, 1] m deep (optional)
//! backend = "bvh"              # bvh, parry or gpu (optional; default bvh)
//! ```

mod scene;

use std::collections::BTreeMap;

use serde::de::IgnoredAny;
use serde::{Deserialize, Serialize};
use sim::effects::weather::Weather;
use sim::scan::{MAX_FRAMES, ScanConfig};

pub use scene::{FIXTURE_TERRAIN, LoadedScene, scene_names};
pub(crate) use scene::{SceneSource, is_toml_text};

use crate::error::{Result, ScenarioError};
use crate::mount_override::MountOverride;
use crate::param_value::ParamValue;

/// Largest ego speed, metres per second (either way).
pub const MAX_SPEED_M_PER_S: f64 = 100.0;
/// Largest ego yaw rate, degrees per second (either way): the simulator's 2 rad/s.
pub const MAX_YAW_RATE_DEG_PER_S: f64 = 114.591_559_026_164_65;
/// Largest range noise scale.
pub const MAX_NOISE_SCALE: f64 = 10.0;
/// Largest dropout probability.
pub const MAX_DROPOUT: f64 = 0.9;
/// Largest intensity scale.
pub const MAX_INTENSITY_SCALE: f64 = 10.0;

/// The ray casting backend of a scan.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScanBackend {
    /// obvhs BVH on the CPU: the production, reproducible reference.
    #[default]
    Bvh,
    /// parry3d queries: the reference of the reference.
    Parry,
    /// wgpu compute shaders (builds with the `gpu` feature).
    Gpu,
}

impl ScanBackend {
    /// The backend named `name` (`bvh`, `parry`, `gpu`).
    ///
    /// ```
    /// use groundtruth_scenario::ScanBackend;
    /// assert_eq!(ScanBackend::parse("gpu")?, ScanBackend::Gpu);
    /// assert!(ScanBackend::parse("cuda").unwrap_err().to_string().contains("bvh, parry, gpu"));
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "bvh" => Ok(Self::Bvh),
            "parry" => Ok(Self::Parry),
            "gpu" => Ok(Self::Gpu),
            other => Err(ScenarioError::invalid("backend", format!("`{other}`"), "bvh, parry, gpu")),
        }
    }

    /// The backend of the simulator's `backend`.
    pub fn from_sim(backend: sim::cast::Backend) -> Self {
        match backend {
            sim::cast::Backend::Bvh => Self::Bvh,
            sim::cast::Backend::Parry => Self::Parry,
            sim::cast::Backend::Gpu => Self::Gpu,
        }
    }

    /// The simulator's backend.
    pub fn to_sim(self) -> sim::cast::Backend {
        match self {
            Self::Bvh => sim::cast::Backend::Bvh,
            Self::Parry => sim::cast::Backend::Parry,
            Self::Gpu => sim::cast::Backend::Gpu,
        }
    }
}

/// The one description of a scan: scene, rig, mount, effects, weather, frames and motion. Every
/// quantity has its unit in its name; [`ScanSpec::validate`] names the field and its range;
/// [`ScanSpec::setup`] turns it into the scanner's input. Serialized (TOML, JSON) it is the
/// `--spec` file of `groundtruth scan` and the `spec` of every manifest; unknown keys are refused.
///
/// ```
/// use groundtruth_scenario::ScanSpec;
/// let spec = ScanSpec::from_toml_str("scene = \"flat-objects\"\nrig = \"vlp16-roof\"\nframes = 2\nspeed_m_per_s = 5.0\n", "spec")?;
/// let scene = spec.load_scene()?;
/// let setup = spec.setup(&scene)?;
/// assert_eq!((setup.config.frames, setup.config.speed_m_per_s), (2, 5.0));
/// let again = ScanSpec::from_toml_str(&spec.to_toml_string()?, "again")?;
/// assert_eq!(again, spec);
/// # Ok::<(), groundtruth_scenario::ScenarioError>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanSpec {
    /// The scene: a bundled scene, a simulator built-in (`flat-objects`), `fixture-terrain`, a
    /// generator family, a `.toml` scene file (which may place user meshes), or scene TOML text.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub scene: String,
    /// A generator family with its default parameters, in place of `scene` (a family name that is
    /// also a bundled scene's, e.g. `basin`, names the bundled scene as `scene`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family: Option<String>,
    /// The family's parameters (`slope_deg`, ...), checked against its ranges.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, ParamValue>,
    /// Seed of the scene generator (added to the scene file's own) and of every random draw of the
    /// scan.
    #[serde(default)]
    pub seed: u64,
    /// The rig: a preset, a `.toml` rig file, or rig TOML text.
    pub rig: String,
    /// The mount override.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mount: Option<MountOverride>,
    /// Number of frames, `1 ..= 100000`.
    pub frames: u64,
    /// Ego speed along its heading, metres per second.
    #[serde(default)]
    pub speed_m_per_s: f64,
    /// Ego yaw rate, degrees per second (+ turns left).
    #[serde(default)]
    pub yaw_rate_deg_per_s: f64,
    /// A path `[x, y]` (world frame, metres; 2 or more points) followed at `speed_m_per_s`, in
    /// place of the yaw rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub waypoints_m: Option<Vec<[f64; 2]>>,
    /// Exact ranges: every measurement effect off (noise, quantisation, dropout, weather).
    #[serde(default)]
    pub ideal: bool,
    /// Range noise as a multiple of the sensor's own `range_sigma_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_scale: Option<f64>,
    /// Probability that a return is dropped at random.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dropout: Option<f64>,
    /// Intensities multiplied by this (clamped to 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity_scale: Option<f64>,
    /// Weather per beam (`{ kind = "fog", visibility_m = 50 }`); default the scene file's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weather: Option<Weather>,
    /// Snow lying on the ground, metres deep (`0 < depth <= 1`): every ground triangle raised
    /// by it and labelled terrain with snow's reflectivity (`sim::scene::snow_cover`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub snow_cover_m: Option<f64>,
    /// Ray casting backend (default `bvh`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backend: Option<ScanBackend>,
    /// Never valid: a yaw rate without its unit, kept so that [`ScanSpec::validate`] names the
    /// key to use. Leave `None`.
    #[serde(default, skip_serializing)]
    pub yaw_rate: Option<IgnoredAny>,
    /// Never valid: a yaw rate in radians per second (front ends take degrees per second). Leave
    /// `None`.
    #[serde(default, skip_serializing)]
    pub yaw_rate_rad_per_s: Option<IgnoredAny>,
    /// Never valid: a speed without its unit. Leave `None`.
    #[serde(default, skip_serializing)]
    pub speed: Option<IgnoredAny>,
}

impl Default for ScanSpec {
    /// The command line's `scan` defaults: `flat-objects`, `vlp16-roof`, one frame, standing.
    fn default() -> Self {
        Self {
            scene: "flat-objects".to_string(),
            family: None,
            params: BTreeMap::new(),
            seed: 0,
            rig: "vlp16-roof".to_string(),
            mount: None,
            frames: 1,
            speed_m_per_s: 0.0,
            yaw_rate_deg_per_s: 0.0,
            waypoints_m: None,
            ideal: false,
            noise_scale: None,
            dropout: None,
            intensity_scale: None,
            snow_cover_m: None,
            weather: None,
            backend: None,
            yaw_rate: None,
            yaw_rate_rad_per_s: None,
            speed: None,
        }
    }
}

/// What the scanner needs, made from a [`ScanSpec`] by [`ScanSpec::setup`]: the scan
/// configuration and the rig (the mesh is the loaded scene's).
#[derive(Clone, Debug)]
pub struct ScanSetup {
    /// The simulator's configuration.
    pub config: ScanConfig,
    /// The rig, mount override and noise scale applied.
    pub rig: sim::Rig,
}

/// Checks `value` is finite and within `lo ..= hi`, naming `field`.
fn check(field: &str, value: f64, lo: f64, hi: f64, allowed: &str) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(ScenarioError::invalid(field, value, allowed))
    }
}

/// The error for a key given without its unit (or in another unit than every front end takes).
pub fn unitless_key(key: &str) -> ScenarioError {
    let (use_key, range) = match key {
        "speed" => ("speed_m_per_s", "-100 ..= 100"),
        _ => ("yaw_rate_deg_per_s", "-114.59 ..= 114.59"),
    };
    ScenarioError::invalid(key, "a key without the unit every front end takes", format!("`{use_key}`, {range}"))
}

/// The error a spec gives for `key` when it is none of its fields (or a key without its unit),
/// for front ends that take keyword arguments (Python): the same words as a spec file's.
///
/// ```
/// let e = groundtruth_scenario::spec::key_error("colour", "scan()").to_string();
/// assert!(e.starts_with("scan(): unknown field `colour`, expected one of"), "{e}");
/// assert!(groundtruth_scenario::spec::key_error("yaw_rate", "scan()").to_string().contains("yaw_rate_deg_per_s"));
/// ```
pub fn key_error(key: &str, source: &str) -> ScenarioError {
    if matches!(key, "yaw_rate" | "yaw_rate_rad_per_s" | "speed") {
        return unitless_key(key);
    }
    let value = serde_json::Value::Object([(key.to_string(), serde_json::Value::Null)].into_iter().collect());
    let message = match serde_json::from_value::<ScanSpec>(value) {
        Err(e) => e.to_string(),
        Ok(_) => format!("`{key}` is a field"),
    };
    ScenarioError::Spec { source_name: source.to_string(), message }
}

/// What a spec says of a `mount` key that is none of [`MountOverride`]'s fields.
pub fn mount_key_error(key: &str) -> String {
    let value = serde_json::Value::Object([(key.to_string(), serde_json::Value::Null)].into_iter().collect());
    match serde_json::from_value::<MountOverride>(value) {
        Err(e) => e.to_string(),
        Ok(_) => format!("`{key}` is a field"),
    }
}

impl ScanSpec {
    /// Reads a spec from TOML text; `source` names it in messages.
    pub fn from_toml_str(text: &str, source: &str) -> Result<Self> {
        let spec: ScanSpec = toml::from_str(text).map_err(|e| ScenarioError::Spec {
            source_name: source.to_string(),
            message: e.message().trim_end().to_string(),
        })?;
        spec.validate()?;
        Ok(spec)
    }

    /// Reads a spec from a JSON value (a manifest's `spec`, Python's keyword arguments); `source`
    /// names it in messages.
    pub fn from_json_value(value: serde_json::Value, source: &str) -> Result<Self> {
        let spec: ScanSpec = serde_json::from_value(value)
            .map_err(|e| ScenarioError::Spec { source_name: source.to_string(), message: e.to_string() })?;
        spec.validate()?;
        Ok(spec)
    }

    /// The spec as TOML text.
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| ScenarioError::invalid("spec", e, "TOML values"))
    }

    /// Checks every field, naming it and its allowed range.
    ///
    /// ```
    /// let spec = groundtruth_scenario::ScanSpec { frames: 0, ..Default::default() };
    /// assert_eq!(spec.validate().unwrap_err().to_string(), "invalid value for `frames`: 0 (allowed: 1 ..= 100000)");
    /// ```
    pub fn validate(&self) -> Result<()> {
        if self.yaw_rate.is_some() {
            return Err(unitless_key("yaw_rate"));
        }
        if self.yaw_rate_rad_per_s.is_some() {
            return Err(unitless_key("yaw_rate_rad_per_s"));
        }
        if self.speed.is_some() {
            return Err(unitless_key("speed"));
        }
        self.scene_source()?;
        if self.rig.trim().is_empty() {
            return Err(ScenarioError::invalid("rig", "(empty)", "a rig preset, a .toml rig file or rig TOML text"));
        }
        if self.frames == 0 || self.frames > MAX_FRAMES as u64 {
            return Err(ScenarioError::invalid("frames", self.frames, format!("1 ..= {MAX_FRAMES}")));
        }
        check("speed_m_per_s", self.speed_m_per_s, -MAX_SPEED_M_PER_S, MAX_SPEED_M_PER_S, "-100 ..= 100")?;
        check(
            "yaw_rate_deg_per_s",
            self.yaw_rate_deg_per_s,
            -MAX_YAW_RATE_DEG_PER_S,
            MAX_YAW_RATE_DEG_PER_S,
            "-114.59 ..= 114.59",
        )?;
        if let Some(w) = &self.waypoints_m {
            if w.len() < 2 {
                return Err(ScenarioError::invalid("waypoints_m", format!("{} point(s)", w.len()), "2 or more points"));
            }
            for (k, p) in w.iter().enumerate() {
                for v in p {
                    check(&format!("waypoints_m[{k}]"), *v, -1e6, 1e6, "-1e6 ..= 1e6")?;
                }
            }
            if self.speed_m_per_s <= 0.0 {
                return Err(ScenarioError::invalid("speed_m_per_s", self.speed_m_per_s, "> 0 with waypoints_m"));
            }
            if self.yaw_rate_deg_per_s != 0.0 {
                return Err(ScenarioError::invalid(
                    "yaw_rate_deg_per_s",
                    self.yaw_rate_deg_per_s,
                    "0 with waypoints_m (give one of the two)",
                ));
            }
        }
        for (name, value, max) in [
            ("noise_scale", self.noise_scale, MAX_NOISE_SCALE),
            ("dropout", self.dropout, MAX_DROPOUT),
            ("intensity_scale", self.intensity_scale, MAX_INTENSITY_SCALE),
        ] {
            if let Some(v) = value {
                check(name, v, 0.0, max, &format!("0 ..= {max}"))?;
            }
        }
        for (k, v) in &self.params {
            if let ParamValue::Float(f) = v
                && !f.is_finite()
            {
                return Err(ScenarioError::invalid(format!("params.{k}"), f, "a finite number"));
            }
        }
        if let Some(w) = &self.weather {
            w.validate()?;
        }
        if let Some(d) = self.snow_cover_m {
            let max = f64::from(sim::scene::snow_cover::MAX_SNOW_COVER_M);
            if !(d > 0.0 && d <= max) {
                return Err(ScenarioError::invalid("snow_cover_m", d, format!("0 < depth <= {max}")));
            }
        }
        if let Some(m) = &self.mount {
            m.validate()?;
        }
        Ok(())
    }

    /// Where the scene comes from (`scene` or `family`, exactly one).
    pub(crate) fn scene_source(&self) -> Result<SceneSource> {
        match (&self.family, self.scene.is_empty()) {
            (Some(f), true) => {
                if scenes::families::NAMES.contains(&f.as_str()) {
                    Ok(SceneSource::Family(f.clone()))
                } else {
                    Err(ScenarioError::invalid("family", format!("`{f}`"), scenes::families::NAMES.join(", ")))
                }
            }
            (None, false) => SceneSource::resolve(&self.scene),
            (Some(_), false) => {
                Err(ScenarioError::invalid("family", "set with `scene`", "one of `scene` and `family`"))
            }
            (None, true) => Err(ScenarioError::invalid(
                "scene",
                "(empty)",
                format!("{} (or a .toml scene file, or `family`)", scene_names().join(", ")),
            )),
        }
    }

    /// Generates the scene (load it once and [`ScanSpec::setup`] any number of scans of it, e.g.
    /// with a `sim::scan::PreparedScene` shared by a sweep's configurations).
    pub fn load_scene(&self) -> Result<LoadedScene> {
        let mut loaded = scene::load(self.scene_source()?, &self.params, self.seed)?;
        if let Some(depth_m) = self.snow_cover_m {
            self.validate()?;
            // The vehicle rides on the snow: the scanner follows the surface it finds under it.
            sim::scene::snow_cover::lay_snow_cover(&mut loaded.mesh, depth_m as f32);
        }
        Ok(loaded)
    }

    /// The spec's rig: the preset, file or TOML text, with the mount override and noise scale.
    pub fn rig(&self) -> Result<sim::Rig> {
        self.rig_from(load_rig(&self.rig)?)
    }

    /// `base` (e.g. a sweep's rig with its sensor values) with the spec's mount override and noise
    /// scale applied.
    pub fn rig_from(&self, base: sim::Rig) -> Result<sim::Rig> {
        let mut rig = base;
        if let Some(m) = &self.mount {
            m.apply_to_rig(&mut rig)?;
        }
        if let Some(scale) = self.noise_scale {
            for sensor in &mut rig.sensors {
                let sigma = sensor.spec.measurement().range_sigma_m;
                sensor.spec.measurement_params_mut().range_sigma_m = Some(sigma * scale as f32);
            }
        }
        Ok(rig)
    }

    /// The one function from a description to the scanner's input: validates the spec and makes
    /// the simulator's configuration and the rig for `scene` (the spec's scene, loaded once by
    /// [`ScanSpec::load_scene`]).
    pub fn setup(&self, scene: &LoadedScene) -> Result<ScanSetup> {
        self.setup_with_rig(scene, load_rig(&self.rig)?)
    }

    /// [`ScanSpec::setup`] on a rig already loaded (`base`; the mount override and noise scale are
    /// applied to it).
    pub fn setup_with_rig(&self, scene: &LoadedScene, base: sim::Rig) -> Result<ScanSetup> {
        self.validate()?;
        let rig = self.rig_from(base)?;
        let config = ScanConfig {
            seed: self.seed,
            frames: self.frames as usize,
            speed_m_per_s: self.speed_m_per_s as f32,
            yaw_rate_rad_per_s: self.yaw_rate_deg_per_s.to_radians() as f32,
            ideal: self.ideal,
            backend: self.backend.unwrap_or_default().to_sim(),
            ego_z_m: scene.ego_ground_z_m,
            waypoints_m: self.waypoints_m.clone().unwrap_or_default(),
            weather: self.weather.or(scene.weather),
        };
        config.validate()?;
        Ok(ScanSetup { config, rig })
    }

    /// Applies the spec's per-frame variations (random dropout, intensity scale) to frame `k`'s
    /// cloud; nothing when neither is set. The noise scale is in the rig already.
    pub fn vary(&self, cloud: &mut sim::OrderedCloud, k: usize) -> Result<()> {
        if let Some(p) = self.dropout {
            // The scan's own seed, on a stream of its own (Purpose::Dropout).
            sim::effects::variation::drop_returns(cloud, p as f32, self.seed, k as u32)?;
        }
        if let Some(scale) = self.intensity_scale {
            sim::effects::variation::scale_intensity(cloud, scale as f32)?;
        }
        Ok(())
    }

    /// Whether [`ScanSpec::vary`] changes anything.
    pub fn varies(&self) -> bool {
        self.dropout.is_some() || self.intensity_scale.is_some()
    }

    /// Sets the yaw rate from radians per second such that the scan's yaw rate is exactly `v`
    /// (`f64::from(v).to_degrees()` turns back into `v` as `f32`: the error of the two
    /// multiplications is far below half an `f32` step).
    pub fn set_yaw_rate_rad_per_s(&mut self, v: f32) {
        self.yaw_rate_deg_per_s = f64::from(v).to_degrees();
    }
}

/// Loads a rig: rig TOML text, a preset, or a rig file (`.toml` or any existing file).
pub fn load_rig(rig: &str) -> Result<sim::Rig> {
    if is_toml_text(rig) {
        let mut r = sim::Rig::from_toml_str(rig, "<rig TOML>")?;
        if r.name.is_empty() {
            r.name = "custom".into();
        }
        return Ok(r);
    }
    if sim::rig::PRESETS.contains(&rig) || !(rig.ends_with(".toml") || std::path::Path::new(rig).is_file()) {
        return Ok(sim::Rig::preset(rig)?);
    }
    let text = std::fs::read_to_string(rig).map_err(|source| ScenarioError::Io { path: rig.into(), source })?;
    Ok(sim::Rig::from_toml_str(&text, rig)?)
}

#[cfg(test)]
mod tests;
