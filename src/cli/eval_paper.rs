//! `groundtruth eval --paper mcdaniel`: McDaniel et al.'s evaluation in one command. The three
//! forests are scanned as the paper recorded them (one nod of the UTM-30LX, axis 0.55 m above the
//! ground; 180 deg for `forest-sparse`, 270 deg for the others), the SVM is trained leave-one-out
//! (two forests train, the third tests), and the command prints Tables I-III in the paper's
//! layout (per true class: sensed points, min-z points, classified ground, classified non-ground),
//! the accuracy on min-z points, the ROC's area and true-positive rates at the paper's
//! false-positive rates, and the whole-cloud scores (every column's decision given to the points in
//! it). It writes the ROC figure (`roc.png`, `roc.svg`: three curves, AUC in the legend) to
//! `--out`, and with `--json FILE` every number.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use classifier::Evaluation;
use classifier::mcdaniel::roc::tpr_at_fpr_below;
use classifier::mcdaniel::{self, CandidateSet, FeatureParams, McDaniel, McDanielParams, TrainParams, TrueClass};
use serde_json::json;

use crate::plot::{LinePlot, Series, save_line_plot};

/// One of the paper's scenes as this command scans it, with the paper's figures.
struct PaperScene {
    /// Bundled scene.
    scene: &'static str,
    /// Rig preset (the paper's mount and field of view).
    rig: &'static str,
    /// The paper's table number.
    table: &'static str,
    /// The paper's rows ground / bushes / trunks / canopy: sensed, min-z, ground, non-ground.
    rows: [[u64; 4]; 4],
    /// The paper's accuracy on min-z points.
    accuracy: f64,
}

/// The paper's three scenes (Tables I-III).
const SCENES: [PaperScene; 3] = [
    PaperScene {
        scene: "forest-sparse",
        rig: "utm30lx-nodding-180",
        table: "I",
        rows: [[53488, 677, 598, 79], [0, 0, 0, 0], [8324, 26, 4, 22], [7786, 232, 0, 232]],
        accuracy: 0.9112,
    },
    PaperScene {
        scene: "forest-moderate",
        rig: "utm30lx-nodding",
        table: "II",
        rows: [[74161, 1131, 928, 203], [30987, 463, 103, 360], [4483, 47, 7, 40], [32154, 664, 0, 664]],
        accuracy: 0.8642,
    },
    PaperScene {
        scene: "forest-dense",
        rig: "utm30lx-nodding",
        table: "III",
        rows: [[65192, 444, 440, 4], [67403, 752, 340, 412], [11494, 50, 11, 39], [10314, 379, 1, 378]],
        accuracy: 0.7809,
    },
];

/// False-positive rates at which the paper quotes a 70 % true-positive rate (sparse, moderate, dense).
const PAPER_FPR_AT_TPR_70: [f64; 3] = [0.005, 0.07, 0.10];

/// Row titles of the tables, in [`TrueClass::ALL`] order.
fn row_title(c: TrueClass) -> &'static str {
    match c {
        TrueClass::Ground => "Ground",
        TrueClass::Bush => "Bushes/Shrubs",
        TrueClass::Trunk => "Tree Trunks",
        TrueClass::Canopy => "Tree Branches/Leaves",
        TrueClass::Other => "Other",
    }
}

/// Arguments of the paper evaluation (parsed by `groundtruth eval`).
pub struct PaperArgs {
    /// Seed of the scenes and the scan noise.
    pub seed: u64,
    /// Turn measurement effects off.
    pub ideal: bool,
    /// Where the ROC figures go.
    pub out: PathBuf,
    /// Optional JSON file for every number.
    pub json: Option<PathBuf>,
}

/// One scanned scene with its candidates.
struct Scanned {
    cloud: sim::OrderedCloud,
    set: CandidateSet,
}

