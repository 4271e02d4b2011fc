//! The ROS 2 messages the bags carry, as serde types that `cdr-encoding` (the CDR
//! serializer of RustDDS and ros2-client) turns into the bytes of a ROS 2 `cdr` message, and their
//! message definitions (the `ros2msg` schema text rosbag2 stores).

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/msg/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, `0 ..< 1e9`.
    pub nanosec: u32,
}

impl Time {
    /// The time `seconds` after the epoch (negative times are clamped to 0).
    pub fn from_seconds(seconds: f64) -> Self {
        let ns = (seconds.max(0.0) * 1e9).round() as u64;
        Self { sec: (ns / 1_000_000_000).min(i32::MAX as u64) as i32, nanosec: (ns % 1_000_000_000) as u32 }
    }

    /// Nanoseconds since the epoch.
    pub fn nanoseconds(self) -> u64 {
        self.sec.max(0) as u64 * 1_000_000_000 + u64::from(self.nanosec)
    }
}

/// `std_msgs/msg/Header`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// Acquisition time.
    pub stamp: Time,
    /// The frame the data is in.
    pub frame_id: String,
}

/// `sensor_msgs/msg/PointField`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PointField {
    /// Field name.
    pub name: String,
    /// Byte offset in a point.
    pub offset: u32,
    /// Datatype ([`datatype`]).
    pub datatype: u8,
    /// Elements.
    pub count: u32,
}

/// `sensor_msgs/msg/PointField` datatypes.
pub mod datatype {
    /// int8.
    pub const INT8: u8 = 1;
    /// uint8.
    pub const UINT8: u8 = 2;
    /// int16.
    pub const INT16: u8 = 3;
    /// uint16.
    pub const UINT16: u8 = 4;
    /// int32.
    pub const INT32: u8 = 5;
    /// uint32.
    pub const UINT32: u8 = 6;
    /// float32.
    pub const FLOAT32: u8 = 7;
    /// float64.
    pub const FLOAT64: u8 = 8;

    /// Size in bytes and PCD type letter of `datatype`, `None` for an unknown one.
    pub fn size_and_letter(datatype: u8) -> Option<(u32, char)> {
        Some(match datatype {
            INT8 => (1, 'I'),
            UINT8 => (1, 'U'),
            INT16 => (2, 'I'),
            UINT16 => (2, 'U'),
            INT32 => (4, 'I'),
            UINT32 => (4, 'U'),
            FLOAT32 => (4, 'F'),
            FLOAT64 => (8, 'F'),
            _ => return None,
        })
    }

    /// The datatype of a PCD type letter and size.
    pub fn of(letter: char, size: usize) -> Option<u8> {
        Some(match (letter, size) {
            ('I', 1) => INT8,
            ('U', 1) => UINT8,
            ('I', 2) => INT16,
            ('U', 2) => UINT16,
            ('I', 4) => INT32,
            ('U', 4) => UINT32,
            ('F', 4) => FLOAT32,
            ('F', 8) => FLOAT64,
            _ => return None,
        })
    }
}

