//! A link to a STOMP 1.2 broker that keeps itself connected: a thread of its own reads the
//! connection (messages into a bounded inbox — it waits when the inbox is full, and TCP holds
//! the broker back), sends heart-beats when the link has been quiet and notices a broker that
//! has gone quiet (three missed heart-beats) or away; it then connects again with a doubling
//! wait (0.1 s up to 2 s), subscribes again and renews the presence. What is sent waits in a
//! bounded outbox ([`OUTBOX_LIMIT`] frames, the oldest dropped and counted beyond) until the
//! connection takes it, so nothing is lost while the broker restarts. TCP_NODELAY is set.
//!
//! Written here rather than taken from a crate: the STOMP crates on crates.io are either
//! asynchronous (a tokio runtime for one socket) or unmaintained and without heart-beats; the
//! protocol is small (frame.rs) and this link is tested against ActiveMQ itself.

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::net::{Shutdown, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::frame::{Decoded, Decoder, Frame};
use crate::ports::broker::Inbound;

/// Frames kept while the broker is away.
pub const OUTBOX_LIMIT: usize = 100_000;

/// The heart-beat period this link offers and asks for (ms).
const HEART_BEAT_MS: u64 = 2_000;

/// A STOMP broker's address: `stomp://[USER:PASS@]HOST[:PORT]` (port 61613 when not given).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StompUrl {
    /// Host name or address.
    pub host: String,
    /// TCP port.
    pub port: u16,
    /// Login and passcode, if given.
    pub login: Option<(String, String)>,
}

impl StompUrl {
    /// Reads `stomp://[USER:PASS@]HOST[:PORT]`; anything else is an error saying why.
    pub fn parse(url: &str) -> Result<StompUrl, String> {
        let rest = (url.strip_prefix("stomp://"))
            .ok_or_else(|| format!("'{url}' is not a STOMP address (stomp://HOST[:PORT])"))?
            .trim_end_matches('/');
        let (login, rest) = match rest.rsplit_once('@') {
            Some((l, r)) => {
                let (u, p) = l.split_once(':').unwrap_or((l, ""));
                (Some((u.to_string(), p.to_string())), r)
            }
            None => (None, rest),
        };
        let (host, port) = match rest.rsplit_once(':') {
            Some((h, p)) if !h.is_empty() && !p.contains(']') => {
                let port = (p.parse::<u16>().ok().filter(|&p| p > 0))
                    .ok_or_else(|| format!("'{url}': '{p}' is not a port (1 to 65535)"))?;
                (h, port)
            }
            _ => (rest, 61613),
        };
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() || host.contains('/') {
            return Err(format!("'{url}' names no host (stomp://HOST[:PORT])"));
        }
        Ok(StompUrl {
            host: host.to_string(),
            port,
            login,
        })
    }
}

impl std::fmt::Display for StompUrl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "stomp://{}:{}", self.host, self.port)
    }
}

/// How a STOMP link connects.
#[derive(Debug, Clone)]
pub struct StompOptions {
    /// The broker.
    pub url: StompUrl,
    /// Destinations subscribed to on every connection (e.g. `/topic/asap.bml.request`).
    pub subscriptions: Vec<String>,
    /// A presence destination: `online` sent on every connection, `offline` on close.
    pub presence: Option<String>,
    /// Messages that may wait in the inbox.
    pub inbox: usize,
    /// Tries to reach the broker at the start before giving up.
    pub start_tries: u32,
}

/// The connection's writing side, shared with the reading thread (heart-beats, subscriptions).
struct Writer {
    stream: Option<TcpStream>,
    last: Instant,
    /// The destinations subscribed to now, with their subscription ids (renewed on every
    /// connection).
    subscriptions: Vec<(String, u64)>,
    next_id: u64,
}

impl Writer {
    /// Subscribes to `destination` (a new id), on this connection if there is one.
    fn subscribe(&mut self, destination: &str) {
        if self.subscriptions.iter().any(|(d, _)| d == destination) {
            return;
        }
        let id = self.next_id;
        self.next_id += 1;
        self.subscriptions.push((destination.to_string(), id));
        // (without a connection, the next one subscribes)
        self.write_subscribe(destination, id);
    }

    fn write_subscribe(&mut self, destination: &str, id: u64) -> bool {
        let id = id.to_string();
        let sub = Frame::new(
            "SUBSCRIBE",
            &[("destination", destination), ("id", &id), ("ack", "auto")],
        );
        self.write(&sub.encode())
    }

