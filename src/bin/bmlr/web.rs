//! The viewer's page and its small web server. [`page`] fills the page template
//! (`assets/viewer/index.html`) with the run's data, the viewer script and the vendored
//! three.js, so that one HTML file holds everything and works opened from disk. [`serve`]
//! serves that page on a loopback address (plain HTTP/1.1, one thread per connection): `/` is
//! the page, `/three-LICENSE.txt` three.js's licence and, when a [`Live`] hub is given, `/live`
//! a WebSocket on which the hub's messages (frames, feedback, timeline) go to every watcher.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

const TEMPLATE: &str = include_str!("../../../assets/viewer/index.html");
const VIEWER: &str = include_str!("../../../assets/viewer/viewer.js");
/// The avatars' part of the viewer (loading, and live driving).
const AVATARS: &str = include_str!("../../../assets/viewer/avatars.js");
/// The crowds' part of the viewer (packed frames, instanced mannequins).
const CROWD: &str = include_str!("../../../assets/viewer/crowd.js");
const THREE: &str = include_str!("../../../assets/viewer/three/three.module.min.js");
/// three.js's glTF loader and the geometry helpers it imports (the same release, same licence).
const GLTF_LOADER: &str = include_str!("../../../assets/viewer/three/GLTFLoader.js");
const GEOMETRY_UTILS: &str = include_str!("../../../assets/viewer/three/BufferGeometryUtils.js");
/// three.js's MIT licence, written beside the page.
pub const THREE_LICENSE: &str = include_str!("../../../assets/viewer/three/LICENSE");
/// The vendored three.js (npm `three`, `build/three.module.min.js`).
const THREE_VERSION: &str = "0.170.0";

/// Longest request head the server reads.
const MAX_REQUEST: usize = 16 * 1024;

/// Messages a watcher may leave unsent before it is cut off (a few seconds of frames).
const WATCHER_QUEUE: usize = 1_024;

/// The page with `data` (the run as JSON) in it.
pub fn page(data: &str) -> String {
    // `<` only occurs inside JSON strings, where \u003c means the same: the data cannot end its
    // script element early
    let data = data.replace('<', "\\u003c");
    fill(
        TEMPLATE,
        &[
            ("VERSION", env!("CARGO_PKG_VERSION")),
            ("DATA", &data),
            ("THREE_VERSION", THREE_VERSION),
            ("THREE", THREE),
            ("GLTF_LOADER", GLTF_LOADER),
            ("GEOMETRY_UTILS", GEOMETRY_UTILS),
            ("AVATARS", AVATARS),
            ("CROWD", CROWD),
            ("VIEWER", VIEWER),
        ],
    )
}

