//! `bmlr serve`: the realizer as a port on the wall clock. `--stdio` is here (one `<bml>` block
//! or stream message per input line, one feedback element per output line); `--tcp` is
//! `tcp.rs`, the brokers `serve_broker.rs` and `brokered.rs`.

use std::io::Write;
use std::process::ExitCode;
use std::sync::mpsc;
use std::time::Duration;

use bml_realizer::engines::assets::Assets;
use bml_realizer::engines::registry_with;
use bml_realizer::language::bml::{BadLine, Checked};
use bml_realizer::language::feedback::{Feedback, Format};
use bml_realizer::planning::timing::{DefaultTimingModels, SpeechTiming};
use bml_realizer::realizer::clock::{Clock, WallClock};
use bml_realizer::realizer::Realizer;
use clap::Args;

/// Arguments of `bmlr serve`.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("port").required(true).args(["stdio", "tcp", "mqtt", "stomp"])))]
pub struct ServeArgs {
    /// Serve on stdin/stdout.
    #[arg(long, conflicts_with_all = ["tcp", "mqtt", "stomp"])]
    pub(crate) stdio: bool,
    /// Serve several clients on a TCP address (e.g. 127.0.0.1:7700; port 0 picks one, printed
    /// on stderr).
    #[arg(long, value_name = "ADDR")]
    pub(crate) tcp: Option<String>,
    /// Serve on an MQTT broker (mqtt://HOST[:PORT]): blocks in on PREFIX/CHARACTER/bml, feedback
    /// out on PREFIX/CHARACTER/feedback, presence on PREFIX/realizers/NAME (docs/broker.md).
    #[arg(long, value_name = "URL", conflicts_with_all = ["tcp", "stomp"])]
    pub(crate) mqtt: Option<String>,
    /// Serve on a STOMP 1.2 broker (stomp://[USER:PASS@]HOST[:PORT]; ActiveMQ, RabbitMQ):
    /// AsapRealizer's or Greta's topics (--flavour), docs/broker.md.
    #[arg(long, value_name = "URL", conflicts_with = "tcp")]
    pub(crate) stomp: Option<String>,
    /// With --stomp: whose conventions: asap (asap.bml.request -> asap.bml.feedback, the
    /// default) or greta (greta.BML -> greta.output.feedback.BML callbacks).
    #[arg(long, value_enum)]
    pub(crate) flavour: Option<Flavour>,
    /// With --stomp: the topics of blocks in and feedback out (IN,OUT), instead of the
    /// flavour's (AsapRealizer's adapters take other topics too).
    #[arg(long, value_name = "IN,OUT", value_delimiter = ',')]
    pub(crate) topics: Vec<String>,
    /// With --mqtt or --stomp: the topics' first level(s) (bml by default).
    #[arg(long, value_name = "PREFIX")]
    pub(crate) prefix: Option<String>,
    /// With --mqtt or --stomp: this realizer's name on the broker (its presence topic and
    /// client id; bmlr-PID by default).
    #[arg(long, value_name = "NAME")]
    pub(crate) name: Option<String>,
    /// With --mqtt or --stomp: serve only these characters (comma-separated; '_' is the
    /// default character); all by default.
    #[arg(long, value_name = "A,B", value_delimiter = ',')]
    pub(crate) characters: Vec<String>,
    /// With --mqtt or --stomp: the feedback's encoding (xml by default).
    #[arg(long, value_enum)]
    pub(crate) format: Option<crate::setup::FormatArg>,
    /// With --mqtt: speak ipaaca as ipaacar does on these channels, one per character
    /// ('default' is the default character): `bml` messages and `realizerRequest` IUs in,
    /// `bmlfeedback` messages out (docs/broker.md).
    #[arg(long, value_name = "CH,CH2", value_delimiter = ',')]
    pub(crate) ipaaca: Vec<String>,
    /// With --mqtt or --stomp: blocks that may wait for one character; beyond, the newest are
    /// dropped and its feedback says how many (1 to 1 000 000; 10 000 by default).
    #[arg(long, value_name = "N")]
    pub(crate) queue_limit: Option<usize>,
    /// With --mqtt or --stomp: the side of the square cells the shared world is cut into
    /// (metres, 1 to 1 000 000; 10 by default): characters' states go to their cell's topic,
    /// and this realizer listens to the cells near its own characters. 0: one cell, every
    /// realizer hears every state (everyone to everyone).
    #[arg(long, value_name = "METRES")]
    pub(crate) cell: Option<f32>,
    /// With --mqtt or --stomp: stop after this many seconds.
    #[arg(long, value_name = "SECS")]
    pub(crate) until: Option<f64>,
    /// Write the frames of the characters served as JSON lines as they happen (docs/cli.md,
    /// "Frames"); flushed at --until and on SIGTERM.
    #[arg(long, value_name = "OUT.jsonl")]
    pub(crate) frames: Option<std::path::PathBuf>,
    /// With --frames: each frame carries only where each character stands (its root) and its
    /// foot contacts, for crowds too large to keep every joint.
    #[arg(long, requires = "frames")]
    pub(crate) frames_roots: bool,
    /// With --tcp: also serve the viewer's page on this loopback address (e.g. 127.0.0.1:8080;
    /// port 0 picks one, printed on stderr); it shows the character move as blocks arrive.
    #[arg(long, value_name = "ADDR", requires = "tcp")]
    pub(crate) view: Option<String>,
    /// With --tcp: send each client only the feedback about its own blocks.
    #[arg(long, requires = "tcp")]
    pub(crate) per_client: bool,
    /// Frames per second of the engine loop.
    #[arg(long, value_name = "HZ", default_value_t = 60.0)]
    pub(crate) fps: f64,
    /// Characters stand still between behaviours: no breathing, no weight shift.
    #[arg(long)]
    pub(crate) no_idle: bool,
    /// The voice that says speech: the built-in TTS, or flite (Debian package `flite`).
    #[arg(long, value_enum, default_value = "builtin")]
    pub(crate) tts: crate::setup::TtsArg,
    /// Speech may change its rate to meet its constraints (an incremental TTS).
    #[arg(long)]
    pub(crate) retimable_speech: bool,
    /// A directory of motion data adding to the embedded defaults (see `bmlr run --assets`).
    #[arg(long, value_name = "DIR")]
    pub(crate) assets: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub(crate) limits: crate::setup::LimitArgs,
    /// A world file (JSON): named points and points moving along keyed paths, as targets of
    /// gaze, pointing and headDirectionShift, added to the built-in scene.
    #[arg(long, value_name = "WORLD.json")]
    pub(crate) world: Option<std::path::PathBuf>,
    /// Characters see; perception feedback reports what each sees when it changes.
    #[arg(long)]
    pub(crate) perception: bool,
    /// PaT-Nets (JSON, docs/nets.md) run with the behaviours; their transitions and the
    /// world variables' changes are reported.
    #[arg(long, value_name = "NETS.json")]
    pub(crate) nets: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub(crate) avatar: crate::avatar::AvatarArgs,
}

