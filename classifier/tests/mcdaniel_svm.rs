//! McDaniel et al. (seed 002), training and evaluation: the dual coordinate descent SVM against
//! LIBLINEAR (the `liblinear` crate, a dev-dependency) and a hand-checked max-margin case, training
//! errors, and ROC/AUC on hand-computed cases.

use classifier::ClassifyError;
use classifier::mcdaniel::{
    self, CandidateSet, FeatureParams, SvmParams, TrainParams, TrueClass, auc, roc_curve, train_linear_svm,
};
use glam::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[test]
fn training_needs_both_classes() {
    let set = CandidateSet {
        feature_params: FeatureParams::default(),
        cell: vec![0, 1],
        point_in_vehicle: vec![Vec3::ZERO; 2],
        features: vec![[1.0; 8], [2.0; 8]],
        ground: vec![true, true],
        class: vec![TrueClass::Ground; 2],
    };
    let err = mcdaniel::train(std::slice::from_ref(&set), &TrainParams::default()).unwrap_err();
    assert_eq!(err, ClassifyError::TrainingSet { ground: 2, non_ground: 0 });
    let mut none = set.clone();
    none.ground = vec![false, false];
    assert_eq!(
        mcdaniel::train(&[none], &TrainParams::default()).unwrap_err(),
        ClassifyError::TrainingSet { ground: 0, non_ground: 2 }
    );
    assert!(mcdaniel::train(&[], &TrainParams::default()).is_err());
    // Both classes: constant features get std 1; the model separates the two.
    let mut ok = set;
    ok.ground = vec![true, false];
    let model = mcdaniel::train(&[ok.clone()], &TrainParams::default()).unwrap();
    assert!(model.std.iter().all(|&s| (s - 0.5).abs() < 1e-12));
    let v = mcdaniel::decision_values(&model, &ok);
    assert!(v[0] > 0.0 && v[1] < 0.0, "{v:?}");
}

#[test]
fn svm_finds_the_max_margin_line_of_a_hand_checked_separable_set() {
    // Positives at x1 in {3, 4, 5}, negatives at {1, 0, -1}, each at x2 = +-1. With the bias
    // regularised as a feature (LIBLINEAR -B 1) the support vectors x1 = 3 and x1 = 1 give
    // 3 w + b = 1, w + b = -1: w = (1, 0), b = -2 (alphas 1.5 and 3.5 spread over the pairs).
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (x1, pos) in [(3.0, true), (4.0, true), (5.0, true), (1.0, false), (0.0, false), (-1.0, false)] {
        for x2 in [-1.0, 1.0] {
            x.extend([x1, x2]);
            y.push(pos);
        }
    }
    let svm = train_linear_svm(&x, 2, &y, &SvmParams { eps: 1e-6, max_iter: 100_000, ..Default::default() }).unwrap();
    assert!(svm.converged);
    assert!((svm.weights[0] - 1.0).abs() < 1e-3, "{svm:?}");
    assert!(svm.weights[1].abs() < 1e-3, "{svm:?}");
    assert!((svm.bias + 2.0).abs() < 1e-3, "{svm:?}");
    // The same without shrinking and with another seed.
    let svm2 =
        train_linear_svm(&x, 2, &y, &SvmParams { eps: 1e-6, max_iter: 100_000, shrinking: false, seed: 9, c: 100.0 })
            .unwrap();
    assert!((svm2.weights[0] - 1.0).abs() < 1e-3 && (svm2.bias + 2.0).abs() < 1e-3, "{svm2:?}");
    // Bad input is refused.
    assert!(train_linear_svm(&x[..5], 2, &y, &SvmParams::default()).is_err());
    assert!(train_linear_svm(&x, 2, &y, &SvmParams { c: -1.0, ..Default::default() }).is_err());
}

/// `n` points in `dim` dimensions: two Gaussian blobs whose means are `separation` apart along a
/// random direction.
fn blobs(n: usize, dim: usize, separation: f64, seed: u64) -> (Vec<f64>, Vec<bool>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let dir: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    let norm = dir.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut x = Vec::with_capacity(n * dim);
    let mut y = Vec::with_capacity(n);
    for i in 0..n {
        let pos = i % 3 != 0;
        for d in &dir {
            // Sum of uniforms: roughly Gaussian, unit-ish variance.
            let noise: f64 = (0..4).map(|_| rng.random_range(-0.866..0.866)).sum();
            let shift = if pos { 0.5 } else { -0.5 } * separation * d / norm;
            x.push(noise + shift + 0.3);
        }
        y.push(pos);
    }
    (x, y)
}

fn liblinear_svm(x: &[f64], dim: usize, y: &[bool], c: f64, eps: f64) -> (Vec<f64>, f64) {
    use liblinear::LibLinearModel;
    liblinear::toggle_liblinear_stdout_output(false);
    let features: Vec<Vec<(u32, f64)>> =
        x.chunks(dim).map(|r| r.iter().enumerate().map(|(k, v)| (k as u32 + 1, *v)).collect()).collect();
    let labels: Vec<f64> = y.iter().map(|&p| if p { 1.0 } else { -1.0 }).collect();
    let mut builder = liblinear::Builder::new();
    builder
        .problem()
        .input_data(liblinear::util::TrainingInput::from_sparse_features(labels, features).unwrap())
        .bias(1.0);
    builder
        .parameters()
        .solver_type(liblinear::SolverType::L2R_L1LOSS_SVC_DUAL)
        .stopping_criterion(eps)
        .constraints_violation_cost(c);
    let model = builder.build_model().unwrap();
    // The weight vector belongs to the first label.
    let sign = if model.labels()[0] == 1 { 1.0 } else { -1.0 };
    let w = (1..=dim as i32).map(|k| sign * model.feature_coefficient(k, 0)).collect();
    let b = sign * model.label_bias(0);
    (w, b)
}

