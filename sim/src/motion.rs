//! Ego motion: a vehicle driving at constant speed and yaw rate, following the terrain under its
//! wheels. Every shot takes the vehicle pose at its own time, so clouds show motion distortion as a
//! real (uncompensated) sensor does.

use glam::{Affine3A, EulerRot, Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::cast::{Caster, Ray};

/// Wheelbase used for terrain following, metres (the vehicle origin is on the ground below the
/// rear axle; front wheels at `x = WHEELBASE_M`).
pub const WHEELBASE_M: f32 = 2.8;
/// Half track width used for terrain following, metres.
pub const HALF_TRACK_M: f32 = 0.8;

/// A vehicle pose in the world: position (metres) and roll / pitch / yaw (radians, ISO 8855).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct VehiclePose {
    /// Position x, metres.
    pub x_m: f64,
    /// Position y, metres.
    pub y_m: f64,
    /// Position z (ground below the rear axle), metres.
    pub z_m: f64,
    /// Roll, radians.
    pub roll_rad: f64,
    /// Pitch, radians (positive: nose down).
    pub pitch_rad: f64,
    /// Yaw, radians (positive: left of +x).
    pub yaw_rad: f64,
}

impl VehiclePose {
    /// The transform taking vehicle-frame points to the world.
    pub fn world_from_vehicle(&self) -> Affine3A {
        let rot = Quat::from_euler(EulerRot::ZYX, self.yaw_rad as f32, self.pitch_rad as f32, self.roll_rad as f32);
        Affine3A::from_rotation_translation(rot, Vec3::new(self.x_m as f32, self.y_m as f32, self.z_m as f32))
    }
}

/// Constant speed and yaw rate from a start pose, or a polyline of waypoints driven at constant
/// speed, with terrain-following z, pitch and roll.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Trajectory {
    /// Forward speed, metres per second.
    pub speed_m_per_s: f64,
    /// Yaw rate, radians per second (positive: turning left); ignored with waypoints.
    pub yaw_rate_rad_per_s: f64,
    /// Waypoints `[x, y]` in the world frame, metres (none, or 2 or more): the vehicle starts at the
    /// first facing the second and drives along the polyline at `speed_m_per_s`, heading along the
    /// segment it is on (it turns on the spot at a waypoint); past the last one it goes on straight.
    pub waypoints_m: Vec<[f64; 2]>,
}

impl Trajectory {
    /// Planar pose (x, y, yaw) at time `t_s`: from the origin facing +x, a straight line or a
    /// circular arc; or the point `speed * t_s` along the waypoints' polyline.
    pub fn planar(&self, t_s: f64) -> (f64, f64, f64) {
        if self.waypoints_m.len() >= 2 {
            return along_polyline(&self.waypoints_m, self.speed_m_per_s * t_s);
        }
        let (v, w) = (self.speed_m_per_s, self.yaw_rate_rad_per_s);
        let yaw = w * t_s;
        if w.abs() < 1e-9 { (v * t_s, 0.0, yaw) } else { (v / w * yaw.sin(), v / w * (1.0 - yaw.cos()), yaw) }
    }

    /// Whether the vehicle stands still.
    pub fn is_static(&self) -> bool {
        self.speed_m_per_s == 0.0 && self.yaw_rate_rad_per_s == 0.0
    }
}

/// The point `s_m` metres along the polyline `points` (from its first point; beyond the last point
/// along the last segment's heading) and the heading there, radians.
fn along_polyline(points: &[[f64; 2]], s_m: f64) -> (f64, f64, f64) {
    let mut left = s_m.max(0.0);
    for (k, w) in points.windows(2).enumerate() {
        let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
        let len = dx.hypot(dy);
        if left <= len || k + 2 == points.len() {
            let u = if len > 0.0 { left / len } else { 0.0 };
            return (w[0][0] + u * dx, w[0][1] + u * dy, dy.atan2(dx));
        }
        left -= len;
    }
    (points[0][0], points[0][1], 0.0)
}

/// Settles a planar pose on the terrain: casts vertical rays at the four wheels (from `z_hint_m + 2 m`
/// down, so ceilings above are ignored) and fits z, pitch and roll. Wheels over no ground keep `z_hint_m`.
pub fn settle_on_terrain(caster: &dyn Caster, x_m: f64, y_m: f64, yaw_rad: f64, z_hint_m: f64) -> VehiclePose {
    let (s, c) = yaw_rad.sin_cos();
    let wheel = |fx: f64, fy: f64| {
        let wx = x_m + fx * c - fy * s;
        let wy = y_m + fx * s + fy * c;
        let top = z_hint_m + 2.0;
        let ray = Ray { origin: Vec3::new(wx as f32, wy as f32, top as f32), dir: Vec3::NEG_Z, t_max: 6.0 };
        caster.cast(&ray).map_or(z_hint_m, |h| top - f64::from(h.t))
    };
    let (w, t) = (f64::from(WHEELBASE_M), f64::from(HALF_TRACK_M));
    let rear_left = wheel(0.0, t);
    let rear_right = wheel(0.0, -t);
    let front_left = wheel(w, t);
    let front_right = wheel(w, -t);
    let rear = 0.5 * (rear_left + rear_right);
    let front = 0.5 * (front_left + front_right);
    let left = 0.5 * (rear_left + front_left);
    let right = 0.5 * (rear_right + front_right);
    VehiclePose {
        x_m,
        y_m,
        z_m: rear,
        // Nose up (front higher) is negative pitch in ISO 8855.
        pitch_rad: -((front - rear) / w).atan(),
        roll_rad: ((left - right) / (2.0 * t)).atan(),
        yaw_rad,
    }
}

