//! Pictures of scans: a bird's-eye view ([`render_bev`]) and a range image ([`render_range`],
//! rows x columns, row 0 at the bottom) of an [`OrderedCloud`], coloured by class, ground truth,
//! range, height or by a classifier's outcome, with a legend and a scale bar in a footer strip,
//! and PNG output written atomically ([`save_png`]).

mod bev;
mod color;
mod draw;
mod range;
mod raster;

pub use bev::{BevOptions, render_bev};
pub use color::{Coloring, OUTCOME_COLORS};
pub use range::{RangeOptions, render_range};
pub use raster::Raster;

use std::path::Path;

use crate::error::{Result, SimError};

/// Which picture of a scan to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Bird's-eye view from above, vehicle at the centre, x (forward) up.
    Bev,
    /// Range image: one pixel row band per grid row (row 0 at the bottom), one column per grid column.
    Range,
}

impl View {
    /// The names [`View::parse`] accepts.
    pub const NAMES: [&'static str; 2] = ["bev", "range"];

    /// Parses `bev` or `range`; other names are refused with the list of allowed ones.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "bev" => Ok(View::Bev),
            "range" => Ok(View::Range),
            _ => Err(SimError::invalid("view", name, Self::NAMES.join(", "))),
        }
    }
}

/// Encodes `img` as PNG and writes it to `path` atomically.
pub fn save_png(path: &Path, img: &Raster) -> Result<()> {
    let bytes = img.to_png().map_err(|e| SimError::io(path, std::io::Error::other(e.to_string())))?;
    crate::io::atomic::write_bytes_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::cloud::OrderedCloud;
    use crate::scene::SemanticClass;

    /// 2 rows x 4 columns: row 0 ground at x = 10 m, row 1 a car at y = 5 m; cell (1, 3) empty.
    fn cloud() -> OrderedCloud {
        let mut c = OrderedCloud::empty(2, 4, 1);
        for col in 0..4 {
            let i = c.index(0, 0, col);
            c.point_in_vehicle[i] = Vec3::new(10.0, col as f32 - 1.5, -1.5);
            c.range_m[i] = 10.0;
            c.label[i] = SemanticClass::ROAD;
            c.ground[i] = true;
            if col < 3 {
                let j = c.index(0, 1, col);
                c.point_in_vehicle[j] = Vec3::new(col as f32, 5.0, 0.5);
                c.range_m[j] = 5.0;
                c.label[j] = SemanticClass::CAR;
            }
        }
        c
    }

    #[test]
    fn bev_places_points_north_up_and_adds_footer() {
        let opts = BevOptions { size_px: 200, half_extent_m: Some(20.0), point_px: 1 };
        let img = render_bev(&cloud(), &Coloring::Class, &opts).unwrap();
        assert_eq!(img.width(), 200);
        assert!(img.height() > 200, "footer below the plot");
        // Ground point (10, -0.5): u = 100 + 0.5 / 0.2 = 102.5, v = 100 - 10 / 0.2 = 50.
        assert_eq!(img.get_pixel(102, 50), SemanticClass::ROAD.color());
        // Car point (0, 5): u = 100 - 25 = 75, v = 100.
        assert_eq!(img.get_pixel(75, 100), SemanticClass::CAR.color());
        assert_eq!(img.get_pixel(10, 10), [18, 18, 18], "background");
    }

    #[test]
    fn range_image_puts_row_zero_at_the_bottom() {
        let opts = RangeOptions { row_px: Some(3), plane: 0 };
        let img = render_range(&cloud(), &Coloring::Ground, &opts).unwrap();
        // 4 columns widen to 320 px (80 px each); 2 rows of 3 px.
        assert_eq!(img.width(), 320);
        assert_eq!(img.get_pixel(0, 5), [200, 160, 90], "row 0 (ground) at the bottom");
        assert_eq!(img.get_pixel(0, 0), [90, 160, 255], "row 1 (car) on top");
        assert_eq!(img.get_pixel(319, 0), [0, 0, 0], "no return is black");
    }

    #[test]
    fn outcome_colouring_tells_the_four_cases() {
        let c = cloud();
        let mut predicted = vec![false; c.len()];
        predicted[c.index(0, 0, 0)] = true; // true ground
        predicted[c.index(0, 1, 0)] = true; // false ground
        let opts = RangeOptions { row_px: Some(1), plane: 0 };
        let img = render_range(&c, &Coloring::Outcome { predicted_ground: &predicted }, &opts).unwrap();
        assert_eq!(img.get_pixel(0, 1), OUTCOME_COLORS[0].0);
        assert_eq!(img.get_pixel(0, 0), OUTCOME_COLORS[1].0);
        assert_eq!(img.get_pixel(100, 1), OUTCOME_COLORS[2].0);
        assert_eq!(img.get_pixel(100, 0), OUTCOME_COLORS[3].0);
        let short = Coloring::Outcome { predicted_ground: &predicted[..3] };
        assert!(render_range(&c, &short, &opts).is_err());
    }

    #[test]
    fn png_is_written_atomically_and_decodes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bev.png");
        let img = render_bev(&cloud(), &Coloring::Height, &BevOptions::default()).unwrap();
        save_png(&path, &img).unwrap();
        let mut reader =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap())).read_info().unwrap();
        let mut back = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut back).unwrap();
        assert_eq!(back, img.as_raw());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        assert!(View::parse("side").unwrap_err().to_string().contains("bev, range"));
    }
}
