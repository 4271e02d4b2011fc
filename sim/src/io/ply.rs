//! PLY point clouds: a binary little-endian writer of a frame's returns and a reader of PLY
//! point clouds (ours and other tools', ASCII or binary).
//!
//! Written vertex properties, in grid order (returns only): `x y z` (float, vehicle frame,
//! metres), `intensity` (float, `[0, 1]`), `ring` (int), `time` (double, seconds), `label`
//! (int, SemanticKITTI class), `instance` (int; ids above 2^31 - 1 are clamped), `ground` (uchar
//! 0/1), `nx ny nz` (float, the true surface normal). The integer fields are `int` rather than
//! `ushort`/`uint` because Open3D's PLY reader skips those two types. The reader returns a `1 x N` [`OrderedCloud`]; properties the file lacks
//! get defaults (intensity 0, ring 0, time 0, label 0, instance 0, ground = whether the label is a
//! ground class, normal zero); `column` is the vertex index and `range_m` the distance from the origin.

use std::path::Path;

use glam::Vec3;

use super::plyfile;
use super::read_util::read_file;
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// The comment our writer puts in the header: the file holds a frame's returns in the vehicle
/// frame (not a sensor's), with their rings.
const OUR_COMMENT: &str = "comment groundtruth frame: returns in grid order, vehicle frame";

/// Whether PLY `bytes` were written by [`encode`] (its header comment): vehicle-frame points with
/// their rings, which a sensor's beam table orders only once moved into that sensor's frame.
pub fn written_by_us(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    let end = head.windows(10).position(|w| w == b"end_header").unwrap_or(head.len());
    head[..end].windows(OUR_COMMENT.len()).any(|w| w == OUR_COMMENT.as_bytes())
}

/// Bytes per written vertex.
const VERTEX_BYTES: usize = 4 * 4 + 4 + 8 + 4 + 4 + 1 + 3 * 4;

/// Encodes the returns of `cloud` as a binary little-endian PLY; returns the bytes and the count.
pub fn encode(cloud: &OrderedCloud) -> Result<(Vec<u8>, usize)> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let n = cloud.returns();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\n{OUR_COMMENT}, metres, seconds\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nproperty float \
         intensity\nproperty int ring\nproperty double time\nproperty int label\nproperty int instance\n\
         property uchar ground\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n"
    );
    let mut out = Vec::with_capacity(header.len() + n * VERTEX_BYTES);
    out.extend_from_slice(header.as_bytes());
    for i in (0..cloud.len()).filter(|&i| cloud.has_return(i)) {
        let p = cloud.point_in_vehicle[i];
        let nrm = cloud.normal[i];
        let mut rec = [0u8; VERTEX_BYTES];
        rec[0..4].copy_from_slice(&p.x.to_le_bytes());
        rec[4..8].copy_from_slice(&p.y.to_le_bytes());
        rec[8..12].copy_from_slice(&p.z.to_le_bytes());
        rec[12..16].copy_from_slice(&cloud.intensity[i].to_le_bytes());
        rec[16..20].copy_from_slice(&i32::from(cloud.ring[i]).to_le_bytes());
        rec[20..28].copy_from_slice(&cloud.time_s[i].to_le_bytes());
        rec[28..32].copy_from_slice(&i32::from(cloud.label[i].0).to_le_bytes());
        rec[32..36].copy_from_slice(&(cloud.instance[i].min(i32::MAX as u32) as i32).to_le_bytes());
        rec[36] = u8::from(cloud.ground[i]);
        rec[37..41].copy_from_slice(&nrm.x.to_le_bytes());
        rec[41..45].copy_from_slice(&nrm.y.to_le_bytes());
        rec[45..49].copy_from_slice(&nrm.z.to_le_bytes());
        out.extend_from_slice(&rec);
    }
    Ok((out, n))
}

/// Writes the returns of `cloud` as a binary PLY at `path` (atomically); returns the point count.
pub fn write(path: &Path, cloud: &OrderedCloud) -> Result<usize> {
    let (bytes, n) = encode(cloud)?;
    super::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(n)
}

