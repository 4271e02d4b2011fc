//! LAS 1.4 writer (point data format 6, via the `las` crate) for a frame's returns; LAZ
//! (compressed, same content) when the crate is built with the `laz` feature. [`read`] reads
//! such a file back (and other tools' LAS files, with what they carry).
//!
//! Per point, in grid order (returns only):
//! - `x y z`: vehicle frame, metres, stored with scale 0.0001 m and offset 0;
//! - `intensity`: our `[0, 1]` intensity times 65535, rounded;
//! - `return_number` = echo + 1, `number_of_returns` = the returns of the same shot (grid cell
//!   across echo planes);
//! - `gps_time`: the point's time in seconds since the start of the scan (not GPS week seconds:
//!   the global encoding leaves "standard GPS time" unset);
//! - `classification` (ASPRS), see [`asprs_class`] and [`SemanticClass::las_class`]: ground truth
//!   ground = 2, bushes and shrubs (our class 73) = 4 (medium vegetation), canopy (vegetation 70)
//!   and trunk = 5 (high vegetation), building = 6, and user-definable classes 64.. for the rest:
//!   car 64, truck 65, other-vehicle 66, person 67, fence 68, other-structure 69, pole 70,
//!   traffic-sign 71, other-object 72; anything else (including unlabeled returns) = 1
//!   (unclassified);
//! - `user_data`: our class id (73 for bushes, not mapped; clamped to 255, so SemanticKITTI's
//!   moving classes 252-259 all read 255);
//! - `point_source_id`: the ring; `scanner_channel`: the sensor id when below 4, else 3;
//! - one extra-bytes field `instance` (uint32, described by a LASF_Spec record 4 VLR, which
//!   laspy and PDAL read as a named dimension).

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;

use las::point::Format;
use las::{Builder, PointDataBuilder, Transform, Vector, Vlr, Writer};

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Coordinate scale, metres per count.
pub const SCALE_M: f64 = 0.0001;

/// Bytes per point record: format 6 (30 bytes) plus the 4-byte `instance` extra field.
const RECORD_BYTES: usize = 34;

/// The ASPRS classification of a return with class `label` and ground truth flag `ground`: 2
/// when `ground`, else [`SemanticClass::las_class`] (see the module docs for the table).
pub fn asprs_class(label: SemanticClass, ground: bool) -> u8 {
    if ground { 2 } else { label.las_class() }
}

/// The 192-byte extra-bytes descriptor of the `instance` field (LAS 1.4 table 24).
fn instance_descriptor() -> Vec<u8> {
    let mut d = vec![0u8; 192];
    d[2] = 5; // data type: unsigned long (u32)
    d[3] = 0; // options: no no_data, min, max, scale or offset
    let name = b"instance";
    d[4..4 + name.len()].copy_from_slice(name);
    let desc = b"instance id (0 = stuff)";
    d[160..160 + desc.len()].copy_from_slice(desc);
    d
}

fn las_err(path: &Path, e: las::Error) -> SimError {
    SimError::bad_file(path, format!("LAS: {e}"))
}

/// Encodes the returns of `cloud` as LAS 1.4 bytes; returns the bytes and the point count.
/// `path` only names the file in errors.
pub fn encode(path: &Path, cloud: &OrderedCloud) -> Result<(Vec<u8>, usize)> {
    encode_with(path, cloud, false)
}

