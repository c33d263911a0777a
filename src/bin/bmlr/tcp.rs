//! `bmlr serve --tcp ADDR`: the realizer port for several clients at once. Each client sends one
//! `<bml>` block per line; feedback goes to every client (or, with `--per-client`, only to the
//! client whose block it is about). A malformed line gets a PARSING_FAILURE warning sent to its
//! sender only; a client that disconnects disturbs neither the others nor the plan.
//!
//! Threads: one accepts connections, one reads each client's lines, one writes to each client; the
//! main thread owns the realizer, ticks it on the wall clock and routes feedback. Every queue
//! between them is bounded: the readers wait when the realizer is behind (the clients' sockets
//! then fill: backpressure), and a client whose unread feedback passes [`UNREAD_LIMIT`] lines is
//! disconnected with a line on stderr, so that it cannot grow the server or slow the others.

use std::collections::HashMap;
use std::io::{BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::process::ExitCode;
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::time::Duration;

use bml_realizer::bml;
use bml_realizer::clock::{Clock, WallClock};
use bml_realizer::feedback::{Feedback, Format, KnownWarning, WarningFeedback};
use bml_realizer::realizer::{Realizer, NO_ID};

type Client = u64;

/// Lines of feedback a client may leave unread before it is disconnected.
pub const UNREAD_LIMIT: usize = 50_000;

/// Lines read from all clients that wait for the realizer.
const PENDING_LINES: usize = 1_024;

/// A connected client: its feedback queue and its socket (to cut it off).
struct Conn {
    tx: SyncSender<String>,
    socket: TcpStream,
}

enum Event {
    Connected(Client, Conn),
    Line(Client, String),
    /// A line that is not UTF-8 or too long: it costs only itself.
    BadLine(Client, bml::BadLine),
    Disconnected(Client),
}

/// Accepts connections and starts a reader and a writer thread for each.
fn accept(listener: TcpListener, events: SyncSender<Event>, max_line: usize) {
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
        let (tx, rx) = mpsc::sync_channel::<String>(UNREAD_LIMIT);
        std::thread::spawn(move || write_lines(write_half, rx));
        if events
            .send(Event::Connected(client, Conn { tx, socket }))
            .is_err()
        {
            return;
        }
        let events = events.clone();
        std::thread::spawn(move || {
            for line in bml::lines(BufReader::new(stream), max_line) {
                let event = match line {
                    Ok(line) => Event::Line(client, line),
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

fn write_lines(mut stream: TcpStream, lines: Receiver<String>) {
    while let Ok(first) = lines.recv() {
        let mut batch = first;
        batch.push('\n');
        for more in lines.try_iter() {
            batch.push_str(&more);
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
    }
}

/// `bmlr serve --tcp ADDR`.
pub fn serve(addr: &str, per_client: bool, fps: f64, realizer: Realizer) -> ExitCode {
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
    let max_line = realizer.limits().block_bytes;
    std::thread::spawn(move || accept(listener, tx, max_line));
    run(realizer, events, per_client, fps);
    ExitCode::SUCCESS
}

fn run(mut realizer: Realizer, events: Receiver<Event>, per_client: bool, fps: f64) {
    let clock = WallClock::new();
    let period = Duration::from_secs_f64(1.0 / fps);
    let mut clients: HashMap<Client, Conn> = HashMap::new();
    // per-client routing: block id → the client that sent it (until the block ends)
    let mut owner: HashMap<String, Client> = HashMap::new();
    let send = |clients: &mut HashMap<Client, Conn>, to: Option<Client>, line: String| {
        let cut = |c: &Client, conn: &Conn| {
            // (stderr may be closed: that is no reason to stop serving)
            let _ = writeln!(
                std::io::stderr(),
                "bmlr serve: client {c} left {UNREAD_LIMIT} lines of feedback unread; disconnected"
            );
            let _ = conn.socket.shutdown(std::net::Shutdown::Both);
        };
        let deliver = |c: &Client, conn: &Conn, line: String| match conn.tx.try_send(line) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                cut(c, conn);
                false
            }
            Err(TrySendError::Disconnected(_)) => false,
        };
        match to {
            Some(c) => {
                if let Some(conn) = clients.get(&c) {
                    if !deliver(&c, conn, line) {
                        clients.remove(&c);
                    }
                }
            }
            None => clients.retain(|c, conn| deliver(c, conn, line.clone())),
        }
    };
    loop {
        let mut routed: Vec<(Option<Client>, Feedback)> = Vec::new();
        match events.recv_timeout(period) {
            Ok(first) => {
                let frame = realizer.tick(clock.now());
                routed.extend(frame.feedback.into_iter().map(|f| (None, f)));
                // at most a queue's worth per frame, so that a flood cannot hold the frame up
                let pending = events.try_iter().take(PENDING_LINES);
                for event in std::iter::once(first).chain(pending) {
                    match event {
                        Event::Connected(c, conn) => {
                            clients.insert(c, conn);
                        }
                        Event::Disconnected(c) => {
                            clients.remove(&c);
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
                        Event::Line(c, line) => {
                            if line.trim().is_empty() {
                                continue;
                            }
                            let (block, diagnostics) = bml::check_with(&line, realizer.limits());
                            let errors: Vec<String> = diagnostics
                                .iter()
                                .filter(|d| d.is_error())
                                .map(|d| format!("{}:{}: {}", d.pos.line, d.pos.col, d.message))
                                .collect();
                            if !errors.is_empty() || block.is_none() {
                                // the sender's problem: only the sender hears of it
                                let id = block
                                    .map(|b| b.id.to_string())
                                    .or_else(|| bml::root_id(&line))
                                    .filter(|id| !id.is_empty())
                                    .unwrap_or_else(|| NO_ID.to_string());
                                routed.push((
                                    Some(c),
                                    Feedback::Warning(WarningFeedback {
                                        id,
                                        kind: KnownWarning::ParsingFailure.into(),
                                        character_id: None,
                                        text: errors.join("; "),
                                    }),
                                ));
                                continue;
                            }
                            let Some(block) = block else { continue };
                            owner.entry(block.id.to_string()).or_insert(c);
                            let _ = realizer.perform_bml(&line);
                            let live = realizer
                                .character(block.character_id.as_deref().unwrap_or(""))
                                .and_then(|m| m.status(&block.id))
                                .is_some();
                            if !live {
                                owner.remove(block.id.as_str()); // rejected: it will never end
                            }
                            let frame = realizer.tick(clock.now());
                            // what this submission produced right away concerns its sender
                            routed.extend(frame.feedback.into_iter().map(|f| {
                                let to = match &f {
                                    Feedback::Warning(_) => Some(c),
                                    _ => None,
                                };
                                (to, f)
                            }));
                        }
                    }
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => return,
        }
        let frame = realizer.tick(clock.now());
        routed.extend(frame.feedback.into_iter().map(|f| (None, f)));
        for (to, fb) in routed {
            let line = Format::Xml.encode(&fb);
            let block = block_of(&fb).map(str::to_string);
            let to = match (per_client, to) {
                (_, Some(c)) => Some(c),
                (true, None) => match block.as_ref().and_then(|b| owner.get(b)) {
                    Some(&c) => Some(c),
                    None => continue, // nobody's block (its sender left)
                },
                (false, None) => None,
            };
            send(&mut clients, to, line);
            if let (Feedback::BlockProgress(p), Some(b)) = (&fb, &block) {
                if p.sync == "end" {
                    owner.remove(b);
                }
            }
        }
    }
}