/// Vehicle poses along a trajectory, sampled at frame boundaries and interpolated in between.
#[derive(Clone, Debug)]
pub struct PoseTrack {
    trajectory: Trajectory,
    /// Frame period, seconds.
    frame_period_s: f64,
    /// Settled poses at `k * frame_period_s`, `k = 0..=frames`.
    knots: Vec<VehiclePose>,
}

impl PoseTrack {
    /// Settles the vehicle at every frame boundary of `frames` frames of `frame_period_s` seconds.
    pub fn new(caster: &dyn Caster, trajectory: Trajectory, frame_period_s: f64, frames: usize, ego_z_m: f64) -> Self {
        let mut knots = Vec::with_capacity(frames + 1);
        let mut z = ego_z_m;
        for k in 0..=frames {
            let (x, y, yaw) = trajectory.planar(k as f64 * frame_period_s);
            let pose = settle_on_terrain(caster, x, y, yaw, z);
            z = pose.z_m;
            knots.push(pose);
            if trajectory.is_static() {
                knots.resize(frames + 1, pose);
                break;
            }
        }
        Self { trajectory, frame_period_s, knots }
    }

    /// The pose at the start of frame `k`.
    pub fn frame_start(&self, k: usize) -> VehiclePose {
        self.knots[k.min(self.knots.len() - 1)]
    }

    /// Whether every pose is the same (a standing vehicle).
    pub fn is_static(&self) -> bool {
        self.trajectory.is_static()
    }

    /// The pose at time `t_s` (seconds since the start of the scan): planar motion in closed form,
    /// z / pitch / roll interpolated linearly between the frame boundaries.
    pub fn at(&self, t_s: f64) -> VehiclePose {
        let (x, y, yaw) = self.trajectory.planar(t_s);
        let f = (t_s / self.frame_period_s).max(0.0);
        let k = (f.floor() as usize).min(self.knots.len().saturating_sub(2));
        let a = self.knots[k];
        let b = self.knots[(k + 1).min(self.knots.len() - 1)];
        let u = (f - k as f64).clamp(0.0, 1.0);
        let lerp = |p: f64, q: f64| p + (q - p) * u;
        VehiclePose {
            x_m: x,
            y_m: y,
            z_m: lerp(a.z_m, b.z_m),
            roll_rad: lerp(a.roll_rad, b.roll_rad),
            pitch_rad: lerp(a.pitch_rad, b.pitch_rad),
            yaw_rad: yaw,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circular_arc_keeps_radius_and_heading() {
        let tr = Trajectory { speed_m_per_s: 10.0, yaw_rate_rad_per_s: 0.5, ..Default::default() };
        let (x, y, yaw) = tr.planar(std::f64::consts::PI); // half a turn... yaw = pi/2
        let r = 10.0 / 0.5;
        assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!((x - r).abs() < 1e-9 && (y - r).abs() < 1e-9, "({x}, {y})");
        let (x, y, _) = Trajectory { speed_m_per_s: 3.0, ..Default::default() }.planar(2.0);
        assert_eq!((x, y), (6.0, 0.0));
    }

    #[test]
    fn waypoints_are_followed_at_speed() {
        let tr = Trajectory {
            speed_m_per_s: 2.0,
            waypoints_m: vec![[1.0, 1.0], [4.0, 5.0], [4.0, 9.0]],
            ..Default::default()
        };
        // Segment 1 is 5 m long (3-4-5), segment 2 4 m.
        let (x, y, yaw) = tr.planar(1.0);
        assert!((x - 2.2).abs() < 1e-12 && (y - 2.6).abs() < 1e-12, "({x}, {y})");
        assert!((yaw - 4f64.atan2(3.0)).abs() < 1e-12);
        let (x, y, yaw) = tr.planar(3.5); // 7 m: 2 m into segment 2
        assert!((x - 4.0).abs() < 1e-12 && (y - 7.0).abs() < 1e-12, "({x}, {y})");
        assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let (x, y, _) = tr.planar(6.0); // 12 m: 3 m past the end, straight on
        assert!((x - 4.0).abs() < 1e-12 && (y - 12.0).abs() < 1e-12, "({x}, {y})");
        assert_eq!(tr.planar(0.0), (1.0, 1.0, 4f64.atan2(3.0)));
    }
}
