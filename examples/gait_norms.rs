//! The realized gait measured as gait laboratories measure people (see `tests/common/gait_lab.rs`):
//! a straight walk at STROLL, WALK and RUN realized at 240 frames a second, the left leg's
//! sagittal angles, the pelvis and the contacts over the steady cycles; prints each measure's
//! mean beside its published band, and draws the mean knee, hip and ankle curves of each manner
//! over the bands' key values into `docs/gait-curves.svg`.
//!
//! Run: `cargo run --release --example gait_norms`

#[path = "../tests/common/gait_lab.rs"]
mod gait_lab;

use gait_lab::{bands, cycles, mean_curves, means, record, Band, MEASURES, WALKS};
use std::fmt::Write;

const FPS: f64 = 240.0;

/// One manner's plot: its name, mean knee, hip and ankle curves, and its bands.
type Plot<'a> = (&'a str, [Vec<f32>; 3], &'a [Band]);

fn main() {
    let mut plots = Vec::new();
    for (manner, distance, seconds) in WALKS {
        let samples = record(manner, distance, seconds, FPS);
        let cycles = cycles(&samples);
        let m = means(&cycles, FPS);
        println!("{manner}: {} cycles", cycles.len());
        for (k, name) in MEASURES.iter().enumerate() {
            let band = bands(manner).iter().find(|b| b.0 == k);
            let verdict = match band {
                Some(&(_, lo, hi, source)) => {
                    let ok = if (lo..=hi).contains(&m[k]) {
                        "in"
                    } else {
                        "OUT"
                    };
                    format!("{ok:>3} [{lo}, {hi}] {source}")
                }
                None => String::new(),
            };
            println!("  {name:<36} {:8.2}   {verdict}", m[k]);
        }
        plots.push((manner, mean_curves(&cycles), bands(manner)));
    }
    std::fs::write("docs/gait-curves.svg", svg(&plots)).expect("write docs/gait-curves.svg");
    println!("wrote docs/gait-curves.svg");
}

/// Where in the cycle (%) a band's measure belongs, and which joint's plot it goes on
/// (0 knee, 1 hip, 2 ankle); none for the measures that are not a joint's angle at a moment.
fn placed(measure: usize, curves: &[Vec<f32>; 3]) -> Option<(usize, f32)> {
    let argmax = |v: &[f32]| (0..v.len()).fold(0, |m, i| if v[i] > v[m] { i } else { m }) as f32;
    let argmin = |v: &[f32]| (0..v.len()).fold(0, |m, i| if v[i] < v[m] { i } else { m }) as f32;
    Some(match measure {
        0 => (0, 0.0),
        1 => (0, 12.0),
        2 => (0, 40.0),
        3 => (0, argmax(&curves[0])),
        5 => (1, 0.0),
        6 => (1, argmin(&curves[1])),
        9 => (2, 0.0),
        10 => (2, 7.0),
        11 => (2, 45.0),
        12 => (2, 62.0),
        _ => return None,
    })
}

/// Three rows (the manners) of three plots (knee, hip, ankle): the realized mean curve, the
/// bands' key values as bars.
fn svg(plots: &[Plot]) -> String {
    let (w, h, pad) = (300.0f32, 170.0f32, 30.0f32);
    let ranges = [(-10.0f32, 110.0f32), (-30.0, 60.0), (-40.0, 30.0)];
    let joints = ["knee flexion", "hip flexion", "ankle dorsiflexion"];
    let mut out = String::new();
    let (width, height) = (3.0 * w + pad, plots.len() as f32 * h + pad);
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11"><rect width="100%" height="100%" fill="white"/>"#
    );
    for (row, (manner, curves, bands)) in plots.iter().enumerate() {
        for (col, curve) in curves.iter().enumerate() {
            let (x0, y0) = (pad + col as f32 * w, pad / 2.0 + row as f32 * h);
            let (pw, ph) = (w - 50.0, h - 40.0);
            let (lo, hi) = ranges[col];
            let y = |v: f32| y0 + 15.0 + ph * (hi - v) / (hi - lo);
            let x = |pct: f32| x0 + 22.0 + pw * pct / 100.0;
            let _ = writeln!(
                out,
                r##"<text x="{}" y="{}">{manner}: {} (deg) over the cycle</text><rect x="{}" y="{}" width="{pw}" height="{ph}" fill="none" stroke="#999"/><line x1="{}" x2="{}" y1="{}" y2="{}" stroke="#ccc"/>"##,
                x0 + 10.0,
                y0 + 10.0,
                joints[col],
                x(0.0),
                y(hi),
                x(0.0),
                x(100.0),
                y(0.0),
                y(0.0)
            );
            for v in [lo, 0.0, hi] {
                let _ = writeln!(
                    out,
                    r##"<text x="{}" y="{}" font-size="9" fill="#555" text-anchor="end">{v}</text>"##,
                    x(0.0) - 2.0,
                    y(v) + 3.0
                );
            }
            for &(k, blo, bhi, _) in bands.iter() {
                if let Some((joint, pct)) = placed(k, curves) {
                    if joint == col {
                        let _ = writeln!(
                            out,
                            r##"<rect x="{}" y="{}" width="8" height="{}" fill="#8c8" fill-opacity="0.6"/>"##,
                            x(pct) - 4.0,
                            y(bhi),
                            y(blo) - y(bhi)
                        );
                    }
                }
            }
            let points: Vec<String> = curve
                .iter()
                .enumerate()
                .map(|(i, v)| format!("{:.1},{:.1}", x(i as f32), y(v.clamp(lo, hi))))
                .collect();
            let _ = writeln!(
                out,
                r##"<polyline points="{}" fill="none" stroke="#c33" stroke-width="1.5"/>"##,
                points.join(" ")
            );
        }
    }
    let _ = write!(
        out,
        r##"<text x="30" y="{}" fill="#555">red: realized mean curve; green bars: published mean ± 2 SD at that moment (docs/locomotion.md)</text>"##,
        height - 4.0
    );
    out.push_str("</svg>\n");
    out
}
