//! `bmlr run` and `bmlr plan`: feed BML files and streams to a realizer on a virtual clock (or in
//! real time) and print its feedback, or print the planned sync times without executing.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::Duration;

use bml_realizer::bml::{BlockStream, Limits, StreamItem};
use bml_realizer::clock::{Clock, WallClock};
use bml_realizer::feedback::{BlockStatus, Feedback, Format};
use bml_realizer::realizer::Realizer;
use bml_realizer::timeline::Timeline;
use bml_realizer::timing::{SpeechTiming, Voice};
use clap::{Args, ValueEnum};

use crate::record::Recording;
use crate::spool::FrameSpool;
use bml_realizer::character::frames;

/// Feedback line format.
#[derive(Clone, Copy, ValueEnum)]
pub enum FormatArg {
    /// BML 1.0 feedback XML, one element per line.
    Xml,
    /// JSON lines.
    Jsonl,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Xml => Format::Xml,
            FormatArg::Jsonl => Format::Jsonl,
        }
    }
}

/// Arguments of `bmlr run`.
#[derive(Args)]
pub struct RunArgs {
    /// Feedback format.
    #[arg(long, value_enum, default_value = "xml")]
    format: FormatArg,
    /// Run against the wall clock instead of the virtual clock.
    #[arg(long)]
    realtime: bool,
    /// Stop the clock at this global time (seconds).
    #[arg(long, value_name = "SECS")]
    until: Option<f64>,
    /// Frames per second of the engine loop (real time; on the virtual clock, frames are
    /// computed at this rate when a frame consumer needs them).
    #[arg(long, value_name = "HZ", default_value_t = 60.0)]
    fps: f64,
    #[command(flatten)]
    pub setup: SetupArgs,
    /// Write the realized motion of the character (--character, else the default one) as BVH,
    /// one frame every 1/--fps seconds (virtual clock only).
    #[arg(long, value_name = "OUT.bvh")]
    bvh: Option<std::path::PathBuf>,
    /// Write the avatar (--avatar, else the default one) with the realized motion and face of
    /// the character --character names, or of the one character that received blocks, as
    /// binary glTF, one key every 1/--fps seconds (virtual clock only). Several characters
    /// without --character: a scene of box mannequins, one per character.
    #[arg(long, value_name = "OUT.glb")]
    gltf: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub avatar: crate::avatar::AvatarArgs,
    /// Write the run's sound as a WAV file: synthesized speech (--tts flite) and audiofile clips,
    /// each at its peg and volume (virtual clock only).
    #[arg(long, value_name = "OUT.wav")]
    wav: Option<std::path::PathBuf>,
    /// Write the realized frames of every character as JSON lines (docs/cli.md, "Frames"):
    /// a header with the skeleton, then one line every 1/--fps seconds (virtual clock only).
    #[arg(long, value_name = "OUT.jsonl")]
    frames: Option<std::path::PathBuf>,
    /// With --frames: write only where each character stands (its root's position and
    /// rotation, and its feet on the ground once it walked), for crowds too large for every
    /// joint.
    #[arg(long, requires = "frames")]
    frames_roots: bool,
    /// BML files (one block each; a directory: its .xml files by name), '-' for a stream of
    /// blocks on stdin, '+SECS' to advance the clock before the next item.
    #[arg(required = true, value_name = "ITEM")]
    items: Vec<String>,
}

