//! McDaniel et al. on the three bundled forests: leave-one-out accuracy on the min-z candidates
//! (train on two scenes, test on the third, as Tables I-III), TPR at FPR < 0.5 %, AUC, stage times,
//! and optionally the default model trained on all three.
//!
//! ```sh
//! cargo run --release -p groundtruth-classifier --example mcdaniel_forests [-- --write-model classifier/models/mcdaniel-forest.json]
//!     [--note TEXT] [--heights] [--debug] [--max-iter N] [--eps X] [--pyramid LAYERS] [--drop K]
//! ```
//!
//! Rigs as seed 002: `forest-sparse` with `sim/rigs/nodding-180.toml` (180 deg), `forest-moderate`
//! and `forest-dense` with the `utm30lx-nodding` preset (270 deg); scene seed 0, scan seed 0, default
//! measurement effects.

use std::time::Instant;

use classifier::mcdaniel::{self, CandidateSet, FeatureParams, McDanielTimes, TrainParams, TrueClass};

fn scan(scene: &str, rig: &str) -> sim::OrderedCloud {
    let scene = scenes::load(scene, 0).expect("bundled scene");
    let rig = sim::Rig::load(rig).expect("rig");
    let config = sim::scan::ScanConfig { ego_z_m: scene.ego_ground_z_m, ..Default::default() };
    sim::scan::scan(&scene.mesh, &rig, &config).expect("scan").remove(0).cloud
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let write_model = args.iter().position(|a| a == "--write-model").and_then(|i| args.get(i + 1)).cloned();
    let nodding_180 = concat!(env!("CARGO_MANIFEST_DIR"), "/../sim/rigs/nodding-180.toml");
    let scenes =
        [("forest-sparse", nodding_180), ("forest-moderate", "utm30lx-nodding"), ("forest-dense", "utm30lx-nodding")];
    let max_iter: usize = args
        .iter()
        .position(|a| a == "--max-iter")
        .and_then(|i| args.get(i + 1))
        .map_or(300_000, |s| s.parse().expect("--max-iter N"));
    let eps: f64 = args
        .iter()
        .position(|a| a == "--eps")
        .and_then(|i| args.get(i + 1))
        .map_or(0.01, |s| s.parse().expect("--eps X"));
    let train_params =
        TrainParams { svm: mcdaniel::SvmParams { max_iter, eps, ..Default::default() }, ..Default::default() };
    let pyramid_layers: u32 = args
        .iter()
        .position(|a| a == "--pyramid")
        .and_then(|i| args.get(i + 1))
        .map_or(4, |s| s.parse().expect("--pyramid N"));
    let params = FeatureParams { pyramid_layers, ..FeatureParams::default() };
    let mut clouds = Vec::new();
    let mut sets: Vec<CandidateSet> = Vec::new();
    for (scene, rig) in scenes {
        let t = Instant::now();
        let cloud = scan(scene, rig);
        let scan_s = t.elapsed().as_secs_f64();
        let mut set = mcdaniel::candidates(&cloud, &params, None).expect("candidates");
        // --drop K (1..=8): feature K held at 0 (an ablation; the model learns no weight for it).
        if let Some(k) = args.iter().position(|a| a == "--drop").and_then(|i| args.get(i + 1)) {
            let k: usize = k.parse().expect("--drop 1..=8");
            set.features.iter_mut().for_each(|f| f[k - 1] = 0.0);
        }
        let origins = classifier::sensor_origin::estimate_origins(&cloud);
        println!(
            "{scene}: {} x {} cells, {} returns, {} candidates ({} ground) ; scan {scan_s:.2} s ; origin {:?}",
            cloud.rows,
            cloud.cols,
            cloud.returns(),
            set.len(),
            set.ground.iter().filter(|&&g| g).count(),
            origins
        );
        clouds.push(cloud);
        sets.push(set);
    }
    for test in 0..3 {
        let train_sets: Vec<CandidateSet> = (0..3).filter(|&k| k != test).map(|k| sets[k].clone()).collect();
        let t = Instant::now();
        let (model, report) = mcdaniel::train_with_report(&train_sets, &train_params).expect("train");
        let train_s = t.elapsed().as_secs_f64();
        println!("  solver: {report:?}");
        let set = &sets[test];
        let scores = mcdaniel::decision_values(&model, set);
        println!(
            "\ntest {} (trained on the other two in {train_s:.3} s): weights {:?} bias {:.3}",
            scenes[test].0, model.weights, model.bias
        );
        println!("  {:<8} {:>8} {:>8} {:>8}", "class", "min-z", "ground", "non-gnd");
        let mut correct = 0;
        for class in TrueClass::ALL {
            let idx: Vec<usize> = (0..set.len()).filter(|&k| set.class[k] == class).collect();
            let called = idx.iter().filter(|&&k| scores[k] > 0.0).count();
            correct += if class == TrueClass::Ground { called } else { idx.len() - called };
            println!("  {:<8} {:>8} {:>8} {:>8}", class.name(), idx.len(), called, idx.len() - called);
        }
        let curve = mcdaniel::roc_curve(&scores, &set.ground).expect("roc");
        if args.iter().any(|a| a == "--debug") {
            let mut neg: Vec<usize> = (0..set.len()).filter(|&k| !set.ground[k]).collect();
            neg.sort_by(|&a, &b| scores[b].total_cmp(&scores[a]));
            for &k in neg.iter().take(6) {
                println!(
                    "  top negative {:?} score {:.3} at {} f {:?}",
                    set.class[k], scores[k], set.point_in_vehicle[k], set.features[k]
                );
            }
        }
        println!(
            "  accuracy {:.4}  AUC {:.4}  TPR at FPR < 0.5 % {:.3}  at FPR < 7 % {:.3}  at FPR < 10 % {:.3}",
            correct as f64 / set.len() as f64,
            mcdaniel::auc(&curve),
            mcdaniel::roc::tpr_at_fpr_below(&curve, 0.005),
            mcdaniel::roc::tpr_at_fpr_below(&curve, 0.07),
            mcdaniel::roc::tpr_at_fpr_below(&curve, 0.10),
        );
        // Whole cloud, at the default height h and (with --heights) others.
        let heights: &[f32] =
            if args.iter().any(|a| a == "--heights") { &[0.05, 0.1, 0.15, 0.25, 0.5] } else { &[0.15] };
        for &h in heights {
            let params = mcdaniel::McDanielParams { ground_height_m: h, ..Default::default() };
            let mut m = mcdaniel::McDaniel::new(model.clone(), params).expect("model");
            let d = m.classify(&clouds[test]).expect("classify");
            let mut eval = classifier::Evaluation::default();
            eval.add_frame(&clouds[test], &d);
            let s = eval.pooled.scores();
            println!(
                "  whole cloud, h = {h} m: acc {:.4} FPR {:.4} precision {:.4} recall {:.4} F1 {:.4}",
                s.acc, s.fpr, s.precision, s.recall, s.f1
            );
        }
    }
    // Stage times on forest-dense (utm30lx-nodding, 200 x 1081), best of 10.
    let model = mcdaniel::train(&sets, &train_params).expect("train");
    let mut m = mcdaniel::McDaniel::new(model.clone(), Default::default()).expect("model");
    let mut best = McDanielTimes { origins_s: f64::MAX, ..Default::default() };
    let mut best_total = f64::MAX;
    for _ in 0..10 {
        m.classify(&clouds[2]).expect("classify");
        if m.times.total_s() < best_total {
            best_total = m.times.total_s();
            best = m.times;
        }
    }
    println!("\nforest-dense utm30lx-nodding, {} threads, best of 10 (ms):", rayon::current_num_threads());
    for (name, s) in best.named() {
        println!("  {name:<10} {:8.3}", s * 1e3);
    }
    println!("  {:<10} {:8.3}", "total", best_total * 1e3);
    if let Some(path) = write_model {
        let mut model = model;
        model.trained_on = serde_json::json!({
            "scenes": [
                {"scene": "forest-sparse", "rig": "sim/rigs/nodding-180.toml", "scene_seed": 0, "scan_seed": 0, "candidates": sets[0].len()},
                {"scene": "forest-moderate", "rig": "utm30lx-nodding", "scene_seed": 0, "scan_seed": 0, "candidates": sets[1].len()},
                {"scene": "forest-dense", "rig": "utm30lx-nodding", "scene_seed": 0, "scan_seed": 0, "candidates": sets[2].len()},
            ],
            "frames": 1,
            "measurement": "default effects (not ideal)",
            "svm": format!("dual coordinate descent, L1-loss (hinge), C = 100, eps {eps}, at most {max_iter} passes, bias as feature 1, seed 0"),
            "note": args.iter().position(|a| a == "--note").and_then(|i| args.get(i + 1)),
            "by": "cargo run --release -p groundtruth-classifier --example mcdaniel_forests -- --write-model classifier/models/mcdaniel-forest.json",
        });
        model.save(std::path::Path::new(&path)).expect("save");
        println!("wrote {path}");
    }
}
