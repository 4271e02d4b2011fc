//! Beam sets: a rig's beams in the sensor frame, cast frame after frame from poses alone
//! ([`Caster::cast_beams`](super::Caster::cast_beams)). A CPU backend makes the world rays on the
//! host; a device backend keeps the beams on the device and makes the rays there, so that per frame
//! only the poses go up and only distances and triangles come back.

use glam::{Affine3A, Vec3};

use super::Ray;

/// One beam: where it leaves the sensor and where it points, in the sensor frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beam {
    /// Origin, metres, sensor frame.
    pub origin_in_sensor: Vec3,
    /// Unit direction, sensor frame.
    pub dir_in_sensor: Vec3,
    /// Largest distance considered, metres (> 0; infinity: unlimited).
    pub t_max_m: f32,
    /// Which of a frame's poses places this beam (its sensor and shot time), `< poses_per_frame`.
    pub pose: u32,
    /// How far toward pose `pose + 1` the beam's shot lies, in `[0, 1)`: the beam is placed by the
    /// two poses blended linearly (rotation then normalised direction), so a sensor that fires at
    /// thousands of times a frame needs only a few hundred poses per frame. 0: exactly `pose`.
    pub pose_blend: f32,
    /// A sideways turn, for the sub-rays that sample a beam's divergence: the world direction
    /// `d + side * side_offset`, normalised, where `d` is the beam's normalised world direction
    /// and `side` that of `dir_in_sensor x z` (horizontal, to the beam's right). 0: the beam itself.
    pub side_offset: f32,
}

/// Beams cast together, each placed by one of `poses_per_frame` poses per frame (module docs).
#[derive(Clone, Debug)]
pub struct BeamSet {
    key: u64,
    beams: Vec<Beam>,
    poses_per_frame: usize,
}

/// Why a beam set was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BeamSetError {
    /// A beam's pose slot is out of range.
    #[error("beam {beam}: pose {pose} (allowed: 0 ..< {poses_per_frame})")]
    Pose {
        /// The beam's index.
        beam: usize,
        /// Its pose slot.
        pose: u32,
        /// Poses per frame.
        poses_per_frame: usize,
    },
    /// A beam's origin or direction is not finite, its direction not unit length or its range not
    /// positive.
    #[error("beam {beam}: {field} = {value} (allowed: {allowed})")]
    Value {
        /// The beam's index.
        beam: usize,
        /// The field.
        field: &'static str,
        /// The value given.
        value: String,
        /// Its allowed range.
        allowed: &'static str,
    },
}

impl BeamSet {
    /// A beam set of `beams` placed by `poses_per_frame` poses per frame; checks every beam.
    pub fn new(beams: Vec<Beam>, poses_per_frame: usize) -> Result<Self, BeamSetError> {
        for (i, b) in beams.iter().enumerate() {
            let bad = |field, value: String, allowed| BeamSetError::Value { beam: i, field, value, allowed };
            if !b.side_offset.is_finite() {
                return Err(bad("side_offset", b.side_offset.to_string(), "finite"));
            }
            if !(0.0..1.0).contains(&b.pose_blend) {
                return Err(bad("pose_blend", b.pose_blend.to_string(), "0 <= blend < 1"));
            }
            let last = b.pose as usize + usize::from(b.pose_blend > 0.0);
            if last >= poses_per_frame {
                return Err(BeamSetError::Pose { beam: i, pose: last as u32, poses_per_frame });
            }
            if !b.origin_in_sensor.is_finite() {
                return Err(bad("origin_in_sensor", format!("{}", b.origin_in_sensor), "finite"));
            }
            if !(b.dir_in_sensor.is_finite() && (b.dir_in_sensor.length() - 1.0).abs() < 1e-4) {
                return Err(bad("dir_in_sensor", format!("{}", b.dir_in_sensor), "finite, unit length"));
            }
            if b.t_max_m.is_nan() || b.t_max_m <= 0.0 {
                return Err(bad("t_max_m", b.t_max_m.to_string(), "> 0 (infinity: unlimited)"));
            }
        }
        Ok(Self { key: super::new_ray_set_key(), beams, poses_per_frame })
    }

    /// A key unique to this set in this process (a device backend keeps the set under it).
    pub fn key(&self) -> u64 {
        self.key
    }

    /// The beams.
    pub fn beams(&self) -> &[Beam] {
        &self.beams
    }

    /// Poses per frame.
    pub fn poses_per_frame(&self) -> usize {
        self.poses_per_frame
    }

    /// Frames per [`Caster::cast_beams`](super::Caster::cast_beams) call a pipeline aims at: about
    /// 2 M rays (several frames of a small rig per device dispatch), 1 to 16 frames.
    pub fn frames_per_call(&self) -> usize {
        const RAYS_PER_CALL: usize = 1 << 21;
        (RAYS_PER_CALL / self.beams.len().max(1)).clamp(1, 16)
    }

    /// Whole frames in `poses` (`poses_per_frame` each; a trailing partial frame is ignored).
    pub fn frames_in(&self, poses: &[Affine3A]) -> usize {
        poses.len() / self.poses_per_frame.max(1)
    }

    /// The world ray of beam `b` in a frame whose poses are `frame_poses`
    /// ([`BeamSet::poses_per_frame`] of them).
    pub fn ray(&self, b: usize, frame_poses: &[Affine3A]) -> Ray {
        let beam = &self.beams[b];
        let pose = frame_poses[beam.pose as usize];
        let world_from_sensor = if beam.pose_blend > 0.0 {
            let (next, f) = (frame_poses[beam.pose as usize + 1], beam.pose_blend);
            Affine3A {
                matrix3: pose.matrix3 * (1.0 - f) + next.matrix3 * f,
                translation: pose.translation.lerp(next.translation, f),
            }
        } else {
            pose
        };
        let mut dir = world_from_sensor.transform_vector3(beam.dir_in_sensor).normalize();
        if beam.side_offset != 0.0 {
            let side = world_from_sensor.transform_vector3(beam.dir_in_sensor.cross(Vec3::Z)).normalize_or_zero();
            dir = (dir + side * beam.side_offset).normalize();
        }
        Ray { origin: world_from_sensor.transform_point3(beam.origin_in_sensor), dir, t_max: beam.t_max_m }
    }