/// The character, motion data, world, idle layer and limits of a realizer on the virtual clock
/// (`bmlr run` and `bmlr view`).
#[derive(Args)]
pub struct SetupArgs {
    /// Character for blocks without a characterId.
    #[arg(long, value_name = "ID")]
    pub character: Option<String>,
    /// A directory of motion data adding to the embedded defaults: any of units.json (procedural
    /// units), gestures.json, poses.json and heads.json (bindings, which win over the embedded
    /// ones for what they bind) and compounds.json (compound physical controllers).
    #[arg(long, value_name = "DIR")]
    pub assets: Option<std::path::PathBuf>,
    /// A world file (JSON): named points and points moving along keyed paths, as targets of
    /// gaze, pointing and headDirectionShift, added to the built-in scene.
    #[arg(long, value_name = "WORLD.json")]
    pub world: Option<std::path::PathBuf>,
    /// Characters stand still between behaviours: no breathing, no weight shift, no blinks (the
    /// idle layer changes the motion only, never the feedback).
    #[arg(long)]
    pub no_idle: bool,
    /// The voice that says speech: the built-in TTS, flite (Debian package `flite`) or
    /// espeak-ng (Debian package `espeak-ng`).
    #[arg(long, value_enum, default_value = "builtin")]
    pub tts: TtsArg,
    /// The espeak-ng voice or language (`en`, `de`, `fr`, `pt-br`; `espeak-ng --voices` lists
    /// them) for --tts espeak; a speech's xml:lang overrides it.
    #[arg(long, value_name = "NAME")]
    pub voice: Option<String>,
    /// Characters see (synthetic vision, settings from the world file's "vision") and
    /// perception feedback reports what each sees when it changes.
    #[arg(long)]
    pub perception: bool,
    /// PaT-Nets (JSON, docs/nets.md) run with the behaviours; their transitions and the
    /// world variables' changes are reported. Nets that can go on changing keep a run going:
    /// give --until.
    #[arg(long, value_name = "NETS.json")]
    pub nets: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl SetupArgs {
    /// The realizer asked for (`posix_time`: feedback carries wall-clock times); the error
    /// names the option that is wrong.
    pub fn realizer(&self, posix_time: bool) -> Result<Realizer, String> {
        let speech = (self.tts.timing(self.voice.as_deref())).map_err(|e| format!("--tts: {e}"))?;
        let realizer = with_assets(Realizer::new(), self.assets.as_deref(), speech)
            .map_err(|e| format!("--assets {e}"))?;
        let mut realizer = with_world(realizer, self.world.as_deref())
            .map_err(|e| format!("--world {e}"))?
            .with_default_character(self.character.clone())
            .with_posix_time(posix_time)
            .with_idle(!self.no_idle)
            .with_limits(self.limits.limits());
        realizer = with_sight_and_nets(realizer, self.perception, self.nets.as_deref())?;
        Ok(realizer)
    }
}

/// The limits on one block (`docs/cli.md`, "Limits"), shared by the commands that read BML.
#[derive(Args, Clone, Copy)]
pub struct LimitArgs {
    /// Deepest nesting of elements in a block (the `<bml>` root counts as 1).
    #[arg(long, value_name = "N", default_value_t = Limits::default().depth)]
    max_depth: usize,
    /// Most attributes on one element (and namespace declarations in scope).
    #[arg(long, value_name = "N", default_value_t = Limits::default().attributes)]
    max_attributes: usize,
    /// Largest block, in bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::default().block_bytes)]
    max_block_bytes: usize,
    /// Most behaviours in one block.
    #[arg(long, value_name = "N", default_value_t = Limits::default().behaviours)]
    max_behaviours: usize,
    /// Largest absolute time or offset in a sync reference, seconds (at most 1e9).
    #[arg(long, value_name = "SECS", default_value_t = Limits::default().time, value_parser = max_time)]
    max_time: f64,
}

/// A `--max-time` value: a number of seconds above 0 and at most the furthest a schedule may go.
fn max_time(s: &str) -> Result<f64, String> {
    let bound = bml_realizer::schedule::strategy::MAX_SCHEDULED_TIME;
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= bound => Ok(t),
        _ => Err(format!("expected seconds above 0 and at most {bound}")),
    }
}

impl LimitArgs {
    /// The limits asked for.
    pub fn limits(&self) -> Limits {
        Limits {
            depth: self.max_depth,
            attributes: self.max_attributes,
            block_bytes: self.max_block_bytes,
            behaviours: self.max_behaviours,
            time: self.max_time,
        }
    }
}

/// `realizer` with the motion data of `dir` (units and bindings), if given, and speech timed by
/// `speech`.
pub fn with_assets(
    realizer: Realizer,
    dir: Option<&Path>,
    speech: SpeechTiming,
) -> Result<Realizer, String> {
    let Some(dir) = dir else {
        if speech == SpeechTiming::default() {
            return Ok(realizer);
        }
        return Ok(realizer.with_speech_timing(speech));
    };
    let assets = bml_realizer::engines::assets::Assets::from_dir(dir)?;
    Ok(realizer.with_engines(move || {
        bml_realizer::engines::registry_with(
            bml_realizer::timing::DefaultTimingModels { speech },
            &assets,
        )
    }))
}

