//! The configuration space of a sweep: the product scenes x seeds x rigs x every parameter axis,
//! numbered `0 .. count` in mixed radix (the last axis varies fastest), decoded on demand so
//! nothing proportional to the count is held in memory.
//!
//! Each configuration is a `groundtruth_scenario::ScanSpec` ([`Space::spec`]); its mount values are
//! the spec's mount override (`sensor` = the body, `absolute`), checked against the one set of
//! mount limits. A configuration's parameters are applied to its rig:
//! - `body = "<sensor>"`: the mount values replace that sensor's `mount` fields (absolute, as in
//!   the manifest) and the sensor values its `spec` fields;
//! - `body = "rig"` (default): the whole rig moves as one rigid body. Its reference point is the
//!   mean of the sensors' mount positions (`lux-roof-4`: x 1.6, y 0, z 1.6); `x_m y_m z_m` place that
//!   point (absolute, vehicle frame) and `roll_deg pitch_deg yaw_deg` turn the body about it,
//!   relative to the rig as designed (0 = as mounted; +pitch tilts every sensor down), so the
//!   sensors keep their relative poses. Sensor values apply to every sensor.
//!
//! Every configuration has a key: the [`stable_key`] of its canonical description (scene, seed,
//! rig, frames, speed, ideal, body and every parameter value), the same sharded or not, on any
//! machine.

use anyhow::{Context, bail};
use groundtruth_scenario::{MountOverride, MountTarget, ScanSpec};
use sim::Rig;

use super::config::{MAX_CONFIGURATIONS, Sweep};
use crate::cli::shard::stable_key;

/// A validated sweep with its rigs loaded: the configuration space.
pub struct Space {
    /// The sweep.
    pub sweep: Sweep,
    /// The base rig of each `sweep.rigs` entry.
    pub rigs: Vec<Rig>,
    /// Number of values of each axis (mount, then sensor), for decoding.
    radix: Vec<u64>,
    /// Configurations per (scene, seed) group.
    pub group_size: u64,
    /// Number of configurations.
    pub count: u64,
}

/// One configuration, decoded from its index.
#[derive(Clone, Debug)]
pub struct Configuration {
    /// Its index in the space.
    pub index: u64,
    /// Index into `sweep.scenes`.
    pub scene: usize,
    /// Index into `sweep.seeds`.
    pub seed: usize,
    /// Index into `sweep.rigs`.
    pub rig: usize,
    /// Value index of each axis.
    pub values: Vec<usize>,
}

impl Space {
    /// Checks every name and value of `sweep` and counts the product; more than
    /// [`MAX_CONFIGURATIONS`] is refused unless `allow_large`.
    pub fn new(sweep: Sweep, allow_large: bool) -> anyhow::Result<Space> {
        let known = crate::cli::common::scene_names();
        for s in &sweep.scenes {
            let is_file = s.ends_with(".toml");
            if is_file && !std::path::Path::new(s).is_file() {
                bail!("scenes: `{s}`: no such scene file");
            }
            if !is_file && !known.contains(s) && s != crate::cli::common::FIXTURE_TERRAIN {
                bail!("scenes: unknown scene `{s}`; known: {} (or a .toml scene file)", known.join(", "));
            }
        }
        let rigs = sweep
            .rigs
            .iter()
            .map(|r| crate::cli::common::load_rig(r).with_context(|| format!("rigs: `{r}`")))
            .collect::<anyhow::Result<Vec<Rig>>>()?;
        for m in &sweep.methods {
            classifier::method_by_name(m, 0).with_context(|| format!("methods: `{m}`"))?;
        }
        if sweep.body != "rig" {
            for (name, rig) in sweep.rigs.iter().zip(&rigs) {
                if !rig.sensors.iter().any(|s| s.name == sweep.body) {
                    let names: Vec<&str> = rig.sensors.iter().map(|s| s.name.as_str()).collect();
                    bail!(
                        "body: rig `{name}` has no sensor `{}`; its sensors: {} (or \"rig\")",
                        sweep.body,
                        names.join(", ")
                    );
                }
            }
        }
        let radix: Vec<u64> = sweep.axes().map(|a| a.values.len() as u64).collect();
        let too_many = || {
            anyhow::anyhow!(
                "the sweep's product exceeds {MAX_CONFIGURATIONS} configurations; narrow it or pass --allow-large"
            )
        };
        let group_size =
            radix.iter().try_fold(sweep.rigs.len() as u64, |a, &n| a.checked_mul(n)).ok_or_else(too_many)?;
        let count = group_size
            .checked_mul(sweep.scenes.len() as u64)
            .and_then(|c| c.checked_mul(sweep.seeds.len() as u64))
            .ok_or_else(too_many)?;
        if count > MAX_CONFIGURATIONS && !allow_large {
            bail!(
                "the sweep's product is {count} configurations (scenes x seeds x rigs x parameter values), over \
                 {MAX_CONFIGURATIONS}; narrow it or pass --allow-large"
            );
        }
        let space = Space { sweep, rigs, radix, group_size, count };
        // Each value applied alone to each rig must give a valid rig (e.g. z_m within +-100 m,
        // LUX frequency 12.5 / 25 / 50 Hz, a spec field the model has).
        for (r, rig) in space.rigs.iter().enumerate() {
            for (a, axis) in space.sweep.axes().enumerate() {
                for k in 0..axis.values.len() {
                    let mut values: Vec<Option<usize>> = vec![None; space.radix.len()];
                    values[a] = Some(k);
                    space.apply(rig, &values).with_context(|| {
                        format!("`{}` = {} on rig `{}`", axis.name, axis.values[k], space.sweep.rigs[r])
                    })?;
                }
            }
        }
        Ok(space)
    }