/// Reads a PLY point cloud (the `vertex` element) into a `1 x N` cloud.
pub fn read(path: &Path) -> Result<OrderedCloud> {
    let bytes = read_file(path)?;
    read_bytes(path, &bytes)
}

/// Parses PLY `bytes` (read from `path`, named in errors) into a `1 x N` cloud.
pub fn read_bytes(path: &Path, bytes: &[u8]) -> Result<OrderedCloud> {
    Ok(read_bytes_with_ring(path, bytes)?.0)
}

/// Reads a PLY point cloud and says whether its vertices carry a `ring` property (the ROS drivers'
/// ring index; `classifier::ordering` then takes rows from it).
pub fn read_with_ring(path: &Path) -> Result<(OrderedCloud, bool)> {
    let bytes = read_file(path)?;
    read_bytes_with_ring(path, &bytes)
}

/// As [`read_bytes`], also saying whether the vertices carry a `ring` property. Ring values that
/// are negative, fractional or beyond 65535 are refused naming the file and the vertex.
pub fn read_bytes_with_ring(path: &Path, bytes: &[u8]) -> Result<(OrderedCloud, bool)> {
    let header = plyfile::parse_header(path, bytes)?;
    let ve = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| SimError::bad_file(path, "PLY has no `vertex` element"))?;
    let el = &header.elements[ve];
    let idx = |names: &[&str]| names.iter().find_map(|n| el.scalar_index(n));
    let (Some(ix), Some(iy), Some(iz)) = (idx(&["x"]), idx(&["y"]), idx(&["z"])) else {
        return Err(SimError::bad_file(path, "PLY `vertex` element lacks scalar x, y or z"));
    };
    let i_int = idx(&["intensity", "scalar_intensity", "reflectance"]);
    let i_ring = idx(&["ring", "channel"]);
    let i_time = idx(&["time", "timestamp"]);
    let i_label = idx(&["label", "class", "scalar_label"]);
    let i_inst = idx(&["instance"]);
    let i_ground = idx(&["ground"]);
    let i_n = match (idx(&["nx"]), idx(&["ny"]), idx(&["nz"])) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let n = el.count;
    let mut cloud = OrderedCloud::empty(1, n, 1);
    plyfile::walk(path, bytes, &header, |e, row, s, _| {
        if e != ve {
            return Ok(());
        }
        let get = |k: Option<usize>, default: f64| k.map_or(default, |k| s[k]);
        let p = Vec3::new(s[ix] as f32, s[iy] as f32, s[iz] as f32);
        let hit = p.is_finite();
        cloud.point_in_vehicle[row] = if hit { p } else { Vec3::NAN };
        cloud.range_m[row] = if hit { p.length() } else { f32::NAN };
        cloud.intensity[row] = get(i_int, 0.0) as f32;
        let ring = get(i_ring, 0.0);
        if !(0.0..=f64::from(u16::MAX)).contains(&ring) || ring.fract() != 0.0 {
            return Err(SimError::bad_file(
                path,
                format!("vertex {row}: ring {ring} is not an integer in 0 ..= 65535"),
            ));
        }
        cloud.ring[row] = ring as u16;
        cloud.column[row] = row as u32;
        cloud.sensor[row] = 0;
        cloud.time_s[row] = get(i_time, 0.0);
        let label = SemanticClass(get(i_label, 0.0) as u16);
        cloud.label[row] = label;
        cloud.instance[row] = get(i_inst, 0.0) as u32;
        cloud.ground[row] = match i_ground {
            Some(k) => s[k] != 0.0,
            None => hit && label.is_ground(),
        };
        if let Some([a, b, c]) = i_n {
            let nrm = Vec3::new(s[a] as f32, s[b] as f32, s[c] as f32);
            cloud.normal[row] = if nrm.is_finite() { nrm } else { Vec3::ZERO };
        }
        Ok(())
    })?;
    Ok((cloud, i_ring.is_some()))
}
