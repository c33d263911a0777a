//! `bmlr serve --tcp ADDR`: the realizer port for several clients at once. Each client sends one
//! `<bml>` block per line (or a stream message: a line that is a JSON object, as on `--stdio`); feedback goes to every client (or, with `--per-client`, only to the
//! client whose block it is about). A malformed line gets a PARSING_FAILURE warning sent to its
//! sender only; a client that disconnects disturbs neither the others nor the plan.
//!
//! Threads: one accepts connections, one reads and checks each client's lines (parsing and
//! validation need no realizer, so a large block is read on its sender's thread), one writes to
//! each client; the main thread owns the realizer, schedules the checked blocks, ticks it on the
//! wall clock and routes feedback, sending what is due at least once a frame even while a queue
//! of blocks waits. Every queue
//! between them is bounded: the readers wait when the realizer is behind (the clients' sockets
//! then fill: backpressure), and a client whose unread feedback passes [`UNREAD_LIMIT`] lines is
//! disconnected with a line on stderr, so that it cannot grow the server or slow the others.

use std::collections::HashMap;
use std::io::{BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::Arc;
use std::time::Duration;

use bml_realizer::language::bml::{self, Checked, Limits};
use bml_realizer::language::feedback::{Feedback, Format, KnownWarning, WarningFeedback};
use bml_realizer::realizer::clock::{Clock, WallClock};
use bml_realizer::realizer::{Realizer, NO_ID};

use crate::live::LiveView;

type Client = u64;

/// Lines of feedback a client may leave unread before it is disconnected.
pub const UNREAD_LIMIT: usize = 50_000;

/// Lines read from all clients that wait for the realizer.
const PENDING_LINES: usize = 1_024;

/// A connected client: its feedback queue and its socket (to cut it off).
struct Conn {
    /// Feedback for this client, encoded by its writer thread (not the realizer's).
    tx: SyncSender<Arc<Feedback>>,
    socket: TcpStream,
}

enum Event {
    Connected(Client, Conn),
    /// A line read and checked on the client's thread.
    Block(Client, Box<Checked>),
    /// A stream message (a line that is a JSON object: `Realizer::stream_message`).
    Stream(Client, String),
    /// A line that is not UTF-8 or too long: it costs only itself.
    BadLine(Client, bml::BadLine),
    Disconnected(Client),
}

/// Accepts connections and starts a reader and a writer thread for each.
fn accept(listener: TcpListener, events: SyncSender<Event>, limits: Limits) {
    let mut next: Client = 0;
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let _ = stream.set_nodelay(true);
        let Ok(write_half) = stream.try_clone() else {
            continue;
        };
        let client = next;
        next += 1;
        let Ok(socket) = stream.try_clone() else {
            continue;
        };
        let (tx, rx) = mpsc::sync_channel::<Arc<Feedback>>(UNREAD_LIMIT);
        std::thread::spawn(move || write_lines(write_half, rx));
        if events
            .send(Event::Connected(client, Conn { tx, socket }))
            .is_err()
        {
            return;
        }
        let events = events.clone();
        std::thread::spawn(move || {
            for line in bml::lines(BufReader::new(stream), limits.block_bytes) {
                let event = match line {
                    Ok(line) if line.trim().is_empty() => continue,
                    Ok(line) if line.trim_start().starts_with('{') => Event::Stream(client, line),
                    Ok(line) => Event::Block(client, Box::new(Checked::new(&line, &limits))),
                    Err(bad) => Event::BadLine(client, bad),
                };
                if events.send(event).is_err() {
                    return;
                }
            }
            let _ = events.send(Event::Disconnected(client));
        });
    }
}

fn write_lines(mut stream: TcpStream, feedback: Receiver<Arc<Feedback>>) {
    while let Ok(first) = feedback.recv() {
        let mut batch = String::new();
        for fb in std::iter::once(first).chain(feedback.try_iter()) {
            batch.push_str(&Format::Xml.encode(&fb));
            batch.push('\n');
        }
        if stream.write_all(batch.as_bytes()).is_err() {
            return; // the reader sees the disconnect
        }
    }
}

