//! Input frames as bytes, read into one page-aligned buffer reused from file to file.
//!
//! The reader ([`super::FrameReader`]) decodes each frame straight from its file's bytes. Where those
//! bytes land matters more than how they are fetched: the kernel copies a file out of the page
//! cache about four times as fast into a destination aligned to the cache line as into one at a
//! 16-byte offset, which is where `malloc` puts a large `Vec<u8>`'s data. Measured on this
//! project's machine (one core, six 2 MB KITTI `.bin` files, min of 40, copy and decode to points):
//! 0.25 ms into a page-aligned buffer, 1.0 ms at a 16-byte offset, and 0.30-0.35 ms to map the
//! file, decode from the map and unmap it (the page faults and the unmapping cost more than the
//! copy). So every file is read, with one `read` call where its length is known, into a buffer of
//! 4 KiB pages; the buffer grows to the largest file and stays.

use std::io::Read;
use std::path::Path;

/// One page of the buffer: the alignment is what makes the kernel's copy fast.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(4096))]
struct Page([u8; PAGE_BYTES]);

/// Bytes per [`Page`].
const PAGE_BYTES: usize = 4096;

/// Largest input file read (4 GiB): a LiDAR frame is a few megabytes (an OS1-128 x 2,048 PCD about
/// 20 MB), so a larger file is refused rather than read whole into memory.
const MAX_FILE_BYTES: usize = 4 << 30;

/// The bytes of the last file loaded, in a page-aligned buffer reused from file to file.
#[derive(Default)]
pub struct InputBytes {
    pages: Vec<Page>,
    len: usize,
}

impl InputBytes {
    /// Reads `path` whole and returns its bytes (the start is aligned to 4 KiB); the previous
    /// file's bytes are released.
    pub fn load(&mut self, path: &Path) -> Result<&[u8], sim::SimError> {
        self.len = 0;
        let io = |e| sim::SimError::io(path, e);
        let mut file = std::fs::File::open(path).map_err(io)?;
        // Room for the whole file and the read that finds its end, where the length is known.
        let expected = file.metadata().ok().filter(|m| m.is_file()).map_or(0, |m| m.len());
        let too_large = |len: u64| {
            sim::SimError::bad_file(
                path,
                format!("{len} bytes: larger than the {MAX_FILE_BYTES} bytes a frame file may have"),
            )
        };
        let expected =
            usize::try_from(expected).ok().filter(|&n| n <= MAX_FILE_BYTES).ok_or_else(|| too_large(expected))?;
        self.reserve(path, expected + 1)?;
        loop {
            if self.len == self.pages.len() * PAGE_BYTES {
                if self.len >= MAX_FILE_BYTES {
                    return Err(too_large(self.len as u64));
                }
                self.reserve(path, (self.len * 2).clamp(PAGE_BYTES, MAX_FILE_BYTES))?;
            }
            let free = &mut bytemuck::cast_slice_mut::<Page, u8>(&mut self.pages)[self.len..];
            match file.read(free) {
                Ok(0) => break,
                Ok(n) => self.len += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        }
        Ok(&bytemuck::cast_slice::<Page, u8>(&self.pages)[..self.len])
    }

    /// Grows the buffer to hold at least `bytes` (pages are zeroed once, when first added); an
    /// allocation that fails is an error naming `path`, not an abort.
    fn reserve(&mut self, path: &Path, bytes: usize) -> Result<(), sim::SimError> {
        let pages = bytes.div_ceil(PAGE_BYTES);
        if pages > self.pages.len() {
            self.pages.try_reserve_exact(pages - self.pages.len()).map_err(|e| {
                sim::SimError::io(path, std::io::Error::new(std::io::ErrorKind::OutOfMemory, e.to_string()))
            })?;
            self.pages.resize(pages, Page([0; PAGE_BYTES]));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_of_any_length_give_their_bytes_page_aligned() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut input = InputBytes::default();
        // Smaller after larger (the buffer is reused) and lengths on and next to page boundaries.
        for len in [0usize, 17, (1 << 20) - 1, 1 << 20, (3 << 20) + 5, 4096, 4095, 4097, 8192, 5] {
            let path = dir.path().join(format!("f{len}"));
            let bytes: Vec<u8> = (0..len).map(|i| (i * 7 % 251) as u8).collect();
            std::fs::write(&path, &bytes).expect("write");
            let got = input.load(&path).expect("load");
            assert_eq!(got, bytes.as_slice(), "{len} bytes");
            assert_eq!(got.as_ptr() as usize % PAGE_BYTES, 0, "aligned at {len} bytes");
        }
        // A sparse file past the limit is refused from its length, before any read.
        let huge = dir.path().join("huge.bin");
        std::fs::File::create(&huge).and_then(|f| f.set_len((MAX_FILE_BYTES + 1) as u64)).expect("sparse file");
        let err = input.load(&huge).expect_err("too large").to_string();
        assert!(err.contains("huge.bin") && err.contains("larger than"), "{err}");
        let missing = dir.path().join("missing.pcd");
        let err = input.load(&missing).expect_err("a missing file is an error");
        assert!(err.to_string().contains("missing.pcd"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_stream_without_a_length_is_read_to_its_end() {
        // A FIFO's metadata has no length: the buffer grows as the bytes come.
        let dir = tempfile::tempdir().expect("temp dir");
        let fifo = dir.path().join("pipe.bin");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs");
        assert!(status.success());
        let bytes: Vec<u8> = (0..20_000u32).map(|i| (i % 253) as u8).collect();
        let writer = {
            let (fifo, bytes) = (fifo.clone(), bytes.clone());
            std::thread::spawn(move || std::fs::write(fifo, bytes).expect("write the pipe"))
        };
        let mut input = InputBytes::default();
        assert_eq!(input.load(&fifo).expect("load"), bytes.as_slice());
        writer.join().expect("writer");
    }
}