/// The voice that says speech (`--tts`).
#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Default)]
pub enum TtsArg {
    /// The built-in TTS: timing and lips, no sound.
    #[default]
    Builtin,
    /// CMU Flite as a program (Debian package `flite`): its timing and its sound.
    Flite,
    /// espeak-ng as a program (Debian package `espeak-ng`): its sound in its languages (--voice,
    /// or xml:lang on a speech), its phonemes timed to it.
    Espeak,
}

impl TtsArg {
    /// The speech timing of this voice (espeak-ng's `voice`, else its English); for flite and
    /// espeak-ng, an error if the program is not installed or lacks the voice, and a voice
    /// asked of another TTS is an error too.
    pub fn timing(self, voice: Option<&str>) -> Result<SpeechTiming, String> {
        use bml_realizer::voice::espeak::{Espeak, VoiceName};
        if voice.is_some() && self != TtsArg::Espeak {
            return Err("--voice names an espeak-ng voice: give --tts espeak".into());
        }
        let voice = match self {
            TtsArg::Builtin => Voice::Builtin,
            TtsArg::Flite => {
                bml_realizer::voice::flite::Flite::default().check()?;
                Voice::Flite
            }
            TtsArg::Espeak => {
                let name = voice.map_or(Ok(VoiceName::default()), VoiceName::new)?;
                Espeak::new(name).check()?;
                Voice::Espeak(name)
            }
        };
        Ok(SpeechTiming {
            voice,
            ..SpeechTiming::default()
        })
    }
}

/// `realizer` with sight reported (`perception`) and the nets of the file at `nets`, if
/// given. The error names the option and the file.
pub fn with_sight_and_nets(
    mut realizer: Realizer,
    perception: bool,
    nets: Option<&Path>,
) -> Result<Realizer, String> {
    if perception {
        let vision = realizer.world().vision();
        realizer.set_perception(Some(vision), true)?;
    }
    if let Some(path) = nets {
        let at = path.display();
        let text = std::fs::read_to_string(path).map_err(|e| format!("--nets {at}: {e}"))?;
        let nets = bml_realizer::nets::file::read(&text, realizer.limits())
            .map_err(|e| format!("--nets {at}: {e}"))?;
        let variables = realizer.world().variables().clone();
        let nets = bml_realizer::nets::Nets::new(nets, variables);
        realizer.set_nets(Some(nets), true)?;
    }
    Ok(realizer)
}

/// `realizer` in the world of the file at `path`, if given. The error names the file.
pub fn with_world(mut realizer: Realizer, path: Option<&Path>) -> Result<Realizer, String> {
    let Some(path) = path else {
        return Ok(realizer);
    };
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (world, _obstacles) = bml_realizer::world::World::from_json(&text)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    *realizer.world_mut() = world;
    Ok(realizer)
}

/// Arguments of `bmlr plan`.
#[derive(Args)]
pub struct PlanArgs {
    /// Character for blocks without a characterId.
    #[arg(long, value_name = "ID")]
    character: Option<String>,
    /// A directory of motion data adding to the embedded defaults (see `bmlr run --assets`).
    #[arg(long, value_name = "DIR")]
    assets: Option<std::path::PathBuf>,
    /// A world file (JSON): named points and points moving along keyed paths, as targets of
    /// gaze, pointing and headDirectionShift, added to the built-in scene.
    #[arg(long, value_name = "WORLD.json")]
    pub world: Option<std::path::PathBuf>,
    /// Also draw the plan as a timeline picture (SVG) with the constraints as links.
    #[arg(long, value_name = "OUT.svg")]
    svg: Option<std::path::PathBuf>,
    #[command(flatten)]
    limits: LimitArgs,
    /// BML files, planned in order as if sent at once.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,
}

/// An item of the command line, read before anything runs.
pub enum Item {
    /// A file's name and text.
    Text(String, String),
    Advance(f64),
    Stdin,
}

/// Most `.xml` files a directory on the command line may hold.
pub const MAX_DIRECTORY_FILES: usize = 20_000;

