//! Prints seed 002's shares table for the three forests: per scene and seed, the returns over
//! beams of one nod of the UTM-30LX at the paper's mount (180 deg for `sparse`, 270 deg for the
//! others) and the shares of ground, bushes/shrubs, trunks and branches/leaves, the paper's
//! Tables I-III beside them; with `--roof`, also the ground share of every roof rig's returns.
//!
//! ```sh
//! cargo run --release -p gt-tests --example forest_shares -- --seeds 0,1,2,3,4 [--roof]
//! ```

use gt_tests::forests::{self, PAPER, ROOF_RIGS};

fn main() {
    let mut seeds: Vec<u64> = (0..5).collect();
    let mut roof = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => {
                let list = args.next().unwrap_or_default();
                seeds = match list.split(',').map(|s| s.trim().parse::<u64>()).collect::<Result<Vec<_>, _>>() {
                    Ok(v) if !v.is_empty() => v,
                    _ => fail(&format!("--seeds: `{list}` is not a comma-separated list of seeds (e.g. 0,1,2)")),
                };
            }
            "--roof" => roof = true,
            "-h" | "--help" => {
                println!("forest_shares [--seeds 0,1,2,...] [--roof]");
                return;
            }
            other => fail(&format!("unknown argument `{other}` (use --seeds LIST, --roof)")),
        }
    }
    println!("| scene | seed | returns | ground | bushes/shrubs | trunks | branches/leaves | worst share error |");
    println!("|---|---|---|---|---|---|---|---|");
    for paper in &PAPER {
        let rig = paper.load_rig();
        let p = paper.shares();
        println!(
            "| {} | paper | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.1} % | |",
            paper.scene,
            100.0 * paper.returns_fraction(),
            100.0 * p[0],
            100.0 * p[1],
            100.0 * p[2],
            100.0 * p[3]
        );
        for &seed in &seeds {
            let c = forests::measure(paper.scene, &rig, seed);
            let m = c.shares();
            let (rel, points) = forests::deviation(paper, &c);
            let worst = rel.iter().copied().fold(0.0, f64::max);
            println!(
                "| {} | {seed} | {:.1} % ({points:+.1}) | {:.1} % | {:.1} % | {:.1} % | {:.1} % | {:.0} %{} |",
                paper.scene,
                100.0 * c.returns_fraction(),
                100.0 * m[0],
                100.0 * m[1],
                100.0 * m[2],
                100.0 * m[3],
                100.0 * worst,
                if worst <= 0.2 && points.abs() <= 15.0 { "" } else { " (out)" }
            );
        }
    }
    if roof {
        println!();
        println!("| roof rig | scene | seed | returns | ground share | ground within {} m |", forests::NEAR_M);
        println!("|---|---|---|---|---|---|");
        for name in ROOF_RIGS {
            let rig = sim::Rig::preset(name).unwrap_or_else(|e| fail(&e.to_string()));
            for paper in &PAPER {
                for &seed in &seeds {
                    let c = forests::measure(paper.scene, &rig, seed);
                    println!(
                        "| {name} | {} | {seed} | {} | {:.1} % | {} |",
                        paper.scene,
                        c.returns,
                        100.0 * c.ground_share(),
                        c.near_ground
                    );
                }
            }
        }
    }
}

fn fail(message: &str) -> ! {
    eprintln!("forest_shares: {message}");
    std::process::exit(2)
}