/// Runs the evaluation of McDaniel et al.
pub fn run(args: &PaperArgs) -> anyhow::Result<()> {
    let params = FeatureParams::default();
    let mut scanned = Vec::new();
    for PaperScene { scene, rig, .. } in &SCENES {
        let mut frames = super::common::scan_standing(scene, rig, args.seed, 1, args.ideal)?;
        let cloud = frames.remove(0).cloud;
        let set = mcdaniel::candidates(&cloud, &params, None).with_context(|| format!("features of `{scene}`"))?;
        scanned.push(Scanned { cloud, set });
    }
    println!(
        "McDaniel et al. (seed 002), leave-one-out over the three forests; seed {}{}",
        args.seed,
        if args.ideal { ", ideal ranges" } else { "" }
    );
    let mut json_scenes = BTreeMap::new();
    let mut series = Vec::new();
    for (k, PaperScene { scene, rig, table, rows: paper_rows, accuracy: paper_acc }) in SCENES.iter().enumerate() {
        let train_idx: Vec<usize> = (0..SCENES.len()).filter(|&j| j != k).collect();
        let train_names: Vec<&str> = train_idx.iter().map(|&j| SCENES[j].scene).collect();
        let sets: Vec<CandidateSet> = train_idx.iter().map(|&j| scanned[j].set.clone()).collect();
        let trained_on = json!({ "scenes": train_names, "seed": args.seed, "ideal": args.ideal });
        let model = mcdaniel::train(&sets, &TrainParams { trained_on, ..Default::default() })
            .with_context(|| format!("training on {}", train_names.join(" + ")))?;
        let test = &scanned[k];
        let scores = mcdaniel::decision_values(&model, &test.set);
        // Per true class: sensed points, min-z points, classified ground, classified non-ground.
        let mut rows: BTreeMap<&str, [u64; 4]> = BTreeMap::new();
        let cloud = &test.cloud;
        for i in (0..cloud.len()).filter(|&i| cloud.has_return(i)) {
            rows.entry(TrueClass::of(cloud.ground[i], cloud.label[i]).name()).or_default()[0] += 1;
        }
        for (c, s) in test.set.class.iter().zip(&scores) {
            let row = rows.entry(c.name()).or_default();
            row[1] += 1;
            row[if *s > 0.0 { 2 } else { 3 }] += 1;
        }
        let correct = test.set.ground.iter().zip(&scores).filter(|(g, s)| **g == (**s > 0.0)).count();
        let accuracy = correct as f64 / test.set.len().max(1) as f64;
        let curve = mcdaniel::roc_curve(&scores, &test.set.ground)?;
        let area = mcdaniel::auc(&curve);
        let tpr = |fpr: f64| tpr_at_fpr_below(&curve, fpr);
        // Whole clouds: every column's decision to the points in it.
        let mut method = McDaniel::new(model, McDanielParams::default())?;
        let decisions = method.classify(cloud)?;
        let mut eval = Evaluation::default();
        eval.add_frame(cloud, &decisions);
        let whole = eval.pooled.scores();

        println!();
        println!("Table {table}: {scene} ({rig}) as test set, {} as training sets", train_names.join(" and "));
        println!(
            "{:<22} {:>9} {:>7} {:>7} {:>10}   paper: {:>7} {:>6} {:>6} {:>10}",
            "Ground Truth", "Sensed", "Min z", "Ground", "Non-Ground", "Sensed", "Min z", "Ground", "Non-Ground"
        );
        for (c, paper) in TrueClass::ALL.iter().zip(paper_rows.iter().map(Some).chain(std::iter::repeat(None))) {
            let r = rows.get(c.name()).copied().unwrap_or_default();
            if *c == TrueClass::Other && r == [0; 4] {
                continue;
            }
            let paper = paper.map_or_else(String::new, |p| format!("{:>7} {:>6} {:>6} {:>10}", p[0], p[1], p[2], p[3]));
            println!("{:<22} {:>9} {:>7} {:>7} {:>10}          {paper}", row_title(*c), r[0], r[1], r[2], r[3]);
        }
        println!(
            "accuracy on min-z points {:.2} % (paper {:.2} %); ROC AUC {area:.4}; TPR at FPR < 0.5 % {:.1} %, < 7 % {:.1} %, < 10 % {:.1} % (paper: 70 % at < {:.1} %)",
            100.0 * accuracy,
            100.0 * paper_acc,
            100.0 * tpr(0.005),
            100.0 * tpr(0.07),
            100.0 * tpr(0.10),
            100.0 * PAPER_FPR_AT_TPR_70[k],
        );
        println!(
            "whole cloud: acc {:.4} FPR {:.4} precision {:.4} recall {:.4} F1 {:.4} IoU {:.4}",
            whole.acc, whole.fpr, whole.precision, whole.recall, whole.f1, whole.iou
        );
        json_scenes.insert(
            scene.to_string(),
            json!({
                "table": table,
                "rig": rig,
                "trained_on": train_names,
                "rows": rows.iter().map(|(c, r)| (c.to_string(), json!({"sensed": r[0], "min_z": r[1], "ground": r[2], "non_ground": r[3]}))).collect::<BTreeMap<_, _>>(),
                "accuracy_min_z": accuracy,
                "paper_accuracy_min_z": paper_acc,
                "auc": area,
                "tpr_at_fpr_below": { "0.005": tpr(0.005), "0.07": tpr(0.07), "0.10": tpr(0.10) },
                "whole_cloud": whole,
            }),
        );
        let short = scene.trim_start_matches("forest-");
        series.push(Series { name: format!("{short} (AUC {area:.3})"), points: curve, dashed: k > 0 });
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating `{}`", args.out.display()))?;
    let plot = LinePlot {
        title: "McDaniel et al.: ROC on min-z points, leave-one-out".into(),
        x_label: "false-positive rate".into(),
        y_label: "true-positive rate".into(),
        x_range: (0.0, 1.0),
        y_range: (0.0, 1.0),
        series,
        diagonal: true,
    };
    for ext in ["png", "svg"] {
        let path = args.out.join(format!("roc.{ext}"));
        save_line_plot(&plot, &path)?;
    }
    println!("\nROC figure: {}", args.out.join("roc.png").display());
    if let Some(path) = &args.json {
        write_json(
            path,
            &json!({ "paper": "mcdaniel", "seed": args.seed, "ideal": args.ideal, "scenes": json_scenes }),
        )?;
    }
    Ok(())
}

fn write_json(path: &Path, value: &serde_json::Value) -> anyhow::Result<()> {
    if path.as_os_str().is_empty() {
        bail!("--json: empty path");
    }
    let text = serde_json::to_string_pretty(value)?;
    sim::io::atomic::write_bytes_atomic(path, text.as_bytes())?;
    Ok(())
}