/// The `.xml` files in directory `dir`, by name, or why not.
fn xml_files(dir: &Path) -> Result<Vec<String>, String> {
    let cannot = |e: std::io::Error| format!("{}: cannot read the directory: {e}", dir.display());
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(cannot)? {
        let path = entry.map_err(cannot)?.path();
        if path.is_file() && path.extension().is_some_and(|x| x == "xml") {
            files.push(path.to_string_lossy().into_owned());
        }
    }
    if files.is_empty() || files.len() > MAX_DIRECTORY_FILES {
        return Err(format!(
            "{}: a directory must hold 1 to {MAX_DIRECTORY_FILES} .xml files, not {}",
            dir.display(),
            files.len()
        ));
    }
    files.sort();
    Ok(files)
}

/// The items of a command line: files read (a directory: its `.xml` files by name), clock
/// advances checked.
pub fn read_items(items: &[String]) -> Result<Vec<Item>, String> {
    let mut expanded = Vec::new();
    for a in items {
        if Path::new(a).is_dir() {
            expanded.extend(xml_files(Path::new(a))?);
        } else {
            expanded.push(a.clone());
        }
    }
    expanded
        .iter()
        .map(|a| {
            if a == "-" {
                Ok(Item::Stdin)
            } else if a.starts_with('+') {
                bml_realizer::bml::advance(a)
                    .map(Item::Advance)
                    .ok_or_else(|| {
                        format!(
                            "'{a}' is not a clock advance: expected +SECS with SECS a number >= 0"
                        )
                    })
            } else {
                std::fs::read_to_string(Path::new(a))
                    .map(|text| Item::Text(a.clone(), text))
                    .map_err(|e| format!("{a}: cannot read: {e}"))
            }
        })
        .collect()
}

/// Prints every feedback message of a frame; false if stdout is gone.
fn print(out: &mut impl Write, format: Format, feedback: &[Feedback]) -> bool {
    for fb in feedback {
        if writeln!(out, "{}", format.encode(fb)).is_err() {
            return false;
        }
    }
    out.flush().is_ok()
}

/// How warnings name blocks read from standard input.
const STDIN: &str = "<stdin>";

/// A realizer on the virtual clock that prints its feedback as it goes (or keeps it, with the
/// time it was sent, for `bmlr view`).
pub struct VirtualRun {
    pub realizer: Realizer,
    format: Format,
    until: f64,
    /// Where feedback is printed (`None`: kept in `log` only).
    out: Option<std::io::StdoutLock<'static>>,
    open: bool,
    /// The frames recorded for --bvh, --frames, --gltf and the viewer.
    pub motion: Option<Recording>,
    /// Every message with the time of the frame that sent it, when it is kept.
    pub log: Option<Vec<(f64, Feedback)>>,
    /// Blocks that could not be parsed or scheduled whole (the run goes on; it exits 1).
    pub outcome: crate::outcome::Outcome,
}

impl VirtualRun {
    /// A run that keeps its feedback and records frames at `fps` instead of printing.
    pub fn recording(realizer: Realizer, fps: f64, until: f64) -> VirtualRun {
        let motion = Recording::new(fps).placed(realizer.world());
        VirtualRun {
            realizer,
            format: Format::Xml,
            until,
            out: None,
            open: true,
            motion: Some(motion),
            log: Some(Vec::new()),
            outcome: Default::default(),
        }
    }

    /// Sends `items` in order and runs until nothing more will happen.
    pub fn items(&mut self, items: Vec<Item>) {
        for item in items {
            match item {
                Item::Text(path, text) => self.perform(&text, &path),
                Item::Advance(s) => self.advance_to(self.realizer.now() + s),
                Item::Stdin => self.stdin(),
            }
        }
        self.run_out();
    }

    /// Prints (or keeps) the feedback of a frame at time `at`.
    fn emit(&mut self, at: f64, feedback: Vec<Feedback>) {
        self.outcome.note(&feedback);
        if let Some(out) = self.out.as_mut() {
            self.open &= print(out, self.format, &feedback);
        }
        if let Some(log) = self.log.as_mut() {
            log.extend(feedback.into_iter().map(|f| (at, f)));
        }
    }

    /// Moves the clock to `t` (capped at `--until`), event by event; frames on the way are
    /// recorded when a BVH or a frames file is asked for (feedback does not depend on them).
    fn advance_to(&mut self, t: f64) {
        let t = t.min(self.until);
        while let Some(m) = self.motion.as_mut().filter(|m| m.next <= t) {
            let at = m.next;
            m.next = (m.count + 1) as f64 * m.period;
            let frame = self.realizer.tick(at);
            self.emit(at, frame.feedback);
            self.hear(at, &frame.poses);
            self.record(at, frame.poses);
        }
        let frame = self.realizer.tick(t);
        self.emit(t, frame.feedback);
        self.hear(t, &frame.poses);
    }

