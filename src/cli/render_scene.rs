//! `groundtruth render --scene NAME|FILE.toml --out FILE.png [--seed N]`: the scene drawn from above
//! (x forward = up in the picture, y left = left), each pixel the class colour of the highest
//! triangle over it, shaded by its slope so ramps, banks and curbs show; a legend of the classes
//! present, a scale bar and the ego vehicle's position and heading (white arrow at the origin).
//! Vertical faces (walls, curbs, pillars) are drawn as lines along their footprint. Where something
//! non-ground covers the ego from above (a garage ceiling), the picture is a floor plan cut
//! [`CUT_ABOVE_EGO_M`] above the ego's ground: triangles entirely above it are left out.

use anyhow::Context;
use font8x8::UnicodeFonts;
use glam::Vec3;
use sim::picture::Raster;
use sim::{SceneMesh, SemanticClass};

/// Height of the floor-plan cut above the ego's ground for indoor scenes, metres.
const CUT_ABOVE_EGO_M: f32 = 2.5;
/// Longest side of the map part of the picture, pixels.
const MAP_PX: u32 = 1200;
/// Width of the legend panel, pixels.
const LEGEND_PX: u32 = 300;
/// Text scale (8x8 glyphs drawn at 2x).
const TEXT_SCALE: u32 = 2;
const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];
const BACKGROUND: [u8; 3] = [24, 24, 24];

/// Draws the picture.
pub fn run(args: &super::render::Args) -> anyhow::Result<()> {
    let name = args.scene.as_deref().context("render needs --scene")?;
    // Bundled scenes, TOML files and the simulator's built-ins, resolved as `scan` resolves them.
    let scene = super::common::load_scene_full(name, args.seed)?;
    let cut_z = covered_from_above(&scene.mesh, scene.ego_ground_z_m).then_some(scene.ego_ground_z_m + CUT_ABOVE_EGO_M);
    let short_name = std::path::Path::new(name).file_stem().map_or(name.into(), |s| s.to_string_lossy().into_owned());
    let mut title = vec![short_name, format!("seed {}", args.seed)];
    if cut_z.is_some() {
        title.push(format!("cut at {CUT_ABOVE_EGO_M} m"));
    }
    let img = draw(&scene.mesh, &title, cut_z)?;
    let png = img.to_png().context("encoding PNG")?;
    sim::io::atomic::write_bytes_atomic(&args.out, &png)?;
    eprintln!("wrote {} ({}x{} px, {} triangles)", args.out.display(), img.width(), img.height(), scene.mesh.len());
    Ok(())
}

/// Whether a non-ground triangle lies over the ego origin more than 2 m above its ground.
fn covered_from_above(mesh: &SceneMesh, ego_z: f32) -> bool {
    (0..mesh.len()).any(|i| {
        let [a, b, c] = mesh.triangle(i);
        if mesh.surfaces[i].class.is_ground() || a.z.min(b.z).min(c.z) < ego_z + 2.0 {
            return false;
        }
        let d = |p: Vec3, q: Vec3| (q.x - p.x) * (0.0 - p.y) - (q.y - p.y) * (0.0 - p.x);
        let (d0, d1, d2) = (d(a, b), d(b, c), d(c, a));
        (d0 >= 0.0 && d1 >= 0.0 && d2 >= 0.0) || (d0 <= 0.0 && d1 <= 0.0 && d2 <= 0.0)
    })
}

