//! `bmlr view ITEM... --out DIR | --serve ADDR`: realizes the items on the virtual clock (as
//! `bmlr run` does), then writes or serves a page that shows the run: the mannequin in 3D with
//! the world's points, the timeline with a cursor, and the feedback up to the cursor. The page's
//! data is the frames file's header and lines (with the face), the mannequin's boxes, every
//! feedback message with the time it was sent, the timeline picture and its time axis, the world,
//! and the run's sound (flite's speech, audiofile clips) as a WAV the page plays with the cursor.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use bml_realizer::character::body::{mannequin, Skeleton};
use bml_realizer::language::feedback::{Feedback, Format};
use bml_realizer::ports::timeline::Timeline;
use bml_realizer::world::World;
use clap::Args;
use serde_json::{json, Value};

use crate::run::VirtualRun;
use crate::setup::SetupArgs;
use crate::web;

/// Arguments of `bmlr view`.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("to").required(true).args(["out", "serve"])))]
pub struct ViewArgs {
    #[command(flatten)]
    setup: SetupArgs,
    /// Frames per second of the motion on the page.
    #[arg(long, value_name = "HZ", default_value_t = 30.0)]
    fps: f64,
    /// Stop the clock at this global time (seconds).
    #[arg(long, value_name = "SECS")]
    until: Option<f64>,
    /// Write the page into this directory: index.html (self-contained; it works opened from
    /// disk) and three-LICENSE.txt.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Serve the page on this loopback address (e.g. 127.0.0.1:8080; port 0 picks one, printed
    /// on stderr) until interrupted.
    #[arg(long, value_name = "ADDR", conflicts_with = "out")]
    serve: Option<String>,
    #[command(flatten)]
    avatar: crate::avatar::AvatarArgs,
    /// BML files (one block each), '-' for a stream of blocks on stdin, '+SECS' to advance the
    /// clock before the next item.
    #[arg(required = true, value_name = "ITEM")]
    items: Vec<String>,
}

/// Most characters the page shows as avatars (each carries its own copy of the avatar); more
/// are shown as mannequins.
pub const MAX_VIEW_AVATARS: usize = 4;

/// Most characters whose frames the page carries as the frames file's lines, each drawn with
/// its face; more are packed and drawn as one crowd (without faces).
pub const CROWD_PAGE: usize = 16;

/// Most characters of a crowd drawn as people (the default avatar, skinned, one copy of its
/// geometry shared by all); more are drawn as instanced mannequins.
pub const CROWD_PEOPLE: usize = 100;

/// `bmlr view`.
pub fn view(args: ViewArgs) -> ExitCode {
    let (page, summary, outcome) = match realize(&args) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("bmlr view: {e}");
            return ExitCode::from(2);
        }
    };
    let written = match (&args.out, &args.serve) {
        (Some(dir), _) => write(dir, &page, &summary),
        (None, Some(addr)) => serve(addr, page),
        (None, None) => unreachable!("clap requires --out or --serve"),
    };
    match written {
        Ok(()) => outcome.exit("view"),
        Err(e) => {
            eprintln!("bmlr view: {e}");
            ExitCode::from(2)
        }
    }
}

