//! `groundtruth`: LiDAR ground truth on demand. Scans procedural scenes with real sensor models,
//! writes labelled ordered clouds, classifies ground points and evaluates the result.

mod alloc;
mod cli;
mod plot;

use clap::Parser;

fn main() -> std::process::ExitCode {
    alloc::keep_freed_memory();
    end_quietly_on_a_closed_pipe();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Gives SIGPIPE its default action back (end the process), as other command-line tools have it:
/// Rust's runtime ignores the signal, so a print to a pipe whose reader has gone (`groundtruth
/// bench classify ... | head -1`) failed and `println!` panicked with a backtrace. Output files are
/// not pipes: their writes are unaffected.
fn end_quietly_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: `signal` only sets the disposition of SIGPIPE to its default; it is called first
    // thing in `main`, before any other thread exists.
    #[allow(unsafe_code)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