/// `bmlr serve --stdio` (runs until stdin closes and nothing more is scheduled) or `--tcp`.
pub fn serve(args: ServeArgs) -> ExitCode {
    match start(&args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bmlr serve: {e}");
            ExitCode::from(2)
        }
    }
}

/// Checks the flags, makes the realizer and serves it on the port asked for; an `Err` is a
/// sentence about the flag at fault (exit code 2).
fn start(args: &ServeArgs) -> Result<ExitCode, String> {
    check_flags(args)?;
    let realizer = realizer(args)?;
    if args.avatar.avatar.is_some() && args.view.is_none() {
        return Err("--avatar shows the characters in the live view; give --view too".into());
    }
    let avatars = (args.view.is_some())
        .then(|| (args.avatar).load(realizer.world(), args.world.as_deref()))
        .transpose()?;
    if let Some(addr) = &args.tcp {
        let view = match (args.view.as_deref())
            .zip(avatars.as_ref())
            .map(|(v, a)| crate::live::LiveView::start(v, realizer.world(), a))
        {
            Some(Err(e)) => return Err(format!("--view {e}")),
            view => view.and_then(Result::ok),
        };
        let frames = live_frames(args, &realizer).map_err(|e| format!("--frames {e}"))?;
        return Ok(crate::tcp::serve(
            addr,
            args.per_client,
            args.fps,
            realizer,
            view,
            frames,
        ));
    }
    if args.mqtt.is_some() || args.stomp.is_some() {
        let m = crate::serve_broker::brokered(args, &realizer)?;
        return Ok(crate::brokered::serve(m, realizer));
    }
    let frames = live_frames(args, &realizer).map_err(|e| format!("--frames {e}"))?;
    Ok(serve_stdio(
        realizer,
        Duration::from_secs_f64(1.0 / args.fps),
        frames,
    ))
}