    /// Ray `r` of a call with `poses`: beam `r % beams` of frame `r / beams`.
    pub fn call_ray(&self, r: usize, poses: &[Affine3A]) -> Ray {
        let (n, per) = (self.beams.len(), self.poses_per_frame);
        let frame = r / n;
        self.ray(r % n, &poses[frame * per..(frame + 1) * per])
    }

    /// The world rays of every frame in `poses`, frame after frame, each in beam order (made on
    /// the calling thread's rayon pool).
    pub fn rays(&self, poses: &[Affine3A]) -> Vec<Ray> {
        use rayon::prelude::*;
        let mut out =
            vec![Ray { origin: Vec3::ZERO, dir: Vec3::X, t_max: 0.0 }; self.beams.len() * self.frames_in(poses)];
        out.par_chunks_mut(super::CHUNK).enumerate().for_each(|(k, chunk)| {
            for (j, ray) in chunk.iter_mut().enumerate() {
                *ray = self.call_ray(k * super::CHUNK + j, poses);
            }
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_follow_each_frames_pose() {
        let beam = |dir: Vec3, pose| Beam {
            origin_in_sensor: Vec3::new(0.1, 0.0, 0.0),
            dir_in_sensor: dir,
            t_max_m: 50.0,
            pose,
            pose_blend: 0.0,
            side_offset: 0.0,
        };
        let set = BeamSet::new(vec![beam(Vec3::X, 0), beam(Vec3::Y, 1)], 2).unwrap();
        let poses = [
            Affine3A::IDENTITY,
            Affine3A::from_translation(Vec3::new(0.0, 0.0, 2.0)),
            Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2),
            Affine3A::from_translation(Vec3::new(5.0, 0.0, 0.0)),
        ];
        let rays = set.rays(&poses);
        assert_eq!(rays.len(), 4);
        assert_eq!(rays[0], Ray { origin: Vec3::new(0.1, 0.0, 0.0), dir: Vec3::X, t_max: 50.0 });
        assert_eq!(rays[1].origin, Vec3::new(0.1, 0.0, 2.0));
        // Frame 1: the first beam turned 90 degrees about z, the second moved 5 m along x.
        assert!((rays[2].dir - Vec3::Y).length() < 1e-6 && (rays[2].origin - Vec3::new(0.0, 0.1, 0.0)).length() < 1e-6);
        assert_eq!(rays[3].origin, Vec3::new(5.1, 0.0, 0.0));
        // A partial frame is ignored.
        assert_eq!(set.rays(&poses[..3]).len(), 2);
        // A quarter of the way from a pose to the next, 4 m and 10 mrad on: 1 m and 2.5 mrad on,
        // to a few nanoradians (a linear blend's error grows with the square of the step).
        let turned = Affine3A::from_translation(Vec3::new(4.0, 0.0, 0.0)) * Affine3A::from_rotation_z(0.01);
        let blended = BeamSet::new(vec![Beam { pose_blend: 0.25, ..beam(Vec3::X, 0) }], 2).unwrap();
        let r = blended.rays(&[Affine3A::IDENTITY, turned])[0];
        assert!((r.dir - Vec3::new(0.0025f32.cos(), 0.0025f32.sin(), 0.0)).length() < 1e-6, "{}", r.dir);
        assert!((r.origin - Vec3::new(1.0 + 0.1 * 0.0025f32.cos(), 0.1 * 0.0025f32.sin(), 0.0)).length() < 1e-6);
    }

    #[test]
    fn bad_beams_are_refused_naming_the_field() {
        let ok = Beam {
            origin_in_sensor: Vec3::ZERO,
            dir_in_sensor: Vec3::Z,
            t_max_m: 1.0,
            pose: 0,
            pose_blend: 0.0,
            side_offset: 0.0,
        };
        let err = |b: Beam| BeamSet::new(vec![ok, b], 1).unwrap_err().to_string();
        assert_eq!(err(Beam { pose: 1, ..ok }), "beam 1: pose 1 (allowed: 0 ..< 1)");
        // A blend needs the next pose.
        assert_eq!(err(Beam { pose_blend: 0.5, ..ok }), "beam 1: pose 1 (allowed: 0 ..< 1)");
        assert!(err(Beam { side_offset: f32::NAN, ..ok }).contains("side_offset = NaN (allowed: finite)"));
        assert!(err(Beam { pose_blend: 1.0, ..ok }).contains("pose_blend = 1 (allowed: 0 <= blend < 1)"));
        assert!(err(Beam { dir_in_sensor: Vec3::new(0.0, 0.0, 2.0), ..ok }).contains("dir_in_sensor"));
        assert!(err(Beam { origin_in_sensor: Vec3::NAN, ..ok }).contains("origin_in_sensor"));
        assert!(err(Beam { t_max_m: f32::NAN, ..ok }).contains("t_max_m = NaN (allowed: > 0 (infinity: unlimited))"));
        assert!(err(Beam { t_max_m: 0.0, ..ok }).contains("t_max_m = 0"));
        assert!(BeamSet::new(vec![ok], 1).unwrap().key() != BeamSet::new(vec![ok], 1).unwrap().key());
    }
}
