//! Point clouds between our PCD layouts and `sensor_msgs/msg/PointCloud2`.
//!
//! A PointCloud2 is a PCD file's binary body with the header as a message: our writers' PCD bytes
//! ([`crate::io::pcd::encode_layout`]: our layout or a driver's) become a message by turning the
//! header's fields into `PointField`s ([`from_pcd`]), and a message is read by the PCD reader's
//! decoder straight from its data, its fields making the record layout a PCD header would
//! ([`frame`]: the one PointCloud2 decoder). So a bag's clouds take exactly the path a PCD file
//! takes into `classify`, and the same cloud gives the same decisions whichever way it comes.

use std::borrow::Cow;

use super::messages::{Header, PointCloud2, PointField, datatype};
use crate::io::pcd::{DataKind, FieldDecl, PcdFrame, grid_of_comment, layout};

/// What is wrong with a PointCloud2 (the message, not the bag).
pub type CloudError = String;

/// The fields, grid and body of our own PCD writer's binary output.
struct PcdParts<'a> {
    fields: Vec<(String, char, usize, usize)>,
    width: usize,
    height: usize,
    comment: Option<String>,
    body: &'a [u8],
}

fn pcd_parts(pcd: &[u8]) -> Result<PcdParts<'_>, CloudError> {
    let mut at = 0;
    let (mut names, mut sizes, mut types, mut counts) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut width, mut height, mut comment) = (0, 0, None);
    loop {
        let end = pcd[at..].iter().position(|&b| b == b'\n').ok_or("a PCD header without DATA")? + at;
        let line = std::str::from_utf8(&pcd[at..end]).map_err(|_| "a PCD header that is not text")?;
        at = end + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("#") if line.starts_with("# groundtruth") => comment = Some(line.to_string()),
            Some("FIELDS") => names = words.map(str::to_string).collect(),
            Some("SIZE") => sizes = words.map(|w| w.parse().unwrap_or(0)).collect(),
            Some("TYPE") => types = words.map(|w| w.chars().next().unwrap_or('?')).collect(),
            Some("COUNT") => counts = words.map(|w| w.parse().unwrap_or(0)).collect(),
            Some("WIDTH") => width = words.next().and_then(|w| w.parse().ok()).unwrap_or(0),
            Some("HEIGHT") => height = words.next().and_then(|w| w.parse().ok()).unwrap_or(0),
            Some("DATA") => {
                if words.next() != Some("binary") {
                    return Err("only binary PCD data becomes a PointCloud2".into());
                }
                break;
            }
            _ => {}
        }
    }
    let fields = names.into_iter().zip(types).zip(sizes).zip(counts).map(|(((n, t), s), c)| (n, t, s, c)).collect();
    Ok(PcdParts { fields, width, height, comment, body: &pcd[at..] })
}

/// The PointCloud2 of binary PCD bytes as our writers emit them (organized: `height` rows of
/// `width` points), stamped with `header`. The data is borrowed from `pcd`, not copied: a bag
/// writer copies it once, into the message's CDR bytes.
pub fn from_pcd(pcd: &[u8], header: Header) -> Result<PointCloud2<'_>, CloudError> {
    let parts = pcd_parts(pcd)?;
    let mut fields = Vec::with_capacity(parts.fields.len());
    let mut offset = 0u32;
    for (name, letter, size, count) in &parts.fields {
        let dt = datatype::of(*letter, *size).ok_or_else(|| format!("field `{name}`: type {letter}{size}"))?;
        fields.push(PointField { name: name.clone(), offset, datatype: dt, count: *count as u32 });
        offset += (*size * *count) as u32;
    }
    let point_step = offset;
    let expected = point_step as usize * parts.width * parts.height;
    if parts.body.len() != expected {
        return Err(format!("{} data bytes, {expected} expected", parts.body.len()));
    }
    let is_dense = !parts.fields.iter().any(|f| f.1 == 'F') || !has_nan(&fields, point_step as usize, parts.body);
    Ok(PointCloud2 {
        header,
        height: parts.height as u32,
        width: parts.width as u32,
        fields,
        is_bigendian: false,
        point_step,
        row_step: point_step * parts.width as u32,
        data: Cow::Borrowed(parts.body),
        is_dense,
    })
}