/// Encodes as LAS, or as LAZ when `compressed` (needs the `laz` cargo feature; without it the
/// las crate refuses with an error naming the missing feature).
pub fn encode_with(path: &Path, cloud: &OrderedCloud, compressed: bool) -> Result<(Vec<u8>, usize)> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let mut builder = Builder::from((1, 4));
    builder.point_format = Format::new(6).map_err(|e| las_err(path, e))?;
    builder.point_format.extra_bytes = 4;
    builder.point_format.is_compressed = compressed;
    builder.generating_software = "groundtruth".into();
    builder.system_identifier = "groundtruth LiDAR simulator".into();
    let t = Transform { scale: SCALE_M, offset: 0.0 };
    builder.transforms = Vector { x: t, y: t, z: t };
    builder.vlrs.push(Vlr {
        user_id: "LASF_Spec".into(),
        record_id: 4,
        description: "extra bytes: instance".into(),
        data: instance_descriptor(),
    });
    let header = builder.into_header().map_err(|e| las_err(path, e))?;
    let n = cloud.returns();
    // Point records are encoded here (format 6, LAS 1.4 table 15, plus 4 extra bytes) and handed
    // to the crate as one slab: the crate's per-`Point` path costs ~200 ns a point.
    let mut records = Vec::with_capacity(n * RECORD_BYTES);
    let cell = cloud.rows * cloud.cols;
    for i in (0..cloud.len()).filter(|&i| cloud.has_return(i)) {
        let p = cloud.point_in_vehicle[i];
        let mut rec = [0u8; RECORD_BYTES];
        for (k, v) in [p.x, p.y, p.z].into_iter().enumerate() {
            let count = (f64::from(v) / SCALE_M).round();
            if !(count >= f64::from(i32::MIN) && count <= f64::from(i32::MAX)) {
                return Err(SimError::invalid("point_in_vehicle", v, "|coordinate| <= 214748 m (LAS scale 0.0001 m)"));
            }
            rec[4 * k..4 * k + 4].copy_from_slice(&(count as i32).to_le_bytes());
        }
        let intensity = (cloud.intensity[i].clamp(0.0, 1.0) * 65535.0).round() as u16;
        rec[12..14].copy_from_slice(&intensity.to_le_bytes());
        let shot = i % cell.max(1);
        let returns_in_shot =
            (0..cloud.planes).filter(|&k| cloud.has_return(k * cell + shot)).count().clamp(1, 15) as u8;
        let return_number = cloud.echo[i].saturating_add(1).min(15);
        rec[14] = return_number | (returns_in_shot << 4);
        rec[15] = cloud.sensor[i].min(3) << 4; // scanner channel in bits 4-5; no flags
        rec[16] = asprs_class(cloud.label[i], cloud.ground[i]);
        rec[17] = cloud.label[i].0.min(255) as u8;
        // rec[18..20]: scan angle 0.
        rec[20..22].copy_from_slice(&cloud.ring[i].to_le_bytes());
        rec[22..30].copy_from_slice(&cloud.time_s[i].to_le_bytes());
        rec[30..34].copy_from_slice(&cloud.instance[i].to_le_bytes());
        records.extend_from_slice(&rec);
    }
    let data = PointDataBuilder::new().for_header(&header).build_from_bytes(records).map_err(|e| las_err(path, e))?;
    let mut writer =
        Writer::new(Cursor::new(Vec::with_capacity(n * RECORD_BYTES + 2048)), header).map_err(|e| las_err(path, e))?;
    writer.write_points(&data).map_err(|e| las_err(path, e))?;
    let bytes = writer.into_inner().map_err(|e| las_err(path, e))?.into_inner();
    Ok((bytes, n))
}

/// Writes the returns of `cloud` as LAS 1.4 at `path` (atomically); returns the point count.
pub fn write(path: &Path, cloud: &OrderedCloud) -> Result<usize> {
    write_with(path, cloud, false)
}

/// Writes LAS, or LAZ when `compressed` (see [`encode_with`]); returns the point count.
pub fn write_with(path: &Path, cloud: &OrderedCloud, compressed: bool) -> Result<usize> {
    let (bytes, n) = encode_with(path, cloud, compressed)?;
    super::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(n)
}

/// The largest ratio of a LAZ file's point records to its size accepted (LASzip compresses point
/// records about 5 to 10 times).
const LAZ_MAX_RATIO: u64 = 64;

