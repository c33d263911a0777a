//! Timeline pictures (`bmlr plan --svg`, `bmlr timeline --svg`): a [`Timeline`] — one lane per
//! behaviour, grouped by character and block, with sync points, block start and end, links between
//! sync points and warnings — built from feedback (a log, or a plan's predictions) and drawn as SVG.

use std::fmt::Write as _;

use crate::language::bml::{self, Anchor, SyncPoint};
use crate::language::feedback::{BlockStatus, Feedback};

/// A sync point: (block, behaviour, sync).
pub type SyncId = (String, String, String);

/// One behaviour's lane.
#[derive(Debug, Clone, PartialEq)]
pub struct Lane {
    /// Behaviour id.
    pub behaviour: String,
    /// Element name (from predictions), if known.
    pub kind: Option<String>,
    /// (sync, global time) in the order they came.
    pub syncs: Vec<(String, f64)>,
    /// A warning names this behaviour.
    pub warned: bool,
}

/// One block: its start, end and lanes.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockRow {
    /// Block id.
    pub id: String,
    /// Character, if any.
    pub character: Option<String>,
    /// Global start (reported, else predicted).
    pub start: Option<f64>,
    /// Global end (reported, else predicted).
    pub end: Option<f64>,
    /// How it ended (or the last predicted status).
    pub status: Option<BlockStatus>,
    /// Behaviours in the order they first appeared.
    pub lanes: Vec<Lane>,
}

/// A link between two sync points: `(block, behaviour, sync)` pairs and a label.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// One end.
    pub from: SyncId,
    /// The other end.
    pub to: SyncId,
    /// `=`, `<=`, `>=` for constraints, `≈` for sync points that merely coincide.
    pub label: String,
}

/// What a picture shows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Timeline {
    /// Blocks in the order they first appeared.
    pub blocks: Vec<BlockRow>,
    /// Links between sync points.
    pub links: Vec<Link>,
    /// (id, text) of every warning.
    pub warnings: Vec<(String, String)>,
}

impl Timeline {
    fn block(&mut self, id: &str, character: Option<&String>) -> &mut BlockRow {
        let i = match self.blocks.iter().position(|b| b.id == id) {
            Some(i) => i,
            None => {
                self.blocks.push(BlockRow {
                    id: id.to_string(),
                    character: character.cloned(),
                    start: None,
                    end: None,
                    status: None,
                    lanes: Vec::new(),
                });
                self.blocks.len() - 1
            }
        };
        &mut self.blocks[i]
    }

    /// A timeline from feedback: reported times where there are any, predicted ones (PENDING
    /// predictions) otherwise. Sync points of one block that coincide are linked.
    pub fn from_feedback(feedback: &[Feedback]) -> Timeline {
        let mut t = Timeline::default();
        // blocks that reported a start (a block revoked before it has none)
        let mut started = std::collections::HashSet::new();
        for fb in feedback {
            match fb {
                Feedback::Prediction(p) => t.prediction(p),
                Feedback::BlockProgress(p) => t.block_progress(p, &mut started),
                Feedback::SyncPointProgress(p) => t.sync_progress(p),
                Feedback::Warning(w) => t.warnings.push((w.id.clone(), w.text.clone())),
                Feedback::World(_) => {}
            }
        }
        for (id, _) in &t.warnings {
            if let Some((b, beh)) = id.split_once(':') {
                if let Some(row) = t.blocks.iter_mut().find(|r| r.id == b) {
                    if let Some(l) = row.lanes.iter_mut().find(|l| l.behaviour == beh) {
                        l.warned = true;
                    }
                }
            }
        }
        t.link_coincident();
        t
    }

    /// A prediction gives blocks their predicted span and behaviours their predicted syncs (the
    /// first prediction of a behaviour; a PENDING one also moves the block).
    fn prediction(&mut self, p: &crate::language::feedback::PredictionFeedback) {
        for b in &p.blocks {
            let row = self.block(&b.id, p.character_id.as_ref());
            if row.start.is_none() || b.status == Some(BlockStatus::Pending) {
                row.start = b.global_start.or(row.start);
                row.end = b.global_end.or(row.end);
            }
            row.status = b.status.or(row.status);
            let start = row.start.unwrap_or(0.0);
            for x in p.behaviours.iter().filter(|x| x.block == b.id) {
                if row.lanes.iter().any(|l| l.behaviour == x.behaviour) {
                    continue;
                }
                row.lanes.push(Lane {
                    behaviour: x.behaviour.to_string(),
                    kind: Some(x.kind.to_string()),
                    syncs: x
                        .syncs
                        .iter()
                        .map(|(s, v)| (s.to_string(), start + v))
                        .collect(),
                    warned: false,
                });
            }
        }
    }

