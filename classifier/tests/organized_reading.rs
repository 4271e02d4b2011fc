//! Organized PCDs read with their rows put in order as they are decoded
//! ([`classifier::ordering::read_organized_into`]) give what reading them and then ordering the
//! rows ([`sim::io::pcd::read_bytes_into`], [`classifier::ordering::order_organized_in_place`])
//! gives: every field of every cell to the bit, the report and the file's conventions, for the
//! drivers' layouts (top-first and bottom-first, zero and NaN no-returns), with and without a
//! `ring` field, with and without a mount, and for ASCII data; bad files are refused by both.

use std::path::Path;

use classifier::ordering::{OrderingReport, order_organized_in_place, read_organized_into};
use glam::{Affine3A, Vec3};
use sim::OrderedCloud;
use sim::io::pcd::{PcdFrame, PcdInfo, PcdLayout, encode_layout, read_bytes_into};

/// Every field of every cell, as bits (NaN compares equal to itself).
fn cells(c: &OrderedCloud) -> Vec<Vec<u64>> {
    let v3 = |v: &[Vec3]| v.iter().flat_map(|p| [p.x, p.y, p.z]).map(|x| u64::from(x.to_bits())).collect();
    let f = |v: &[f32]| v.iter().map(|x| u64::from(x.to_bits())).collect();
    vec![
        vec![c.rows as u64, c.cols as u64, c.planes as u64],
        v3(&c.point_in_vehicle),
        f(&c.range_m),
        f(&c.intensity),
        c.ring.iter().map(|&x| u64::from(x)).collect(),
        c.column.iter().map(|&x| u64::from(x)).collect(),
        c.sensor.iter().map(|&x| u64::from(x)).collect(),
        c.time_s.iter().map(|x| x.to_bits()).collect(),
        c.echo.iter().map(|&x| u64::from(x)).collect(),
        c.label.iter().map(|x| u64::from(x.0)).collect(),
        c.instance.iter().map(|&x| u64::from(x)).collect(),
        c.ground.iter().map(|&x| u64::from(x)).collect(),
        v3(&c.normal),
    ]
}

/// Both ways of reading `bytes` (an organized one-plane PCD): (cloud, report, info) each.
#[allow(clippy::type_complexity)]
fn both(
    bytes: &[u8],
    mount: Affine3A,
) -> (
    classifier::Result<(OrderedCloud, OrderingReport, PcdInfo)>,
    classifier::Result<(OrderedCloud, OrderingReport, PcdInfo)>,
) {
    let path = Path::new("frame.pcd");
    let mut two_steps = OrderedCloud::default();
    let info = read_bytes_into(path, bytes, &mut two_steps).expect("readable");
    let mut report = OrderingReport::default();
    let a =
        order_organized_in_place(&mut two_steps, info.has_ring, mount, &mut report).map(|()| (two_steps, report, info));
    let frame = PcdFrame::parse(path, bytes).expect("readable");
    let (mut fused, mut report) = (OrderedCloud::default(), OrderingReport::default());
    let b = read_organized_into(&frame, mount, &mut fused, &mut report).map(|info| (fused, report, info));
    (a, b)
}

/// `bytes` with the header's `ring` field renamed, so that readers do not know it.
fn without_ring(bytes: &[u8]) -> Vec<u8> {
    let end = bytes.windows(5).position(|w| w == b"DATA ").expect("a DATA line");
    let header = String::from_utf8(bytes[..end].to_vec()).expect("text header").replacen(" ring", " rung", 1);
    assert!(header.contains(" rung"), "the layout has a ring field");
    [header.as_bytes(), &bytes[end..]].concat()
}

#[test]
fn reading_in_order_equals_reading_then_ordering() {
    let cloud = classifier::synthetic::noisy_cars_frame(0.05, 7, true, 0.01);
    let mount = Affine3A::from_rotation_z(0.3) * Affine3A::from_translation(Vec3::new(1.3, -0.2, 1.85));
    let mut compared = 0;
    for layout in [PcdLayout::Velodyne, PcdLayout::Ouster] {
        let written = encode_layout(&cloud, layout, false, Some(&mount.inverse())).expect("encode");
        for bytes in [written.clone(), without_ring(&written)] {
            for m in [Affine3A::IDENTITY, mount] {
                let (a, b) = both(&bytes, m);
                let ((ca, ra, ia), (cb, rb, ib)) = (a.expect("two steps"), b.expect("in order"));
                let name = format!("{} ring {} mount {}", layout.name(), ia.has_ring, m != Affine3A::IDENTITY);
                assert_eq!(cells(&ca), cells(&cb), "{name}");
                assert_eq!(ra, rb, "{name}");
                assert_eq!(ia, ib, "{name}");
                assert!(ra.placed > cloud.returns() / 2, "{name}: {}", ra.summary());
                compared += 1;
            }
        }
    }
    // ASCII data (our layout, taken here as a driver's file would be), with normals to turn.
    let mut with_normals = cloud.clone();
    for (i, n) in with_normals.normal.iter_mut().enumerate() {
        *n = Vec3::new((i % 7) as f32 * 0.1, 0.2, 1.0).normalize();
    }
    let ascii = encode_layout(&with_normals, PcdLayout::Groundtruth, true, None).expect("encode");
    let (a, b) = both(&ascii, mount);
    let ((ca, ra, _), (cb, rb, _)) = (a.expect("two steps"), b.expect("in order"));
    assert_eq!((cells(&ca), ra), (cells(&cb), rb));
    // Rows bottom-first already: each cell's normal is the written one, turned by the mount.
    let turned =
        (0..cb.len()).filter(|&i| (cb.normal[i] - mount.transform_vector3(with_normals.normal[i])).length() < 1e-6);
    assert_eq!(turned.count(), cb.len(), "normals turned into the vehicle frame");
    assert_eq!(compared, 8);
}

