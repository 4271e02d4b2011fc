//! Input frames as bytes, mapped into memory rather than copied.
//!
//! `classify` and `bench classify` decode each frame straight from its file's bytes. Copying a
//! file out of the page cache (`read`) costs about as much as decoding it: measured on this
//! project's machine (one core, min of 60), 1.8 ms for a 4.4 MB OS1-128 PCD and 0.8 ms for a
//! 2 MB KITTI `.bin`, against 0.5 and 0.2 ms to map and touch every cache line. Files from
//! 1 MiB on are therefore mapped (`memmap2`, read-only); smaller ones, and files that cannot be
//! mapped (pipes, special files), are read into a reused buffer.
//!
//! The mapping's contract: the file is not truncated or rewritten by another program while its
//! frame is decoded (as with every tool that maps its input; a file truncated under the map ends
//! the program with `SIGBUS`). Recordings being classified are finished files.

use std::path::Path;

/// Files at least this large are mapped; smaller ones are read (mapping has a fixed cost).
const MAP_FROM_BYTES: u64 = 1 << 20;

/// The bytes of the last file loaded, mapped or read into a buffer reused from file to file.
#[derive(Default)]
pub struct InputBytes {
    map: Option<memmap2::Mmap>,
    buf: Vec<u8>,
}

impl InputBytes {
    /// Loads `path` (mapped from [`MAP_FROM_BYTES`] on, else read) and returns its bytes; the
    /// previous file's bytes are released.
    pub fn load(&mut self, path: &Path) -> Result<&[u8], sim::SimError> {
        self.map = None;
        let file = std::fs::File::open(path).map_err(|e| sim::SimError::io(path, e))?;
        let len = file.metadata().map(|m| m.is_file().then_some(m.len())).ok().flatten();
        if len.is_some_and(|n| n >= MAP_FROM_BYTES) {
            // SAFETY: a read-only private map of a regular file; the bytes stay valid while the
            // map lives (it is dropped before the next file is loaded). The module's contract
            // (no other program truncates or rewrites the file meanwhile) is the one every
            // program that maps its input relies on.
            #[allow(unsafe_code)]
            if let Ok(map) = unsafe { memmap2::Mmap::map(&file) } {
                return Ok(self.map.insert(map));
            }
        }
        drop(file);
        sim::io::read_file_into(path, &mut self.buf)?;
        Ok(&self.buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_and_small_files_give_their_bytes() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut input = InputBytes::default();
        for len in [0usize, 17, (1 << 20) - 1, 1 << 20, (3 << 20) + 5] {
            let path = dir.path().join(format!("f{len}"));
            let bytes: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
            std::fs::write(&path, &bytes).expect("write");
            assert_eq!(input.load(&path).expect("load"), bytes.as_slice(), "{len} bytes");
            assert_eq!(input.map.is_some(), len >= 1 << 20, "mapped at {len} bytes");
        }
        let missing = dir.path().join("missing.pcd");
        let err = input.load(&missing).expect_err("a missing file is an error");
        assert!(err.to_string().contains("missing.pcd"), "{err}");
    }
}