/// `sensor_msgs/msg/PointCloud2`, its data borrowed where it was decoded from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointCloud2<'a> {
    /// Stamp and frame.
    pub header: Header,
    /// Rows (1 for an unorganized cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The point's fields.
    pub fields: Vec<PointField>,
    /// Whether the data is big-endian.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points, row by row.
    #[serde(borrow, with = "serde_bytes")]
    pub data: std::borrow::Cow<'a, [u8]>,
    /// Whether every point is valid (no NaN).
    pub is_dense: bool,
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/msg/Transform`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation, metres.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

impl Transform {
    /// The transform of an affine map (rotation and translation).
    pub fn of(t: &glam::DAffine3) -> Self {
        let (_, r, p) = t.to_scale_rotation_translation();
        Self {
            translation: Vector3 { x: p.x, y: p.y, z: p.z },
            rotation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w },
        }
    }
}

/// `geometry_msgs/msg/TransformStamped`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's pose in the parent frame (`parent_from_child`).
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// The rosbag2 type name of a point cloud.
pub const POINTCLOUD2: &str = "sensor_msgs/msg/PointCloud2";
/// The rosbag2 type name of a transform list.
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";

/// Separator between the definitions of a message and its dependencies in a `ros2msg` schema.
const SEPARATOR: &str = "================================================================================\n";

const HEADER_DEF: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const TIME_DEF: &str = "int32 sec\nuint32 nanosec\n";

/// The `ros2msg` schema text of `sensor_msgs/msg/PointCloud2`, its dependencies after it.
pub fn pointcloud2_definition() -> String {
    format!(
        "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n\
         {SEPARATOR}MSG: std_msgs/Header\n{HEADER_DEF}\
         {SEPARATOR}MSG: builtin_interfaces/Time\n{TIME_DEF}\
         {SEPARATOR}MSG: sensor_msgs/PointField\n\
         uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n\
         string name\nuint32 offset\nuint8 datatype\nuint32 count\n"
    )
}

/// The `ros2msg` schema text of `tf2_msgs/msg/TFMessage`, its dependencies after it.
pub fn tf_message_definition() -> String {
    format!(
        "geometry_msgs/TransformStamped[] transforms\n\
         {SEPARATOR}MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\nTransform transform\n\
         {SEPARATOR}MSG: std_msgs/Header\n{HEADER_DEF}\
         {SEPARATOR}MSG: builtin_interfaces/Time\n{TIME_DEF}\
         {SEPARATOR}MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n\
         {SEPARATOR}MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n\
         {SEPARATOR}MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"
    )
}

/// The 4-byte encapsulation header of little-endian CDR (`CDR_LE`).
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];
/// The 4-byte encapsulation header of big-endian CDR (`CDR_BE`).
pub const CDR_BE: [u8; 4] = [0x00, 0x00, 0x00, 0x00];

/// A message as ROS 2 `cdr` bytes: the encapsulation header, then the little-endian CDR body.
pub fn to_cdr<T: Serialize>(message: &T, size_hint: usize) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(size_hint + 64);
    out.extend_from_slice(&CDR_LE);
    cdr_encoding::to_writer::<T, byteorder::LittleEndian, _>(&mut out, message).map_err(|e| e.to_string())?;
    Ok(out)
}

/// A message decoded from ROS 2 `cdr` bytes (either byte order), borrowing from them.
pub fn from_cdr<'de, T: Deserialize<'de>>(bytes: &'de [u8]) -> std::result::Result<T, String> {
    if bytes.len() < 4 {
        return Err(format!("{} bytes: shorter than the CDR encapsulation header", bytes.len()));
    }
    let body = &bytes[4..];
    let decoded = match [bytes[0], bytes[1]] {
        [0x00, 0x01] => cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(body),
        [0x00, 0x00] => cdr_encoding::from_bytes::<T, byteorder::BigEndian>(body),
        [a, b] => return Err(format!("encapsulation {a:#04x}{b:02x}: not plain CDR (XCDR2 and others are not read)")),
    };
    decoded.map(|(t, _)| t).map_err(|e| format!("CDR: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_cloud_round_trips_with_ros2_alignment() {
        let pc = PointCloud2 {
            header: Header { stamp: Time { sec: 3, nanosec: 500 }, frame_id: "lidar".into() },
            height: 1,
            width: 2,
            fields: vec![PointField { name: "x".into(), offset: 0, datatype: datatype::FLOAT32, count: 1 }],
            is_bigendian: false,
            point_step: 4,
            row_step: 8,
            data: std::borrow::Cow::Owned(vec![1, 2, 3, 4, 5, 6, 7, 8]),
            is_dense: true,
        };
        let bytes = to_cdr(&pc, 0).unwrap();
        // Encapsulation, sec, nanosec, frame_id "lidar\0" (len 6), then height aligned to 4.
        assert_eq!(&bytes[..4], &CDR_LE);
        assert_eq!(&bytes[4..8], &3i32.to_le_bytes());
        assert_eq!(&bytes[12..16], &6u32.to_le_bytes());
        assert_eq!(&bytes[16..22], b"lidar\0");
        assert_eq!(&bytes[24..28], &1u32.to_le_bytes(), "height after two bytes of padding");
        let back: PointCloud2<'_> = from_cdr(&bytes).unwrap();
        assert_eq!(back, pc);
        assert!(matches!(back.data, std::borrow::Cow::Borrowed(_)), "the data is borrowed, not copied");
        assert!(from_cdr::<PointCloud2<'_>>(&bytes[..30]).is_err());
        assert!(from_cdr::<PointCloud2<'_>>(&[0, 9, 0, 0, 1]).unwrap_err().contains("not plain CDR"));
    }

    #[test]
    fn times_split_into_seconds_and_nanoseconds() {
        let t = Time::from_seconds(12.000_000_25);
        assert_eq!((t.sec, t.nanosec), (12, 250));
        assert_eq!(t.nanoseconds(), 12_000_000_250);
    }
}