/// Runs the items and returns the page, a summary of it, and how many blocks could not be parsed.
fn realize(args: &ViewArgs) -> Result<(String, String, crate::outcome::Outcome), String> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err("--fps must be a positive number".into());
    }
    if args.until.is_some_and(|u| !(u.is_finite() && u >= 0.0)) {
        return Err("--until must be a number of seconds >= 0".into());
    }
    let items = crate::setup::read_items(&args.items)?;
    if args.setup.nets.is_some() && args.until.is_none() {
        return Err("--nets: nets may go on changing for ever; give --until SECS".into());
    }
    let until = args.until.unwrap_or(f64::INFINITY);
    let realizer = args.setup.realizer(false)?;
    let avatars = (args.avatar).load(realizer.world(), args.setup.world.as_deref())?;
    let mut run = VirtualRun::recording(realizer, args.fps, until);
    run.items(items);
    crate::run::report_unfinished(&run.realizer);
    let motion = run.take_motion().expect("a recording run records");
    let log = run.log.take().unwrap_or_default();
    // those that received blocks, and those the world file places standing by
    let mut characters = crate::record::received(&run.realizer);
    characters.extend(run.realizer.world().placements().map(|(id, _)| id));
    characters.sort_unstable();
    characters.dedup();
    if characters.is_empty() {
        characters.push(""); // the default character, standing
    }
    // a crowd's page carries its frames packed and draws them without faces
    let packed = (characters.len() > CROWD_PAGE).then(|| {
        let times: Vec<f64> = motion.frames.iter().map(|(t, _)| *t).collect();
        let rests: Vec<_> = characters.iter().map(|id| motion.standing(id)).collect();
        crate::pack::packed(&times, &motion.bodies(&characters, &rests), &characters)
    });
    let (header, lines) = match packed {
        Some(_) => {
            let header = bml_realizer::character::frames::header(
                &Skeleton::adult(),
                args.fps,
                &[],
                bml_realizer::character::frames::Detail::Full,
            );
            (header, Vec::new())
        }
        None => motion.lines(&characters),
    };
    // the sound goes in as a WAV data: URL, played in step with the cursor
    let audio = match motion.heard_any() {
        true => Some(motion.wav(&run.realizer)?.0),
        false => None,
    };
    // each character on its avatar, moving as in `bmlr run --gltf`
    let avatars = if characters.len() <= MAX_VIEW_AVATARS {
        (characters.iter())
            .map(|id| motion.avatar_glb(id, avatars.of(id)))
            .collect()
    } else {
        eprintln!(
            "bmlr view: {} characters, shown as mannequins (avatars for at most {MAX_VIEW_AVATARS})",
            characters.len()
        );
        Vec::new()
    };
    // a crowd of people, not mannequins, while the page can draw them
    let crowd_avatar = packed.is_some() && characters.len() <= CROWD_PEOPLE;
    if packed.is_some() && !crowd_avatar {
        eprintln!(
            "bmlr view: {} characters, drawn as mannequins (people for at most {CROWD_PEOPLE})",
            characters.len()
        );
    }
    let data = PageData {
        title: &title(&args.items),
        live: false,
        header: &header,
        lines: &lines,
        log: &log,
        world: run.realizer.world(),
        audio,
        avatars,
        live_avatars: Vec::new(),
        packed,
        crowd_avatar,
    };
    let page = web::page(&data.to_json());
    let s = if characters.len() == 1 { "" } else { "s" };
    let summary = format!(
        "{} frames at {} fps, {} character{s}, {} kB",
        motion.count,
        args.fps,
        characters.len(),
        page.len() / 1024
    );
    Ok((page, summary, run.outcome))
}

/// The page's heading: the items, shortened to their file names.
fn title(items: &[String]) -> String {
    let names: Vec<&str> = (items.iter())
        .map(|i| i.rsplit(['/', '\\']).next().unwrap_or(i))
        .collect();
    names.join(" ")
}

/// The page's data (see the module comment).
pub struct PageData<'a> {
    /// The heading.
    pub title: &'a str,
    /// Whether frames and feedback come over the WebSocket as they happen.
    pub live: bool,
    /// The frames file's header line.
    pub header: &'a str,
    /// Its frame lines.
    pub lines: &'a [String],
    /// Every feedback message with the time it was sent.
    pub log: &'a [(f64, Feedback)],
    /// The world's points and paths.
    pub world: &'a World,
    /// The run's sound as a WAV file, if it made any.
    pub audio: Option<Vec<u8>>,
    /// Per character (in the header's order) its avatar with its motion, as GLB; none: the
    /// mannequins. Live: the avatars without motion, in the order of `live_avatars`.
    pub avatars: Vec<Vec<u8>>,
    /// Live: per avatar, the character it shows and how its frames' data sets its nodes
    /// (`{"id", "moving": [node…], "hips": node, "morphs": [[node, targets]…]}`).
    pub live_avatars: Vec<serde_json::Value>,
    /// A crowd's frames, packed (see [`crate::pack`]) instead of `lines`.
    pub packed: Option<Value>,
    /// Whether a crowd is drawn as people: the default avatar goes in once, and every
    /// character is a skinned copy sharing its geometry.
    pub crowd_avatar: bool,
}

