//! A scanned scenario: the labelled ordered clouds, decisions on them (ours by method name, or the
//! user's), region masks and per-region scores.

use classifier::{FrameInput, method_by_name};
use sim::scan::Frame;

use crate::error::{Result, ScenarioError};
use crate::geometry::Geometry;
use crate::region::Region;
use crate::score::RegionScore;

/// Ground decisions of a whole scan: per frame, one `bool` per cell of its cloud (all echo planes,
/// grid order), `true` = ground; cells without a return are ignored.
pub type Decisions = Vec<Vec<bool>>;

/// The result of [`crate::Scenario::scan`].
///
/// ```
/// use groundtruth_scenario::{Region, Scenario};
/// let scan = Scenario::family("flat").ideal(true).scan()?;
/// // A "segmenter" that calls every point below 0.2 m (vehicle frame) ground.
/// let decisions = scan.decide_points(|points| points.iter().map(|p| p[2] < 0.2).collect())?;
/// let ground = scan.score(&Region::Ground, &decisions)?;
/// assert!(ground.recall() > 0.99, "{ground}");
/// # Ok::<(), groundtruth_scenario::ScenarioError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Scan {
    pub(crate) frames: Vec<Frame>,
    pub(crate) family: String,
    pub(crate) scene_name: String,
    pub(crate) rig: sim::Rig,
    pub(crate) geometry: Geometry,
    pub(crate) seed: u64,
}

impl Scan {
    /// Frames from elsewhere (files read back, a recording) as a scan of no known family, named
    /// `scene_name`: the regions that need a family's geometry (`RampSurface`, ...) are refused,
    /// the others work, with the bare ground at z = 0.
    ///
    /// ```
    /// use groundtruth_scenario::{Region, Scan, Scenario};
    /// let frames = Scenario::family("flat").scan()?.frames().to_vec();
    /// let scan = Scan::from_frames(frames, "flat.pcd", sim::Rig { name: String::new(), sensors: Vec::new() });
    /// assert!(scan.region_mask(0, &Region::Ground)?.iter().any(|&m| m));
    /// assert!(scan.region_mask(0, &Region::RampSurface).is_err());
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn from_frames(frames: Vec<Frame>, scene_name: &str, rig: sim::Rig) -> Self {
        Self {
            frames,
            family: "unknown".into(),
            scene_name: scene_name.into(),
            rig,
            geometry: Geometry::Other,
            seed: 0,
        }
    }