/// Whether any x of the points is NaN (a no-return cell of an organized cloud).
fn has_nan(fields: &[PointField], step: usize, data: &[u8]) -> bool {
    let Some(x) = fields.iter().find(|f| f.name == "x" && f.datatype == datatype::FLOAT32) else { return false };
    let o = x.offset as usize;
    data.chunks_exact(step).any(|p| f32::from_le_bytes([p[o], p[o + 1], p[o + 2], p[o + 3]]).is_nan())
}

/// The `# groundtruth rows=R planes=P` comment of our own layout's PCD header, if `pcd` has one:
/// a bag keeps it in its channel metadata, so that our clouds read back as ours.
pub fn groundtruth_comment(pcd: &[u8]) -> Option<String> {
    pcd_parts(pcd).ok().and_then(|p| p.comment)
}

/// A PointCloud2 as the PCD reader's frame, decoded from where its data lies (no PCD bytes in
/// between): its fields in offset order make the record layout (gaps between fields, and after
/// the last, skipped), rows without padding are read in place (padded rows are gathered once).
/// `comment` (our layout's `# groundtruth` line, from the channel's metadata) restores our
/// multi-echo grids; `path` names the message in errors. So a bag's clouds take exactly the path a
/// PCD file takes into `classify`, and the same cloud gives the same decisions whichever way it
/// comes. Refused, with what is wrong: big-endian data, an unknown datatype, overlapping fields or
/// fields beyond `point_step`, a `row_step` shorter than a row, data of the wrong length, no
/// `x`, `y` and `z` of a float type.
pub fn frame<'a>(
    path: &'a std::path::Path,
    cloud: &'a PointCloud2<'_>,
    comment: Option<&str>,
) -> Result<PcdFrame<'a>, CloudError> {
    if cloud.is_bigendian {
        return Err("big-endian data (is_bigendian): not read".into());
    }
    let (width, height, step) = (cloud.width as usize, cloud.height as usize, cloud.point_step as usize);
    if step == 0 || width == 0 || height == 0 {
        return Err(format!("an empty cloud: height {height}, width {width}, point_step {step}"));
    }
    let row_bytes = width.checked_mul(step).ok_or("width x point_step overflows")?;
    if (cloud.row_step as usize) < row_bytes {
        return Err(format!("row_step {} is shorter than width {width} x point_step {step}", cloud.row_step));
    }
    let expected = (cloud.row_step as usize).checked_mul(height).ok_or("row_step x height overflows")?;
    if cloud.data.len() != expected {
        return Err(format!(
            "{} data bytes, but height {height} x row_step {} = {expected}",
            cloud.data.len(),
            cloud.row_step
        ));
    }
    let mut fields: Vec<&PointField> = cloud.fields.iter().collect();
    fields.sort_by_key(|f| f.offset);
    for axis in ["x", "y", "z"] {
        let ok = fields.iter().any(|f| f.name == axis && matches!(f.datatype, datatype::FLOAT32 | datatype::FLOAT64));
        if !ok {
            return Err(format!("no float field `{axis}`"));
        }
    }
    // The record layout: each field where it lies, a byte-wide padding field over every gap.
    let mut decls = Vec::with_capacity(fields.len() + 1);
    let pad = |gap: usize, decls: &mut Vec<FieldDecl>| {
        if gap > 0 {
            decls.push(FieldDecl { name: "_".to_string(), letter: 'U', size: 1, count: gap });
        }
    };
    let mut at = 0usize;
    for f in &fields {
        let (size, letter) = datatype::size_and_letter(f.datatype)
            .ok_or_else(|| format!("field `{}`: datatype {}", f.name, f.datatype))?;
        let (offset, count) = (f.offset as usize, f.count.max(1) as usize);
        if offset < at {
            return Err(format!("field `{}` at offset {offset} overlaps the field before it (ending at {at})", f.name));
        }
        let end = offset + size as usize * count;
        if end > step {
            return Err(format!("field `{}` ends at byte {end}, beyond point_step {step}", f.name));
        }
        pad(offset - at, &mut decls);
        decls.push(FieldDecl { name: f.name.clone(), letter, size: size as usize, count });
        at = end;
    }
    pad(step - at, &mut decls);
    let grid = comment.and_then(grid_of_comment);
    let header =
        layout(path, &decls, width, height, width * height, DataKind::Binary, 0, grid).map_err(|e| e.to_string())?;
    let body = if cloud.row_step as usize == row_bytes {
        Cow::Borrowed(&cloud.data[..])
    } else {
        let mut rows = Vec::with_capacity(row_bytes * height);
        for row in cloud.data.chunks_exact(cloud.row_step as usize) {
            rows.extend_from_slice(&row[..row_bytes]);
        }
        Cow::Owned(rows)
    };
    PcdFrame::from_records(path, header, body).map_err(|e| e.to_string())
}