impl PageData<'_> {
    /// As JSON; the frames file's lines go in as they are.
    pub fn to_json(&self) -> String {
        use serde_json::value::RawValue;
        let raw = |line: &str| -> Box<RawValue> {
            RawValue::from_string(line.to_string()).expect("a frames line is JSON")
        };
        let messages: Vec<Feedback> = self.log.iter().map(|(_, f)| f.clone()).collect();
        let audio = self.audio.as_ref().map(|wav| {
            use base64::Engine as _;
            let b64 = base64::engine::general_purpose::STANDARD.encode(wav);
            format!("data:audio/wav;base64,{b64}")
        });
        let avatars: Vec<String> = self
            .avatars
            .iter()
            .map(|glb| {
                use base64::Engine as _;
                base64::engine::general_purpose::STANDARD.encode(glb)
            })
            .collect();
        let crowd_avatar = self.crowd_avatar.then(|| {
            use base64::Engine as _;
            base64::engine::general_purpose::STANDARD
                .encode(bml_realizer::character::avatar::DEFAULT_GLB)
        });
        let data = json!({
            "avatars": avatars,
            "crowdAvatar": crowd_avatar,
            "liveAvatars": self.live_avatars,
            "title": self.title,
            "live": self.live,
            "segments": mannequin::segments(&Skeleton::adult()),
            "parts": balance_parts(&Skeleton::adult()),
            "feedback": self.log.iter().map(|(t, f)| message(*t, f)).collect::<Vec<_>>(),
            "timeline": timeline(&messages),
            "world": world_data(self.world),
            "header": raw(self.header),
            "frames": self.lines.iter().map(|l| raw(l)).collect::<Vec<_>>(),
            "packed": self.packed,
            "audio": audio,
        });
        serde_json::to_string(&data).expect("the page data encodes")
    }
}

/// The physical humanoid's parts for the page's centre of mass and support polygon: per part,
/// the skeleton joint it follows, its mass, its centre of mass in that joint's frame, and for
/// the feet the corners of the sole.
fn balance_parts(skeleton: &Skeleton) -> Value {
    let Ok(h) = bml_realizer::character::dynamics::humanoid::Humanoid::new(skeleton) else {
        return Value::Array(Vec::new());
    };
    let parts = h.parts.iter().map(|p| {
        let m = p.mass();
        let sole = p.sole().map(|corners| corners.map(|c| c.to_array()));
        json!({ "joint": p.joint, "mass": m.mass, "com": m.com.to_array(), "sole": sole })
    });
    Value::Array(parts.collect())
}

/// A feedback message for the page: when it was sent, its element name and its XML.
pub fn message(time: f64, f: &Feedback) -> Value {
    let kind = f.element_name();
    json!({"time": (time * 1e6).round() / 1e6, "kind": kind, "text": Format::Xml.encode(f)})
}

/// The timeline picture of `feedback` and its time axis.
pub fn timeline(feedback: &[Feedback]) -> Value {
    let t = Timeline::from_feedback(feedback);
    json!({"svg": t.to_svg(), "axis": t.axis()})
}

/// A position in metres, to the micrometre (as in the frames file).
fn metres(p: glam::Vec3) -> [f64; 3] {
    p.to_array().map(|v| (f64::from(v) * 1e6).round() / 1e6)
}

/// The world's points, paths and obstacles.
fn world_data(w: &World) -> Value {
    use bml_realizer::world::space::Shape;
    let obstacles: Vec<Value> = (w.obstacles().all().iter())
        .map(|o| {
            let m = |v: f32| (f64::from(v) * 1e6).round() / 1e6;
            let h = m(o.height);
            match o.shape {
                Shape::Circle { centre, radius } => {
                    json!({"circle": [m(centre.x), m(centre.y), m(radius)], "height": h})
                }
                Shape::Box { min, max } => {
                    json!({"box": [m(min.x), m(min.y), m(max.x), m(max.y)], "height": h})
                }
                Shape::Segment { a, b } => {
                    json!({"segment": [m(a.x), m(a.y), m(b.x), m(b.y)], "height": h})
                }
            }
        })
        .collect();
    let points: serde_json::Map<String, Value> = (w.points())
        .map(|(name, at)| (name.to_string(), json!(metres(at))))
        .collect();
    let paths: serde_json::Map<String, Value> = (w.paths())
        .map(|(name, keys)| {
            let keys: Vec<Value> = keys.iter().map(|(t, p)| json!([t, metres(*p)])).collect();
            (name.to_string(), Value::Array(keys))
        })
        .collect();
    json!({"points": points, "paths": paths, "obstacles": obstacles})
}

/// Writes DIR/index.html and DIR/three-LICENSE.txt.
fn write(dir: &std::path::Path, page: &str, summary: &str) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let index = dir.join("index.html");
    for (path, text) in [
        (&index, page),
        (&dir.join("three-LICENSE.txt"), web::THREE_LICENSE),
    ] {
        std::fs::write(path, text).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    }
    eprintln!("wrote {}: {summary}", index.display());
    Ok(())
}

/// Serves the page on `addr` until the process is stopped.
fn serve(addr: &str, page: String) -> Result<(), String> {
    let (listener, at) = web::bind(addr)?;
    eprintln!("bmlr view: serving http://{at}/ (Ctrl-C stops)");
    web::serve(listener, Arc::new(page), None);
    Ok(())
}
