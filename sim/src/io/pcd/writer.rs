//! The organized PCD writer of our own layout (see the parent module's docs for the fields).

use std::io::Write;
use std::path::Path;

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

/// Field names, type letters and sizes the writer emits, in order.
const WRITE_FIELDS: [(&str, char, usize); 16] = [
    ("x", 'F', 4),
    ("y", 'F', 4),
    ("z", 'F', 4),
    ("intensity", 'F', 4),
    ("ring", 'U', 2),
    ("time", 'F', 8),
    ("label", 'U', 4),
    ("instance", 'U', 4),
    ("ground", 'U', 1),
    ("range", 'F', 4),
    ("sensor", 'U', 1),
    ("echo", 'U', 1),
    ("column", 'U', 4),
    ("normal_x", 'F', 4),
    ("normal_y", 'F', 4),
    ("normal_z", 'F', 4),
];

/// Bytes per point of the binary records the writer emits.
pub const RECORD_BYTES: usize = 4 * 4 + 2 + 8 + 4 + 4 + 1 + 4 + 1 + 1 + 4 + 3 * 4;

fn header_text(cloud: &OrderedCloud, ascii: bool) -> String {
    let mut h = String::with_capacity(512);
    h.push_str("# .PCD v0.7 - Point Cloud Data file format\n");
    h.push_str(&format!("# groundtruth rows={} planes={}\n", cloud.rows, cloud.planes));
    h.push_str("VERSION 0.7\nFIELDS");
    for (name, _, _) in WRITE_FIELDS {
        h.push(' ');
        h.push_str(name);
    }
    h.push_str("\nSIZE");
    for (_, _, size) in WRITE_FIELDS {
        h.push_str(&format!(" {size}"));
    }
    h.push_str("\nTYPE");
    for (_, ty, _) in WRITE_FIELDS {
        h.push(' ');
        h.push(ty);
    }
    h.push_str("\nCOUNT");
    for _ in WRITE_FIELDS {
        h.push_str(" 1");
    }
    let height = cloud.rows * cloud.planes;
    h.push_str(&format!(
        "\nWIDTH {}\nHEIGHT {}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {}\n",
        cloud.cols,
        height,
        cloud.cols * height,
        if ascii { "ascii" } else { "binary" }
    ));
    h
}

/// Encodes the organized PCD file of `cloud` (binary, or ASCII when `ascii`).
pub fn encode(cloud: &OrderedCloud, ascii: bool) -> Result<Vec<u8>> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let n = cloud.len();
    let header = header_text(cloud, ascii);
    let mut out = Vec::with_capacity(header.len() + n * if ascii { 120 } else { RECORD_BYTES });
    out.extend_from_slice(header.as_bytes());
    for i in 0..n {
        let p = cloud.point_in_vehicle[i];
        let nrm = cloud.normal[i];
        if ascii {
            // `{}` prints the shortest text that parses back to the same float.
            let _ = writeln!(
                out,
                "{} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {}",
                p.x,
                p.y,
                p.z,
                cloud.intensity[i],
                cloud.ring[i],
                cloud.time_s[i],
                cloud.label[i].0,
                cloud.instance[i],
                u8::from(cloud.ground[i]),
                cloud.range_m[i],
                cloud.sensor[i],
                cloud.echo[i],
                cloud.column[i],
                nrm.x,
                nrm.y,
                nrm.z
            );
        } else {
            let mut rec = [0u8; RECORD_BYTES];
            rec[0..4].copy_from_slice(&p.x.to_le_bytes());
            rec[4..8].copy_from_slice(&p.y.to_le_bytes());
            rec[8..12].copy_from_slice(&p.z.to_le_bytes());
            rec[12..16].copy_from_slice(&cloud.intensity[i].to_le_bytes());
            rec[16..18].copy_from_slice(&cloud.ring[i].to_le_bytes());
            rec[18..26].copy_from_slice(&cloud.time_s[i].to_le_bytes());
            rec[26..30].copy_from_slice(&u32::from(cloud.label[i].0).to_le_bytes());
            rec[30..34].copy_from_slice(&cloud.instance[i].to_le_bytes());
            rec[34] = u8::from(cloud.ground[i]);
            rec[35..39].copy_from_slice(&cloud.range_m[i].to_le_bytes());
            rec[39] = cloud.sensor[i];
            rec[40] = cloud.echo[i];
            rec[41..45].copy_from_slice(&cloud.column[i].to_le_bytes());
            rec[45..49].copy_from_slice(&nrm.x.to_le_bytes());
            rec[49..53].copy_from_slice(&nrm.y.to_le_bytes());
            rec[53..57].copy_from_slice(&nrm.z.to_le_bytes());
            out.extend_from_slice(&rec);
        }
    }
    Ok(out)
}

/// Writes `cloud` as an organized PCD file at `path` (atomically). Returns the point count
/// (`WIDTH * HEIGHT`, every cell).
pub fn write(path: &Path, cloud: &OrderedCloud, ascii: bool) -> Result<usize> {
    let bytes = encode(cloud, ascii)?;
    super::super::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(cloud.len())
}