    /// The scanned frames: labelled ordered clouds (points in the vehicle frame, labels, instances,
    /// true normals, ground flags) and the vehicle poses.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("flat").scan()?;
    /// let c = &scan.frames()[0].cloud;
    /// assert_eq!(c.rows, 16);
    /// assert_eq!(c.len(), c.rows * c.cols * c.planes);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// The scene's generator family.
    ///
    /// ```
    /// assert_eq!(groundtruth_scenario::Scenario::bundled("hill").scan()?.family(), "hill");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn family(&self) -> &str {
        &self.family
    }

    /// The scene's name (bundled name, family or file).
    ///
    /// ```
    /// assert_eq!(groundtruth_scenario::Scenario::bundled("basin").scan()?.scene_name(), "basin");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn scene_name(&self) -> &str {
        &self.scene_name
    }

    /// The rig as scanned (mount overrides applied).
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("flat").mount_z_m(0.6).scan()?;
    /// assert_eq!(scan.rig().sensors[0].mount.z_m, 0.6);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn rig(&self) -> &sim::Rig {
        &self.rig
    }

    /// The scenario's seed.
    ///
    /// ```
    /// assert_eq!(groundtruth_scenario::Scenario::family("flat").seed(9).scan()?.seed(), 9);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Height of the scene's bare ground (terrain without objects) at world (x, y), metres, from the
    /// family's geometry parameters (0 for families without relief parameters).
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("basin").param("depth_m", 1.5).scan()?;
    /// assert_eq!(scan.ground_z_m(10.0, -9.0), -1.5);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn ground_z_m(&self, x_m: f32, y_m: f32) -> f32 {
        self.geometry.ground_z_m(x_m, y_m)
    }

    /// The mask of `region` over frame `frame`'s cloud: one `bool` per cell.
    ///
    /// ```
    /// use groundtruth_scenario::{Region, Scenario};
    /// let scan = Scenario::family("elevated").scan()?;
    /// let roofs = scan.region_mask(0, &Region::VehicleRoofs)?;
    /// assert!(roofs.iter().filter(|&&m| m).count() > 50);
    /// // Asking a region of another family is an error, not an empty mask.
    /// assert!(scan.region_mask(0, &Region::RampSurface).is_err());
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn region_mask(&self, frame: usize, region: &Region) -> Result<Vec<bool>> {
        let f = self.frames.get(frame).ok_or_else(|| {
            ScenarioError::invalid("frame", frame, format!("0 ..= {}", self.frames.len().saturating_sub(1)))
        })?;
        region.mask(f, &self.geometry, &self.family)
    }

    /// Classifies every frame with one of our methods by name (`nitsch`, `ransac`, `grid`,
    /// `mcdaniel`, ...; see `classifier::METHODS`), seed 0.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("flat").scan()?;
    /// let d = scan.classify("ransac")?;
    /// assert_eq!(d[0].len(), scan.frames()[0].cloud.len());
    /// assert!(scan.classify("no-such-method").is_err());
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn classify(&self, method: &str) -> Result<Decisions> {
        let mut m = method_by_name(method, 0)?;
        self.frames
            .iter()
            .map(|f| {
                let input =
                    FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
                Ok(m.classify(&input)?)
            })
            .collect()
    }

    /// Runs a point-list segmenter on every frame: `segment` gets the frame's returns as `[x, y, z]`
    /// in the vehicle frame (metres; x forward, y left, z up from the ground under the rear axle)
    /// and must return one decision per point, `true` = ground. The decisions are written back
    /// into the frame's cells.
    ///
    /// ```
    /// let scan = groundtruth_scenario::Scenario::family("flat").scan()?;
    /// // A wrong-length answer is an error naming the frame.
    /// let err = scan.decide_points(|_| vec![true]).unwrap_err();
    /// assert!(err.to_string().contains("frame 0"), "{err}");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn decide_points(&self, mut segment: impl FnMut(&[[f32; 3]]) -> Vec<bool>) -> Result<Decisions> {
        self.frames
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let c = &f.cloud;
                let cells: Vec<usize> = (0..c.len()).filter(|&i| c.has_return(i)).collect();
                let points: Vec<[f32; 3]> = cells.iter().map(|&i| c.point_in_vehicle[i].to_array()).collect();
                let answer = segment(&points);
                if answer.len() != points.len() {
                    return Err(ScenarioError::Shape {
                        what: format!("points of frame {k}"),
                        expected: points.len(),
                        got: answer.len(),
                    });
                }
                let mut d = vec![false; c.len()];
                for (&i, &g) in cells.iter().zip(&answer) {
                    d[i] = g;
                }
                Ok(d)
            })
            .collect()
    }

    /// Scores `decisions` (per frame, one `bool` per cell) over `region`, pooled over the frames.
    /// Errors if the shapes differ from the scan's, or the region holds no return.
    ///
    /// ```
    /// use groundtruth_scenario::{Region, Scenario};
    /// let scan = Scenario::family("flat").scan()?;
    /// let all_ground: Vec<Vec<bool>> = scan.frames().iter().map(|f| vec![true; f.cloud.len()]).collect();
    /// let s = scan.score(&Region::NonGround, &all_ground)?;
    /// assert_eq!(s.false_ground_rate(), 1.0);
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn score(&self, region: &Region, decisions: &[impl AsRef<[bool]>]) -> Result<RegionScore> {
        if decisions.len() != self.frames.len() {
            return Err(ScenarioError::Shape {
                what: "frames".into(),
                expected: self.frames.len(),
                got: decisions.len(),
            });
        }
        let mut score = RegionScore { region: region.to_string(), ..RegionScore::default() };
        for (k, (f, d)) in self.frames.iter().zip(decisions).enumerate() {
            let d = d.as_ref();
            if d.len() != f.cloud.len() {
                return Err(ScenarioError::Shape {
                    what: format!("cells of frame {k}"),
                    expected: f.cloud.len(),
                    got: d.len(),
                });
            }
            let mask = region.mask(f, &self.geometry, &self.family)?;
            for i in (0..d.len()).filter(|&i| mask[i]) {
                score.add(f.cloud.ground[i], d[i]);
            }
        }
        if score.returns() == 0 {
            return Err(ScenarioError::EmptyRegion { region: region.to_string(), frames: self.frames.len() });
        }
        Ok(score)
    }

    /// Scores the decisions on frame `frame` alone (one `bool` per cell) over `region`; as
    /// [`Scan::score`] for a single frame.
    ///
    /// ```
    /// use groundtruth_scenario::{Region, Scenario};
    /// let scan = Scenario::family("flat").frames(2).scan()?;
    /// let d = scan.classify("nitsch")?;
    /// let s = scan.score_frame(1, &Region::Ground, &d[1])?;
    /// assert!(s.recall() > 0.9, "{s}");
    /// assert!(scan.score_frame(2, &Region::Ground, &d[1]).is_err());
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn score_frame(&self, frame: usize, region: &Region, decisions: &[bool]) -> Result<RegionScore> {
        let mask = self.region_mask(frame, region)?;
        let c = &self.frames[frame].cloud;
        if decisions.len() != c.len() {
            return Err(ScenarioError::Shape {
                what: format!("cells of frame {frame}"),
                expected: c.len(),
                got: decisions.len(),
            });
        }
        let mut score = RegionScore { region: region.to_string(), ..RegionScore::default() };
        for i in (0..c.len()).filter(|&i| mask[i]) {
            score.add(c.ground[i], decisions[i]);
        }
        if score.returns() == 0 {
            return Err(ScenarioError::EmptyRegion { region: region.to_string(), frames: 1 });
        }
        Ok(score)
    }

    /// Classifies with our method `method` ([`Scan::classify`]) and scores it over `region`.
    ///
    /// ```
    /// use groundtruth_scenario::{Region, Scenario};
    /// let scan = Scenario::family("basin").param("depth_m", 2.0).rig("os1-64-roof").scan()?;
    /// let beyond = scan.score_method("nitsch", &Region::BeyondBasin)?;
    /// assert!(beyond.recall() >= 0.9, "{beyond}");
    /// # Ok::<(), groundtruth_scenario::ScenarioError>(())
    /// ```
    pub fn score_method(&self, method: &str, region: &Region) -> Result<RegionScore> {
        self.score(region, &self.classify(method)?)
    }
}