    /// Number of (scene, seed) groups.
    pub fn groups(&self) -> u64 {
        (self.sweep.scenes.len() * self.sweep.seeds.len()) as u64
    }

    /// Decodes configuration `index` (< `count`).
    pub fn decode(&self, index: u64) -> Configuration {
        let group = index / self.group_size;
        let mut rest = index % self.group_size;
        let mut values = vec![0usize; self.radix.len()];
        for (v, &n) in values.iter_mut().zip(&self.radix).rev() {
            *v = (rest % n) as usize;
            rest /= n;
        }
        let seeds = self.sweep.seeds.len() as u64;
        Configuration {
            index,
            scene: (group / seeds) as usize,
            seed: (group % seeds) as usize,
            rig: rest as usize,
            values,
        }
    }

    /// The configuration's parameters as `(column, value)` pairs, in column order.
    pub fn params<'s>(&'s self, c: &Configuration) -> impl Iterator<Item = (&'s str, &'s serde_json::Value)> {
        self.sweep.axes().zip(c.values.clone()).map(|(a, k)| (a.name.as_str(), &a.values[k]))
    }

    /// The configuration's stable key.
    pub fn key(&self, c: &Configuration) -> String {
        let s = &self.sweep;
        let mut text = format!(
            "scene={};seed={};rig={};frames={};speed_m_per_s={};ideal={};body={}",
            s.scenes[c.scene], s.seeds[c.seed], s.rigs[c.rig], s.frames, s.speed_m_per_s, s.ideal, s.body
        );
        for (name, v) in self.params(c) {
            text.push_str(&format!(";{name}={v}"));
        }
        stable_key(&text)
    }

    /// The weather of configuration `c` (`None` when the sweep has no weather axis).
    pub fn weather(&self, c: &Configuration) -> anyhow::Result<Option<sim::effects::weather::Weather>> {
        let Some((name, v)) =
            self.params(c).find(|(name, _)| name.split('.').next() == Some(super::config::WEATHER_AXIS))
        else {
            return Ok(None);
        };
        // `weather` holds specs; `weather.KIND.FIELD` one field's numbers.
        let spec = match name.split('.').collect::<Vec<_>>().as_slice() {
            [_, kind, field] => format!("{kind}:{field}={v}"),
            _ => v.as_str().unwrap_or_default().to_string(),
        };
        Ok(Some(sim::effects::weather::Weather::parse(&spec)?))
    }

    /// The scan spec of configuration `c`: its scene, seed, rig, the mount override its mount
    /// values make (on `body`), frames, speed and weather. Its rig's sensor values are applied to
    /// the base rig by [`Space::sensor_rig`].
    pub fn spec(&self, c: &Configuration) -> anyhow::Result<ScanSpec> {
        let values: Vec<Option<usize>> = c.values.iter().map(|&k| Some(k)).collect();
        Ok(ScanSpec {
            scene: self.sweep.scenes[c.scene].clone(),
            seed: self.sweep.seeds[c.seed],
            rig: self.sweep.rigs[c.rig].clone(),
            mount: Some(self.mount(&values)?),
            frames: self.sweep.frames as u64,
            speed_m_per_s: f64::from(self.sweep.speed_m_per_s),
            ideal: self.sweep.ideal,
            weather: self.weather(c)?,
            ..ScanSpec::default()
        })
    }

    /// The base rig of configuration `c` with its sensor values (not its mount values) applied.
    pub fn sensor_rig(&self, c: &Configuration) -> anyhow::Result<Rig> {
        let values: Vec<Option<usize>> = c.values.iter().map(|&k| Some(k)).collect();
        self.with_sensor_values(&self.rigs[c.rig], &values)
    }

    /// The rig of configuration `c` (the sweep scans through [`Space::spec`]).
    #[cfg(test)]
    pub fn rig(&self, c: &Configuration) -> anyhow::Result<Rig> {
        Ok(self.spec(c)?.rig_from(self.sensor_rig(c)?)?)
    }

    /// The mount override of the given axis values (`None`: left as designed) on `body`.
    fn mount(&self, values: &[Option<usize>]) -> anyhow::Result<MountOverride> {
        let sensor = match self.sweep.body.as_str() {
            "rig" => MountTarget::rig(),
            name => MountTarget::Name(name.to_string()),
        };
        let mut o = MountOverride { sensor: Some(sensor), ..MountOverride::default() };
        for (axis, k) in self.sweep.axes().zip(values) {
            let Some(k) = *k else { continue };
            let v = || axis.values[k].as_f64().context("mount values are numbers").map(|v| Some(v as f32));
            match axis.name.as_str() {
                "x_m" => o.x_m = v()?,
                "y_m" => o.y_m = v()?,
                "z_m" => o.z_m = v()?,
                "roll_deg" => o.roll_deg = v()?,
                "pitch_deg" => o.pitch_deg = v()?,
                "yaw_deg" => o.yaw_deg = v()?,
                _ => {}
            }
        }
        Ok(o)
    }

    /// `base` with the given axis values (`None`: left as designed) applied, validated.
    fn apply(&self, base: &Rig, values: &[Option<usize>]) -> anyhow::Result<Rig> {
        let mut rig = self.with_sensor_values(base, values)?;
        self.mount(values)?.apply_to_rig(&mut rig)?;
        Ok(rig)
    }

    /// `base` with the sensor values of the given axes applied (to `body`, or every sensor of the
    /// rig), validated.
    fn with_sensor_values(&self, base: &Rig, values: &[Option<usize>]) -> anyhow::Result<Rig> {
        let mut rig = base.clone();
        let mut sensor: Vec<(&str, &serde_json::Value)> = Vec::new();
        for (axis, k) in self.sweep.axes().zip(values) {
            let Some(k) = *k else { continue };
            let first = axis.name.split('.').next();
            if first == Some(super::config::WEATHER_AXIS) || super::config::MOUNT_PARAMS.contains(&axis.name.as_str()) {
                continue;
            }
            sensor.push((axis.name.trim_start_matches("sensor."), &axis.values[k]));
        }
        let targets: Vec<usize> = if self.sweep.body == "rig" {
            (0..rig.sensors.len()).collect()
        } else {
            vec![rig.sensors.iter().position(|s| s.name == self.sweep.body).context("body sensor")?]
        };
        if !sensor.is_empty() {
            for &i in &targets {
                let s = &mut rig.sensors[i];
                let mut spec = serde_json::to_value(&s.spec).context("sensor spec as JSON")?;
                for &(field, v) in &sensor {
                    set_path(&mut spec, field, v.clone());
                }
                s.spec = serde_json::from_value(spec).with_context(|| {
                    format!("sensor `{}` ({}): not a parameter of its model", s.name, s.spec.model_name())
                })?;
            }
        }
        rig.validate().map_err(anyhow::Error::from)?;
        Ok(rig)
    }
}