#[test]
fn svm_agrees_with_liblinear_on_separable_and_noisy_data() {
    // Where LIBLINEAR converges within its 1000 passes (separable at C = 100, overlapping at C = 1
    // and 10) both solvers must agree: predictions on >= 99 % of the points, weights within 3 %,
    // primal objectives within 0.5 %.
    let dim = 8;
    let eps = 1e-4;
    let run = |separation: f64, c: f64| {
        let (x, y) = blobs(1500, dim, separation, 5);
        let ours = train_linear_svm(&x, dim, &y, &SvmParams { c, eps, ..Default::default() }).unwrap();
        let (w, b) = liblinear_svm(&x, dim, &y, c, eps);
        let theirs = mcdaniel::LinearSvm { weights: w, bias: b, iterations: 0, converged: true };
        let same = (0..y.len())
            .filter(|&i| {
                let r = &x[i * dim..(i + 1) * dim];
                (ours.decision_value(r) > 0.0) == (theirs.decision_value(r) > 0.0)
            })
            .count();
        let o1 = mcdaniel::svm::primal_objective(&ours, &x, dim, &y, c);
        let o2 = mcdaniel::svm::primal_objective(&theirs, &x, dim, &y, c);
        (ours, theirs, same as f64 / y.len() as f64, o1, o2)
    };
    for (separation, c, what) in [(8.0, 100.0, "separable C=100"), (2.0, 1.0, "noisy C=1"), (2.0, 10.0, "noisy C=10")] {
        let (ours, theirs, same, o1, o2) = run(separation, c);
        let wn = theirs.weights.iter().map(|v| v * v).sum::<f64>().sqrt();
        let dw = ours.weights.iter().zip(&theirs.weights).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        eprintln!(
            "{what}: same prediction {same:.4}, objective ours {o1:.6} liblinear {o2:.6}, |w| {wn:.4}, |dw| {dw:.2e}, passes {}",
            ours.iterations
        );
        assert!(ours.converged, "{what}");
        assert!(same >= 0.99, "{what}: {same}");
        assert!((o1 - o2).abs() <= 5e-3 * o2, "{what}: objectives {o1} vs {o2}");
        assert!(dw <= 0.03 * wn, "{what}: weights {:?} vs {:?}", ours.weights, theirs.weights);
        assert!((ours.bias - theirs.bias).abs() <= 0.03 * wn.max(1.0), "{what}: bias {} vs {}", ours.bias, theirs.bias);
    }
    // Overlapping classes at C = 100: LIBLINEAR stops at its 1000 passes far from converged; ours
    // runs up to 300,000 passes, reaches an objective no worse, and predicts the same almost
    // everywhere.
    let (ours, _, same, o1, o2) = run(4.0, 100.0);
    eprintln!(
        "noisy C=100: same prediction {same:.4}, objective ours {o1:.3} liblinear {o2:.3}, passes {}",
        ours.iterations
    );
    assert!(o1 <= o2 * (1.0 + 1e-6), "objectives {o1} vs {o2}");
    assert!(same >= 0.99, "{same}");
}

#[test]
fn roc_and_auc_on_hand_computed_cases() {
    let curve = roc_curve(&[0.9, 0.8, 0.7, 0.6], &[true, false, true, false]).unwrap();
    assert_eq!(curve, vec![(0.0, 0.0), (0.0, 0.5), (0.5, 0.5), (0.5, 1.0), (1.0, 1.0)]);
    assert!((auc(&curve) - 0.75).abs() < 1e-12);
    // Ties enter together: a diagonal step.
    let curve = roc_curve(&[1.0, 1.0], &[true, false]).unwrap();
    assert_eq!(curve, vec![(0.0, 0.0), (1.0, 1.0)]);
    assert!((auc(&curve) - 0.5).abs() < 1e-12);
    // Perfect and inverted rankings; order of input does not matter.
    let curve = roc_curve(&[0.1, 5.0, -3.0, 2.0], &[false, true, false, true]).unwrap();
    assert_eq!(auc(&curve), 1.0);
    assert_eq!(mcdaniel::roc::tpr_at_fpr_below(&curve, 0.005), 1.0);
    assert_eq!(auc(&roc_curve(&[0.1, 5.0], &[true, false]).unwrap()), 0.0);
    // 3 positives, 2 negatives: scores P 3, N 2.5, P 2, P 2 (tie), N 1.
    let curve = roc_curve(&[3.0, 2.5, 2.0, 2.0, 1.0], &[true, false, true, true, false]).unwrap();
    assert_eq!(curve, vec![(0.0, 0.0), (0.0, 1.0 / 3.0), (0.5, 1.0 / 3.0), (0.5, 1.0), (1.0, 1.0)]);
    assert!((auc(&curve) - (0.5 / 3.0 + 0.5)).abs() < 1e-12);
    // Errors: lengths, NaN, one class.
    assert!(roc_curve(&[1.0], &[true, false]).is_err());
    assert!(roc_curve(&[f64::NAN, 1.0], &[true, false]).is_err());
    assert!(roc_curve(&[1.0, 2.0], &[true, true]).is_err());
}