    fn record(&mut self, time: f64, poses: Vec<bml_realizer::engine::CharacterPose>) {
        if let Some(m) = self.motion.as_mut() {
            m.push_frame(time, poses);
        }
    }

    /// Lets the recording hear the sounds of every tick (recorded frames and the ticks between).
    fn hear(&mut self, time: f64, poses: &[bml_realizer::engine::CharacterPose]) {
        if let Some(m) = self.motion.as_mut() {
            m.observe(time, poses);
        }
    }

    fn perform(&mut self, text: &str, source: &str) {
        if self.realizer.now() >= self.until {
            return;
        }
        if self.realizer.perform_bml_from(text, Some(source)).is_err() {
            self.outcome.unparsed += 1;
        }
        let now = self.realizer.now();
        let frame = self.realizer.tick(now);
        self.emit(now, frame.feedback);
        self.hear(now, &frame.poses);
    }

    /// Blocks from standard input, line by line: a line that is not UTF-8 (or too long) costs
    /// only itself.
    fn stdin(&mut self) {
        let mut stream = BlockStream::new();
        let max_line = self.realizer.limits().block_bytes;
        for line in bml_realizer::bml::lines(std::io::stdin().lock(), max_line) {
            match line {
                Ok(text) => {
                    stream.push(&text);
                    stream.push("\n");
                    while let Some(item) = stream.next_item(false) {
                        self.stream(item);
                    }
                }
                Err(bad) => {
                    self.outcome.unparsed += 1;
                    self.realizer.refuse_line(STDIN, &bad);
                }
            }
        }
        while let Some(item) = stream.next_item(true) {
            self.stream(item);
        }
    }

    /// Runs until nothing more will happen (or `--until`, or stdout closed).
    fn run_out(&mut self) {
        while let Some(t) = self.realizer.next_event() {
            if t > self.until || !self.open {
                break;
            }
            self.advance_to(t);
        }
        if self.until.is_finite() {
            self.advance_to(self.until);
        }
    }

    /// The recorded frames, with one last frame at the final time.
    pub fn take_motion(&mut self) -> Option<Recording> {
        let mut m = self.motion.take()?;
        let now = self.realizer.now();
        if m.count == 0 || m.next <= now + 1e-9 {
            let frame = self.realizer.tick(now);
            m.observe(now, &frame.poses);
            m.push_frame(now, frame.poses);
        }
        Some(m)
    }

    /// Writes the --bvh, --frames and --gltf files asked for.
    fn write_recordings(
        &mut self,
        args: &RunArgs,
        avatar: Option<&crate::avatar::Avatars>,
    ) -> Result<(), (u8, String)> {
        let Some(mut m) = self.take_motion() else {
            return Ok(());
        };
        if let Some(path) = &args.bvh {
            m.write_bvh(&self.realizer, path, args.setup.character.as_deref())?;
        }
        if let Some(path) = &args.frames {
            m.write_frames(&self.realizer, path)?;
        }
        if let Some(path) = &args.gltf {
            let asked = args.setup.character.as_deref();
            m.write_gltf(&self.realizer, path, asked, avatar)?;
        }
        if let Some(path) = &args.wav {
            m.write_wav(&self.realizer, path)?;
        }
        Ok(())
    }

    fn stream(&mut self, item: StreamItem) {
        match item {
            StreamItem::Block(text) | StreamItem::Garbage(text) => self.perform(&text, STDIN),
            StreamItem::Advance(s) => self.advance_to(self.realizer.now() + s),
        }
    }
}

