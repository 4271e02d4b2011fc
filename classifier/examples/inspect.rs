//! Prints, per grid row of plane 0 of a PCD, returns, ground truth and misses of `nitsch`
//! (a diagnostic: `cargo run --release -p groundtruth-classifier --example inspect -- FILE.pcd`).

#![allow(clippy::needless_range_loop)]

use classifier::{Nitsch, NitschParams};

fn main() {
    let path = std::env::args().nth(1).expect("usage: inspect FILE.pcd");
    let cloud = sim::io::pcd::read(std::path::Path::new(&path)).unwrap();
    let mut m = Nitsch::new(NitschParams::default()).unwrap();
    let g = m.classify(&cloud).unwrap();
    println!("rows {} cols {} planes {} wrap {}", cloud.rows, cloud.cols, cloud.planes, m.view(&cloud).wrap);
    if std::env::args().nth(2).is_some() {
        dump(&cloud, &m, &g, 8, 5);
    }
    let mut seen = std::collections::BTreeMap::new();
    for i in 0..cloud.rows * cloud.cols {
        if cloud.ground[i]
            && !g[i]
            && let Some(root) = m.workspace.cluster_of(i)
        {
            *seen.entry(root).or_insert(0) += 1;
        }
    }
    for (root, missed) in seen {
        let (size, inside, h, dec) = m.workspace.cluster_summary(root);
        let p = cloud.point_in_vehicle[root];
        println!(
            "missed {missed:4} in cluster {root}: size {size} inside {inside} height {h:.2} ground {dec} at {p:?}"
        );
    }
    let mut fps = std::collections::BTreeMap::new();
    for i in 0..cloud.rows * cloud.cols {
        if !cloud.ground[i]
            && g[i]
            && let Some(root) = m.workspace.cluster_of(i)
        {
            *fps.entry((root, cloud.label[i].name())).or_insert(0) += 1;
        }
    }
    for ((root, class), k) in fps {
        let (size, inside, h, dec) = m.workspace.cluster_summary(root);
        println!("false {k:4} {class} in cluster {root}: size {size} inside {inside} height {h:.2} ground {dec}");
    }
    for r in 0..cloud.rows {
        let (mut ret, mut gt, mut tp, mut fp, mut fn_, mut cand_fn, mut gsum) = (0, 0, 0, 0, 0, 0, 0.0);
        for c in 0..cloud.cols {
            let i = r * cloud.cols + c;
            if !cloud.point_in_vehicle[i].is_finite() {
                continue;
            }
            ret += 1;
            let t = cloud.ground[i];
            gt += usize::from(t);
            match (t, g[i]) {
                (true, true) => tp += 1,
                (false, true) => fp += 1,
                (true, false) => {
                    fn_ += 1;
                    gsum += m.features.g_rho[i];
                    cand_fn += usize::from(m.features.g_rho[i] >= 0.6);
                }
                _ => {}
            }
        }
        println!(
            "row {r:3}: returns {ret:5} gt {gt:5} tp {tp:5} fp {fp:4} fn {fn_:4} (candidates among fn {cand_fn:4}, mean g_rho {:.2})",
            if fn_ > 0 { gsum / fn_ as f32 } else { 0.0 }
        );
    }
}

/// Prints the neighbourhood of the missed ground cells of row `row` (first `n`).
#[allow(dead_code)]
pub fn dump(cloud: &sim::OrderedCloud, m: &Nitsch, g: &[bool], row: usize, n: usize) {
    let view = m.view(cloud);
    let mut shown = 0;
    for c in 0..cloud.cols {
        let i = row * cloud.cols + c;
        if cloud.ground[i] && !g[i] && shown < n {
            shown += 1;
            println!(
                "cell r{row} c{c} p {:?} g {:.2} n {:?}",
                cloud.point_in_vehicle[i], m.features.g_rho[i], m.features.normal[i]
            );
            for (k, j) in view.neighbours(row, c).iter().enumerate() {
                if let Some(j) = j {
                    println!("   d{} r{} c{} {:?}", k + 1, j / cloud.cols, j % cloud.cols, cloud.point_in_vehicle[*j]);
                }
            }
        }
    }
}
