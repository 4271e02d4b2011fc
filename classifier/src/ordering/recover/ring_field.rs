//! The table of a cloud that carries a ring (laser) field but whose sensor was not given (no rig,
//! no calibration file): the drivers' PCDs, PLYs, LAS files and PointCloud2 messages, nuScenes
//! `.pcd.bin`. Each ring value with returns is one laser; its median `tan(elevation)` and median
//! horizontal distance are matched against every known table ([`super::matching`]) as unfolded
//! rings are, the lasers sorted by elevation (a driver's laser ids need not go up with elevation).
//! A matched sensor gives its own table and each ring the row the alignment gives it; otherwise
//! the table is the rings' own elevations, an unnamed sensor. Columns per turn come from the
//! azimuth gaps within the fullest rings, whatever order the points come in.

use std::f32::consts::TAU;

use super::super::InputPoint;
use super::super::beam_table::BeamTable;
use super::super::unfold::sampled_median;
use super::{RecoveredOrder, RecoveredSensor, RecoveryError, given_table, matching, named_table, unnamed_table};

/// Largest ring value a ring field may hold without a sensor given: no spinning sensor has more
/// than 256 lasers (dual returns of 128 lasers share their laser's ring).
pub const MAX_RING_VALUE: u16 = 255;

/// What the ring field gave: the table, each point's row in it (0 lowest; unusable points 0) and
/// the sensor for the report.
pub(crate) struct RingFieldTable {
    /// The table to order with.
    pub table: BeamTable,
    /// Per point, the table row of its ring.
    pub point_rows: Vec<u16>,
    /// The sensor.
    pub sensor: RecoveredSensor,
}

