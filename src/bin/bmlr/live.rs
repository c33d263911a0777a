//! The live view of `bmlr serve --tcp ADDR --view ADDR2`: the viewer's page served on ADDR2, and
//! over its WebSocket the realizer's frames (the frames file's lines, [`FPS`] a second), every
//! feedback message with the time it was sent, and the timeline of the last [`WINDOW`] seconds,
//! redrawn at most twice a second while feedback arrives. A watcher who connects late first gets
//! the last [`BACKLOG`] feedback messages and the latest timeline, then the frames from then on.
//! Characters with an avatar (the default character and the world's, up to
//! [`crate::view::MAX_VIEW_AVATARS`]) are shown as it: the page carries each avatar once, and
//! each frame message its moving nodes' rotations and its morph weights (`avatar::Driver`).

use std::collections::VecDeque;
use std::sync::Arc;

use bml_realizer::character::avatar::{animated_glb, Driver};
use bml_realizer::character::body::Skeleton;
use bml_realizer::character::frames;
use bml_realizer::engines::interface::CharacterPose;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::world::World;
use serde_json::json;

use crate::web::{self, Live};

/// Frames a second sent to watchers.
pub const FPS: f64 = 30.0;
/// Seconds of feedback the live timeline shows.
pub const WINDOW: f64 = 30.0;
/// Feedback messages a watcher who connects late is sent first.
pub const BACKLOG: usize = 2_000;
/// Least time between two timeline pictures (seconds).
const REDRAW: f64 = 0.5;

/// What the server tells the live page.
pub struct LiveView {
    live: Live,
    skeleton: Skeleton,
    next_frame: f64,
    /// Feedback of the last [`WINDOW`] seconds, with the time each was sent.
    recent: VecDeque<(f64, Feedback)>,
    /// Feedback arrived since the last timeline, and when that was drawn.
    stale: bool,
    drawn_at: f64,
    /// The characters shown as avatars, each with its driver.
    avatars: Vec<(String, Driver)>,
}

/// Numbers in a frame's avatar data keep 6 decimals, as the frames file's.
fn short(v: f32) -> f64 {
    (f64::from(v) * 1e6).round() / 1e6 + 0.0
}

impl LiveView {
    /// Serves the live page on `addr` (loopback only; the address it got is printed on stderr)
    /// for a realizer in `world`, its characters shown as their `avatars`.
    pub fn start(
        addr: &str,
        world: &World,
        avatars: &crate::avatar::Avatars,
    ) -> Result<LiveView, String> {
        let (listener, at) = web::bind(addr)?;
        let skeleton = Skeleton::adult();
        let header = frames::header(&skeleton, FPS, &[""], frames::Detail::Full);
        let ids = std::iter::once("").chain(world.placements().map(|(id, _)| id));
        let shown: Vec<&str> = ids.take(crate::view::MAX_VIEW_AVATARS).collect();
        let glbs = (shown.iter())
            .map(|id| animated_glb(&avatars.of(id).model, &avatars.of(id).retarget, &[], id))
            .collect();
        let drivers: Vec<(String, Driver)> = (shown.iter())
            .map(|&id| {
                let a = avatars.of(id);
                (
                    id.to_string(),
                    Driver::new(&a.model, a.placed(world.placement(id))),
                )
            })
            .collect();
        let wiring = (drivers.iter())
            .map(|(id, d)| {
                json!({"id": id, "moving": d.moving(), "hips": d.hips(), "morphs": d.morph_nodes()})
            })
            .collect();
        let data = crate::view::PageData {
            title: "bmlr serve",
            live: true,
            header: &header,
            lines: &[],
            log: &[],
            world,
            audio: None,
            avatars: glbs,
            live_avatars: wiring,
            packed: None,
            crowd_avatar: false,
        }
        .to_json();
        let live = Live::new(BACKLOG);
        let page = Arc::new(web::page(&data));
        let hub = live.clone();
        std::thread::spawn(move || web::serve(listener, page, Some(hub)));
        eprintln!("bmlr serve: live view on http://{at}/");
        Ok(LiveView {
            live,
            skeleton,
            next_frame: 0.0,
            recent: VecDeque::new(),
            stale: false,
            drawn_at: f64::NEG_INFINITY,
            avatars: drivers,
        })
    }

    /// The realizer's poses at time `t` (sent when a frame is due and someone watches), and the
    /// timeline when it is due.
    pub fn frame(&mut self, t: f64, poses: &[CharacterPose]) {
        if self.stale && t - self.drawn_at >= REDRAW {
            self.timeline(t);
        }
        if t < self.next_frame || !self.live.watched() {
            return;
        }
        self.next_frame = t + 1.0 / FPS;
        let poses: Vec<(&str, &CharacterPose)> = (poses.iter())
            .map(|p| (p.character.as_deref().unwrap_or(""), p))
            .collect();
        let line = frames::line(&self.skeleton, t, &poses);
        let (mut rotations, mut weights) = (Vec::new(), Vec::new());
        let mut avatars = serde_json::Map::new();
        for (id, p) in &poses {
            let Some((_, driver)) = self.avatars.iter().find(|a| a.0 == *id) else {
                continue;
            };
            driver.frame(&p.pose, &p.face, &mut rotations, &mut weights);
            let r: Vec<f64> = rotations.iter().map(|&v| short(v)).collect();
            let w: Vec<f64> = weights.iter().map(|&v| short(v)).collect();
            avatars.insert(id.to_string(), json!({"r": r, "w": w}));
        }
        let avatars = serde_json::Value::Object(avatars);
        self.live
            .send(format!("{{\"frame\":{line},\"avatars\":{avatars}}}"));
    }

    /// A feedback message sent at time `t`.
    pub fn feedback(&mut self, t: f64, fb: &Feedback) {
        let message = json!({ "feedback": crate::view::message(t, fb) });
        self.live.feedback(message.to_string());
        self.recent.push_back((t, fb.clone()));
        while self.recent.front().is_some_and(|(at, _)| *at < t - WINDOW) {
            self.recent.pop_front();
        }
        self.stale = true;
    }

    fn timeline(&mut self, t: f64) {
        let feedback: Vec<Feedback> = self.recent.iter().map(|(_, f)| f.clone()).collect();
        let message = json!({ "timeline": crate::view::timeline(&feedback) });
        self.live.timeline(message.to_string());
        self.stale = false;
        self.drawn_at = t;
    }
}
