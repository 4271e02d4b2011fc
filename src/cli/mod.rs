//! Command-line interface: one module per subcommand.

mod bench;
mod bench_agreement;
mod bench_classify;
mod bench_scan;
mod classify;
mod classify_bag;
mod common;
mod dataset;
mod demo;
mod eval;
mod eval_dataset;
mod eval_paper;
mod list;
mod render;
mod render_scan;
mod render_scene;
mod scan;
mod scene;
mod shard;
mod sweep;
mod train;
mod train_learned;

use clap::{Parser, Subcommand};

/// LiDAR ground truth on demand: scan procedural scenes, classify ground, evaluate.
#[derive(Parser, Debug)]
#[command(name = "groundtruth", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run: the size of the largest variant (eval's three modes and the flat spellings
// it still reads) costs nothing worth boxing it for.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
enum Command {
    /// The main job on a built-in default: scan, classify, score and draw (city, hdl64e-roof, nitsch).
    Demo(demo::Args),
    /// List the scenes, rigs and classification methods this build knows.
    List(list::Args),
    /// Scan a scene with a rig and write ordered labelled clouds and a manifest.
    Scan(scan::Args),
    /// Scene tools (export a scene mesh).
    #[command(subcommand)]
    Scene(scene::Command),
    /// Draw a scene from above, or a scan as a bird's-eye view or range image (PNG).
    Render(render::Args),
    /// Classify ground points in scanned clouds.
    Classify(classify::Args),
    /// Score methods: `eval scene` (a scanned scene, Table I style), `eval dataset` (a labelled recording) or `eval paper mcdaniel`.
    Eval(eval::Args),
    /// Train a learning method (McDaniel et al.'s SVM, or the learned method's trees) on our scans and write the model (JSON).
    Train(train::Args),
    /// Sensor-mount sensitivity sweeps: run (sharded, resumable), merge, plot, report.
    Sweep(sweep::Args),
    /// Labelled scans as a SemanticKITTI-layout dataset (sharded, resumable), or `verify DIR`.
    Dataset(dataset::Args),
    /// Benchmarks that print one JSON object.
    #[command(subcommand)]
    Bench(bench::Command),
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(a) => demo::run(a),
        Command::List(a) => list::run(a),
        Command::Scan(a) => scan::run(a),
        Command::Scene(c) => scene::run(c),
        Command::Render(a) => render::run(a),
        Command::Classify(a) => classify::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Train(a) => train::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Dataset(a) => dataset::run(a),
        Command::Bench(c) => bench::run(c),
    }
}

#[cfg(test)]
mod tests {
    use clap::{CommandFactory, Parser};

    use super::{Cli, Command, bench, bench_agreement, bench_scan, demo};

    /// The speed that `demo`, `bench scan` and `bench agreement` take from `words`: either spelling,
    /// else the command's own default.
    fn speed(words: &[&str]) -> Result<f32, clap::Error> {
        let cli = Cli::try_parse_from(["groundtruth"].iter().chain(words))?;
        Ok(match cli.command {
            Command::Demo(a) => a.speed.or(demo::DEFAULT_SPEED_M_PER_S),
            Command::Bench(bench::Command::Scan(a)) => a.speed.or(bench_scan::DEFAULT_SPEED_M_PER_S),
            Command::Bench(bench::Command::Agreement(a)) => a.speed.or(bench_agreement::DEFAULT_SPEED_M_PER_S),
            other => panic!("not a command with a speed: {other:?}"),
        })
    }

    #[test]
    fn speed_flags_take_the_unit_spelling_and_the_deprecated_one() {
        Cli::command().debug_assert();
        let cases = [
            (&["demo"][..], demo::DEFAULT_SPEED_M_PER_S),
            (&["bench", "scan"][..], bench_scan::DEFAULT_SPEED_M_PER_S),
            (&["bench", "agreement"][..], bench_agreement::DEFAULT_SPEED_M_PER_S),
        ];
        // The defaults as the help states them.
        assert_eq!(cases.map(|c| c.1), [5.0, 0.0, 10.0]);
        for (words, default) in cases {
            assert_eq!(speed(words).unwrap(), default, "{words:?}");
            for flag in ["--speed-m-per-s", "--speed"] {
                let given = [words, &[flag, "-2.5"][..]].concat();
                assert_eq!(speed(&given).unwrap(), -2.5, "{given:?}");
            }
            let both = [words, &["--speed-m-per-s", "1", "--speed", "2"][..]].concat();
            let e = speed(&both).unwrap_err();
            assert_eq!(e.kind(), clap::error::ErrorKind::ArgumentConflict, "{both:?}");
            // The unit spelling shows in the help with the command's default, the old one does not.
            let sub = Cli::command();
            let sub = words.iter().fold(sub, |c, w| c.find_subcommand(w).unwrap().clone());
            let help = sub
                .get_arguments()
                .map(|a| (a.get_id().as_str().to_string(), a.is_hide_set(), a.get_help().map(|h| h.to_string())))
                .collect::<Vec<_>>();
            let unit = help.iter().find(|(id, ..)| id == "speed_m_per_s").unwrap();
            assert!(!unit.1 && unit.2.as_deref().unwrap().contains(&format!("default {default}")), "{unit:?}");
            assert!(help.iter().find(|(id, ..)| id == "speed").unwrap().1, "{words:?}");
        }
    }
}