/// Reads a LAS file (ours or another tool's) into a `1 x N` cloud in file order, the inverse of
/// [`encode`] for our files: `x y z` (vehicle frame for ours; within the 0.1 mm scale), intensity
/// / 65535, `echo` = return number - 1, `time_s` = GPS time (0 without), `label` = `user_data`
/// (our class id; 0 where another tool left it 0), ground = classification 2, `ring` = point
/// source id, `sensor` = scanner channel, `instance` = the first 4 extra bytes when the record has
/// exactly 4 (our `instance` field), `range_m` = distance from the origin, `column` = point index.
/// A malformed file is an error naming it.
pub fn read(path: &Path) -> Result<OrderedCloud> {
    Ok(read_with_origin(path)?.0)
}

/// [`read`], also saying whether the file was written by [`write`] (its header's generating
/// software is `groundtruth`): then its points are in the vehicle frame and `point_source_id` is
/// each return's ring.
pub fn read_with_origin(path: &Path) -> Result<(OrderedCloud, bool)> {
    let file = std::fs::File::open(path).map_err(|e| las_err(path, e.into()))?;
    let file_len = file.metadata().map_err(|e| SimError::io(path, e))?.len();
    read_from(path, std::io::BufReader::new(file), file_len)
}

/// [`read`] on the bytes of a LAS file already in memory (copied once: the `las` crate's reader
/// owns its input); `path` only names the file in errors.
pub fn read_bytes(path: &Path, bytes: &[u8]) -> Result<OrderedCloud> {
    Ok(read_from(path, Cursor::new(bytes.to_vec()), bytes.len() as u64)?.0)
}

/// Bytes of an extended VLR's header (LAS 1.4 table 10): its data follows.
const EVLR_HEADER_BYTES: u64 = 60;

/// Refuses, before the `las` crate reads the header, the counts that would make it allocate more
/// than the file holds or overflow: a LAS 1.4 header's first extended VLR whose record length is
/// past the end of the file (the crate zero-fills a buffer of the declared length, up to 2^64
/// bytes: an abort), and point records whose bytes overflow 64 bits (the crate multiplies and adds
/// them unchecked: a panic where overflow checks are on). Leaves `input` at its start; a header too
/// short for these fields is left to the crate to refuse.
fn check_counts_fit<R: Read + Seek>(path: &Path, input: &mut R, file_len: u64) -> Result<()> {
    let io = |e| SimError::io(path, e);
    let mut head = Vec::with_capacity(255);
    input.by_ref().take(255).read_to_end(&mut head).map_err(io)?;
    let u16_at = |at: usize| u16::from_le_bytes([head[at], head[at + 1]]);
    let u32_at = |at: usize| u32::from_le_bytes(head[at..at + 4].try_into().unwrap_or_default());
    let u64_at = |at: usize| u64::from_le_bytes(head[at..at + 8].try_into().unwrap_or_default());
    if head.len() < 111 || &head[..4] != b"LASF" {
        input.rewind().map_err(io)?;
        return Ok(());
    }
    // LAS 1.4 table 3: offset to point data at 96, record length at 105, legacy count at 107; for
    // 1.4 and later, first EVLR start at 235, EVLR count at 243, 64-bit point count at 247.
    let large = head[24] == 1 && head[25] >= 4 && head.len() >= 255;
    let legacy = u64::from(u32_at(107));
    // The crate's rule: the legacy count when not 0, else the 64-bit one.
    let declared = if legacy == 0 && large { u64_at(247) } else { legacy };
    let record = u64::from(u16_at(105));
    if declared.checked_mul(record).and_then(|b| b.checked_add(u64::from(u32_at(96)))).is_none() {
        return Err(SimError::bad_file(
            path,
            format!("LAS header: {declared} point records of {record} bytes overflow 64 bits"),
        ));
    }
    let (evlr_start, evlrs) = if large { (u64_at(235), u32_at(243)) } else { (0, 0) };
    if evlr_start > 0 && evlrs > 0 && evlr_start.saturating_add(EVLR_HEADER_BYTES) <= file_len {
        // The record length after the header: bytes 20..28 of the EVLR header.
        input.seek(SeekFrom::Start(evlr_start + 20)).map_err(io)?;
        let mut length = [0u8; 8];
        input.read_exact(&mut length).map_err(io)?;
        let length = u64::from_le_bytes(length);
        let room = file_len - evlr_start - EVLR_HEADER_BYTES;
        if length > room {
            return Err(SimError::bad_file(
                path,
                format!(
                    "LAS header: the extended VLR at byte {evlr_start} declares {length} bytes, more than \
                     the {room} bytes left in the file"
                ),
            ));
        }
    }
    input.rewind().map_err(io)
}

