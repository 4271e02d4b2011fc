//! Small helpers shared by the readers: bounded file reading and little-endian scalar decoding.

use std::path::Path;

use crate::error::{Result, SimError};

/// Reads a whole file, mapping I/O errors to [`SimError::Io`] naming the file.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| SimError::io(path, e))
}

/// Scalar types the binary formats use, with their byte size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    /// Signed integer of 1, 2, 4 or 8 bytes.
    I(usize),
    /// Unsigned integer of 1, 2, 4 or 8 bytes.
    U(usize),
    /// IEEE float of 4 or 8 bytes.
    F(usize),
}

impl Scalar {
    /// Size in bytes.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I(n) | Scalar::U(n) | Scalar::F(n) => n,
        }
    }

    /// Decodes one value from the start of `b` (which holds at least `size()` bytes), widening to
    /// `f64`; big-endian when `big` is set. Returns `None` if `b` is too short.
    pub(crate) fn decode(self, b: &[u8], big: bool) -> Option<f64> {
        let n = self.size();
        let raw = b.get(..n)?;
        let mut buf = [0u8; 8];
        if big {
            for (k, &byte) in raw.iter().rev().enumerate() {
                buf[k] = byte;
            }
        } else {
            buf[..n].copy_from_slice(raw);
        }
        let v = match self {
            Scalar::U(1) => f64::from(buf[0]),
            Scalar::U(2) => f64::from(u16::from_le_bytes([buf[0], buf[1]])),
            Scalar::U(4) => f64::from(u32::from_le_bytes([buf[0], buf[1], buf[2], buf[3]])),
            Scalar::U(8) => u64::from_le_bytes(buf) as f64,
            Scalar::I(1) => f64::from(buf[0] as i8),
            Scalar::I(2) => f64::from(i16::from_le_bytes([buf[0], buf[1]])),
            Scalar::I(4) => f64::from(i32::from_le_bytes([buf[0], buf[1], buf[2], buf[3]])),
            Scalar::I(8) => i64::from_le_bytes(buf) as f64,
            Scalar::F(4) => f64::from(f32::from_le_bytes([buf[0], buf[1], buf[2], buf[3]])),
            Scalar::F(8) => f64::from_le_bytes(buf),
            _ => return None,
        };
        Some(v)
    }
}

/// Splits `bytes` into the header text up to and including the line for which `is_last` holds,
/// and the offset where the data begins. Header lines end with `\n` (a trailing `\r` is dropped).
/// Returns `None` if no such line appears within the first `max_header` bytes.
pub(crate) fn header_lines(
    bytes: &[u8],
    max_header: usize,
    mut is_last: impl FnMut(&str) -> bool,
) -> Option<(Vec<String>, usize)> {
    let mut lines = Vec::new();
    let mut start = 0;
    let limit = bytes.len().min(max_header);
    while start < limit {
        let end = bytes[start..limit].iter().position(|&b| b == b'\n').map(|p| start + p)?;
        let line = String::from_utf8_lossy(&bytes[start..end]);
        let line = line.trim_end_matches('\r').to_string();
        start = end + 1;
        let last = is_last(&line);
        lines.push(line);
        if last {
            return Some((lines, start));
        }
    }
    None
}