/// Renders `mesh` from above with a legend titled by the `title` lines, leaving out triangles
/// entirely above `cut_z`.
fn draw(mesh: &SceneMesh, title: &[String], cut_z: Option<f32>) -> anyhow::Result<Raster> {
    let (lo, hi) = mesh.bounds().context("the scene is empty")?;
    let extent = (hi - lo).truncate().max_element().max(1.0);
    let m_per_px = extent / MAP_PX as f32;
    let (w, h) = (((hi.y - lo.y) / m_per_px).ceil() as u32 + 1, ((hi.x - lo.x) / m_per_px).ceil() as u32 + 1);
    // Pixel (col, row) centre in world: x = hi.x - (row + 0.5) m, y = hi.y - (col + 0.5) m.
    let to_px = |p: Vec3| ((hi.y - p.y) / m_per_px, (hi.x - p.x) / m_per_px);
    let mut zbuf = vec![f32::NEG_INFINITY; (w * h) as usize];
    let mut img = Raster::from_pixel(w + LEGEND_PX, h.max(300), BACKGROUND);
    let light = Vec3::new(0.4, 0.3, 1.0).normalize();
    let mut present = std::collections::BTreeSet::new();
    let mut walls = Vec::new();
    for i in 0..mesh.len() {
        let n = mesh.triangle_normal(i);
        let tri = mesh.triangle(i);
        if cut_z.is_some_and(|cz| tri.iter().all(|v| v.z > cz)) {
            continue;
        }
        let class = mesh.surfaces[i].class;
        present.insert(class);
        if n.z.abs() < 1e-3 {
            walls.push(i); // vertical faces cover no area seen from above: drawn as lines below
            continue;
        }
        let shade = 0.55 + 0.45 * n.dot(light).abs();
        let c = class.color().map(|v| (f32::from(v) * shade).min(255.0) as u8);
        let [a, b, cc] = tri.map(to_px);
        let (min_c, max_c) =
            (a.0.min(b.0).min(cc.0).floor().max(0.0), a.0.max(b.0).max(cc.0).ceil().min(w as f32 - 1.0));
        let (min_r, max_r) =
            (a.1.min(b.1).min(cc.1).floor().max(0.0), a.1.max(b.1).max(cc.1).ceil().min(h as f32 - 1.0));
        let det = (b.0 - a.0) * (cc.1 - a.1) - (cc.0 - a.0) * (b.1 - a.1);
        if det.abs() < 1e-12 {
            continue;
        }
        for row in min_r as u32..=max_r as u32 {
            for col in min_c as u32..=max_c as u32 {
                let (px, py) = (col as f32 + 0.5, row as f32 + 0.5);
                let l1 = ((px - a.0) * (cc.1 - a.1) - (cc.0 - a.0) * (py - a.1)) / det;
                let l2 = ((b.0 - a.0) * (py - a.1) - (px - a.0) * (b.1 - a.1)) / det;
                let l0 = 1.0 - l1 - l2;
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let z = l0 * tri[0].z + l1 * tri[1].z + l2 * tri[2].z;
                let k = (row * w + col) as usize;
                if z > zbuf[k] {
                    zbuf[k] = z;
                    img.put_pixel(col, row, c);
                }
            }
        }
    }
    for i in walls {
        let tri = mesh.triangle(i);
        let top = tri.iter().map(|v| v.z).fold(f32::MIN, f32::max);
        let c = mesh.surfaces[i].class.color().map(|v| (f32::from(v) * 0.8) as u8);
        for (p, q) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
            let ((x0, y0), (x1, y1)) = (to_px(p), to_px(q));
            let steps = (x1 - x0).abs().max((y1 - y0).abs()).ceil() as u32 + 1;
            for k in 0..=steps {
                let t = k as f32 / steps as f32;
                let (col, row) = ((x0 + t * (x1 - x0)) as i64, (y0 + t * (y1 - y0)) as i64);
                if col >= 0 && row >= 0 && (col as u32) < w && (row as u32) < h {
                    let idx = (row as u32 * w + col as u32) as usize;
                    if top >= zbuf[idx] - 1e-3 {
                        zbuf[idx] = top;
                        img.put_pixel(col as u32, row as u32, c);
                    }
                }
            }
        }
    }
    draw_ego(&mut img, to_px(Vec3::ZERO), m_per_px);
    draw_scale_bar(&mut img, h, m_per_px);
    draw_legend(&mut img, w, title, &present);
    Ok(img)
}

/// A white arrow (4.5 m long, at least 12 px) at the ego origin pointing along +x (up).
fn draw_ego(img: &mut Raster, (cx, cy): (f32, f32), m_per_px: f32) {
    let len = (4.5 / m_per_px).max(12.0);
    for t in 0..len as i32 {
        let half_width = (len - t as f32) * 0.35;
        for dx in -half_width as i32..=half_width as i32 {
            put(img, cx as i32 + dx, (cy + 0.5 * len) as i32 - t, WHITE);
        }
    }
}

/// A scale bar of a round length (about a fifth of the map width) with its label, bottom left.
fn draw_scale_bar(img: &mut Raster, map_h: u32, m_per_px: f32) {
    let target = 0.2 * MAP_PX as f32 * m_per_px;
    let len_m = [1.0f32, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0]
        .into_iter()
        .rev()
        .find(|&l| l <= target)
        .unwrap_or(1.0);
    let len_px = (len_m / m_per_px).round() as i32;
    let (x0, y0) = (16, map_h as i32 - 24);
    fill_rect(img, x0 - 4, y0 - 22, len_px + 8, 34, BLACK);
    fill_rect(img, x0, y0, len_px, 6, WHITE);
    for x in [x0, x0 + len_px - 2] {
        fill_rect(img, x, y0 - 6, 2, 12, WHITE);
    }
    draw_text(img, x0, y0 - 20, &format!("{len_m} m"), WHITE);
}