/// `bmlr run`.
pub fn run(args: RunArgs) -> ExitCode {
    let (items, realizer, avatar) = match checked(&args) {
        Ok(ok) => ok,
        Err(e) => {
            eprintln!("bmlr run: {e}");
            return ExitCode::from(2);
        }
    };
    if args.realtime {
        return run_realtime(realizer, items, &args);
    }
    let detail = if args.frames_roots {
        frames::Detail::Roots
    } else {
        frames::Detail::Full
    };
    let spool = match args
        .frames
        .as_deref()
        .map(|f| FrameSpool::create(f, detail))
    {
        None => None,
        Some(Ok(spool)) => Some(spool),
        Some(Err(e)) => {
            eprintln!("bmlr run: {e}");
            return ExitCode::from(2);
        }
    };
    let keep = args.bvh.is_some() || args.gltf.is_some();
    let motion = (keep || spool.is_some() || args.wav.is_some())
        .then(|| Recording::streaming(args.fps, spool, keep).placed(realizer.world()));
    let mut run = VirtualRun {
        realizer,
        format: args.format.into(),
        until: args.until.unwrap_or(f64::INFINITY),
        out: Some(std::io::stdout().lock()),
        open: true,
        outcome: Default::default(),
        motion,
        log: None,
    };
    run.items(items);
    report_unfinished(&run.realizer);
    if let Err((code, e)) = run.write_recordings(&args, avatar.as_ref()) {
        eprintln!("bmlr run: {e}");
        return ExitCode::from(code);
    }
    run.outcome.exit("run")
}

/// The items and the realizer of `bmlr run`, or what is wrong with the command line (exit 2).
#[allow(clippy::type_complexity)] // what runs, what runs it, what shows it
fn checked(
    args: &RunArgs,
) -> Result<(Vec<Item>, Realizer, Option<crate::avatar::Avatars>), String> {
    let items = read_items(&args.items)?;
    if args.until.is_some_and(|u| !(u.is_finite() && u >= 0.0)) {
        return Err("--until must be a number of seconds >= 0".into());
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err("--fps must be a positive number".into());
    }
    for (asked, flag) in [
        (args.bvh.is_some(), "--bvh"),
        (args.frames.is_some(), "--frames"),
        (args.gltf.is_some(), "--gltf"),
        (args.wav.is_some(), "--wav"),
    ] {
        if args.realtime && asked {
            return Err(format!(
                "{flag} records on the virtual clock; leave out --realtime"
            ));
        }
    }
    if args.gltf.is_none() && args.avatar.avatar.is_some() {
        return Err("--avatar shows the motion in --gltf OUT.glb; give it too".into());
    }
    if args.setup.nets.is_some() && args.until.is_none() {
        return Err("--nets: nets may go on changing for ever; give --until SECS".into());
    }
    let realizer = args.setup.realizer(args.realtime)?;
    let avatar = match &args.gltf {
        Some(_) => Some(
            args.avatar
                .load(realizer.world(), args.setup.world.as_deref())?,
        ),
        None => None,
    };
    Ok((items, realizer, avatar))
}

/// Tells stderr which blocks did not finish (waiting for activation, persistent behaviour, or
/// the clock stopped).
pub fn report_unfinished(realizer: &Realizer) {
    let mut told = 0;
    for (character, m) in realizer.characters() {
        for (id, status) in m.live_blocks() {
            told += 1;
            if told > MAX_UNFINISHED_TOLD {
                continue;
            }
            let why = match status {
                BlockStatus::Pending => "pre-planned, never activated",
                BlockStatus::Lurking => "still waiting for the blocks it is appended to",
                _ => "still running",
            };
            let who = if character.is_empty() {
                String::new()
            } else {
                format!(" (character {character})")
            };
            eprintln!(
                "bmlr run: block '{id}'{who} did not finish at {:.3} s: {status}, {why}",
                realizer.now()
            );
        }
    }
    if told > MAX_UNFINISHED_TOLD {
        eprintln!(
            "bmlr run: and {} more blocks did not finish at {:.3} s",
            told - MAX_UNFINISHED_TOLD,
            realizer.now()
        );
    }
}

/// Unfinished blocks named one by one at the end of a run (a crowd stopped by `--until` would
/// fill the terminal); the rest are counted.
const MAX_UNFINISHED_TOLD: usize = 10;