    /// A block started (its predicted syncs move with it) or ended.
    fn block_progress(
        &mut self,
        p: &crate::language::feedback::BlockProgress,
        started: &mut std::collections::HashSet<String>,
    ) {
        let row = self.block(&p.block, p.character_id.as_ref());
        match p.sync.as_str() {
            "start" => {
                // predicted sync times move with the block's actual start
                if let Some(old) = row.start {
                    let shift = p.global_time - old;
                    for l in &mut row.lanes {
                        for s in &mut l.syncs {
                            s.1 += shift;
                        }
                    }
                }
                row.start = Some(p.global_time);
                started.insert(p.block.to_string());
            }
            // revoked before it started: it never ran, so nothing of it is drawn
            // but the moment it was removed
            "end"
                if p.status == Some(BlockStatus::Revoked)
                    && !started.contains(p.block.as_str()) =>
            {
                row.start = Some(p.global_time);
                row.end = Some(p.global_time);
                row.lanes.clear();
            }
            "end" => row.end = Some(p.global_time),
            _ => {}
        }
        row.status = p.status.or(row.status);
    }

    /// A sync point passed: its lane gets the actual time.
    fn sync_progress(&mut self, p: &crate::language::feedback::SyncPointProgress) {
        let row = self.block(&p.block, p.character_id.as_ref());
        let lane = match row.lanes.iter().position(|l| l.behaviour == p.behaviour) {
            Some(i) => &mut row.lanes[i],
            None => {
                row.lanes.push(Lane {
                    behaviour: p.behaviour.to_string(),
                    kind: None,
                    syncs: Vec::new(),
                    warned: false,
                });
                row.lanes.last_mut().expect("just pushed")
            }
        };
        match lane.syncs.iter_mut().find(|s| s.0 == p.sync) {
            Some(s) => s.1 = p.global_time,
            None => lane.syncs.push((p.sync.to_string(), p.global_time)),
        }
    }

    /// Links sync points of different behaviours of one block that happen at the same time.
    fn link_coincident(&mut self) {
        for row in &self.blocks {
            let mut all: Vec<(f64, &str, &str)> = row
                .lanes
                .iter()
                .flat_map(|l| {
                    l.syncs
                        .iter()
                        .map(move |(s, t)| (*t, l.behaviour.as_str(), s.as_str()))
                })
                .filter(|p| p.0.is_finite())
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0));
            for w in all.windows(2) {
                if (w[1].0 - w[0].0).abs() < 1e-3 && w[0].1 != w[1].1 {
                    self.links.push(Link {
                        from: (row.id.clone(), w[0].1.into(), w[0].2.into()),
                        to: (row.id.clone(), w[1].1.into(), w[1].2.into()),
                        label: "≈".into(),
                    });
                }
            }
        }
    }

    /// Adds the constraints of `block` between sync points as links (`bmlr plan`), replacing the
    /// links of mere coincidence inside it.
    pub fn add_constraints(&mut self, block: &bml::Block) {
        self.links
            .retain(|l| !(l.label == "≈" && l.from.0 == block.id));
        let point = |a: &Anchor| match a {
            Anchor::Point(SyncPoint::Local { behaviour, sync }) => Some((
                block.id.to_string(),
                behaviour.to_string(),
                sync.to_string(),
            )),
            Anchor::Point(SyncPoint::External {
                block: b,
                behaviour,
                sync,
            }) => Some((b.to_string(), behaviour.to_string(), sync.to_string())),
            _ => None,
        };
        for c in bml::extract(block) {
            if let (Some(from), Some(to)) = (point(&c.left), point(&c.right)) {
                self.links.push(Link {
                    from,
                    to,
                    label: c.relation.symbol().to_string(),
                });
            }
        }
    }

    /// The picture as an SVG document.
    pub fn to_svg(&self) -> String {
        svg(self)
    }

    /// Where times are in the picture of [`Timeline::to_svg`] (for a cursor drawn over it).
    pub fn axis(&self) -> Axis {
        let (t0, t1) = time_range(self);
        Axis {
            t0,
            t1,
            left: LEFT,
            px_per_s: px_per_s(t0, t1),
        }
    }
}

/// The time axis of a timeline picture: time `t` is at x = `left + (t - t0) * px_per_s`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Axis {
    /// The first time shown (seconds).
    pub t0: f64,
    /// The last time shown.
    pub t1: f64,
    /// Where `t0` is (pixels from the left edge).
    pub left: f64,
    /// Pixels per second.
    pub px_per_s: f64,
}