/// Sets `spec.a.b.c = v`, creating tables on the way.
fn set_path(spec: &mut serde_json::Value, path: &str, v: serde_json::Value) {
    let mut node = spec;
    let parts: Vec<&str> = path.split('.').collect();
    for (i, p) in parts.iter().enumerate() {
        if !node.is_object() {
            *node = serde_json::json!({});
        }
        let obj = node.as_object_mut().expect("an object");
        if i + 1 == parts.len() {
            obj.insert(p.to_string(), v);
            return;
        }
        node = obj.entry(p.to_string()).or_insert_with(|| serde_json::json!({}));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn space(extra: &str) -> Space {
        let text = format!(
            "scenes = [\"city\", \"flat\"]\nrigs = [\"lux-roof-4\"]\nseeds = [0, 1]\nmethods = [\"nitsch\"]\n{extra}"
        );
        Space::new(Sweep::parse(&text, "t").unwrap(), false).unwrap()
    }

    #[test]
    fn decode_covers_the_product_in_mixed_radix() {
        let s = space("[mount]\nz_m = [1.2, 1.6, 2.0]\npitch_deg = [-2.0, 0.0]\n");
        assert_eq!(s.count, 2 * 2 * 3 * 2);
        assert_eq!(s.group_size, 6);
        let c = s.decode(7);
        assert_eq!((c.scene, c.seed, c.rig, c.values.clone()), (0, 1, 0, vec![0, 1]));
        let keys: std::collections::HashSet<String> = (0..s.count).map(|i| s.key(&s.decode(i))).collect();
        assert_eq!(keys.len() as u64, s.count);
    }

    #[test]
    fn the_rig_moves_as_one_body() {
        let s = space("[mount]\nz_m = [2.0]\npitch_deg = [2.0]\n");
        let rig = s.rig(&s.decode(0)).unwrap();
        // Reference point (1.6, 0, 1.6) lifted to z 2.0; every sensor pitched 2 deg further down.
        let base = Rig::preset("lux-roof-4").unwrap();
        for (a, b) in rig.sensors.iter().zip(&base.sensors) {
            assert!((a.mount.pitch_deg - (b.mount.pitch_deg + 2.0)).abs() < 1e-4, "{:?}", a.mount);
            assert!(a.mount.roll_deg.abs() < 1e-4 && a.mount.yaw_deg.abs() < 1e-4);
        }
        let mean_z: f32 = rig.sensors.iter().map(|s| s.mount.z_m).sum::<f32>() / 4.0;
        assert!((mean_z - 2.0).abs() < 1e-5, "{mean_z}");
        // Height only: positions shift, angles are kept exactly.
        let s = space("[mount]\nz_m = [1.2]\n");
        let rig = s.rig(&s.decode(0)).unwrap();
        assert_eq!(rig.sensors[2].mount.pitch_deg, 7.2);
        assert!((rig.sensors[2].mount.z_m - 1.2).abs() < 1e-6);
    }

    #[test]
    fn sensor_parameters_and_one_named_sensor() {
        // LUX frequency on every sensor of the rig.
        let s = space("[sensor]\nfrequency_hz = [12.5, 25.0]\n");
        assert_eq!(s.count, 2 * 2 * 2);
        let rig = s.rig(&s.decode(1)).unwrap();
        for sensor in &rig.sensors {
            let sim::sensor::SensorSpec::IbeoLux(lux) = &sensor.spec else { panic!("not a LUX") };
            assert_eq!(lux.frequency_hz, 25.0);
        }
        // One named sensor: absolute mount values, the others untouched.
        let s = space("body = \"roof_3\"\n[mount]\npitch_deg = [12.0]\nz_m = [1.9]\n");
        let rig = s.rig(&s.decode(0)).unwrap();
        let base = Rig::preset("lux-roof-4").unwrap();
        assert_eq!(rig.sensors[3].mount.pitch_deg, 12.0);
        assert_eq!(rig.sensors[3].mount.z_m, 1.9);
        assert_eq!(rig.sensors[..3], base.sensors[..3]);
        // OS1 columns.
        let text = "scenes = [\"flat\"]\nrigs = [\"os1-64-roof\"]\nseeds = [0]\nmethods = [\"nitsch\"]\n\
                    [sensor]\ncolumns = [512, 1024]\n";
        let s = Space::new(Sweep::parse(text, "t").unwrap(), false).unwrap();
        let rig = s.rig(&s.decode(0)).unwrap();
        let sim::sensor::SensorSpec::Os1_64(os1) = &rig.sensors[0].spec else { panic!("not an OS1-64") };
        assert_eq!(os1.columns, 512);
    }

    #[test]
    fn bad_values_and_products_are_refused() {
        let bad = |extra: &str, needle: &str| {
            let text =
                format!("scenes = [\"city\"]\nrigs = [\"lux-roof-4\"]\nseeds = [0]\nmethods = [\"nitsch\"]\n{extra}");
            let e = match Sweep::parse(&text, "t").and_then(|s| Space::new(s, false)) {
                Ok(_) => panic!("{extra} accepted"),
                Err(e) => format!("{e:#}"),
            };
            assert!(e.contains(needle), "{extra}: {e}");
        };
        bad("[mount]\nz_m = [200.0]\n", "invalid value for `mount.z_m`: 200 (allowed: -100 ..= 100)");
        bad("[sensor]\nfrequency_hz = [13.0]\n", "frequency_hz");
        bad("[sensor]\ncolumns = [1024]\n", "columns");
        bad("body = \"roof_9\"\n", "roof_9");
        bad(
            "[mount]\nx_m = { from = 0, to = 99 }\ny_m = { from = 0, to = 99 }\nz_m = { from = 0, to = 99 }\nyaw_deg = { from = 0, to = 99 }\n",
            "--allow-large",
        );
    }
}