/// `bmlr run --realtime`: the wall clock drives the realizer at `--fps`; `+SECS` waits.
fn run_realtime(realizer: Realizer, items: Vec<Item>, args: &RunArgs) -> ExitCode {
    let mut run = RealtimeRun {
        realizer,
        clock: WallClock::new(),
        format: args.format.into(),
        until: args.until.unwrap_or(f64::INFINITY),
        period: 1.0 / args.fps,
        out: std::io::stdout().lock(),
        outcome: Default::default(),
    };
    for item in items {
        let open = match item {
            Item::Text(path, text) => run.perform(&text, &path),
            Item::Advance(s) => run.wait_until(run.clock.now() + s),
            Item::Stdin => run.stdin(),
        };
        if !open {
            return ExitCode::SUCCESS; // stdout is gone
        }
    }
    // until nothing more will happen
    while let Some(t) = run.realizer.next_event() {
        if t > run.until || !run.wait_until(t) {
            break;
        }
    }
    if run.until.is_finite() {
        run.wait_until(run.until);
    }
    report_unfinished(&run.realizer);
    run.outcome.exit("run")
}

/// A realizer on the wall clock that prints its feedback as it goes. Its methods return false
/// when stdout is gone.
struct RealtimeRun {
    realizer: Realizer,
    clock: WallClock,
    format: Format,
    until: f64,
    period: f64,
    out: std::io::StdoutLock<'static>,
    /// Blocks that could not be parsed or scheduled whole.
    outcome: crate::outcome::Outcome,
}

impl RealtimeRun {
    /// A frame now (capped at `--until`), its feedback printed.
    fn tick(&mut self) -> bool {
        let frame = self.realizer.tick(self.clock.now().min(self.until));
        self.outcome.note(&frame.feedback);
        print(&mut self.out, self.format, &frame.feedback)
    }

    /// Frames every period until global time `t` (or `--until`).
    fn wait_until(&mut self, t: f64) -> bool {
        loop {
            let now = self.clock.now().min(self.until);
            if !self.tick() {
                return false;
            }
            if now >= t || now >= self.until {
                return true;
            }
            std::thread::sleep(Duration::from_secs_f64(self.period.min((t - now).max(0.0))));
        }
    }

    /// Performs a block now.
    fn perform(&mut self, text: &str, source: &str) -> bool {
        let open = self.tick();
        let result = self.realizer.perform_bml_from(text, Some(source));
        self.outcome.unparsed += usize::from(result.is_err());
        open
    }

    /// Blocks from standard input: a reader thread hands over lines, and blocks run as soon as
    /// they are complete (a line that is not UTF-8, or too long, costs only itself).
    fn stdin(&mut self) -> bool {
        let (tx, rx) = mpsc::sync_channel(256);
        let max_line = self.realizer.limits().block_bytes;
        std::thread::spawn(move || {
            for line in bml_realizer::bml::lines(std::io::stdin().lock(), max_line) {
                if tx.send(Some(line)).is_err() {
                    return;
                }
            }
            let _ = tx.send(None);
        });
        let mut stream = BlockStream::new();
        let mut finished = false;
        while !finished {
            match rx.recv_timeout(Duration::from_secs_f64(self.period)) {
                Ok(Some(Ok(text))) => {
                    stream.push(&text);
                    stream.push("\n");
                }
                Ok(Some(Err(bad))) => {
                    self.outcome.unparsed += 1;
                    self.realizer.refuse_line(STDIN, &bad);
                }
                Ok(None) | Err(mpsc::RecvTimeoutError::Disconnected) => finished = true,
                Err(mpsc::RecvTimeoutError::Timeout) => {}
            }
            while let Some(item) = stream.next_item(finished) {
                let open = match item {
                    StreamItem::Block(t) | StreamItem::Garbage(t) => self.perform(&t, STDIN),
                    StreamItem::Advance(s) => self.wait_until(self.clock.now() + s),
                };
                if !open {
                    return false;
                }
            }
            if !self.tick() {
                return false;
            }
        }
        true
    }
}