/// The legend panel right of the map: title, then one colour swatch and name per class present.
fn draw_legend(img: &mut Raster, map_w: u32, title: &[String], present: &std::collections::BTreeSet<SemanticClass>) {
    let x0 = map_w as i32 + 12;
    let max_chars = ((LEGEND_PX - 16) / (8 * TEXT_SCALE)) as usize;
    let mut y = 12;
    for line in title {
        let short: String = line.chars().take(max_chars).collect();
        draw_text(img, x0, y, &short, WHITE);
        y += 20;
    }
    y += 12;
    for (ground, heading) in [(true, "ground"), (false, "non-ground")] {
        draw_text(img, x0, y, heading, [180, 180, 180]);
        y += 22;
        for class in present.iter().filter(|c| c.is_ground() == ground) {
            fill_rect(img, x0, y, 16, 16, class.color());
            draw_text(img, x0 + 24, y, class.name(), WHITE);
            y += 22;
        }
        y += 10;
    }
}

/// Draws `text` with the 8x8 font at `TEXT_SCALE`, top-left corner at `(x, y)`.
fn draw_text(img: &mut Raster, x: i32, y: i32, text: &str, color: [u8; 3]) {
    let s = TEXT_SCALE as i32;
    for (k, ch) in text.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(ch) else { continue };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) != 0 {
                    fill_rect(img, x + (k as i32 * 8 + col) * s, y + row as i32 * s, s, s, color);
                }
            }
        }
    }
}

fn fill_rect(img: &mut Raster, x: i32, y: i32, w: i32, h: i32, color: [u8; 3]) {
    for yy in y..y + h {
        for xx in x..x + w {
            put(img, xx, yy, color);
        }
    }
}

fn put(img: &mut Raster, x: i32, y: i32, color: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, color);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim::Surface;

    fn scene() -> SceneMesh {
        let mut m = SceneMesh::new();
        m.push_heightfield((-50.0, -50.0), 10.0, (10, 10), |_, _| 0.0, |_, _| Surface::stuff(SemanticClass::ROAD));
        m.push_box(Vec3::new(20.0, -5.0, 0.0), Vec3::new(30.0, 5.0, 1.5), Surface::object(SemanticClass::CAR, 1));
        m
    }

    /// The shaded colour of a horizontal surface of `class`.
    fn flat_color(class: SemanticClass) -> [u8; 3] {
        let shade = 0.55 + 0.45 * Vec3::new(0.4, 0.3, 1.0).normalize().z;
        class.color().map(|v| (f32::from(v) * shade).min(255.0) as u8)
    }

    #[test]
    fn top_view_puts_classes_where_they_are() {
        let img = draw(&scene(), &["t".into()], None).unwrap();
        // 100 m over 1200 px; x forward is up: x = 25 m lies 25 m above the centre row.
        let px_per_m = MAP_PX as f32 / 100.0;
        assert_eq!(img.width(), MAP_PX + 1 + LEGEND_PX);
        let (cx, cy) = (600.0, 600.0);
        let car = img.get_pixel(cx as u32, (cy - 25.0 * px_per_m) as u32);
        assert_eq!(car, flat_color(SemanticClass::CAR));
        let road = img.get_pixel((cx + 30.0 * px_per_m) as u32, (cy + 30.0 * px_per_m) as u32);
        assert_eq!(road, flat_color(SemanticClass::ROAD));
        // The ego arrow at the origin.
        assert_eq!(img.get_pixel(cx as u32, cy as u32), WHITE);
    }

    #[test]
    fn a_ceiling_over_the_ego_switches_to_a_floor_plan() {
        let mut m = scene();
        assert!(!covered_from_above(&m, 0.0));
        m.push_box(
            Vec3::new(-10.0, -10.0, 2.7),
            Vec3::new(10.0, 10.0, 3.0),
            Surface::object(SemanticClass::OTHER_STRUCTURE, 2),
        );
        assert!(covered_from_above(&m, 0.0));
        let img = draw(&m, &["t".into()], Some(2.5)).unwrap();
        let px_per_m = MAP_PX as f32 / 100.0;
        // Under the cut-away ceiling the road shows again.
        assert_eq!(img.get_pixel((600.0 + 5.0 * px_per_m) as u32, 600), flat_color(SemanticClass::ROAD));
    }
}