/// [`read`] from `input` (`file_len` bytes long); `path` only names the file in errors.
fn read_from<R: Read + Seek + Send + Sync + 'static>(
    path: &Path,
    mut input: R,
    file_len: u64,
) -> Result<(OrderedCloud, bool)> {
    check_counts_fit(path, &mut input, file_len)?;
    let mut reader = las::Reader::new(input).map_err(|e| las_err(path, e))?;
    let ours = reader.header().generating_software() == "groundtruth";
    // The header's point count must fit the file: `read_all` reserves what the header declares,
    // so a 300-byte file declaring billions of points would allocate gigabytes (found by the
    // `las` fuzz target). LAZ: up to `LAZ_MAX_RATIO` times smaller than its records.
    let (declared, format) = (reader.header().number_of_points(), *reader.header().point_format());
    let record = u64::from(format.len()).max(1);
    let holds = if format.is_compressed { file_len.saturating_mul(LAZ_MAX_RATIO) } else { file_len } / record;
    if declared > holds {
        return Err(SimError::bad_file(
            path,
            format!(
                "LAS header: number of point records {declared} is more than the file's {file_len} bytes \
                 can hold ({holds} records of {record} bytes)"
            ),
        ));
    }
    let data = reader.read_all().map_err(|e| las_err(path, e))?;
    let n = data.len();
    let mut c = OrderedCloud::empty(1, n, 1);
    for (i, p) in data.points().enumerate() {
        let p = p.map_err(|e| las_err(path, e))?;
        let v = glam::Vec3::new(p.x as f32, p.y as f32, p.z as f32);
        if !v.is_finite() {
            return Err(SimError::bad_file(path, format!("LAS: point {i} has a non-finite coordinate")));
        }
        c.point_in_vehicle[i] = v;
        c.range_m[i] = v.length();
        c.intensity[i] = f32::from(p.intensity) / 65535.0;
        c.echo[i] = p.return_number.saturating_sub(1);
        c.time_s[i] = p.gps_time.unwrap_or(0.0);
        c.label[i] = SemanticClass(u16::from(p.user_data));
        c.ground[i] = u8::from(p.classification) == 2;
        c.ring[i] = p.point_source_id;
        c.sensor[i] = p.scanner_channel;
        c.column[i] = u32::try_from(i).unwrap_or(u32::MAX);
        if let [a, b, c4, d] = p.extra_bytes[..] {
            c.instance[i] = u32::from_le_bytes([a, b, c4, d]);
        }
    }
    Ok((c, ours))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_gives_back_what_encode_wrote() {
        let mut c = OrderedCloud::empty(2, 3, 1);
        for (i, k) in [(1usize, 0u16), (4, 1)] {
            c.point_in_vehicle[i] = glam::Vec3::new(1.5 + f32::from(k), -2.25, 0.125);
            c.range_m[i] = c.point_in_vehicle[i].length();
            c.intensity[i] = 0.5;
            c.ring[i] = k + 7;
            c.time_s[i] = 0.01 * f64::from(k);
            c.label[i] = if k == 0 { SemanticClass::ROAD } else { SemanticClass::CAR };
            c.ground[i] = k == 0;
            c.instance[i] = 70_000 * u32::from(k);
            c.sensor[i] = 0;
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.las");
        assert_eq!(write(&path, &c).unwrap(), 2);
        let r = read(&path).unwrap();
        assert_eq!((r.rows, r.cols, r.returns()), (1, 2, 2));
        for (j, i) in [(0usize, 1usize), (1, 4)] {
            assert!((r.point_in_vehicle[j] - c.point_in_vehicle[i]).abs().max_element() < 1e-4);
            assert_eq!(
                (r.label[j], r.ground[j], r.ring[j], r.instance[j]),
                (c.label[i], c.ground[i], c.ring[i], c.instance[i])
            );
            assert_eq!(r.time_s[j], c.time_s[i]);
            assert!((r.intensity[j] - 0.5).abs() < 1e-4);
        }
        // A header declaring more points than the file holds is refused before anything is
        // reserved (the legacy 32-bit point count at byte 107, LAS 1.4's 64-bit one at 247).
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
        bytes[247..255].copy_from_slice(&1_000_000_000_000u64.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("number of point records") && e.contains("x.las"), "{e}");
        std::fs::write(&path, b"LASF truncated").unwrap();
        assert!(read(&path).unwrap_err().to_string().contains("x.las"));
    }

    /// Our file of two points, one returning per shot (the bytes [`read_bytes`] is tried on).
    fn two_points() -> (OrderedCloud, Vec<u8>) {
        let mut c = OrderedCloud::empty(1, 2, 1);
        for i in 0..2 {
            c.point_in_vehicle[i] = glam::Vec3::new(1.0 + i as f32, 2.0, -0.5);
            c.range_m[i] = c.point_in_vehicle[i].length();
            c.ring[i] = 3;
            c.instance[i] = 9;
        }
        let (bytes, n) = encode(Path::new("x.las"), &c).unwrap();
        assert_eq!(n, 2);
        (c, bytes)
    }

    #[test]
    fn read_bytes_reads_what_read_reads() {
        let (_, bytes) = two_points();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.las");
        std::fs::write(&path, &bytes).unwrap();
        let (from_file, from_bytes) = (read(&path).unwrap(), read_bytes(&path, &bytes).unwrap());
        assert_eq!(from_bytes.returns(), 2);
        assert_eq!(from_file.point_in_vehicle, from_bytes.point_in_vehicle);
        assert_eq!((from_file.ring, from_file.instance), (from_bytes.ring, from_bytes.instance));
        let e = read_bytes(Path::new("y.las"), &bytes[..bytes.len() - 1]).unwrap_err().to_string();
        assert!(e.contains("y.las"), "{e}");
    }

    #[test]
    fn counts_past_the_file_are_refused_before_the_crate_reads_them() {
        let (_, mut bytes) = two_points();
        // A first extended VLR (LAS 1.4: start at byte 235, count at 243) at the end of the
        // points declaring 2^40 bytes of data in a file of about a kilobyte.
        let evlr_start = bytes.len() as u64;
        bytes[235..243].copy_from_slice(&evlr_start.to_le_bytes());
        bytes[243..247].copy_from_slice(&1u32.to_le_bytes());
        let mut evlr = vec![0u8; EVLR_HEADER_BYTES as usize];
        evlr[20..28].copy_from_slice(&(1u64 << 40).to_le_bytes());
        bytes.extend_from_slice(&evlr);
        let e = read_bytes(Path::new("e.las"), &bytes).unwrap_err().to_string();
        assert!(e.contains("extended VLR") && e.contains("1099511627776 bytes") && e.contains("e.las"), "{e}");
        // The same EVLR with no data: the file reads.
        bytes[evlr_start as usize + 20..evlr_start as usize + 28].copy_from_slice(&0u64.to_le_bytes());
        assert_eq!(read_bytes(Path::new("e.las"), &bytes).unwrap().returns(), 2);
        // A 64-bit point count (legacy count 0) whose records overflow 64 bits.
        let (_, mut bytes) = two_points();
        bytes[107..111].copy_from_slice(&0u32.to_le_bytes());
        bytes[247..255].copy_from_slice(&(u64::MAX / 2).to_le_bytes());
        let e = read_bytes(Path::new("o.las"), &bytes).unwrap_err().to_string();
        assert!(e.contains("overflow 64 bits") && e.contains("o.las"), "{e}");
    }
}