/// `bmlr plan`: submits the files at time 0 without running the clock and prints each block's
/// predicted sync times (block-relative, and global in parentheses) and every warning.
pub fn plan(args: PlanArgs) -> ExitCode {
    let items = match read_items(&args.files) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("bmlr plan: {e}");
            return ExitCode::from(2);
        }
    };
    let mut realizer = match with_assets(
        Realizer::new(),
        args.assets.as_deref(),
        SpeechTiming::default(),
    ) {
        Ok(r) => r
            .with_default_character(args.character)
            .with_limits(args.limits.limits()),
        Err(e) => {
            eprintln!("bmlr plan: --assets {e}");
            return ExitCode::from(2);
        }
    };
    realizer = match with_world(realizer, args.world.as_deref()) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("bmlr plan: --world {e}");
            return ExitCode::from(2);
        }
    };
    let mut feedback = Vec::new();
    let mut blocks = Vec::new();
    let mut outcome = crate::outcome::Outcome::default();
    for item in items {
        match item {
            Item::Text(path, text) => {
                let parsed = realizer.perform_bml_from(&text, Some(&path));
                outcome.unparsed += usize::from(parsed.is_err());
                feedback.extend(realizer.tick(0.0).feedback);
                if let Ok(parsed) = bml_realizer::bml::load(&text) {
                    blocks.push(parsed.block);
                }
            }
            Item::Advance(_) | Item::Stdin => {
                eprintln!("bmlr plan: only files can be planned");
                return ExitCode::from(2);
            }
        }
    }
    if let Some(path) = &args.svg {
        let mut timeline = Timeline::from_feedback(&feedback);
        for b in &blocks {
            timeline.add_constraints(b);
        }
        if let Err(e) = write_svg(path, &timeline) {
            eprintln!("bmlr plan: {e}");
            return ExitCode::from(2);
        }
    }
    let mut out = std::io::stdout().lock();
    for line in plan_lines(&feedback) {
        if writeln!(out, "{line}").is_err() {
            break;
        }
    }
    outcome.note(&feedback);
    outcome.exit("plan")
}

/// The plan report: for each block's last full prediction, a header and one line per sync;
/// warnings as they came.
fn plan_lines(feedback: &[Feedback]) -> Vec<String> {
    let mut lines = Vec::new();
    for fb in feedback {
        match fb {
            Feedback::Prediction(p) if !p.behaviours.is_empty() => {
                for b in &p.blocks {
                    let start = b.global_start.unwrap_or(0.0);
                    lines.push(format!(
                        "{} start {:.3} end {}",
                        b.id,
                        start,
                        b.global_end
                            .map_or_else(|| "unknown".to_string(), |e| format!("{e:.3}"))
                    ));
                    for x in p.behaviours.iter().filter(|x| x.block == b.id) {
                        for (sync, t) in &x.syncs {
                            lines.push(format!(
                                "  {}:{}:{} {:.3} ({:.3})",
                                x.block,
                                x.behaviour,
                                sync,
                                t,
                                start + t
                            ));
                        }
                    }
                }
            }
            Feedback::Warning(w) => {
                lines.push(format!("warning {} {}: {}", w.id, w.kind.as_str(), w.text))
            }
            _ => {}
        }
    }
    lines
}

/// Writes a timeline picture and says so on stderr.
pub fn write_svg(path: &Path, timeline: &Timeline) -> Result<(), String> {
    std::fs::write(path, timeline.to_svg())
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let lanes: usize = timeline.blocks.iter().map(|b| b.lanes.len()).sum();
    eprintln!(
        "wrote {} ({} block{}, {lanes} behaviour{})",
        path.display(),
        timeline.blocks.len(),
        if timeline.blocks.len() == 1 { "" } else { "s" },
        if lanes == 1 { "" } else { "s" }
    );
    Ok(())
}

/// Arguments of `bmlr timeline`.
#[derive(Args)]
pub struct TimelineArgs {
    /// A feedback log (XML or JSON lines).
    log: std::path::PathBuf,
    /// The picture to write.
    #[arg(long, value_name = "OUT.svg", required = true)]
    svg: std::path::PathBuf,
}

/// `bmlr timeline LOG --svg OUT.svg`: draws what a log reports.
pub fn timeline(args: TimelineArgs) -> ExitCode {
    let text = match std::fs::read_to_string(&args.log) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("bmlr timeline: {}: cannot read: {e}", args.log.display());
            return ExitCode::from(2);
        }
    };
    let log = match bml_realizer::feedback::diff::Log::parse(&text) {
        Ok(l) => l,
        Err(e) => {
            eprintln!(
                "bmlr timeline: {}:{}: {}",
                args.log.display(),
                e.line,
                e.error
            );
            return ExitCode::from(2);
        }
    };
    let feedback: Vec<Feedback> = log.messages.into_iter().map(|(_, f)| f).collect();
    match write_svg(&args.svg, &Timeline::from_feedback(&feedback)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bmlr timeline: {e}");
            ExitCode::from(2)
        }
    }
}
