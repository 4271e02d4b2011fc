//! The scenario builder: a scene (family and named parameters, a bundled scene, or TOML), a rig
//! (preset, file or value), mount overrides, ideal or measured ranges, seed, frames and speed; then
//! [`Scenario::scan`].

use std::path::{Path, PathBuf};

use sim::scan::{MAX_FRAMES, ScanConfig};

use crate::error::{Result, ScenarioError};
use crate::geometry::Geometry;
use crate::mount_override::MountOverride;
use crate::param_value::ParamValue;
use crate::scan::Scan;

/// Where the scene comes from.
#[derive(Clone, Debug)]
enum SceneSource {
    Family(String),
    Bundled(String),
    Toml { text: String, base_dir: PathBuf },
    File(PathBuf),
}

/// Where the rig comes from.
#[derive(Clone, Debug)]
enum RigSource {
    Preset(String),
    File(PathBuf),
    Value(sim::Rig),
}

/// A scenario to scan: what the scene is, which rig sees it and how.
///
/// Defaults: rig `vlp16-roof`, measured ranges (noise, dropout: `ideal(false)`), seed 0, one frame,
/// standing vehicle.
///
/// ```
/// use groundtruth_scenario::{Region, Scenario};
///
/// // A 12 deg down ramp 5 m ahead, seen by an HDL-64E mounted at 1.9 m.
/// let scan = Scenario::family("ramp")
///     .param("slope_deg", -12.0)
///     .param("distance_m", 5.0)
///     .rig("hdl64e-roof")
///     .mount_z_m(1.9)
///     .scan()?;
/// let score = scan.score_method("nitsch", &Region::RampSurface)?;
/// assert!(score.recall() >= 0.95, "{score}");
/// # Ok::<(), groundtruth_scenario::ScenarioError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Scenario {
    source: SceneSource,
    params: Vec<(String, ParamValue)>,
    rig: RigSource,
    mount: MountOverride,
    sensor: usize,
    ideal: bool,
    seed: u64,
    frames: usize,
    speed_m_per_s: f32,
    yaw_rate_rad_per_s: f32,
    /// `None`: the scene file's `[weather]`, if any.
    weather: Option<sim::effects::weather::Weather>,
}

impl Scenario {
    fn new(source: SceneSource) -> Self {
        Self {
            source,
            params: Vec::new(),
            rig: RigSource::Preset("vlp16-roof".into()),
            mount: MountOverride::default(),
            sensor: 0,
            ideal: false,
            seed: 0,
            frames: 1,
            speed_m_per_s: 0.0,
            yaw_rate_rad_per_s: 0.0,
            weather: None,
        }
    }

