//! `groundtruth`: LiDAR ground truth on demand. Scans procedural scenes with real sensor models,
//! writes labelled ordered clouds, classifies ground points and evaluates the result.

mod alloc;
mod cli;
mod input_bytes;
mod plot;

use clap::Parser;

fn main() -> std::process::ExitCode {
    alloc::keep_freed_memory();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
