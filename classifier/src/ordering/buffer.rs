//! The cloud that ordering refills frame after frame ([`CloudBuffer`]): its buffers, and which of
//! its fields the last fill left at their reset values, so that the next one does not write them
//! again.

use sim::OrderedCloud;
use sim::cloud::KnownFields;

/// An ordered cloud that [`super::order_cloud_into`] fills frame after frame. It keeps the
/// buffers (no allocation once they are large enough) and knows which fields the last fill left
/// at their reset values (a KITTI file has no times, labels, instances or normals; the ring and
/// column of every cell are the same for a grid of the same shape), so that the next fill does not
/// rewrite them ([`OrderedCloud::reset_as_grid`]). The cloud is lent out for reading;
/// lending it out for writing ([`CloudBuffer::cloud_mut`]) drops that knowledge, so it cannot go
/// stale.
///
/// ```
/// use classifier::ordering::{BeamTable, CloudBuffer, OrderingReport, PathChoice, PointAttributes, UnfoldParams, order_cloud_into};
/// use glam::{Affine3A, Vec3};
///
/// // Two rings of 8 points each, 1 m below the sensor, in a grid of 2 rows x 8 columns.
/// let table = BeamTable::spinning(vec![-30f32.to_radians(), -20f32.to_radians()], 8);
/// let points: Vec<Vec3> = [-30f32, -20.0]
///     .iter()
///     .flat_map(|e| (0..8).map(move |k| (e.to_radians(), (22.5 + k as f32 * 45.0).to_radians())))
///     .map(|(e, a)| Vec3::new(a.cos() / e.tan().abs(), a.sin() / e.tan().abs(), -1.0))
///     .collect();
/// let (mut buffer, mut report) = (CloudBuffer::default(), OrderingReport::default());
/// for _frame in 0..2 {
///     order_cloud_into(&points, &PointAttributes::default(), &table, Affine3A::IDENTITY,
///         PathChoice::BeamTable, &UnfoldParams::default(), &mut buffer, &mut report).unwrap();
/// }
/// let cloud = buffer.cloud();
/// assert_eq!((cloud.rows, cloud.cols, cloud.returns()), (2, 8, 16));
/// assert!(cloud.time_s.iter().all(|&t| t == 0.0) && cloud.normal.iter().all(|n| *n == Vec3::ZERO));
/// ```
#[derive(Clone, Debug, Default)]
pub struct CloudBuffer {
    cloud: OrderedCloud,
    /// The fields that hold their reset values in every cell (what the last fill left alone).
    known: KnownFields,
}

impl CloudBuffer {
    /// The cloud of the last fill.
    pub fn cloud(&self) -> &OrderedCloud {
        &self.cloud
    }

    /// The cloud for writing (another reader filling the same buffers): the next fill then
    /// resets every field.
    pub fn cloud_mut(&mut self) -> &mut OrderedCloud {
        self.known = KnownFields::default();
        &mut self.cloud
    }

    /// The cloud, out of the buffer.
    pub fn into_cloud(self) -> OrderedCloud {
        self.cloud
    }

    /// The cloud and what is known of its fields, for a fill that keeps the latter true.
    pub(crate) fn parts(&mut self) -> (&mut OrderedCloud, &mut KnownFields) {
        (&mut self.cloud, &mut self.known)
    }
}

#[cfg(test)]
mod tests {
    use glam::{Affine3A, Vec3};
    use sim::SemanticClass;

    use super::*;
    use crate::ordering::{BeamTable, OrderingReport, PathChoice, PointAttributes, UnfoldParams, order_cloud_into};

    /// Every field of a cloud, NaN-safe (`Debug` prints NaN as itself).
    fn fields(cloud: &OrderedCloud) -> String {
        format!("{cloud:?}")
    }

    /// Two rings of 16 points on the ground 1.6 m below the sensor (half of them in the first frame).
    fn ring_points(every: usize) -> Vec<Vec3> {
        [-30f32, -20.0]
            .iter()
            .flat_map(|e| (0..16).filter(move |k| k % every == 0).map(move |k| (e.to_radians(), k)))
            .map(|(e, k)| {
                let a = (11.25 + k as f32 * 22.5).to_radians();
                let d = 1.6 / e.tan().abs();
                Vec3::new(d * a.cos(), d * a.sin(), -1.6)
            })
            .collect()
    }

    /// A frame with times and labels, then one without, a larger grid, and one after the cloud was
    /// written through `cloud_mut`: each refilled cloud equals the cloud ordered afresh, field by
    /// field, though later fills skipped the fields that the one before had left alone.
    #[test]
    fn a_refilled_cloud_equals_a_fresh_one() {
        let order = |points: &[Vec3], attributes: &PointAttributes<'_>, cols: usize, buffer: &mut CloudBuffer| {
            let table = BeamTable::spinning(vec![-30f32.to_radians(), -20f32.to_radians()], cols);
            let mut report = OrderingReport::default();
            let (choice, params) = (PathChoice::BeamTable, UnfoldParams::default());
            order_cloud_into(points, attributes, &table, Affine3A::IDENTITY, choice, &params, buffer, &mut report)
                .expect("orders");
            let mut fresh = CloudBuffer::default();
            order_cloud_into(points, attributes, &table, Affine3A::IDENTITY, choice, &params, &mut fresh, &mut report)
                .expect("orders");
            assert_eq!(fields(buffer.cloud()), fields(fresh.cloud()));
        };
        let mut buffer = CloudBuffer::default();
        let half = ring_points(2);
        let (times, labels) = (vec![0.05; half.len()], vec![SemanticClass(40); half.len()]);
        let rich = PointAttributes { labels: Some(&labels), time_s: Some(&times), ..PointAttributes::default() };
        order(&half, &rich, 16, &mut buffer);
        assert!(buffer.cloud().ground.iter().filter(|&&g| g).count() == half.len());
        assert_eq!(
            buffer.known,
            KnownFields { grid: true, time_s: false, echo: true, label: false, instance: true, normal: true }
        );
        let all = ring_points(1);
        order(&all, &PointAttributes::default(), 16, &mut buffer);
        assert!(buffer.cloud().time_s.iter().all(|&t| t == 0.0) && !buffer.cloud().ground.contains(&true));
        assert_eq!(
            buffer.known,
            KnownFields { grid: true, time_s: true, echo: true, label: true, instance: true, normal: true }
        );
        order(&all, &PointAttributes::default(), 32, &mut buffer);
        buffer.cloud_mut().normal[3] = Vec3::Z;
        buffer.cloud_mut().instance[5] = 7;
        assert_eq!(buffer.known, KnownFields::default());
        order(&half, &PointAttributes::default(), 32, &mut buffer);
        assert_eq!((buffer.cloud().normal[3], buffer.cloud().instance[5]), (Vec3::ZERO, 0));
    }
}
