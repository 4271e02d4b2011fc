//! Hesai's angle-correction CSV (`Laser id,Elevation,Azimuth`): the catalogue's Hesai tables read
//! back as a user's file, and bad files refused naming the file, the line and the field.

use std::path::Path;

use classifier::ordering::Calibration;
use sim::sensor::catalogue::{PANDAR_XT32, PANDAR64};

fn parse(name: &str, text: &str, expected: Option<usize>) -> Result<Calibration, String> {
    Calibration::parse(Path::new(name), text, expected).map_err(|e| e.to_string())
}

/// A Hesai CSV of `elevation` / `azimuth` in laser id order, ids from 1.
fn csv(header: &str, elevation: &[f64], azimuth: &[f64]) -> String {
    let mut text = format!("{header}\n");
    for (i, (e, a)) in elevation.iter().zip(azimuth).enumerate() {
        text.push_str(&format!("{},{e},{a}\n", i + 1));
    }
    text
}

#[test]
fn the_catalogued_hesai_tables_read_back_in_laser_id_order() {
    for (entry, header) in [(&PANDAR64, "Laser id,Elevation,Azimuth"), (&PANDAR_XT32, "Channel,Elevation,Azimuth")] {
        let text = csv(header, entry.elevation_deg, entry.azimuth_offset_deg);
        let c = parse("angle.csv", &text, Some(entry.channels())).unwrap();
        assert_eq!(c.lasers.len(), entry.channels());
        assert_eq!(c.columns, None);
        for (i, l) in c.lasers.iter().enumerate() {
            assert_eq!(l.elevation_deg, entry.elevation_deg[i], "{} laser {i}", entry.model);
            // Hesai's azimuth is clockwise: ours is left positive.
            assert_eq!(l.azimuth_offset_deg, -entry.azimuth_offset_deg[i], "{} laser {i}", entry.model);
        }
    }
    // Lines in any order, CRLF, blank lines, a trailing comma and a byte-order mark.
    let shuffled = "\u{feff}Laser id,Elevation,Azimuth\r\n2,-1.5,0.25\r\n\r\n1,2.0,-1.0,\r\n3,0.5,0\r\n";
    let c = parse("unit.CSV", shuffled, None).unwrap();
    let e: Vec<(f64, f64)> = c.lasers.iter().map(|l| (l.elevation_deg, l.azimuth_offset_deg)).collect();
    assert_eq!(e, [(2.0, 1.0), (-1.5, -0.25), (0.5, 0.0)]);
}

#[test]
fn bad_hesai_files_are_refused_naming_the_file_and_the_field() {
    let header = "Laser id,Elevation,Azimuth\n";
    let cases = [
        // (file text, what the message must name)
        ("1,2.0,0\n2,1.0,0\n", "line 1: expected the header `Laser id,Elevation,Azimuth`"),
        ("Laser,Elev,Az\n1,2.0,0\n2,1.0,0\n", "expected the header"),
        (header, "no lasers"),
        ("Laser id,Elevation,Azimuth\n1,2.0,0\n3,1.0,0\n", "`Laser id` 2 missing"),
        ("Laser id,Elevation,Azimuth\n2,2.0,0\n3,1.0,0\n", "`Laser id` 1 missing"),
        ("Laser id,Elevation,Azimuth\n1,2.0,0\n2,1.0,0\n1,0.0,0\n", "line 4: `Laser id` 1 repeated (first on line 2)"),
        ("Channel,Elevation,Azimuth\n1,2.0,0\n1,1.0,0\n", "line 3: `Channel` 1 repeated"),
        ("Laser id,Elevation,Azimuth\n0,2.0,0\n1,1.0,0\n", "line 2: `Laser id` 0"),
        ("Laser id,Elevation,Azimuth\n1,NaN,0\n2,1.0,0\n", "line 2: `Elevation` is NaN"),
        ("Laser id,Elevation,Azimuth\n1,2.0,0\n2,1.0,inf\n", "line 3: `Azimuth` is inf"),
        ("Laser id,Elevation,Azimuth\n1,2.0,0\n2,up,0\n", "line 3: `Elevation`: `up` is not a number"),
        ("Laser id,Elevation,Azimuth\n1,2.0\n2,1.0,0\n", "line 2: expected 3 values"),
        ("Laser id,Elevation,Azimuth\n1.5,2.0,0\n2,1.0,0\n", "line 2: `Laser id` `1.5` is not a whole number"),
        ("Laser id,Elevation,Azimuth\n1,95.0,0\n2,1.0,0\n", "elevation 95 is not finite or beyond +-90"),
        ("Laser id,Elevation,Azimuth\n1,1.0,0\n2,1.0,0.5\n", "two lasers at elevation 1 degrees"),
    ];
    for (text, needle) in cases {
        let e = parse("/data/pandar/angle.csv", text, None).unwrap_err();
        assert!(e.contains("/data/pandar/angle.csv"), "{e}");
        assert!(e.contains(needle), "{e}\n  does not name: {needle}");
    }
    let e = parse("angle.csv", "Laser id,Elevation,Azimuth\n1,2.0,0\n2,1.0,0\n", Some(64)).unwrap_err();
    assert!(e.contains("2 lasers, but the sensor has 64"), "{e}");
    let e = parse("angle.xls", "", None).unwrap_err();
    assert!(e.contains("allowed: toml, txt, yaml, yml, json, csv"), "{e}");
}