/// The block a message is about.
fn block_of(fb: &Feedback) -> Option<&str> {
    match fb {
        Feedback::BlockProgress(p) => Some(&p.block),
        Feedback::SyncPointProgress(p) => Some(&p.block),
        Feedback::Prediction(p) => p.blocks.first().map(|b| b.id.as_str()),
        Feedback::Warning(w) => Some(w.id.split(':').next().unwrap_or(&w.id)),
        Feedback::World(_) => None,
    }
}

/// `bmlr serve --tcp ADDR`.
pub fn serve(
    addr: &str,
    per_client: bool,
    fps: f64,
    realizer: Realizer,
    view: Option<LiveView>,
    frames: Option<crate::live_frames::LiveFrames>,
) -> ExitCode {
    let listener = match TcpListener::bind(addr) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("bmlr serve: cannot listen on {addr}: {e}");
            return ExitCode::from(2);
        }
    };
    match listener.local_addr() {
        Ok(a) => eprintln!("bmlr serve: listening on {a}"),
        Err(e) => {
            eprintln!("bmlr serve: {e}");
            return ExitCode::from(2);
        }
    }
    let (tx, events) = mpsc::sync_channel(PENDING_LINES);
    let limits = *realizer.limits();
    std::thread::spawn(move || accept(listener, tx, limits));
    let mut server = Server::new(realizer, per_client, fps);
    server.view = view;
    server.frames = frames;
    let zero = crate::live_frames::posix_zero(&server.clock);
    if let Some(f) = server.frames.as_mut() {
        f.start_clock(Some(zero));
    }
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        let _ = signal_hook::flag::register(signal, stop.clone());
    }
    let frames = server.run(events, &stop);
    match frames.map(crate::live_frames::LiveFrames::finish) {
        Some(Err(e)) => {
            eprintln!("bmlr serve: --frames {e}");
            ExitCode::from(2)
        }
        _ => ExitCode::SUCCESS,
    }
}

/// Feedback to send, with the client it is for (`None`: by the routing rule).
type Routed = Vec<(Option<Client>, Feedback)>;

/// The realizer's side of the port: the realizer, the clients and who sent which block.
struct Server {
    realizer: Realizer,
    clock: WallClock,
    period: Duration,
    per_client: bool,
    clients: HashMap<Client, Conn>,
    /// Per-client routing: block id → the client that sent it (until the block ends).
    owner: HashMap<String, Client>,
    /// The live view (`--view`), told every frame and every message.
    view: Option<LiveView>,
    /// The frames file (`--frames`), told every frame.
    frames: Option<crate::live_frames::LiveFrames>,
}

impl Server {
    fn new(realizer: Realizer, per_client: bool, fps: f64) -> Self {
        Server {
            realizer,
            clock: WallClock::new(),
            period: Duration::from_secs_f64(1.0 / fps),
            per_client,
            clients: HashMap::new(),
            owner: HashMap::new(),
            view: None,
            frames: None,
        }
    }

