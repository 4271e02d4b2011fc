//! Weather meets the sensor's return mode (docs/weather.md, "Return modes"): scans of the `city`
//! street in snow with a catalogued dual-capable sensor (the HDL-32E on the roof), moving.
//!
//! - `Dual`: beams whose plane 0 is a flake and plane 1 the surface behind it exist; flakes only
//!   ever lie in plane 0, in front of what follows; the same bytes at 1 and 2 threads.
//! - `Last`: no flake is reported where the beam's surface is detectable in the snow (checked
//!   against the `clear` scan of the same beams: same rays, same noise, no medium); `Strongest`
//!   does report some there (a flake brighter than a dark or far surface), so the check can fail.

use gt_tests::{ScanSpec, cloud_bits, scan_with_threads};
use sim::effects::weather::{SensorWeather, Weather, unsaturated_power};
use sim::rig::Rig;
use sim::scan::Frame;
use sim::scene::SemanticClass;
use sim::sensor::{ReturnMode, SensorSpec};

const SNOW: Weather = Weather::Snow { rate_mm_h: 3.0 };

/// The HDL-32E roof rig in `mode`.
fn rig(mode: ReturnMode) -> Rig {
    let mut rig = Rig::preset("hdl32e-roof").unwrap();
    let SensorSpec::Hdl32e(spec) = &mut rig.sensors[0].spec else { panic!("not an HDL-32E") };
    spec.return_mode = Some(mode);
    rig
}

/// One frame of `city` at 10 m/s in `weather`, scanned on `threads` threads.
fn scan(mode: ReturnMode, weather: Weather, threads: usize) -> Frame {
    let spec = ScanSpec {
        scene: "city".into(),
        seed: 3,
        frames: 1,
        speed_m_per_s: 10.0,
        weather: Some(weather),
        ..ScanSpec::default()
    };
    let scene = spec.load_scene().unwrap();
    scan_with_threads(threads, &scene, &rig(mode), &spec).remove(0)
}

fn is_medium(class: SemanticClass) -> bool {
    [SemanticClass::SNOW, SemanticClass::RAIN, SemanticClass::FOG].contains(&class)
}

#[test]
fn dual_return_reports_the_flake_and_the_surface_behind_it() {
    let frame = scan(ReturnMode::Dual, SNOW, 1);
    let c = &frame.cloud;
    assert_eq!(c.planes, 2);
    let (mut behind, mut flakes, mut sky_flakes) = (0, 0, 0);
    for row in 0..c.rows {
        for col in 0..c.cols {
            let (a, b) = (c.index(0, row, col), c.index(1, row, col));
            assert!(!(c.has_return(b) && c.label[b] == SemanticClass::SNOW), "a flake in plane 1 at {row}/{col}");
            if !(c.has_return(a) && c.label[a] == SemanticClass::SNOW) {
                continue;
            }
            flakes += 1;
            if !c.has_return(b) {
                sky_flakes += 1;
                continue;
            }
            // The surface behind the flake: the same shot, farther, with its ground truth.
            assert!(!is_medium(c.label[b]), "{:?} behind a flake", c.label[b]);
            assert!(c.range_m[b] > c.range_m[a], "{} m behind a flake at {} m", c.range_m[b], c.range_m[a]);
            assert_eq!((c.ring[b], c.column[b], c.time_s[b], c.echo[b]), (c.ring[a], c.column[a], c.time_s[a], 1));
            behind += 1;
        }
    }
    eprintln!("dual: {flakes} flakes in plane 0, {behind} with a surface behind, {sky_flakes} against the sky");
    assert!(behind > 20, "{behind} beams with a flake in front of a surface");
    assert!(sky_flakes > 20, "{sky_flakes} flakes against the sky");
    let two = scan(ReturnMode::Dual, SNOW, 2);
    assert!(cloud_bits(c) == cloud_bits(&two.cloud), "dual differs between 1 and 2 threads");
}

/// Flakes the scan `weather` reports in front of a surface that is detectable in the snow: the
/// beam's `clear` return (same rays and noise, no medium) attenuated by the snow still reaches
/// the threshold. Returns (flakes there, all flakes).
fn flakes_in_front_of_detectable_surfaces(mode: ReturnMode) -> (usize, usize) {
    let (snowy, clear) = (scan(mode, SNOW, 2), scan(mode, Weather::Clear, 1));
    let m = rig(mode).sensors[0].spec.measurement();
    let w = SensorWeather::new(&SNOW, &m);
    let (s, c) = (&snowy.cloud, &clear.cloud);
    let (mut hidden, mut flakes) = (0, 0);
    for i in (0..s.len()).filter(|&i| s.has_return(i) && s.label[i] == SemanticClass::SNOW) {
        flakes += 1;
        if c.has_return(i) {
            let (r, intensity) = (c.range_m[i], c.intensity[i]);
            let power = unsaturated_power(&m, intensity, r) * w.transmission(r);
            hidden += usize::from(power >= w.threshold());
        }
    }
    (hidden, flakes)
}

#[test]
fn last_return_never_reports_a_flake_in_front_of_a_detectable_surface() {
    let (hidden, flakes) = flakes_in_front_of_detectable_surfaces(ReturnMode::Last);
    eprintln!("last: {flakes} flakes, {hidden} in front of a detectable surface");
    assert_eq!(hidden, 0, "last return: {hidden} flakes in front of a detectable surface");
    assert!(flakes > 20, "last return: {flakes} flakes (the sky's)");
    let (hidden, flakes) = flakes_in_front_of_detectable_surfaces(ReturnMode::Strongest);
    eprintln!("strongest: {flakes} flakes, {hidden} in front of a detectable surface");
    assert!(hidden > 0, "strongest return: no flake outshines a surface ({flakes} flakes)");
}