/// The flags' values and combinations clap does not check.
fn check_flags(args: &ServeArgs) -> Result<(), String> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err("--fps must be a positive number".into());
    }
    if (args.queue_limit).is_some_and(|n| !(1..=crate::brokered::MAX_QUEUE_LIMIT).contains(&n)) {
        return Err(format!(
            "--queue-limit must be from 1 to {}",
            crate::brokered::MAX_QUEUE_LIMIT
        ));
    }
    // (clap's `requires` is not checked beside the port group: said here)
    let brokered = args.mqtt.is_some() || args.stomp.is_some();
    let (mqtt, stomp, tcp) = (
        args.mqtt.is_some(),
        args.stomp.is_some(),
        args.tcp.is_some(),
    );
    let either = "--mqtt or --stomp";
    let misplaced = [
        ("--prefix", args.prefix.is_some(), brokered, either),
        ("--name", args.name.is_some(), brokered, either),
        (
            "--characters",
            !args.characters.is_empty(),
            brokered,
            either,
        ),
        ("--format", args.format.is_some(), brokered, either),
        (
            "--queue-limit",
            args.queue_limit.is_some(),
            brokered,
            either,
        ),
        ("--cell", args.cell.is_some(), brokered, either),
        ("--until", args.until.is_some(), brokered, either),
        ("--ipaaca", !args.ipaaca.is_empty(), mqtt, "--mqtt"),
        ("--flavour", args.flavour.is_some(), stomp, "--stomp"),
        ("--topics", !args.topics.is_empty(), stomp, "--stomp"),
        ("--view", args.view.is_some(), tcp, "--tcp"),
        ("--per-client", args.per_client, tcp, "--tcp"),
    ];
    match misplaced.iter().find(|m| m.1 && !m.2) {
        Some((flag, _, _, port)) => Err(format!("{flag} goes with {port}")),
        None => Ok(()),
    }
}

/// The realizer the flags describe: its voice, motion data, world, sight and nets.
fn realizer(args: &ServeArgs) -> Result<Realizer, String> {
    let voice = args.tts.timing(None).map_err(|e| format!("--tts: {e}"))?;
    let speech = SpeechTiming {
        retimable: args.retimable_speech,
        ..voice
    };
    let assets = (args.assets.as_deref().map(Assets::from_dir).transpose())
        .map_err(|e| format!("--assets {e}"))?
        .unwrap_or_default();
    let realizer = Realizer::new()
        .with_engines(move || registry_with(DefaultTimingModels { speech }, &assets))
        .with_posix_time(true)
        .with_idle(!args.no_idle)
        .with_limits(args.limits.limits());
    let realizer = crate::setup::with_world(realizer, args.world.as_deref())
        .map_err(|e| format!("--world {e}"))?;
    crate::setup::with_sight_and_nets(realizer, args.perception, args.nets.as_deref())
}

/// The frames file asked for, started.
pub(crate) fn live_frames(
    args: &ServeArgs,
    realizer: &Realizer,
) -> Result<Option<crate::live_frames::LiveFrames>, String> {
    let Some(path) = &args.frames else {
        return Ok(None);
    };
    let ids = crate::live_frames::shown(&args.characters, realizer);
    let detail = match args.frames_roots {
        true => bml_realizer::character::frames::Detail::Roots,
        false => bml_realizer::character::frames::Detail::Full,
    };
    crate::live_frames::LiveFrames::create(path, ids, realizer, args.fps, detail).map(Some)
}

/// Whose conventions a STOMP realizer follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Flavour {
    /// AsapRealizer's ActiveMQ adapters.
    Asap,
    /// Greta's ActiveMQ components.
    Greta,
}

/// A line of `serve --stdio`'s input.
enum Line {
    /// A `<bml>` block, read and checked.
    Block(Box<Checked>),
    /// A stream message (JSON).
    Stream(String),
    /// A line that is not UTF-8 or too long.
    Bad(BadLine),
}

