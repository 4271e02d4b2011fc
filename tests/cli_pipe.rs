//! The binary writing to a pipe whose reader has gone: it ends quietly (by SIGPIPE, as other
//! command-line tools do), without a panic or a backtrace.

use std::process::{Command, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_groundtruth");

#[test]
fn a_closed_pipe_ends_the_program_without_a_panic() {
    let mut child = Command::new(BIN)
        .args(["bench", "classify", "--scene", "flat-objects", "--rig", "lux-roof-4", "--frames", "1"])
        .args(["--repeats", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes before the program has scanned and classified its frame and printed.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(out.status.code(), Some(101), "{stderr}");
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}: {stderr}", out.status);
    }
}
