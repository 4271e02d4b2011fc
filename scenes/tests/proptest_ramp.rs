//! Property: for any slope in the allowed range, every ramp triangle measures the requested slope.

use proptest::prelude::*;
use sim::SemanticClass;

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn any_ramp_slope_is_reproduced_within_0_1_deg(slope in -20.0f32..=20.0, length in 5.0f32..40.0) {
        let text = format!(
            "version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = {slope}\nlength_m = {length}\ndistance_m = 10.0\nwidth_m = 5.0\n"
        );
        let s = scenes::load_str(&text, "prop", std::path::Path::new("."), 0).unwrap();
        let m = &s.mesh;
        let mut n = 0;
        for i in 0..m.len() {
            let [a, b, c] = m.triangle(i);
            let mid = (a + b + c) / 3.0;
            if m.surfaces[i].class == SemanticClass::ROAD && mid.x > 10.0 && mid.x < 10.0 + length && mid.y.abs() < 2.5 {
                let nrm = m.triangle_normal(i);
                let measured = (-nrm.x).atan2(nrm.z).to_degrees();
                prop_assert!((measured - slope).abs() < 0.1, "measured {} for {}", measured, slope);
                n += 1;
            }
        }
        prop_assert!(n >= 10);
    }
}