    /// A scene of generator `family` (`ramp`, `basin`, `elevated`, `hill`, `flat`, `city`, ...; see
    /// `scenes::families::NAMES`) with its default parameters; set them with [`Scenario::param`].
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("basin").param("depth_m", 1.5).scan()?;
    /// assert_eq!(scan.family(), "basin");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn family(family: &str) -> Self {
        Self::new(SceneSource::Family(family.to_string()))
    }

    /// A bundled scene by name (`ramp-up`, `basin`, `city`, ...; see `scenes::bundled_names`);
    /// [`Scenario::param`] overrides its parameters.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::bundled("ramp-down").scan()?;
    /// assert_eq!(scan.family(), "ramp");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn bundled(name: &str) -> Self {
        Self::new(SceneSource::Bundled(name.to_string()))
    }

    /// A scene from TOML text (the scene file format of `scenes`); user meshes resolve against
    /// the current directory.
    ///
    /// ```
    /// let text = "version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = 8.0\n";
    /// let scan = groundtruth_scenario::Scenario::toml(text).scan()?;
    /// assert_eq!(scan.family(), "ramp");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn toml(text: &str) -> Self {
        Self::new(SceneSource::Toml { text: text.to_string(), base_dir: PathBuf::from(".") })
    }

    /// A scene from a TOML file; user meshes resolve against its directory.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::toml_file("no/such/scene.toml").scan().unwrap_err();
    /// assert!(err.to_string().contains("no/such/scene.toml"));
    /// ```
    pub fn toml_file(path: impl AsRef<Path>) -> Self {
        Self::new(SceneSource::File(path.as_ref().to_path_buf()))
    }

    /// Sets the family parameter `name` (a field of the family's `[params]`, e.g. `slope_deg`);
    /// ranges are checked at [`Scenario::scan`], whose error names `params.<name>` and its range.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("ramp").param("slope_deg", 30.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("slope_deg"), "{err}");
    /// ```
    pub fn param(mut self, name: &str, value: impl Into<ParamValue>) -> Self {
        self.params.retain(|(n, _)| n != name);
        self.params.push((name.to_string(), value.into()));
        self
    }

    /// The rig preset `name` (`vlp16-roof`, `hdl64e-roof`, `os1-64-roof`, `os1-128-roof`, `lux`,
    /// `lux-roof-4`, ...; see `sim::rig::PRESETS`) or a path to a rig TOML file.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("flat").rig("os1-64-roof").ideal(true).scan()?;
    /// assert_eq!((scan.frames()[0].cloud.rows, scan.frames()[0].cloud.cols), (64, 1024));
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn rig(mut self, name_or_path: &str) -> Self {
        self.rig = if sim::rig::PRESETS.contains(&name_or_path) {
            RigSource::Preset(name_or_path.to_string())
        } else {
            RigSource::File(PathBuf::from(name_or_path))
        };
        self
    }

    /// A rig given as a value (e.g. built in code or loaded with `sim::Rig::load`).
    ///
    /// ```
    /// let rig = sim::Rig::preset("vlp16-roof")?;
    /// let scan = groundtruth_scenario::Scenario::family("flat").rig_value(rig).scan()?;
    /// assert_eq!(scan.frames()[0].cloud.rows, 16);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn rig_value(mut self, rig: sim::Rig) -> Self {
        self.rig = RigSource::Value(rig);
        self
    }

    /// Which sensor of the rig the mount overrides apply to (default 0, the only one of the
    /// single-sensor presets).
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").sensor(3).mount_z_m(2.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("sensor"), "{err}");
    /// ```
    pub fn sensor(mut self, index: usize) -> Self {
        self.sensor = index;
        self
    }

    /// Replaces the set fields of the chosen sensor's mount.
    ///
    /// ```
    /// use groundtruth_scenario::{MountOverride, Scenario};
    /// let o = MountOverride { z_m: Some(0.5), pitch_deg: Some(-2.0), ..Default::default() };
    /// let scan = Scenario::family("flat").mount(o).scan()?;
    /// assert_eq!(scan.rig().sensors[0].mount.z_m, 0.5);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount(mut self, overrides: MountOverride) -> Self {
        let o = overrides;
        let m = &mut self.mount;
        m.x_m = o.x_m.or(m.x_m);
        m.y_m = o.y_m.or(m.y_m);
        m.z_m = o.z_m.or(m.z_m);
        m.roll_deg = o.roll_deg.or(m.roll_deg);
        m.pitch_deg = o.pitch_deg.or(m.pitch_deg);
        m.yaw_deg = o.yaw_deg.or(m.yaw_deg);
        self
    }

    /// Mount position x (forward), metres.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").mount_x_m(0.5).scan()?;
    /// assert_eq!(s.rig().sensors[0].mount.x_m, 0.5);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount_x_m(self, v: f32) -> Self {
        self.mount(MountOverride { x_m: Some(v), ..Default::default() })
    }

    /// Mount position y (left), metres.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").mount_y_m(0.4).scan()?;
    /// assert_eq!(s.rig().sensors[0].mount.y_m, 0.4);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount_y_m(self, v: f32) -> Self {
        self.mount(MountOverride { y_m: Some(v), ..Default::default() })
    }

    /// Mount height above the ground under the rear axle, metres.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").mount_z_m(f32::NAN).scan().unwrap_err();
    /// assert!(err.to_string().contains("mount.z_m"), "{err}");
    /// ```
    pub fn mount_z_m(self, v: f32) -> Self {
        self.mount(MountOverride { z_m: Some(v), ..Default::default() })
    }

    /// Mount roll, degrees.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").mount_roll_deg(3.0).scan()?;
    /// assert_eq!(s.rig().sensors[0].mount.roll_deg, 3.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount_roll_deg(self, v: f32) -> Self {
        self.mount(MountOverride { roll_deg: Some(v), ..Default::default() })
    }

    /// Mount pitch, degrees; positive tilts the sensor down.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").mount_pitch_deg(-5.0).scan()?;
    /// assert_eq!(s.rig().sensors[0].mount.pitch_deg, -5.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount_pitch_deg(self, v: f32) -> Self {
        self.mount(MountOverride { pitch_deg: Some(v), ..Default::default() })
    }

    /// Mount yaw, degrees; positive turns the sensor left.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").mount_yaw_deg(90.0).scan()?;
    /// assert_eq!(s.rig().sensors[0].mount.yaw_deg, 90.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount_yaw_deg(self, v: f32) -> Self {
        self.mount(MountOverride { yaw_deg: Some(v), ..Default::default() })
    }

    /// `true`: exact ranges, every measurement effect off (noise, quantisation, dropout);
    /// `false` (default): the sensor's measurement model.
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").ideal(true).scan()?;
    /// let c = &s.frames()[0].cloud;
    /// let i = (0..c.len()).find(|&i| c.has_return(i) && c.ground[i]).unwrap();
    /// assert!(c.point_in_vehicle[i].z.abs() < 1e-3);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn ideal(mut self, ideal: bool) -> Self {
        self.ideal = ideal;
        self
    }

    /// The seed of the scene generator (added to the file's own seed) and of every random draw of
    /// the scan.
    ///
    /// ```
    /// use groundtruth_scenario::Scenario;
    /// let a = Scenario::family("flat").seed(4).scan()?;
    /// let b = Scenario::family("flat").seed(4).scan()?;
    /// let bits = |s: &groundtruth_scenario::Scan| s.frames()[0].cloud.range_m.iter().map(|r| r.to_bits()).collect::<Vec<_>>();
    /// assert_eq!(bits(&a), bits(&b));
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Number of frames (1 ..= 100000, default 1).
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").frames(2).speed_m_per_s(10.0).scan()?;
    /// assert_eq!(s.frames().len(), 2);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn frames(mut self, frames: usize) -> Self {
        self.frames = frames;
        self
    }

    /// Ego speed along its heading, metres per second (-100 ..= 100, default 0).
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").speed_m_per_s(500.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("speed_m_per_s"), "{err}");
    /// ```
    pub fn speed_m_per_s(mut self, v: f32) -> Self {
        self.speed_m_per_s = v;
        self
    }

    /// Ego yaw rate, radians per second (-2 ..= 2, default 0).
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").frames(2).speed_m_per_s(5.0).yaw_rate_rad_per_s(0.3).scan()?;
    /// assert!(s.frames()[1].vehicle_pose.yaw_rad > 0.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn yaw_rate_rad_per_s(mut self, v: f32) -> Self {
        self.yaw_rate_rad_per_s = v;
        self
    }

    /// Weather decided per beam (fog by visibility, rain and snow by rate; see
    /// [`sim::effects::weather`]), in place of the scene file's `[weather]` table. Returns from the
    /// medium are labelled fog, rain or snow and are never ground. Refused at [`Scenario::scan`] when
    /// out of range (visibility 1 ..= 100000 m, rain 0 ..= 200 mm/h, snow 0 ..= 20 mm/h).
    ///
    /// ```
    /// use groundtruth_scenario::{Scenario, Weather};
    /// let s = Scenario::family("flat").rig("hdl64e-roof").weather(Weather::Fog { visibility_m: 30.0 }).scan()?;
    /// let c = &s.frames()[0].cloud;
    /// let fog = (0..c.len()).filter(|&i| c.has_return(i) && c.label[i] == sim::scene::SemanticClass::FOG).count();
    /// assert!(fog > 1000, "{fog} fog returns");
    /// let err = Scenario::family("flat").weather(Weather::Fog { visibility_m: 0.5 }).scan().unwrap_err();
    /// assert!(err.to_string().contains("visibility_m"), "{err}");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn weather(mut self, weather: sim::effects::weather::Weather) -> Self {
        self.weather = Some(weather);
        self
    }

    /// The scene's TOML text with the parameter overrides applied, and its base directory.
    fn scene_text(&self) -> Result<(String, String, PathBuf)> {
        let (text, name, base_dir) = match &self.source {
            SceneSource::Family(f) => {
                (format!("version = 1\nfamily = {}\n", toml::Value::String(f.clone())), f.clone(), PathBuf::from("."))
            }
            SceneSource::Bundled(n) => {
                let t = scenes::bundled_text(n).ok_or_else(|| scenes::SceneError::UnknownScene {
                    name: n.clone(),
                    known: scenes::bundled_names().join(", "),
                })?;
                (t.to_string(), n.clone(), PathBuf::from("."))
            }
            SceneSource::Toml { text, base_dir } => (text.clone(), "scenario TOML".to_string(), base_dir.clone()),
            SceneSource::File(p) => {
                let t = std::fs::read_to_string(p).map_err(|source| ScenarioError::Io { path: p.clone(), source })?;
                let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
                (t, p.display().to_string(), dir)
            }
        };
        if self.params.is_empty() {
            return Ok((text, name, base_dir));
        }
        let mut doc: toml::Table = text.parse().map_err(|e: toml::de::Error| scenes::SceneError::Toml {
            source_name: name.clone(),
            message: e.to_string(),
        })?;
        let params = doc.entry("params").or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let toml::Value::Table(params) = params else {
            return Err(ScenarioError::invalid("params", "not a table", "a [params] table"));
        };
        for (k, v) in &self.params {
            if let ParamValue::Float(f) = v
                && !f.is_finite()
            {
                return Err(ScenarioError::invalid(format!("params.{k}"), f, "a finite number"));
            }
            params.insert(k.clone(), v.to_toml());
        }
        let text = toml::to_string(&doc).map_err(|e| ScenarioError::invalid("params", e, "TOML values"))?;
        Ok((text, name, base_dir))
    }

    fn build_rig(&self) -> Result<sim::Rig> {
        let mut rig = match &self.rig {
            RigSource::Preset(n) => sim::Rig::preset(n)?,
            RigSource::File(p) => {
                let text =
                    std::fs::read_to_string(p).map_err(|source| ScenarioError::Io { path: p.clone(), source })?;
                let mut rig = sim::Rig::from_toml_str(&text, p)?;
                if rig.name.is_empty() {
                    rig.name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                }
                rig
            }
            RigSource::Value(r) => r.clone(),
        };
        self.mount.validate()?;
        if self.mount != MountOverride::default() {
            let n = rig.sensors.len();
            let s = rig.sensors.get_mut(self.sensor).ok_or_else(|| {
                ScenarioError::invalid(
                    "sensor",
                    self.sensor,
                    format!("0 ..= {} (the rig's sensors)", n.saturating_sub(1)),
                )
            })?;
            s.mount = self.mount.apply(s.mount);
        }
        Ok(rig)
    }

    /// Generates the scene, builds the rig and scans every frame into labelled ordered clouds.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("elevated").rig("vlp16-roof").scan()?;
    /// assert!(scan.frames()[0].cloud.returns() > 10_000);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scan(&self) -> Result<Scan> {
        if self.frames == 0 || self.frames > MAX_FRAMES {
            return Err(ScenarioError::invalid("frames", self.frames, format!("1 ..= {MAX_FRAMES}")));
        }
        let (text, name, base_dir) = self.scene_text()?;
        let scene = scenes::load_str(&text, &name, &base_dir, self.seed)?;
        let geometry = Geometry::parse(&scene.family, &text, &name)?;
        let rig = self.build_rig()?;
        let config = ScanConfig {
            seed: self.seed,
            frames: self.frames,
            speed_m_per_s: self.speed_m_per_s,
            yaw_rate_rad_per_s: self.yaw_rate_rad_per_s,
            ideal: self.ideal,
            ego_z_m: scene.ego_ground_z_m,
            weather: self.weather.or(scene.weather),
            ..ScanConfig::default()
        };
        let frames = sim::scan::scan(&scene.mesh, &rig, &config)?;
        Ok(Scan::new(frames, scene.family, name, rig, geometry, self.seed))
    }
}