/// The scale of a picture of the times `t0`–`t1`: about 1200 pixels wide, within bounds.
fn px_per_s(t0: f64, t1: f64) -> f64 {
    (1200.0 / (t1 - t0)).clamp(20.0, 400.0)
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const LEFT: f64 = 220.0;
const TOP: f64 = 40.0;
const BLOCK_ROW: f64 = 26.0;
const LANE: f64 = 30.0;
const RIGHT: f64 = 40.0;

/// A tick spacing (seconds) that puts ticks at least `min_px` apart.
fn tick_step(px_per_s: f64, min_px: f64) -> f64 {
    for step in [
        0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 60.0, 120.0, 300.0,
    ] {
        if step * px_per_s >= min_px {
            return step;
        }
    }
    600.0
}

/// The time range the picture shows: every finite time of the timeline (one second if there is
/// only one; 0–1 s if there is none).
fn time_range(t: &Timeline) -> (f64, f64) {
    let times = (t.blocks.iter())
        .flat_map(|b| {
            (b.start.into_iter().chain(b.end))
                .chain(b.lanes.iter().flat_map(|l| l.syncs.iter().map(|s| s.1)))
        })
        .filter(|v| v.is_finite());
    let (t0, t1) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, z), v| {
        (a.min(v), z.max(v))
    });
    if t0.is_finite() && t1 > t0 {
        (t0, t1)
    } else if t0.is_finite() {
        (t0, t0 + 1.0)
    } else {
        (0.0, 1.0)
    }
}

/// The SVG being drawn: the time scale, and where each sync's mark is (for the links).
struct Canvas {
    s: String,
    t0: f64,
    t1: f64,
    /// Pixels per second.
    px: f64,
    positions: Vec<(SyncId, (f64, f64))>,
}

impl Canvas {
    fn x(&self, v: f64) -> f64 {
        LEFT + (v - self.t0) * self.px
    }

    /// Vertical lines with their times, every `tick_step`.
    fn axis(&mut self, height_plot: f64) {
        let step = tick_step(self.px, 60.0);
        let mut tick = (self.t0 / step).ceil() * step;
        while tick <= self.t1 + 1e-9 {
            let xt = self.x(tick);
            let _ = writeln!(
                self.s,
                r##"<line x1="{xt:.1}" y1="{:.1}" x2="{xt:.1}" y2="{height_plot:.1}" stroke="#e4e4e4"/><text x="{xt:.1}" y="{:.1}" font-size="11" text-anchor="middle" fill="#555">{tick:.2} s</text>"##,
                TOP,
                TOP - 8.0
            );
            tick += step;
        }
    }

    /// A block's row at height `y`: its span and its name, character and times.
    fn block_row(&mut self, b: &BlockRow, who: &str, y: f64) {
        let status = b.status.map_or(String::new(), |st| format!(" {st}"));
        if let (Some(a), Some(e)) = (b.start, b.end.or(Some(self.t1))) {
            let _ = writeln!(
                self.s,
                r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#dbe8f6" stroke="#6f94c0"/>"##,
                self.x(a),
                y + 4.0,
                (self.x(e.max(a)) - self.x(a)).max(1.0),
                BLOCK_ROW - 8.0
            );
        }
        let _ = writeln!(
            self.s,
            r##"<text x="6" y="{:.1}" font-size="13" font-weight="bold">{}{}</text><text x="{:.1}" y="{:.1}" font-size="10" fill="#355">{}</text>"##,
            y + 17.0,
            esc(&b.id),
            esc(who),
            self.x(b.start.unwrap_or(self.t0)) + 4.0,
            y + 17.0,
            esc(&format!(
                "{}{}{}",
                b.start.map_or(String::new(), |v| format!("start {v:.3}")),
                b.end.map_or(String::new(), |v| format!("  end {v:.3}")),
                status
            ))
        );
    }