    /// Ends the subscription to `destination`, if there is one.
    fn unsubscribe(&mut self, destination: &str) {
        let Some(k) = self
            .subscriptions
            .iter()
            .position(|(d, _)| d == destination)
        else {
            return;
        };
        let (_, id) = self.subscriptions.remove(k);
        let id = id.to_string();
        self.write(&Frame::new("UNSUBSCRIBE", &[("id", &id)]).encode());
    }

    /// Writes `bytes`, or drops the connection (the reader then connects again).
    fn write(&mut self, bytes: &[u8]) -> bool {
        let Some(s) = self.stream.as_mut() else {
            return false;
        };
        if s.write_all(bytes).is_ok() {
            self.last = Instant::now();
            return true;
        }
        let _ = s.shutdown(Shutdown::Both);
        self.stream = None;
        false
    }
}

/// A connected STOMP link (see the module documentation).
pub struct StompLink {
    writer: Arc<Mutex<Writer>>,
    inbox: Receiver<Inbound>,
    outbox: VecDeque<Vec<u8>>,
    dropped: u64,
    presence: Option<String>,
    stop: Arc<AtomicBool>,
}

impl StompLink {
    /// Connects (trying `start_tries` times), subscribes, says it is online.
    pub fn connect(options: StompOptions) -> Result<StompLink, String> {
        let writer = Arc::new(Mutex::new(Writer {
            stream: None,
            last: Instant::now(),
            subscriptions: (options.subscriptions.iter().cloned()).zip(0..).collect(),
            next_id: options.subscriptions.len() as u64,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, inbox) = mpsc::sync_channel(options.inbox.max(1));
        let (ready_tx, ready) = mpsc::channel::<Result<(), String>>();
        let reader = Reader {
            options: options.clone(),
            writer: writer.clone(),
            tx,
            stop: stop.clone(),
        };
        std::thread::spawn(move || reader.run(ready_tx));
        match ready.recv() {
            Ok(Ok(())) => Ok(StompLink {
                writer,
                inbox,
                outbox: VecDeque::new(),
                dropped: 0,
                presence: options.presence,
                stop,
            }),
            Ok(Err(e)) => Err(format!("cannot reach the broker at {}: {e}", options.url)),
            Err(_) => Err(format!("cannot reach the broker at {}", options.url)),
        }
    }

    /// The next thing heard, waiting at most `wait`.
    pub fn recv_timeout(&self, wait: Duration) -> Option<Inbound> {
        self.inbox.recv_timeout(wait).ok()
    }

    /// What has been heard already, without waiting.
    pub fn try_recv(&self) -> Option<Inbound> {
        self.inbox.try_recv().ok()
    }

    /// Sends `body` to `destination` with extra `headers` (after what waits). No
    /// `content-length` is sent, so that JMS clients receive a `TextMessage`; a NUL octet
    /// in the body ends it there.
    pub fn send(&mut self, destination: &str, body: Vec<u8>, headers: &[(String, String)]) {
        let mut f = Frame::new("SEND", &[("destination", destination)]);
        f.headers.extend(headers.iter().cloned());
        let end = memchr::memchr(0, &body).unwrap_or(body.len());
        f.body = body;
        f.body.truncate(end);
        if self.outbox.len() >= OUTBOX_LIMIT {
            self.outbox.pop_front();
            self.dropped += 1;
        }
        self.outbox.push_back(f.encode());
    }

    /// Subscribes to `destination` (now and on every connection after), if not already.
    pub fn subscribe(&mut self, destination: &str) {
        (self.writer.lock().unwrap_or_else(|e| e.into_inner())).subscribe(destination);
    }

    /// Ends the subscription to `destination`.
    pub fn unsubscribe(&mut self, destination: &str) {
        (self.writer.lock().unwrap_or_else(|e| e.into_inner())).unsubscribe(destination);
    }

    /// Writes what waits, as far as the connection takes it.
    pub fn flush(&mut self) {
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        while let Some(frame) = self.outbox.front() {
            if !w.write(frame) {
                return;
            }
            self.outbox.pop_front();
        }
    }

    /// Frames waiting for the connection.
    pub fn waiting(&self) -> usize {
        self.outbox.len()
    }

    /// How many frames were dropped since last asked (the outbox was full).
    pub fn take_dropped(&mut self) -> u64 {
        std::mem::take(&mut self.dropped)
    }

    /// Says it is offline, writes what waits (for up to `linger`) and disconnects.
    pub fn close(mut self, linger: Duration) {
        if let Some(p) = self.presence.clone() {
            self.send(&p, b"offline".to_vec(), &[]);
        }
        let until = Instant::now() + linger;
        while !self.outbox.is_empty() && Instant::now() < until {
            self.flush();
            if !self.outbox.is_empty() {
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        self.stop.store(true, Ordering::SeqCst);
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        w.write(&Frame::new("DISCONNECT", &[]).encode());
        if let Some(s) = w.stream.take() {
            let _ = s.shutdown(Shutdown::Both);
        }
    }
}

/// The heart-beat periods agreed: (send every, expect every); `None`: none.
type Beats = (Option<Duration>, Option<Duration>);

/// The thread that reads the connection and makes it again when lost.
struct Reader {
    options: StompOptions,
    writer: Arc<Mutex<Writer>>,
    tx: SyncSender<Inbound>,
    stop: Arc<AtomicBool>,
}

impl Reader {
    fn run(self, ready: mpsc::Sender<Result<(), String>>) {
        let mut ready = Some(ready);
        let (mut failures, mut wait) = (0u32, Duration::from_millis(100));
        while !self.stop.load(Ordering::SeqCst) {
            let (stream, decoder, beats) = match self.open() {
                Ok(c) => c,
                Err(e) => {
                    failures += 1;
                    if ready.is_some() && failures >= self.options.start_tries.max(1) {
                        let _ = ready
                            .take()
                            .map(|r| r.send(Err(format!("{e} ({failures} tries)"))));
                        return;
                    }
                    std::thread::sleep(wait);
                    wait = (wait * 2).min(Duration::from_secs(2));
                    continue;
                }
            };
            (failures, wait) = (0, Duration::from_millis(100));
            let hello = match ready.take() {
                Some(r) => r.send(Ok(())).is_ok(),
                None => self.tx.send(Inbound::Reconnected).is_ok(),
            };
            if !hello {
                return;
            }
            let why = self.read(stream, decoder, beats);
            if self.stop.load(Ordering::SeqCst) {
                return;
            }
            self.writer.lock().unwrap_or_else(|e| e.into_inner()).stream = None;
            if self.tx.send(Inbound::Lost(why)).is_err() {
                return;
            }
        }
    }

    /// Connects, says CONNECT, waits for CONNECTED, subscribes and says it is online: the
    /// reading side, what was read past CONNECTED, and the heart-beat periods (send, expect).
    fn open(&self) -> Result<(TcpStream, Decoder, Beats), String> {
        let url = &self.options.url;
        let addr = ((url.host.as_str(), url.port).to_socket_addrs())
            .map_err(|e| e.to_string())?
            .next()
            .ok_or("the host has no address")?;
        let mut stream =
            TcpStream::connect_timeout(&addr, Duration::from_secs(5)).map_err(|e| e.to_string())?;
        let _ = stream.set_nodelay(true);
        let _ = stream.set_write_timeout(Some(Duration::from_secs(5)));
        stream
            .set_read_timeout(Some(Duration::from_millis(100)))
            .map_err(|e| e.to_string())?;
        let beat = format!("{HEART_BEAT_MS},{HEART_BEAT_MS}");
        let mut hello = Frame::new(
            "CONNECT",
            &[
                ("accept-version", "1.2"),
                ("host", &url.host),
                ("heart-beat", &beat),
            ],
        );
        if let Some((login, pass)) = &url.login {
            hello.headers.push(("login".into(), login.clone()));
            hello.headers.push(("passcode".into(), pass.clone()));
        }
        stream
            .write_all(&hello.encode())
            .map_err(|e| e.to_string())?;
        let mut decoder = Decoder::default();
        let until = Instant::now() + Duration::from_secs(5);
        let connected = loop {
            if Instant::now() > until {
                return Err("no CONNECTED from the broker within 5 s".into());
            }
            match decoder.take()? {
                Some(Decoded::Frame(f)) if f.command == "CONNECTED" => break f,
                Some(Decoded::Frame(f)) if f.command == "ERROR" => {
                    return Err(format!(
                        "the broker refused: {}",
                        f.header("message").unwrap_or("")
                    ))
                }
                Some(_) => continue,
                None => {}
            }
            let mut buf = [0u8; 4096];
            match stream.read(&mut buf) {
                Ok(0) => return Err("the broker closed the connection".into()),
                Ok(n) => decoder.push(&buf[..n]),
                Err(e) if timed_out(&e) => {}
                Err(e) => return Err(e.to_string()),
            }
        };
        let beats = heart_beats(connected.header("heart-beat"));
        let writing = stream.try_clone().map_err(|e| e.to_string())?;
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        w.stream = Some(writing);
        for (d, id) in w.subscriptions.clone() {
            if !w.write_subscribe(&d, id) {
                return Err("the connection ended while subscribing".into());
            }
        }
        if let Some(p) = &self.options.presence {
            let mut online = Frame::new("SEND", &[("destination", p)]);
            online.body = b"online".to_vec();
            w.write(&online.encode());
        }
        Ok((stream, decoder, beats))
    }

    /// Reads until the connection is lost (why).
    fn read(&self, mut stream: TcpStream, mut decoder: Decoder, (send, expect): Beats) -> String {
        let mut heard = Instant::now();
        let mut buf = vec![0u8; 64 * 1024];
        loop {
            loop {
                match decoder.take() {
                    Ok(Some(Decoded::Frame(f))) => {
                        heard = Instant::now();
                        match f.command.as_str() {
                            "MESSAGE" => {
                                let topic = f.header("destination").unwrap_or_default().to_string();
                                let m = Inbound::Message {
                                    topic,
                                    payload: f.body,
                                };
                                if self.tx.send(m).is_err() {
                                    return "the link was closed".into();
                                }
                            }
                            "ERROR" => {
                                let _ = stream.shutdown(Shutdown::Both);
                                return format!(
                                    "the broker said: {}",
                                    f.header("message").unwrap_or("ERROR")
                                );
                            }
                            _ => {}
                        }
                    }
                    Ok(Some(Decoded::HeartBeat)) => heard = Instant::now(),
                    Ok(None) => break,
                    Err(e) => {
                        let _ = stream.shutdown(Shutdown::Both);
                        return format!("not STOMP from the broker: {e}");
                    }
                }
            }
            if self.stop.load(Ordering::SeqCst) {
                return "closed".into();
            }
            if let Some(e) = expect {
                if heard.elapsed() > e * 3 {
                    let _ = stream.shutdown(Shutdown::Both);
                    return format!(
                        "no heart-beat from the broker for {:.1} s",
                        heard.elapsed().as_secs_f64()
                    );
                }
            }
            if let Some(s) = send {
                let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
                if w.last.elapsed() >= s && w.stream.is_some() {
                    w.write(b"\n");
                }
            }
            match stream.read(&mut buf) {
                Ok(0) => return "the broker closed the connection".into(),
                Ok(n) => {
                    heard = Instant::now();
                    decoder.push(&buf[..n]);
                }
                Err(e) if timed_out(&e) => {}
                Err(e) => return e.to_string(),
            }
        }
    }
}

fn timed_out(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
    )
}

/// The heart-beat periods agreed from the broker's `heart-beat:sx,sy` (STOMP 1.2: this link
/// sends every max(ours, sy) when both are non-zero, and expects every max(sx, ours)).
fn heart_beats(header: Option<&str>) -> Beats {
    let (sx, sy) = header
        .and_then(|h| h.split_once(','))
        .and_then(|(a, b)| Some((a.trim().parse::<u64>().ok()?, b.trim().parse::<u64>().ok()?)))
        .unwrap_or((0, 0));
    let agree =
        |theirs: u64| (theirs > 0).then(|| Duration::from_millis(theirs.max(HEART_BEAT_MS)));
    (agree(sy), agree(sx))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stomp_addresses_are_read_or_refused_with_the_reason() {
        let u = StompUrl::parse("stomp://127.0.0.1:61614").unwrap();
        assert_eq!(
            (u.host.as_str(), u.port, u.login),
            ("127.0.0.1", 61614, None)
        );
        assert_eq!(StompUrl::parse("stomp://mq").unwrap().port, 61613);
        let l = StompUrl::parse("stomp://admin:secret@mq:1").unwrap();
        assert_eq!(l.login, Some(("admin".into(), "secret".into())));
        assert_eq!(l.to_string(), "stomp://mq:1");
        assert!(StompUrl::parse("mqtt://x")
            .unwrap_err()
            .contains("not a STOMP"));
        assert!(StompUrl::parse("stomp://x:0")
            .unwrap_err()
            .contains("not a port"));
        assert!(StompUrl::parse("stomp://").unwrap_err().contains("no host"));
    }

    #[test]
    fn heart_beats_are_agreed_as_the_specification_says() {
        assert_eq!(heart_beats(Some("0,0")), (None, None));
        assert_eq!(heart_beats(None), (None, None));
        let (send, expect) = heart_beats(Some("5000,1000"));
        assert_eq!(send, Some(Duration::from_millis(2000)));
        assert_eq!(expect, Some(Duration::from_millis(5000)));
    }

    #[test]
    fn no_broker_is_an_error_naming_the_address_after_the_tries() {
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let e = StompLink::connect(StompOptions {
            url: StompUrl::parse(&format!("stomp://127.0.0.1:{port}")).unwrap(),
            subscriptions: vec![],
            presence: None,
            inbox: 8,
            start_tries: 2,
        })
        .err()
        .unwrap();
        assert!(e.contains(&format!("stomp://127.0.0.1:{port}")), "{e}");
    }
}