/// `bmlr serve --stdio`: one block per line, read and checked on a thread of its own (parsing
/// and validation need no realizer), scheduled and played on this one; what is due is written
/// out at least once a frame, also while a queue of blocks waits.
fn serve_stdio(
    mut realizer: Realizer,
    period: Duration,
    mut frames: Option<crate::live_frames::LiveFrames>,
) -> ExitCode {
    let clock = WallClock::new();
    if let Some(f) = frames.as_mut() {
        f.start_clock(Some(crate::live_frames::posix_zero(&clock)));
    }
    let rx = read_stdin(*realizer.limits());
    let mut out = std::io::stdout().lock();
    let mut write = |feedback: Vec<Feedback>| -> bool {
        feedback
            .iter()
            .all(|fb| writeln!(out, "{}", Format::Xml.encode(fb)).is_ok())
            && out.flush().is_ok()
    };
    let tick = |realizer: &mut Realizer, frames: &mut Option<crate::live_frames::LiveFrames>| {
        let frame = realizer.tick(clock.now());
        if let Some(f) = frames.as_mut() {
            f.push(frame.time, &frame.poses);
        }
        frame.feedback
    };
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    if frames.is_some() {
        let _ = signal_hook::flag::register(signal_hook::consts::SIGTERM, stop.clone());
    }
    let mut open = true;
    let code = 'serve: loop {
        let items = arrived(&rx, period, &mut open);
        // bring the clock up to date before blocks arrive (they are planned at this time)
        let mut feedback = tick(&mut realizer, &mut frames);
        let mut frame_start = clock.now();
        for item in items {
            match item {
                Line::Block(checked) => {
                    let _ = realizer.perform_checked(*checked, Some("<stdin>"));
                }
                Line::Stream(text) => {
                    let _ = realizer.stream_message("<stdin>", &text);
                }
                Line::Bad(bad) => realizer.refuse_line("<stdin>", &bad),
            }
            if clock.now() - frame_start >= period.as_secs_f64() {
                feedback.extend(tick(&mut realizer, &mut frames));
                if !write(std::mem::take(&mut feedback)) {
                    break 'serve ExitCode::SUCCESS;
                }
                frame_start = clock.now();
            }
        }
        feedback.extend(tick(&mut realizer, &mut frames));
        if !write(feedback) {
            break 'serve ExitCode::SUCCESS;
        }
        if (!open && realizer.next_event().is_none())
            || stop.load(std::sync::atomic::Ordering::SeqCst)
        {
            break 'serve ExitCode::SUCCESS;
        }
    };
    match frames.map(crate::live_frames::LiveFrames::finish) {
        Some(Err(e)) => {
            eprintln!("bmlr serve: --frames {e}");
            ExitCode::from(2)
        }
        _ => code,
    }
}

/// A thread reading standard input line by line into what [`serve_stdio`] serves; `None` at
/// its end. The channel is bounded: the reader waits while the realizer is behind, and the pipe
/// fills (backpressure).
fn read_stdin(limits: bml_realizer::language::bml::Limits) -> mpsc::Receiver<Option<Line>> {
    let (tx, rx) = mpsc::sync_channel::<Option<Line>>(256);
    std::thread::spawn(move || {
        // a line that is not UTF-8 or too long costs only itself
        for line in bml_realizer::language::bml::lines(std::io::stdin().lock(), limits.block_bytes)
        {
            let item = match line {
                Ok(text) if text.trim().is_empty() => continue,
                // a live port has no use for clock advances: time passes by itself
                Ok(text) if bml_realizer::language::bml::advance(text.trim()).is_some() => continue,
                // a stream message (`Realizer::stream_message`): a JSON object
                Ok(text) if text.trim_start().starts_with('{') => Line::Stream(text),
                Ok(text) => Line::Block(Box::new(Checked::new(&text, &limits))),
                Err(bad) => Line::Bad(bad),
            };
            if tx.send(Some(item)).is_err() {
                return;
            }
        }
        let _ = tx.send(None);
    });
    rx
}

/// What has arrived within `period` (waiting for the first line at most that long), and
/// whatever else is there; `open` turns false at the input's end, after which it only waits.
fn arrived(rx: &mpsc::Receiver<Option<Line>>, period: Duration, open: &mut bool) -> Vec<Line> {
    let mut items = Vec::new();
    if !*open {
        std::thread::sleep(period);
        return items;
    }
    match rx.recv_timeout(period) {
        Ok(Some(item)) => items.push(item),
        Ok(None) | Err(mpsc::RecvTimeoutError::Disconnected) => *open = false,
        Err(mpsc::RecvTimeoutError::Timeout) => {}
    }
    for more in rx.try_iter() {
        match more {
            Some(item) => items.push(item),
            None => *open = false,
        }
    }
    items
}