    /// A behaviour's lane at height `y`: its name, its span and a mark per sync.
    fn lane(&mut self, block: &str, l: &Lane, y: f64) {
        let mid = y + LANE * 0.6;
        let colour = if l.warned { "#c0392b" } else { "#222" };
        let _ = writeln!(
            self.s,
            r#"<text x="14" y="{:.1}" font-size="12" fill="{colour}">{}{}{}</text>"#,
            mid + 4.0,
            if l.warned { "⚠ " } else { "" },
            esc(&l.behaviour),
            esc(&l.kind.as_ref().map_or(String::new(), |k| format!(" ({k})")))
        );
        let finite: Vec<&(String, f64)> = l.syncs.iter().filter(|p| p.1.is_finite()).collect();
        if let (Some(first), Some(last)) = (
            finite.iter().map(|p| p.1).reduce(f64::min),
            finite.iter().map(|p| p.1).reduce(f64::max),
        ) {
            let _ = writeln!(
                self.s,
                r##"<line x1="{:.1}" y1="{mid:.1}" x2="{:.1}" y2="{mid:.1}" stroke="#888" stroke-width="3"/>"##,
                self.x(first),
                self.x(last)
            );
        }
        // labels above or below the lane, wherever they do not overlap the previous one;
        // a label that fits nowhere is left out (the mark's tooltip still names it)
        let mut free = [f64::NEG_INFINITY; 2];
        for (name, tv) in &finite {
            let xs = self.x(*tv);
            let half = 2.6 * name.chars().count() as f64 + 2.0;
            let _ = writeln!(
                self.s,
                r##"<circle cx="{xs:.1}" cy="{mid:.1}" r="3.5" fill="{colour}"><title>{}:{}:{} {tv:.3} s</title></circle>"##,
                esc(block),
                esc(&l.behaviour),
                esc(name)
            );
            if let Some(level) = (0..2).find(|&k| xs - half >= free[k]) {
                free[level] = xs + half;
                let ly = if level == 0 { mid - 7.0 } else { mid + 14.0 };
                let _ = writeln!(
                    self.s,
                    r##"<text x="{xs:.1}" y="{ly:.1}" font-size="9" text-anchor="middle" fill="#444">{}</text>"##,
                    esc(name)
                );
            }
            let id = (block.to_string(), l.behaviour.clone(), name.clone());
            self.positions.push((id, (xs, mid)));
        }
    }

    /// A dashed curve from one sync's mark to another's.
    fn link(&mut self, link: &Link) {
        let at = |p: &SyncId| self.positions.iter().find(|q| &q.0 == p).map(|q| q.1);
        let (Some((x1, y1)), Some((x2, y2))) = (at(&link.from), at(&link.to)) else {
            return;
        };
        let colour = if link.label == "≈" {
            "#9aa"
        } else {
            "#2c7a4b"
        };
        let bend = 18.0 + (y2 - y1).abs() * 0.1;
        let _ = writeln!(
            self.s,
            r#"<path d="M {x1:.1} {y1:.1} C {:.1} {y1:.1} {:.1} {y2:.1} {x2:.1} {y2:.1}" fill="none" stroke="{colour}" stroke-dasharray="4 3"><title>{}:{}:{} {} {}:{}:{}</title></path>"#,
            x1 + bend,
            x2 + bend,
            esc(&link.from.0),
            esc(&link.from.1),
            esc(&link.from.2),
            esc(&link.label),
            esc(&link.to.0),
            esc(&link.to.1),
            esc(&link.to.2)
        );
    }
}

fn svg(t: &Timeline) -> String {
    let (t0, t1) = time_range(t);
    let px = px_per_s(t0, t1);
    let mut c = Canvas {
        s: String::new(),
        t0,
        t1,
        px,
        positions: Vec::new(),
    };
    let lanes: usize = t.blocks.iter().map(|b| b.lanes.len()).sum();
    let height_plot = TOP + 20.0 + t.blocks.len() as f64 * BLOCK_ROW + lanes as f64 * LANE;
    let height = height_plot + 20.0 + 16.0 * t.warnings.len() as f64 + 10.0;
    let width = c.x(t1) + RIGHT;
    let _ = writeln!(
        c.s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif">"#
    );
    let _ = writeln!(c.s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    c.axis(height_plot);
    let mut y = TOP + 20.0;
    let mut character: Option<&String> = None;
    for b in &t.blocks {
        // the character is named where it changes
        let who = if b.character != character.cloned() && b.character.is_some() {
            character = b.character.as_ref();
            format!(" [{}]", b.character.as_deref().unwrap_or(""))
        } else {
            String::new()
        };
        c.block_row(b, &who, y);
        y += BLOCK_ROW;
        for l in &b.lanes {
            c.lane(&b.id, l, y);
            y += LANE;
        }
    }
    for link in &t.links {
        c.link(link);
    }
    let mut wy = height_plot + 24.0;
    for (id, text) in &t.warnings {
        let _ = writeln!(
            c.s,
            r##"<text x="6" y="{wy:.1}" font-size="11" fill="#c0392b">⚠ {}: {}</text>"##,
            esc(id),
            esc(text)
        );
        wy += 16.0;
    }
    c.s.push_str("</svg>\n");
    c.s
}

#[cfg(test)]
mod tests;
