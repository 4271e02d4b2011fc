//! The scene's own geometry parameters, read back from its description: where the ramp, the basin,
//! the plateaus and the hill's slope are, and the height of the bare ground at any (x, y), which the
//! regions use.

use scenes::families::basin::trapezoid;
use scenes::families::{basin, elevated, hill, ramp};

use crate::error::Result;

/// The geometry of the families that have region-defining parameters.
#[derive(Clone, Debug)]
pub enum Geometry {
    /// `ramp`.
    Ramp(ramp::Params),
    /// `basin`.
    Basin(basin::Params),
    /// `elevated`.
    Elevated(elevated::Params),
    /// `hill`.
    Hill(hill::Params),
    /// Any other family: bare ground at z = 0.
    Other,
}

impl Geometry {
    /// Reads the parameters of `family` from the scene's TOML text.
    pub fn parse(family: &str, text: &str, source: &str) -> Result<Self> {
        Ok(match family {
            "ramp" => Self::Ramp(scenes::schema::doc::<ramp::Params>(text, source)?.params),
            "basin" => Self::Basin(scenes::schema::doc::<basin::Params>(text, source)?.params),
            "elevated" => Self::Elevated(scenes::schema::doc::<elevated::Params>(text, source)?.params),
            "hill" => Self::Hill(scenes::schema::doc::<hill::Params>(text, source)?.params),
            _ => Self::Other,
        })
    }

    /// Height of the bare ground (the generator's terrain, no objects) at world (x, y), metres.
    pub fn ground_z_m(&self, x: f32, y: f32) -> f32 {
        match self {
            Self::Ramp(p) => {
                if y.abs() < 0.5 * p.width_m && x < p.end_x() {
                    p.profile_z(x)
                } else {
                    0.0
                }
            }
            Self::Basin(p) => {
                let s = if p.side == basin::Side::Right { -1.0 } else { 1.0 };
                -p.depth_m * trapezoid(x, p.along_edges()).min(trapezoid(s * y, p.cross_edges()))
            }
            Self::Elevated(p) => {
                let run = p.plateau_height_m / p.plateau_bank_deg.to_radians().tan();
                elevated::PLATEAUS
                    .iter()
                    .map(|&(x0, x1, y0, y1)| {
                        p.plateau_height_m
                            * trapezoid(x, [x0 - run, x0, x1, x1 + run]).min(trapezoid(y, [y0 - run, y0, y1, y1 + run]))
                    })
                    .fold(0.0, f32::max)
            }
            Self::Hill(p) => p.profile().height(x),
            Self::Other => 0.0,
        }
    }

    /// Unit up-normal of the bare ground at (x, y) (central differences over 0.1 m).
    pub fn ground_up(&self, x: f32, y: f32) -> glam::Vec3 {
        let h = 0.05;
        let dx = (self.ground_z_m(x + h, y) - self.ground_z_m(x - h, y)) / (2.0 * h);
        let dy = (self.ground_z_m(x, y + h) - self.ground_z_m(x, y - h)) / (2.0 * h);
        glam::Vec3::new(-dx, -dy, 1.0).normalize()
    }
}
