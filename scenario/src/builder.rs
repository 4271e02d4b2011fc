//! The scenario builder: a scene (family and named parameters, a bundled scene, or TOML), a rig
//! (preset, file or value), mount overrides, ideal or measured ranges, seed, frames and speed; then
//! [`Scenario::scan`].

use std::path::Path;

use crate::error::Result;
use crate::mount_override::{MountOverride, MountTarget};
use crate::param_value::ParamValue;
use crate::scan::Scan;
use crate::spec::ScanSpec;

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
    /// The description every setter writes into.
    spec: ScanSpec,
    /// A rig given as a value ([`Scenario::rig_value`]), in place of `spec.rig`.
    rig_value: Option<sim::Rig>,
}

impl Scenario {
    fn new(spec: ScanSpec) -> Self {
        Self { spec, rig_value: None }
    }

    /// A scenario over a whole [`ScanSpec`] (checked at [`Scenario::scan`]); the setters below
    /// change its fields.
    ///
    /// ```
    /// use groundtruth_scenario::{Scenario, ScanSpec};
    /// let spec = ScanSpec { scene: "flat-objects".into(), frames: 2, speed_m_per_s: 5.0, ..Default::default() };
    /// assert_eq!(Scenario::from_spec(spec).scan()?.frames().len(), 2);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn from_spec(spec: ScanSpec) -> Self {
        Self { spec, rig_value: None }
    }

    /// The description of the scan this builder makes.
    pub fn spec(&self) -> &ScanSpec {
        &self.spec
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
        Self::new(ScanSpec { scene: String::new(), family: Some(family.to_string()), ..ScanSpec::default() })
    }

    /// A scene by name: a bundled scene (`ramp-up`, `basin`, `city`, ...; see
    /// `scenes::bundled_names`), a simulator built-in (`flat-objects`) or `fixture-terrain`;
    /// [`Scenario::param`] overrides a bundled scene's parameters.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::bundled("flat-objects").ideal(true).scan()?;
    /// assert!(scan.frames()[0].cloud.returns() > 1000);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::bundled("ramp-down").scan()?;
    /// assert_eq!(scan.family(), "ramp");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn bundled(name: &str) -> Self {
        Self::new(ScanSpec { scene: name.to_string(), ..ScanSpec::default() })
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
        Self::new(ScanSpec { scene: text.to_string(), ..ScanSpec::default() })
    }

    /// A scene from a TOML file; user meshes resolve against its directory.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::toml_file("no/such/scene.toml").scan().unwrap_err();
    /// assert!(err.to_string().contains("no/such/scene.toml"));
    /// ```
    pub fn toml_file(path: impl AsRef<Path>) -> Self {
        Self::new(ScanSpec { scene: path.as_ref().display().to_string(), ..ScanSpec::default() })
    }

    /// Sets the family parameter `name` (a field of the family's `[params]`, e.g. `slope_deg`);
    /// ranges are checked at [`Scenario::scan`], whose error names `params.<name>` and its range.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("ramp").param("slope_deg", 30.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("slope_deg"), "{err}");
    /// ```
    pub fn param(mut self, name: &str, value: impl Into<ParamValue>) -> Self {
        self.spec.params.insert(name.to_string(), value.into());
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
        self.spec.rig = name_or_path.to_string();
        self.rig_value = None;
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
        self.spec.rig.clone_from(&rig.name);
        self.rig_value = Some(rig);
        self
    }

    /// Which sensor of the rig the mount overrides apply to (default: the rig's only sensor; a rig
    /// of several needs one named, or [`Scenario::mount`] with `sensor = "rig"` for the whole rig).
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").sensor(3).mount_z_m(2.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("sensor"), "{err}");
    /// ```
    pub fn sensor(self, index: usize) -> Self {
        self.mount(MountOverride { sensor: Some(MountTarget::Index(index)), ..Default::default() })
    }

    /// Sets the fields `overrides` sets (values, and its target and mode when it names them).
    ///
    /// ```
    /// use groundtruth_scenario::{MountOverride, Scenario};
    /// let o = MountOverride { z_m: Some(0.5), pitch_deg: Some(-2.0), ..Default::default() };
    /// let scan = Scenario::family("flat").mount(o).scan()?;
    /// assert_eq!(scan.rig().sensors[0].mount.z_m, 0.5);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn mount(mut self, overrides: MountOverride) -> Self {
        self.spec.mount.get_or_insert_with(MountOverride::default).merge(&overrides);
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
        self.spec.ideal = ideal;
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
        self.spec.seed = seed;
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
        self.spec.frames = frames as u64;
        self
    }

    /// Ego speed along its heading, metres per second (-100 ..= 100, default 0).
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").speed_m_per_s(500.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("speed_m_per_s"), "{err}");
    /// ```
    pub fn speed_m_per_s(mut self, v: f32) -> Self {
        self.spec.speed_m_per_s = f64::from(v);
        self
    }

    /// Ego yaw rate, degrees per second (-114.59 ..= 114.59, i.e. 2 rad/s; default 0; + turns left).
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").frames(2).speed_m_per_s(5.0).yaw_rate_deg_per_s(17.0).scan()?;
    /// assert!(s.frames()[1].vehicle_pose.yaw_rad > 0.0);
    /// let err = groundtruth_scenario::Scenario::family("flat").yaw_rate_deg_per_s(200.0).scan().unwrap_err();
    /// assert!(err.to_string().contains("yaw_rate_deg_per_s"), "{err}");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn yaw_rate_deg_per_s(mut self, v: f64) -> Self {
        self.spec.yaw_rate_deg_per_s = v;
        self
    }

    /// Ego yaw rate, radians per second: a convenience over [`Scenario::yaw_rate_deg_per_s`] (the
    /// scan's yaw rate is exactly `v`).
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").frames(2).speed_m_per_s(5.0).yaw_rate_rad_per_s(0.3).scan()?;
    /// assert!(s.frames()[1].vehicle_pose.yaw_rad > 0.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn yaw_rate_rad_per_s(mut self, v: f32) -> Self {
        self.spec.set_yaw_rate_rad_per_s(v);
        self
    }

    /// A path `[x, y]` (world frame, metres; 2 or more points) the ego follows at its speed (> 0).
    ///
    /// ```
    /// let s = groundtruth_scenario::Scenario::family("flat").frames(2).speed_m_per_s(5.0).waypoints_m(vec![[0.0, 0.0], [10.0, 10.0]]).scan()?;
    /// assert!(s.frames()[1].vehicle_pose.yaw_rad > 0.7);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn waypoints_m(mut self, points: Vec<[f64; 2]>) -> Self {
        self.spec.waypoints_m = Some(points);
        self
    }

    /// Weather decided per beam (fog by visibility, rain and snow by rate; see
    /// [`sim::effects::weather`]), in place of the scene file's `[weather]` table. Returns from the
    /// medium are labelled fog, rain or snow and are never ground. Refused at [`Scenario::scan`] when
    /// out of range (visibility 1 ..= 100000 m, rain 0 ..= 200 mm/h, snow 0 ..= 5 mm/h).
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
        self.spec.weather = Some(weather);
        self
    }

    /// Range noise as a multiple of each sensor's own (`range_sigma_m`), 0 ..= 10.
    ///
    /// ```
    /// let err = groundtruth_scenario::Scenario::family("flat").noise_scale(20.0).scan().unwrap_err();
    /// assert_eq!(err.to_string(), "invalid value for `noise_scale`: 20 (allowed: 0 ..= 10)");
    /// ```
    pub fn noise_scale(mut self, scale: f64) -> Self {
        self.spec.noise_scale = Some(scale);
        self
    }

    /// Probability that a return is dropped at random, 0 ..= 0.9 (seeded by the scan's seed).
    ///
    /// ```
    /// let all = groundtruth_scenario::Scenario::family("flat").scan()?.frames()[0].cloud.returns();
    /// let some = groundtruth_scenario::Scenario::family("flat").dropout(0.5).scan()?.frames()[0].cloud.returns();
    /// assert!(some < all * 6 / 10 && some > all * 4 / 10, "{some} of {all}");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn dropout(mut self, probability: f64) -> Self {
        self.spec.dropout = Some(probability);
        self
    }

    /// Intensities multiplied by `scale` (clamped to 1), 0 ..= 10.
    pub fn intensity_scale(mut self, scale: f64) -> Self {
        self.spec.intensity_scale = Some(scale);
        self
    }

    /// The ray casting backend (default `bvh`).
    pub fn backend(mut self, backend: crate::spec::ScanBackend) -> Self {
        self.spec.backend = Some(backend);
        self
    }

    /// Generates the scene, builds the rig and scans every frame into labelled ordered clouds.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("elevated").rig("vlp16-roof").scan()?;
    /// assert!(scan.frames()[0].cloud.returns() > 10_000);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scan(&self) -> Result<Scan> {
        self.spec.validate()?;
        let scene = self.spec.load_scene()?;
        let base = match &self.rig_value {
            Some(r) => r.clone(),
            None => crate::spec::load_rig(&self.spec.rig)?,
        };
        let setup = self.spec.setup_with_rig(&scene, base)?;
        let mut frames = sim::scan::scan(&scene.mesh, &setup.rig, &setup.config)?;
        for f in &mut frames {
            self.spec.vary(&mut f.cloud, f.index)?;
        }
        Ok(Scan {
            frames,
            family: scene.family,
            scene_name: scene.name,
            rig: setup.rig,
            geometry: scene.geometry,
            seed: self.spec.seed,
        })
    }
}