/// The table of `points` (sensor frame) whose lasers are `rings` (one value per point).
/// With `given` (a calibration file's table), the rings are aligned with its lasers and only the
/// columns come from the data.
pub(crate) fn recover_ring_field<P: InputPoint>(
    points: &[P],
    rings: &[u16],
    given: Option<&BeamTable>,
) -> Result<RingFieldTable, RecoveryError> {
    let usable = |p: glam::Vec3| p.is_finite() && p != glam::Vec3::ZERO;
    // Points per ring value (counting sort): tan(elevation), horizontal distance, azimuth.
    let mut counts = vec![0usize; usize::from(MAX_RING_VALUE) + 2];
    let mut n_usable = 0usize;
    for (k, (p, &g)) in points.iter().zip(rings).enumerate() {
        if !usable(p.xyz()) {
            continue;
        }
        if g > MAX_RING_VALUE {
            return Err(RecoveryError::NoOrder {
                points: points.len(),
                why: format!(
                    "point {k} has ring {g}, beyond {MAX_RING_VALUE}: no spinning sensor has more than {} lasers",
                    usize::from(MAX_RING_VALUE) + 1
                ),
            });
        }
        counts[usize::from(g) + 1] += 1;
        n_usable += 1;
    }
    if n_usable < 64 {
        return Err(RecoveryError::NoOrder { points: n_usable, why: "fewer than 64 usable points".into() });
    }
    let mut start = counts.clone();
    for g in 1..start.len() {
        start[g] += start[g - 1];
    }
    let mut fill = start.clone();
    // Per slot, the point's index: azimuths are needed in the four fullest rings only.
    let (mut tan, mut dist, mut source) = (vec![0f32; n_usable], vec![0f32; n_usable], vec![0u32; n_usable]);
    for (k, (p, &g)) in points.iter().zip(rings).enumerate() {
        let v = p.xyz();
        if !usable(v) {
            continue;
        }
        let i = &mut fill[usize::from(g)];
        let d = (v.x * v.x + v.y * v.y).sqrt().max(1e-6);
        (tan[*i], dist[*i], source[*i]) = (v.z / d, d, k as u32);
        *i += 1;
    }
    let az = |i: usize| {
        let v = points[source[i] as usize].xyz();
        v.y.atan2(v.x)
    };
    let span = |g: usize| start[g]..start[g + 1];
    let present: Vec<usize> = (0..=usize::from(MAX_RING_VALUE)).filter(|&g| !span(g).is_empty()).collect();
    if present.len() < 2 {
        return Err(RecoveryError::NoOrder {
            points: n_usable,
            why: format!("{} ring value(s) hold points: fewer than two lasers", present.len()),
        });
    }
    let mut scratch = Vec::new();
    let mut lasers: Vec<(usize, f32, f32)> = present
        .iter()
        .map(|&g| (g, sampled_median(&tan[span(g)], &mut scratch), sampled_median(&dist[span(g)], &mut scratch)))
        .collect();
    lasers.sort_by(|a, b| a.1.total_cmp(&b.1));
    let tan_sorted: Vec<f32> = lasers.iter().map(|l| l.1).collect();
    let dist_sorted: Vec<f32> = lasers.iter().map(|l| l.2).collect();
    let matched = if given.is_some() { None } else { matching::match_rings(&tan_sorted, &dist_sorted) };
    // Columns: the median azimuth gap within the four fullest rings, their azimuths sorted, over
    // the points at or beyond a matched sensor's minimum range (nearer ones are no-returns:
    // nuScenes' motion-compensated ones pile up at one azimuth and would shorten the median gap).
    let min_range_m = matched.as_ref().map_or(given.map_or(0.0, |g| g.min_range_m), |m| m.sensor.min_range_m);
    let mut fullest = present.clone();
    fullest.sort_by_key(|&g| std::cmp::Reverse(span(g).len()));
    let mut gaps = Vec::new();
    for &g in fullest.iter().take(4) {
        let mut a: Vec<f32> =
            span(g).filter(|&i| dist[i] * (1.0 + tan[i] * tan[i]).sqrt() >= min_range_m).map(az).collect();
        a.sort_by(f32::total_cmp);
        gaps.extend(a.windows(2).map(|w| w[1] - w[0]).filter(|&s| s > 1e-4));
    }
    let largest = span(fullest[0]).len();
    let cols_estimate = super::median(&mut gaps);
    let cols_estimate = if cols_estimate.is_finite() && cols_estimate > 0.0 {
        ((TAU / cols_estimate).round() as usize).clamp(2, 1 << 16)
    } else {
        largest.max(2)
    };
    let (mut given_error_deg, mut firing_times) = (None, None);
    let (table, columns, row_of_sorted) = match (given, &matched) {
        (Some(g), _) => {
            let table;
            (table, firing_times) = given_table(g, cols_estimate);
            let rows = table.rows().map_err(|e| RecoveryError::NoOrder { points: n_usable, why: e.to_string() })?;
            if let Some(&g) = present.last().filter(|&&g| g >= rows.len()) {
                return Err(RecoveryError::NoOrder {
                    points: n_usable,
                    why: format!(
                        "ring {g} holds points, out of range 0 ..= {} (the calibration file's lasers)",
                        rows.len() - 1
                    ),
                });
            }
            let Some(fit) = matching::align(&tan_sorted, &dist_sorted, &rows) else {
                return Err(RecoveryError::NoOrder {
                    points: n_usable,
                    why: format!(
                        "the ring field holds {} lasers with points; the calibration file has {}",
                        lasers.len(),
                        rows.len()
                    ),
                });
            };
            given_error_deg = Some(fit.sum_deg / lasers.len() as f32);
            (table, cols_estimate, Some(fit.rows))
        }
        (None, Some(m)) => {
            let (table, columns) = named_table(m.sensor, cols_estimate);
            let rows = table.rows().map_err(|e| RecoveryError::NoOrder { points: n_usable, why: e.to_string() })?;
            let row_of = matching::align(&tan_sorted, &dist_sorted, &rows).map(|a| a.rows);
            (table, columns, row_of)
        }
        (None, None) => (unnamed_table(&tan_sorted, cols_estimate), cols_estimate, None),
    };
    // Without a matched table's alignment, a ring's row is its rank in elevation.
    let row_of_sorted = row_of_sorted.unwrap_or_else(|| (0..lasers.len()).collect());
    let mut row_of_ring = vec![0u16; usize::from(MAX_RING_VALUE) + 1];
    for (i, l) in lasers.iter().enumerate() {
        row_of_ring[l.0] = row_of_sorted[i] as u16;
    }
    let point_rows = rings.iter().map(|&g| row_of_ring.get(usize::from(g)).copied().unwrap_or(0)).collect();
    Ok(RingFieldTable {
        sensor: RecoveredSensor {
            model: matched.map(|m| m.sensor.model).or(firing_times),
            rings: lasers.len(),
            rows: table.elevations_rad.len(),
            columns,
            order: RecoveredOrder::RingField,
            echoes: 1,
            mean_error_deg: matched.map(|m| m.mean_error_deg).or(given_error_deg),
            calibrated: given.is_some(),
        },
        table,
        point_rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ordering::recover::known::known_sensors;

    /// A turn of `cols` points per laser of `elevations_deg` over a 1.8 m-deep floor and a 20 m
    /// wall, with `ring_of(laser)` as each point's ring, in firing order.
    fn turn(elevations_deg: &[f32], cols: usize, ring_of: impl Fn(usize) -> u16) -> (Vec<glam::Vec3>, Vec<u16>) {
        let (mut pts, mut rings) = (Vec::new(), Vec::new());
        for c in 0..cols {
            let az = c as f32 * TAU / cols as f32;
            for (l, e) in elevations_deg.iter().enumerate() {
                let e = e.to_radians();
                let dir = glam::Vec3::new(e.cos() * az.cos(), e.cos() * az.sin(), e.sin());
                let t = if dir.z < -0.02 { (1.8 / -dir.z).min(20.0) } else { 20.0 };
                pts.push(dir * t);
                rings.push(ring_of(l));
            }
        }
        (pts, rings)
    }

    #[test]
    fn a_known_table_with_laser_ids_out_of_elevation_order_is_named_and_each_ring_gets_its_row() {
        let hdl32 = known_sensors().iter().find(|s| s.model == "hdl32e").expect("hdl32e is known");
        let e: Vec<f32> = hdl32.rows.elevation_rad.iter().map(|e| e.to_degrees()).collect();
        // Laser ids interleaved as the HDL-32E's own: even ids bottom half, odd ids top half.
        let id = |l: usize| if l < 16 { 2 * l } else { 2 * (l - 16) + 1 } as u16;
        let (pts, rings) = turn(&e, 1808, id);
        let got = recover_ring_field(&pts, &rings, None).expect("recovered");
        assert_eq!(got.sensor.model, Some("hdl32e"));
        assert_eq!((got.sensor.rows, got.sensor.rings), (32, 32));
        assert!((got.sensor.columns as i64 - 1808).abs() <= 10, "{}", got.sensor.columns);
        for (k, &g) in rings.iter().enumerate() {
            let laser = (0..32).find(|&l| id(l) == g).unwrap();
            assert_eq!(usize::from(got.point_rows[k]), laser, "point {k}");
        }
    }

    #[test]
    fn rings_of_no_known_table_make_an_unnamed_sensor_of_their_own_elevations() {
        // 20 lasers 1.3 deg apart from -20 deg: no catalogued sensor.
        let e: Vec<f32> = (0..20).map(|l| -20.0 + 1.3 * l as f32).collect();
        let (pts, rings) = turn(&e, 1000, |l| 19 - l as u16);
        let got = recover_ring_field(&pts, &rings, None).expect("recovered");
        assert_eq!(got.sensor.model, None);
        assert_eq!((got.sensor.rows, got.sensor.columns), (20, 1000));
        for (k, &g) in rings.iter().enumerate() {
            assert_eq!(got.point_rows[k], 19 - g, "ring {g} is row {}", 19 - g);
        }
        let top = got.table.elevations_rad.last().unwrap().to_degrees();
        assert!((top - e[19]).abs() < 0.05, "top row {top} deg");
    }

    #[test]
    fn a_ring_beyond_any_sensor_or_a_single_laser_is_refused() {
        let e: Vec<f32> = (0..16).map(|l| -15.0 + 2.0 * l as f32).collect();
        let (pts, mut rings) = turn(&e, 200, |l| l as u16);
        rings[7] = 300;
        let err = recover_ring_field(&pts, &rings, None).err().expect("refused").to_string();
        assert!(err.contains("ring 300"), "{err}");
        let one = vec![3u16; pts.len()];
        let err = recover_ring_field(&pts, &one, None).err().expect("refused").to_string();
        assert!(err.contains("fewer than two lasers"), "{err}");
    }
}