/// `template` with every `{{KEY}}` replaced by its value, in one pass (a value is never searched
/// for keys, so the run's text cannot smuggle one in).
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(at) = rest.find("{{") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let key = after.find("}}").map(|end| &after[..end]);
        match key.and_then(|k| values.iter().find(|(name, _)| *name == k)) {
            Some((k, v)) => {
                out.push_str(v);
                rest = &after[k.len() + 2..];
            }
            None => {
                out.push_str("{{");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The watchers of a live page and what a new one is sent first.
#[derive(Clone, Default)]
pub struct Live {
    inner: Arc<Mutex<Watchers>>,
}

#[derive(Default)]
struct Watchers {
    queues: Vec<SyncSender<Arc<str>>>,
    /// The last feedback messages, sent to a watcher when it connects, at most `keep` of them.
    backlog: std::collections::VecDeque<Arc<str>>,
    keep: usize,
    /// The latest timeline, sent after the backlog.
    timeline: Option<Arc<str>>,
}

impl Live {
    /// Watchers that are sent the last `keep` feedback messages when they connect.
    pub fn new(keep: usize) -> Live {
        let live = Live::default();
        live.lock().keep = keep;
        live
    }

    /// Whether anyone watches (frames need not be encoded otherwise).
    pub fn watched(&self) -> bool {
        !self.lock().queues.is_empty()
    }

    /// Sends `message` (a frame) to every watcher.
    pub fn send(&self, message: String) {
        self.lock().broadcast(message.into());
    }

    /// Sends a feedback message to every watcher and keeps it for those who connect later.
    pub fn feedback(&self, message: String) {
        let message: Arc<str> = message.into();
        let mut w = self.lock();
        w.broadcast(message.clone());
        w.backlog.push_back(message);
        while w.backlog.len() > w.keep {
            w.backlog.pop_front();
        }
    }

    /// Sends a timeline to every watcher; it replaces the one those who connect later get.
    pub fn timeline(&self, message: String) {
        let message: Arc<str> = message.into();
        let mut w = self.lock();
        w.broadcast(message.clone());
        w.timeline = Some(message);
    }

    /// A new watcher: its queue, filled with the backlog and the latest timeline.
    fn watch(&self) -> Receiver<Arc<str>> {
        let mut w = self.lock();
        let (tx, rx) = mpsc::sync_channel(WATCHER_QUEUE + w.backlog.len() + 1);
        for m in w.backlog.iter().chain(&w.timeline) {
            let _ = tx.try_send(m.clone());
        }
        w.queues.push(tx);
        rx
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Watchers> {
        // a watcher thread that panicked leaves the lists usable
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Binds `addr`, which must be a loopback address (the page shows what the realizer does to
/// anyone who can reach it). Returns the listener and the address it got.
pub fn bind(addr: &str) -> Result<(TcpListener, SocketAddr), String> {
    let addrs: Vec<SocketAddr> = (addr.to_socket_addrs())
        .map_err(|e| format!("'{addr}' is not an address: {e}"))?
        .collect();
    if addrs.is_empty() || addrs.iter().any(|a| !a.ip().is_loopback()) {
        return Err(format!(
            "'{addr}' is not a loopback address; the page is served on 127.0.0.1 or ::1 only"
        ));
    }
    let listener =
        TcpListener::bind(&addrs[..]).map_err(|e| format!("cannot listen on {addr}: {e}"))?;
    let at = listener.local_addr().map_err(|e| e.to_string())?;
    Ok((listener, at))
}

/// Serves `page` (and, with `live`, its WebSocket) on `listener` until the process ends.
pub fn serve(listener: TcpListener, page: Arc<String>, live: Option<Live>) {
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let (page, live) = (page.clone(), live.clone());
        std::thread::spawn(move || {
            let _ = answer(stream, &page, live.as_ref());
        });
    }
}

/// Answers one connection: reads the request head and sends the page, the licence, a 404, or
/// switches to the WebSocket.
fn answer(mut stream: TcpStream, page: &str, live: Option<&Live>) -> std::io::Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(10)))?;
    let head = read_head(&mut stream)?;
    let mut lines = head.lines();
    let request: Vec<&str> = lines.next().unwrap_or("").split_whitespace().collect();
    let header = |name: &str| {
        head.lines().skip(1).find_map(|l| {
            let (k, v) = l.split_once(':')?;
            k.trim()
                .eq_ignore_ascii_case(name)
                .then(|| v.trim().to_string())
        })
    };
    let (method, path) = match request.as_slice() {
        [m, p, ..] => (*m, p.split(['?', '#']).next().unwrap_or("")),
        _ => {
            return respond(
                &mut stream,
                "400 Bad Request",
                "text/plain",
                b"bad request\n",
            )
        }
    };
    if method != "GET" {
        return respond(
            &mut stream,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
        );
    }
    match (path, live, header("sec-websocket-key")) {
        ("/" | "/index.html", _, _) => respond(
            &mut stream,
            "200 OK",
            "text/html; charset=utf-8",
            page.as_bytes(),
        ),
        ("/three-LICENSE.txt", _, _) => respond(
            &mut stream,
            "200 OK",
            "text/plain; charset=utf-8",
            THREE_LICENSE.as_bytes(),
        ),
        ("/live", Some(live), Some(key)) => watch(stream, &key, live),
        _ => respond(&mut stream, "404 Not Found", "text/plain", b"not found\n"),
    }
}

/// The request head, up to the blank line.
fn read_head(stream: &mut TcpStream) -> std::io::Result<String> {
    let mut head = Vec::new();
    let mut buf = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") {
        let n = stream.read(&mut buf)?;
        if n == 0 || head.len() + n > MAX_REQUEST {
            return Err(std::io::ErrorKind::InvalidData.into());
        }
        head.extend_from_slice(&buf[..n]);
    }
    Ok(String::from_utf8_lossy(&head).into_owned())
}

fn respond(stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> std::io::Result<()> {
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    stream.write_all(body)?;
    stream.flush()
}

/// Switches to the WebSocket protocol and sends the hub's messages until the watcher leaves.
fn watch(mut stream: TcpStream, key: &str, live: &Live) -> std::io::Result<()> {
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    write!(
        stream,
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: {accept}\r\n\r\n"
    )?;
    stream.set_read_timeout(None)?;
    let mut socket =
        tungstenite::WebSocket::from_raw_socket(stream, tungstenite::protocol::Role::Server, None);
    for message in live.watch() {
        if socket
            .send(tungstenite::Message::text(message.as_ref()))
            .is_err()
        {
            break; // the watcher left; its queue is dropped with this thread
        }
    }
    Ok(())
}

impl Watchers {
    /// Queues `message` for every watcher; one that has fallen [`WATCHER_QUEUE`] messages
    /// behind is cut off.
    fn broadcast(&mut self, message: Arc<str>) {
        self.queues.retain(|q| match q.try_send(message.clone()) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                eprintln!(
                    "bmlr serve: a viewer fell {WATCHER_QUEUE} messages behind; disconnected"
                );
                false
            }
            Err(TrySendError::Disconnected(_)) => false,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filling_is_one_pass_and_leaves_unknown_braces() {
        let out = fill("a {{X}} b {{Y}} {{Z}} {{", &[("X", "{{Y}}"), ("Y", "y")]);
        assert_eq!(out, "a {{Y}} b y {{Z}} {{");
    }

    #[test]
    fn the_data_cannot_close_its_script() {
        let p = page(r#"{"text": "</script><script>alert(1)</script>"}"#);
        assert_eq!(
            p.matches("</script>").count(),
            8,
            "the eight script elements only (the timing switch, data, three.js, its glTF loader \
             and geometry helpers, the avatars, the crowd, the viewer)"
        );
        assert!(p.contains(r#""\u003c/script>\u003cscript>alert(1)\u003c/script>""#));
    }

    #[test]
    fn only_loopback_addresses_are_served() {
        assert!(bind("127.0.0.1:0").is_ok());
        let e = bind("0.0.0.0:0").unwrap_err();
        assert!(e.contains("not a loopback address"), "{e}");
        assert!(bind("no such place").is_err());
    }
}