    /// Serves until every reader is gone: each frame, the events that arrived (at most a
    /// queue's worth, so that a flood cannot hold the frame up), the feedback of each sent as
    /// soon as it is handled (encoding is the writers' work), and the clock brought up to date
    /// whenever a frame's time has passed.
    /// Returns the frames file to finish when told to stop.
    fn run(
        mut self,
        events: Receiver<Event>,
        stop: &AtomicBool,
    ) -> Option<crate::live_frames::LiveFrames> {
        loop {
            if stop.load(Ordering::SeqCst) {
                return self.frames;
            }
            match events.recv_timeout(self.period) {
                Ok(first) => {
                    let mut frame_start = self.clock.now();
                    let pending = events.try_iter().take(PENDING_LINES);
                    for event in std::iter::once(first).chain(pending) {
                        let mut routed = Routed::new();
                        if self.clock.now() - frame_start >= self.period.as_secs_f64() {
                            self.tick(&mut routed);
                            frame_start = self.clock.now();
                        }
                        self.handle(event, &mut routed);
                        self.send_all(routed);
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => return self.frames,
            }
            let mut routed = Routed::new();
            self.tick(&mut routed);
            self.send_all(routed);
        }
    }

    /// Brings the realizer up to the wall clock; its feedback goes by the routing rule.
    fn tick(&mut self, routed: &mut Routed) {
        let now = self.clock.now();
        let frame = self.realizer.tick(now);
        if let Some(view) = self.view.as_mut() {
            view.frame(now, &frame.poses);
        }
        if let Some(f) = self.frames.as_mut() {
            f.push(frame.time, &frame.poses);
        }
        routed.extend(frame.feedback.into_iter().map(|f| (None, f)));
    }

    fn handle(&mut self, event: Event, routed: &mut Routed) {
        match event {
            Event::Connected(c, conn) => {
                self.clients.insert(c, conn);
            }
            Event::Disconnected(c) => {
                self.clients.remove(&c);
            }
            Event::BadLine(c, bad) => routed.push((
                Some(c),
                Feedback::Warning(WarningFeedback {
                    id: NO_ID.into(),
                    kind: KnownWarning::ParsingFailure.into(),
                    character_id: None,
                    text: format!("line {}: {}", bad.line, bad.reason),
                }),
            )),
            Event::Block(c, checked) => self.submit(c, *checked, routed),
            Event::Stream(c, line) => {
                self.tick(routed);
                let _ = (self.realizer).stream_message(&format!("client {c}"), &line);
                self.answer(c, routed);
            }
        }
    }

    /// Schedules and starts a block from client `c`. What the submission produces right away
    /// (its start, or a warning) is the sender's: warnings go to it alone.
    fn submit(&mut self, c: Client, checked: Checked, routed: &mut Routed) {
        // the clock up to date first: the block is planned at this time
        self.tick(routed);
        let block = checked
            .block
            .as_ref()
            .filter(|_| checked.is_valid())
            .map(|b| (b.id.to_string(), b.character_id.clone()));
        if let Some((id, _)) = &block {
            self.owner.entry(id.clone()).or_insert(c);
        }
        let _ = self.realizer.perform_checked(checked, None);
        if let Some((id, character)) = block {
            let live = self
                .realizer
                .character(character.as_deref().unwrap_or(""))
                .and_then(|m| m.status(&id))
                .is_some();
            if !live {
                self.owner.remove(&id); // rejected: it will never end
            }
        }
        self.answer(c, routed);
    }

    /// Routes what client `c`'s line produced right away: warnings to it alone.
    fn answer(&mut self, c: Client, routed: &mut Routed) {
        let frame = self.realizer.tick(self.clock.now());
        routed.extend(frame.feedback.into_iter().map(|f| {
            let to = matches!(f, Feedback::Warning(_)).then_some(c);
            (to, f)
        }));
    }

    /// Sends each message to its client(s).
    fn send_all(&mut self, routed: Routed) {
        for (to, fb) in routed {
            if let Some(view) = self.view.as_mut() {
                view.feedback(self.realizer.now(), &fb);
            }
            let block = block_of(&fb).map(str::to_string);
            let to = match (self.per_client, to) {
                (_, Some(c)) => Some(c),
                (true, None) => match block.as_ref().and_then(|b| self.owner.get(b)) {
                    Some(&c) => Some(c),
                    None => continue, // nobody's block (its sender left)
                },
                (false, None) => None,
            };
            let ended = matches!(&fb, Feedback::BlockProgress(p) if p.sync == "end");
            self.send(to, Arc::new(fb));
            if let (true, Some(b)) = (ended, &block) {
                self.owner.remove(b);
            }
        }
    }

    /// Queues `fb` for client `to` (or every client); a client whose queue is full has left
    /// too much unread and is cut off.
    fn send(&mut self, to: Option<Client>, fb: Arc<Feedback>) {
        let deliver = |c: &Client, conn: &Conn, fb: Arc<Feedback>| match conn.tx.try_send(fb) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                // (stderr may be closed: that is no reason to stop serving)
                let _ = writeln!(
                    std::io::stderr(),
                    "bmlr serve: client {c} left {UNREAD_LIMIT} lines of feedback unread; disconnected"
                );
                let _ = conn.socket.shutdown(std::net::Shutdown::Both);
                false
            }
            Err(TrySendError::Disconnected(_)) => false,
        };
        match to {
            Some(c) => {
                if let Some(conn) = self.clients.get(&c) {
                    if !deliver(&c, conn, fb) {
                        self.clients.remove(&c);
                    }
                }
            }
            None => self.clients.retain(|c, conn| deliver(c, conn, fb.clone())),
        }
    }
}
