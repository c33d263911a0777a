//! `bmlr run`: feed BML files and streams to a realizer on a virtual clock (or in real time) and
//! print its feedback; the run on the virtual clock (`VirtualRun`) is `bmlr view`'s too.

use std::io::Write;
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::Duration;

use bml_realizer::language::bml::{BlockStream, StreamItem};
use bml_realizer::language::feedback::{BlockStatus, Feedback, Format};
use bml_realizer::realizer::clock::{Clock, WallClock};
use bml_realizer::realizer::Realizer;
use clap::Args;

use crate::record::Recording;
use crate::setup::{read_items, FormatArg, Item, SetupArgs};
use crate::spool::FrameSpool;
use bml_realizer::character::frames;

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

    fn record(&mut self, time: f64, poses: Vec<bml_realizer::engines::interface::CharacterPose>) {
        if let Some(m) = self.motion.as_mut() {
            m.push_frame(time, poses);
        }
    }

    /// Lets the recording hear the sounds of every tick (recorded frames and the ticks between).
    fn hear(&mut self, time: f64, poses: &[bml_realizer::engines::interface::CharacterPose]) {
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
        for line in bml_realizer::language::bml::lines(std::io::stdin().lock(), max_line) {
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
            // (the characters go on looking, each on its own grid of times, up to the end)
            while let Some(t) =
                (self.realizer.next_look()).filter(|&t| t > self.realizer.now() && t <= self.until)
            {
                self.advance_to(t);
            }
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
            for line in bml_realizer::language::bml::lines(std::io::stdin().lock(), max_line) {
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
