//! `bmlr serve --tcp`: many clients at once on loopback, per-client and broadcast feedback,
//! garbage and disconnects.

use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

struct Server {
    child: Child,
    addr: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The tests of this file run one at a time: each measures how a server serves its clients, and
/// the fifty-client and flood tests would otherwise share two cores.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn server(extra: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["serve", "--tcp", "127.0.0.1:0"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .trim()
        .strip_prefix("bmlr serve: listening on ")
        .unwrap_or_else(|| panic!("{line}"))
        .to_string();
    Server { child, addr }
}

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// Reads lines until `done` says so or the deadline passes.
fn read_until(
    reader: &mut BufReader<TcpStream>,
    deadline: Instant,
    mut done: impl FnMut(&str) -> bool,
) -> Vec<String> {
    let mut lines = Vec::new();
    reader
        .get_ref()
        .set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    while Instant::now() < deadline {
        let mut line = String::new();
        match reader.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {
                let stop = done(&line);
                lines.push(line);
                if stop {
                    break;
                }
            }
            Err(_) => continue, // timeout: try again
        }
    }
    lines
}

/// Sends `line` and reads until the block progress `sync` (`block:start` or `block:end`)
/// arrives, which must be within 2 s; how long that took.
fn await_sync(
    writer: &mut TcpStream,
    reader: &mut BufReader<TcpStream>,
    line: &str,
    sync: &str,
) -> Duration {
    let sent = Instant::now();
    writer.write_all(format!("{line}\n").as_bytes()).unwrap();
    let wanted = format!(r#"id="{sync}""#);
    let lines = read_until(reader, sent + Duration::from_secs(2), |l| {
        l.contains(&wanted)
    });
    assert!(
        lines.iter().any(|l| l.contains(&wanted)),
        "{sync} did not come within 2 s: {lines:?}"
    );
    sent.elapsed()
}

#[test]
fn fifty_clients_times_200_blocks_lose_no_feedback() {
    let _serial = one_at_a_time();
    let s = server(&["--per-client"]);
    let started = Instant::now();
    let handles: Vec<_> = (0..50)
        .map(|c| {
            let addr = s.addr.clone();
            std::thread::spawn(move || {
                let stream = TcpStream::connect(&addr).unwrap();
                let mut writer = stream.try_clone().unwrap();
                let mut text = String::new();
                for b in 0..200 {
                    text.push_str(&format!(
                        r#"<bml {NS} id="c{c}b{b}"><head id="h" lexeme="NOD" start="0" end="0.3"/></bml>"#
                    ));
                    text.push('\n');
                }
                writer.write_all(text.as_bytes()).unwrap();
                let mut reader = BufReader::new(stream);
                let mut ends = 0;
                let lines = read_until(&mut reader, Instant::now() + Duration::from_secs(60), |l| {
                    if l.contains(":end\" globalTime") && l.contains("blockProgress") {
                        ends += 1;
                    }
                    ends == 200
                });
                (c, lines)
            })
        })
        .collect();
    for h in handles {
        let (c, lines) = h.join().unwrap();
        let count = |needle: &str| lines.iter().filter(|l| l.contains(needle)).count();
        // per block: IN_PREP, PENDING and IN_EXEC predictions, start, 7 syncs, end
        assert_eq!(count("<blockProgress"), 400, "client {c}");
        assert_eq!(count("<syncPointProgress"), 1400, "client {c}");
        assert_eq!(count("<predictionFeedback"), 600, "client {c}");
        assert_eq!(lines.len(), 2400, "client {c}");
        // only its own blocks
        assert!(
            lines.iter().all(|l| l.contains(&format!("id=\"c{c}b"))),
            "client {c}"
        );
    }
    assert!(started.elapsed() < Duration::from_secs(60));
}

#[test]
fn garbage_gets_a_warning_for_its_sender_only_and_a_disconnect_disturbs_no_one() {
    let _serial = one_at_a_time();
    let s = server(&[]);
    let good = TcpStream::connect(&s.addr).unwrap();
    let mut bad = TcpStream::connect(&s.addr).unwrap();
    let quitter = TcpStream::connect(&s.addr).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    drop(quitter);
    bad.write_all(b"this is not BML\n<bml id=\"x\"><oops></bml>\n")
        .unwrap();
    let mut good_w = good.try_clone().unwrap();
    good_w
        .write_all(
            format!(r#"<bml {NS} id="g1"><head id="h" lexeme="NOD" start="0" end="0.1"/></bml>"#)
                .as_bytes(),
        )
        .unwrap();
    good_w.write_all(b"\n").unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut good_r = BufReader::new(good);
    let good_lines = read_until(&mut good_r, deadline, |l| l.contains("id=\"g1:end\""));
    assert!(
        good_lines.iter().any(|l| l.contains("id=\"g1:end\"")),
        "{good_lines:?}"
    );
    assert!(
        !good_lines.iter().any(|l| l.contains("PARSING_FAILURE")),
        "{good_lines:?}"
    );
    // the broadcast reaches the bad client too, with its own two warnings
    let mut bad_r = BufReader::new(bad);
    let mut warnings = 0;
    let bad_lines = read_until(&mut bad_r, deadline, |l| {
        warnings += usize::from(l.contains("PARSING_FAILURE"));
        l.contains("id=\"g1:end\"")
    });
    assert_eq!(
        bad_lines
            .iter()
            .filter(|l| l.contains("PARSING_FAILURE"))
            .count(),
        2,
        "{bad_lines:?}"
    );
    assert!(bad_lines.iter().any(|l| l.contains("id=\"g1:end\"")));
}

/// A line that is not UTF-8 costs that line and one warning to its sender; the connection stays
/// and the next block from it runs.
#[test]
fn a_line_that_is_not_utf8_costs_only_itself() {
    let _serial = one_at_a_time();
    let s = server(&[]);
    let mut conn = TcpStream::connect(&s.addr).unwrap();
    let mut reader = BufReader::new(conn.try_clone().unwrap());
    conn.write_all(b"<bml id=\"x\">\xff\xfe</bml>\n").unwrap();
    let good = format!(r#"<bml {NS} id="after"><gesture id="g" lexeme="BEAT"/></bml>"#);
    conn.write_all(format!("{good}\n").as_bytes()).unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    let lines = read_until(&mut reader, deadline, |l| l.contains(r#"id="after:end""#));
    let warnings: Vec<&String> = lines
        .iter()
        .filter(|l| l.contains("PARSING_FAILURE"))
        .collect();
    assert_eq!(warnings.len(), 1, "{lines:?}");
    assert!(warnings[0].contains("not UTF-8"), "{lines:?}");
    assert!(
        lines.iter().any(|l| l.contains(r#"id="after:end""#)),
        "{lines:?}"
    );
}

/// Peak resident memory of a process, kB (Linux).
fn peak_rss_kb(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// One client floods the server and never reads its feedback; another sends a block every half
/// second. The flooder is cut off when its unread feedback passes the limit, the server stays
/// small, and the second client's blocks end within 2 s of being sent.
#[cfg(target_os = "linux")]
#[test]
fn a_client_that_floods_and_never_reads_slows_no_one_and_grows_nothing() {
    let _serial = one_at_a_time();
    let s = server(&["--per-client"]);
    let addr = s.addr.clone();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flooding = stop.clone();
    let flooder = std::thread::spawn(move || {
        let mut conn = TcpStream::connect(&addr).unwrap();
        let mut n = 0u64;
        while !flooding.load(std::sync::atomic::Ordering::Relaxed) {
            let line = format!("<bml {NS} id=\"f{n}\"/>\n");
            if conn.write_all(line.as_bytes()).is_err() {
                break; // cut off
            }
            n += 1;
        }
        n
    });
    let conn = TcpStream::connect(&s.addr).unwrap();
    let mut writer = conn.try_clone().unwrap();
    let mut reader = BufReader::new(conn);
    for b in 0..8 {
        let sent = Instant::now();
        let line = format!(
            r#"<bml {NS} id="calm{b}"><head id="h" lexeme="NOD" start="0" end="0.3"/></bml>"#
        );
        await_sync(&mut writer, &mut reader, &line, &format!("calm{b}:end"));
        std::thread::sleep(Duration::from_millis(500).saturating_sub(sent.elapsed()));
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let flooded = flooder.join().unwrap();
    assert!(flooded > 10_000, "the flood was only {flooded} blocks");
    let rss = peak_rss_kb(s.child.id());
    assert!(rss < 250_000, "the server grew to {rss} kB");
}

/// A chain of `n` gestures in one line, each starting at the previous one's end.
fn chain(id: &str, n: usize) -> String {
    let body: String = (0..n)
        .map(|i| match i {
            0 => r#"<gesture id="g0" lexeme="BEAT"/>"#.to_string(),
            _ => format!(
                r#"<gesture id="g{i}" lexeme="BEAT" start="g{}:end"/>"#,
                i - 1
            ),
        })
        .collect();
    format!("<bml {NS} id=\"{id}\">{body}</bml>\n")
}

/// While one client sends blocks of 10 000 behaviours, another's small blocks start as soon as
/// they arrive: the large blocks are read on their sender's thread, and only their scheduling
/// (a few milliseconds) happens on the realizer's. Before, the realizer's thread read each large
/// block twice and then scheduled it, holding every other client up for about 150 ms.
#[test]
fn large_blocks_from_one_client_hold_up_no_other() {
    let _serial = one_at_a_time();
    let s = server(&["--per-client"]);
    let addr = s.addr.clone();
    let big = std::thread::spawn(move || {
        let mut conn = TcpStream::connect(&addr).unwrap();
        for b in 0..6 {
            conn.write_all(chain(&format!("big{b}"), 10_000).as_bytes())
                .unwrap();
            std::thread::sleep(Duration::from_millis(100));
        }
        conn
    });
    let conn = TcpStream::connect(&s.addr).unwrap();
    let mut writer = conn.try_clone().unwrap();
    let mut reader = BufReader::new(conn);
    let mut worst = Duration::ZERO;
    for b in 0..60 {
        let line = format!(r#"<bml {NS} id="small{b}"><gesture id="g" lexeme="BEAT"/></bml>"#);
        let waited = await_sync(&mut writer, &mut reader, &line, &format!("small{b}:start"));
        worst = worst.max(waited);
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(big.join().unwrap());
    eprintln!("slowest start of a small block: {worst:?}");
    // (a debug build reads about 20 ms here on an idle machine and the build before the change
    // 820 ms; the bound leaves room for a busy machine. The release figure, under a frame, is in
    // docs/performance.md.)
    assert!(
        worst < Duration::from_millis(400),
        "a small block waited {worst:?} for its start"
    );
}
