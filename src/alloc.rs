//! glibc's allocator kept from handing memory back between frames.
//!
//! The program reads, orders and classifies frame after frame with buffers of a few megabytes.
//! glibc's malloc serves such blocks by `mmap` (or grows the heap for them once its threshold has
//! risen) and gives them back to the kernel when they are freed (`munmap`, or trimming the top of
//! the heap), so the next frame's buffers are fresh pages again: a page fault and a zeroed page
//! every 4 KiB. Measured with `bench classify` (min of 3 x 20 repeats, one core): KITTI frames
//! read + order 5.3 ms with the default settings against 3.5 ms with these; the OS1-128 PCD
//! read + order 3.5 against 2.6 ms. Raising the `mmap` threshold to its largest value (32 MiB) and the trim
//! threshold to 1 GiB keeps freed blocks for reuse; the settings are glibc's documented
//! `mallopt` knobs, the ones its `GLIBC_TUNABLES` environment variable also sets.

/// Applies the settings (glibc on Linux; nothing elsewhere). Call first thing in `main`, before
/// any thread starts.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only changes two of malloc's parameters; it is called before any other
    // thread exists, and both values are in the ranges glibc documents (a failure leaves the
    // defaults, which are correct, only slower).
    #[allow(unsafe_code)]
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}
