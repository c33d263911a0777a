//! A contact sheet of a crowd seen from above: panels of where every walker stood at chosen
//! times, walls drawn, each walker a dot coloured by where it is bound (east red, west blue,
//! arrived grey), rendered to PNG with resvg for a person to look at.

use glam::Vec2;
use resvg::{tiny_skia, usvg};

/// Panels taken so far: (time, every walker's ground place).
#[derive(Default)]
pub struct Sheet {
    panels: Vec<(f64, Vec<Vec2>)>,
}

/// Pixels a metre.
const SCALE: f32 = 40.0;

impl Sheet {
    /// Keeps where everyone stands at `time`.
    pub fn take(&mut self, time: f64, places: Vec<Vec2>) {
        self.panels.push((time, places));
    }

    /// Draws the panels (the area `lo`..`hi` of the floor each), `columns` a row, with
    /// `walls` (segments [x1, z1, x2, z2]) and `goals`, and writes the PNG to `path`.
    pub fn save(
        &self,
        path: &str,
        (lo, hi): (Vec2, Vec2),
        columns: usize,
        walls: &[[f32; 4]],
        goals: &[Vec2],
    ) {
        let columns = columns.max(1);
        let size = (hi - lo) * SCALE;
        let rows = self.panels.len().div_ceil(columns);
        let (w, h) = (size.x * columns as f32, (size.y + 18.0) * rows as f32);
        let mut svg = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}"><rect width="{w}" height="{h}" fill="white"/>"#
        );
        let at = |p: Vec2| (p - lo) * SCALE;
        for (n, (time, places)) in self.panels.iter().enumerate() {
            let (ox, oy) = (
                (n % columns) as f32 * size.x,
                (n / columns) as f32 * (size.y + 18.0),
            );
            svg += &format!(
                r#"<g transform="translate({ox},{oy})"><clipPath id="c{n}"><rect width="{}" height="{}"/></clipPath><rect width="{}" height="{}" fill="none" stroke="gray"/>"#,
                size.x, size.y, size.x, size.y
            );
            // (the time as a bar: resvg without fonts draws no text) one tick a second
            let ticks = time.round() as i32;
            for s in 0..ticks {
                let x = 4.0 + s as f32 * 4.0;
                let tall = if s % 10 == 9 { 12.0 } else { 6.0 };
                svg += &format!(
                    r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="black"/>"#,
                    size.y + 2.0,
                    size.y + 2.0 + tall
                );
            }
            svg += &format!(r#"<g clip-path="url(#c{n})">"#);
            for [a, b, c, d] in walls {
                let (p, q) = (at(Vec2::new(*a, *b)), at(Vec2::new(*c, *d)));
                svg += &format!(
                    r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="black" stroke-width="3"/>"#,
                    p.x, p.y, q.x, q.y
                );
            }
            for (k, p) in places.iter().enumerate() {
                let c = at(*p);
                let colour = if p.distance(goals[k]) < 0.3 {
                    "gray"
                } else if goals[k].x > p.x {
                    "crimson"
                } else {
                    "royalblue"
                };
                svg += &format!(
                    r#"<circle cx="{}" cy="{}" r="{}" fill="{colour}" fill-opacity="0.8"/>"#,
                    c.x,
                    c.y,
                    0.25 * SCALE
                );
            }
            svg += "</g></g>";
        }
        svg += "</svg>";
        let tree = usvg::Tree::from_str(&svg, &usvg::Options::default()).expect("an SVG");
        let mut pixmap = tiny_skia::Pixmap::new(w.ceil() as u32, h.ceil() as u32).expect("a size");
        resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
        pixmap.save_png(path).expect("a PNG written");
    }
}