/// The cloud with one more field, `ground` (`uint8`, 1 = ground), appended to every point: the
/// decisions `ground`, one per point in the cloud's own order. A `ground` field the cloud already
/// has (our own layout carries its ground truth there) is kept, renamed `ground_truth`, so that
/// decision and truth sit side by side.
pub fn with_ground_field(cloud: &PointCloud2<'_>, ground: &[u8]) -> Result<PointCloud2<'static>, CloudError> {
    let n = cloud.width as usize * cloud.height as usize;
    if ground.len() != n {
        return Err(format!("{} decisions for {n} points", ground.len()));
    }
    if cloud.fields.iter().any(|f| f.name == "ground_truth") {
        return Err("the cloud already has a `ground_truth` field".into());
    }
    let (step, row_step) = (cloud.point_step as usize, cloud.row_step as usize);
    let new_step = step + 1;
    let mut data = Vec::with_capacity(n * new_step);
    for (r, row) in cloud.data.chunks_exact(row_step).enumerate() {
        for (c, p) in row[..cloud.width as usize * step].chunks_exact(step).enumerate() {
            data.extend_from_slice(p);
            data.push(ground[r * cloud.width as usize + c]);
        }
    }
    let mut fields = cloud.fields.clone();
    for f in fields.iter_mut().filter(|f| f.name == "ground") {
        f.name = "ground_truth".into();
    }
    fields.push(PointField { name: "ground".into(), offset: step as u32, datatype: datatype::UINT8, count: 1 });
    Ok(PointCloud2 {
        header: cloud.header.clone(),
        height: cloud.height,
        width: cloud.width,
        fields,
        is_bigendian: false,
        point_step: new_step as u32,
        row_step: (new_step * cloud.width as usize) as u32,
        data: Cow::Owned(data),
        is_dense: cloud.is_dense,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::pcd::{PcdLayout, encode_layout};

    fn cloud() -> crate::OrderedCloud {
        let mut c = crate::OrderedCloud::empty(2, 3, 1);
        for i in 0..5 {
            c.point_in_vehicle[i] = glam::Vec3::new(i as f32, 1.0, -1.5);
            c.range_m[i] = 2.0 + i as f32;
            c.intensity[i] = 0.5;
            c.sensor[i] = 0;
        }
        c
    }

    #[test]
    fn pcd_bytes_round_trip_through_a_point_cloud2() {
        for layout in [PcdLayout::Groundtruth, PcdLayout::Velodyne, PcdLayout::Ouster] {
            let pcd = encode_layout(&cloud(), layout, false, None).unwrap();
            let msg = from_pcd(&pcd, Header::default()).unwrap();
            assert!(matches!(msg.data, Cow::Borrowed(_)), "the data is borrowed from the PCD bytes");
            assert_eq!((msg.height, msg.width), (2, 3), "{layout:?}");
            assert_eq!(msg.data.len(), 6 * msg.point_step as usize);
            let name = std::path::Path::new("b#/points[0]");
            let decoded = frame(name, &msg, groundtruth_comment(&pcd).as_deref()).unwrap();
            let (a, mut b) = (
                crate::io::pcd::read_bytes_with_info(std::path::Path::new("a.pcd"), &pcd).unwrap(),
                crate::OrderedCloud::default(),
            );
            let info = decoded.read_into(&mut b, None, glam::Affine3A::IDENTITY).unwrap();
            assert_eq!(info, a.1, "{layout:?}");
            let a = a.0;
            assert_eq!((a.rows, a.cols, a.planes), (b.rows, b.cols, b.planes), "{layout:?}");
            assert!(
                a.point_in_vehicle.iter().zip(&b.point_in_vehicle).all(|(p, q)| p == q || (p.is_nan() && q.is_nan())),
                "{layout:?}"
            );
            assert_eq!(a.intensity, b.intensity);
        }
    }

    #[test]
    fn gaps_become_padding_and_bad_clouds_are_refused() {
        // x y z at 0, 4, 8 (float32), a gap of 4 bytes, then a uint16 ring at 16; point_step 20,
        // rows padded to 48 bytes.
        let f = |name: &str, offset, dt| PointField { name: name.into(), offset, datatype: dt, count: 1 };
        let mut data = Vec::new();
        for p in 0..2u16 {
            for v in [1.0f32, 2.0, 3.0, 0.0] {
                data.extend_from_slice(&v.to_le_bytes());
            }
            data.extend_from_slice(&(7 + p).to_le_bytes());
            data.extend_from_slice(&[0, 0]);
        }
        data.extend_from_slice(&[0u8; 8]);
        let msg = PointCloud2 {
            header: Header::default(),
            height: 1,
            width: 2,
            fields: vec![
                f("z", 8, datatype::FLOAT32),
                f("x", 0, datatype::FLOAT32),
                f("y", 4, datatype::FLOAT32),
                f("ring", 16, datatype::UINT16),
            ],
            is_bigendian: false,
            point_step: 20,
            row_step: 48,
            data: Cow::Owned(data),
            is_dense: true,
        };
        let name = std::path::Path::new("m#/points[0]");
        let mut c = crate::OrderedCloud::default();
        frame(name, &msg, None).unwrap().read_into(&mut c, None, glam::Affine3A::IDENTITY).unwrap();
        assert_eq!(c.ring, vec![7, 8]);
        assert_eq!(c.point_in_vehicle, vec![glam::Vec3::new(1.0, 2.0, 3.0); 2]);
        let bad = |m: PointCloud2<'_>, needle: &str| {
            let e = frame(name, &m, None).err().expect("refused");
            assert!(e.contains(needle), "{e}");
        };
        bad(PointCloud2 { row_step: 50, ..msg.clone() }, "data bytes");
        bad(PointCloud2 { row_step: 10, ..msg.clone() }, "row_step 10");
        bad(PointCloud2 { point_step: 17, row_step: 48, ..msg.clone() }, "beyond point_step");
        bad(PointCloud2 { fields: vec![f("x", 0, 7), f("y", 2, 7), f("z", 8, 7)], ..msg.clone() }, "overlaps");
        bad(PointCloud2 { fields: vec![f("x", 0, 7), f("y", 4, 7)], ..msg.clone() }, "no float field `z`");
        bad(
            PointCloud2 { fields: vec![f("x", 0, 7), f("y", 4, 7), f("z", 8, 7), f("ring", 16, 9)], ..msg.clone() },
            "datatype 9",
        );
        bad(PointCloud2 { is_bigendian: true, ..msg.clone() }, "big-endian");
        let g = with_ground_field(&msg, &[1, 0]).unwrap();
        assert_eq!((g.point_step, g.row_step, g.data.len()), (21, 42, 42));
        assert_eq!((g.data[20], g.data[41]), (1, 0));
    }
}