/// Sets the `ring` field (`uint16`) of `point` in binary PCD `bytes`.
fn set_ring(bytes: &mut [u8], point: usize, ring: u16) {
    let data = bytes.windows(12).position(|w| w == b"DATA binary\n").expect("binary data") + 12;
    let header = String::from_utf8(bytes[..data].to_vec()).expect("text header");
    let words = |key: &str| -> Vec<String> {
        let line = header.lines().find(|l| l.starts_with(key)).expect("header line");
        line.split_whitespace().skip(1).map(str::to_string).collect()
    };
    let (fields, sizes) = (words("FIELDS"), words("SIZE"));
    let sizes: Vec<usize> = sizes.iter().map(|s| s.parse().expect("size")).collect();
    let k = fields.iter().position(|f| f == "ring").expect("a ring field");
    assert_eq!(sizes[k], 2);
    let (offset, record): (usize, usize) = (sizes[..k].iter().sum(), sizes.iter().sum());
    let at = data + point * record + offset;
    bytes[at..at + 2].copy_from_slice(&ring.to_le_bytes());
}

#[test]
fn bad_organized_files_are_refused_by_both() {
    let cloud = classifier::synthetic::noisy_cars_frame(0.05, 7, true, 0.01);
    let (rows, cols) = (cloud.rows, cloud.cols);
    let refused = |c: &OrderedCloud, rings: &[(usize, u16)], want: &str| {
        let mut bytes = encode_layout(c, PcdLayout::Velodyne, false, None).expect("encode");
        for &(point, ring) in rings {
            set_ring(&mut bytes, point, ring);
        }
        let (a, b) = both(&bytes, Affine3A::IDENTITY);
        for (way, r) in [("two steps", a), ("in order", b)] {
            let e = r.err().unwrap_or_else(|| panic!("{way}: {want} accepted")).to_string();
            assert!(e.contains(want), "{way}: {e}");
        }
    };
    // A row holding two rings; two rows of one ring; a ring beyond the rows.
    refused(&cloud, &[(3 * cols + 5, 9)], "row 3 holds rings 3 and 9");
    let ring_0: Vec<(usize, u16)> = (cols..2 * cols).map(|i| (i, 0)).collect();
    refused(&cloud, &ring_0, "appears in more than one row");
    let beyond: Vec<(usize, u16)> = (0..cols).map(|i| (i, rows as u16)).collect();
    refused(&cloud, &beyond, "out of range");
    // Both ways accept the file these were made from.
    let (a, b) = both(&encode_layout(&cloud, PcdLayout::Velodyne, false, None).expect("encode"), Affine3A::IDENTITY);
    assert!(a.is_ok() && b.is_ok());
    // Returns in one ring only.
    let mut one = cloud.clone();
    for (i, (p, r)) in one.point_in_vehicle.iter_mut().zip(&mut one.range_m).enumerate() {
        if i / cols != rows / 2 {
            (*p, *r) = (Vec3::NAN, f32::NAN);
        }
    }
    refused(&one, &[], "1 rings hold returns");
}

#[test]
fn damaged_files_are_refused_or_read_never_panicking() {
    let cloud = classifier::synthetic::noisy_cars_frame(0.05, 7, true, 0.01);
    let good = encode_layout(&cloud, PcdLayout::Ouster, false, None).expect("encode");
    let (mut refused, mut read) = (0, 0);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for case in 0..300 {
        let mut bytes = good.clone();
        // Bytes overwritten in the header (the first 400) or anywhere, or the file cut short.
        for _ in 0..1 + case % 4 {
            let span = if case % 2 == 0 { 400 } else { bytes.len() };
            let at = (next() as usize) % span;
            bytes[at] = next() as u8;
        }
        if case % 5 == 0 {
            bytes.truncate((next() as usize) % good.len());
        }
        let path = Path::new("damaged.pcd");
        let Ok(frame) = PcdFrame::parse(path, &bytes) else {
            refused += 1;
            continue;
        };
        let (mut c, mut report) = (OrderedCloud::default(), OrderingReport::default());
        match read_organized_into(&frame, Affine3A::IDENTITY, &mut c, &mut report) {
            Ok(_) => {
                read += 1;
                assert_eq!(report.cell_of_point.len(), frame.len());
            }
            Err(_) => refused += 1,
        }
    }
    assert_eq!(refused + read, 300);
    assert!(refused > 50 && read > 50, "refused {refused}, read {read}");
}
