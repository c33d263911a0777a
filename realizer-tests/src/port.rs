//! How the harness drives a realizer: the [`TestPort`] trait (send BML, let time pass, reset),
//! the per-test context [`Ctx`] with the original's sends, sleeps and unbounded waits (bounded
//! here: on a virtual clock a wait fails when nothing more can happen, in real time after a
//! timeout), and [`ProcessPort`], a port to any realizer process that reads one `<bml>` block per
//! stdin line and writes one feedback element per stdout line (`bmlr serve --stdio`).

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use crate::check::{Check, Failure};
use crate::files;
use crate::record::Recorder;

/// A realizer as the harness sees it.
pub trait TestPort {
    /// Sends one `<bml>` block.
    fn perform_bml(&mut self, bml: &str);

    /// Lets `secs` seconds pass (a clock advance on a virtual clock, a wall-clock wait in real
    /// time) and returns the feedback lines produced meanwhile, in order.
    fn sleep(&mut self, secs: f64) -> Vec<String>;

    /// Lets time pass until something may have happened: on a virtual clock up to the next event
    /// (`None` if nothing more will happen without input), in real time a short wait.
    fn step(&mut self) -> Option<Vec<String>>;

    /// Whether time is the wall clock (waits then need a timeout).
    fn real_time(&self) -> bool;

    /// Gets the realizer ready for the next test of `fixture` (a fresh realizer, or an empty
    /// REPLACE block).
    fn reset(&mut self, fixture: Fixture) -> Result<(), String>;
}

/// The test fixture a test belongs to: the realizer configuration it needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fixture {
    /// The standard realizer (the BML 1.0 and AsapRealizer tests).
    Standard,
    /// A realizer with incremental, retimable speech (AsapRealizer's incremental-TTS fixture).
    IncrementalSpeech,
}

/// How long a wait may take in real time (the original gave a whole test 150 s).
pub const REAL_TIME_WAIT: Duration = Duration::from_secs(60);

/// One test's view: the port, the recorder, the catalogue's actions.
pub struct Ctx<'a> {
    port: &'a mut dyn TestPort,
    /// What has arrived.
    pub rec: Recorder,
}

impl<'a> Ctx<'a> {
    /// A context on `port` with an empty recorder.
    pub fn new(port: &'a mut dyn TestPort) -> Self {
        Ctx {
            port,
            rec: Recorder::new(),
        }
    }

    fn feed(&mut self, lines: Vec<String>) {
        for l in lines {
            if !l.trim().is_empty() {
                self.rec.feedback_xml(&l);
            }
        }
    }

    /// Sends a RealizerTester file (path relative to `bml-1/`).
    pub fn send(&mut self, file: &str) -> Check {
        let text = files::get(file)
            .ok_or_else(|| Failure(format!("the suite has no test file {file}")))?;
        self.send_text(text);
        Ok(())
    }

    /// Sends BML text.
    pub fn send_text(&mut self, bml: &str) {
        self.port.perform_bml(bml);
        let lines = self.port.sleep(0.0);
        self.feed(lines);
    }

    /// `Thread.sleep(ms)`: a clock advance on a virtual clock.
    pub fn sleep_ms(&mut self, ms: u64) {
        let lines = self.port.sleep(ms as f64 / 1000.0);
        self.feed(lines);
    }

    /// Empties the recorder (`clearFeedbackLists`).
    pub fn clear(&mut self) {
        self.rec.clear();
    }

    fn wait(&mut self, what: &str, done: impl Fn(&Recorder) -> bool) -> Check {
        let started = Instant::now();
        while !done(&self.rec) {
            match self.port.step() {
                Some(lines) => self.feed(lines),
                None => {
                    return Err(Failure(format!(
                        "waited for {what}, but the realizer has nothing more to do\n{}",
                        self.rec.trace()
                    )))
                }
            }
            if self.port.real_time() && started.elapsed() > REAL_TIME_WAIT {
                return Err(Failure(format!(
                    "waited {} s for {what}\n{}",
                    REAL_TIME_WAIT.as_secs(),
                    self.rec.trace()
                )));
            }
        }
        Ok(())
    }

    /// `waitForBMLEndFeedback(B)`.
    pub fn wait_end(&mut self, block: &str) -> Check {
        self.wait(&format!("the end of {block}"), |r| r.stop(block).is_some())
    }

    /// `waitForBMLStartFeedback(B)`.
    pub fn wait_start(&mut self, block: &str) -> Check {
        self.wait(&format!("the start of {block}"), |r| {
            r.start(block).is_some()
        })
    }

    /// `waitForBMLSchedulingFinishedFeedback(B)`: a prediction of B with a known end.
    pub fn wait_scheduled(&mut self, block: &str) -> Check {
        self.wait(&format!("the scheduling of {block} to finish"), |r| {
            r.scheduled.iter().any(|b| b == block)
        })
    }

    /// `waitForFeedback(B, beh, S)`.
    pub fn wait_sync(&mut self, id: &str) -> Check {
        let mut p = id.splitn(3, ':');
        let (b, beh, s) = (
            p.next().unwrap_or(""),
            p.next().unwrap_or(""),
            p.next().unwrap_or(""),
        );
        self.wait(&format!("sync {id}"), |r| r.sync(b, beh, s).is_some())
    }
}

/// Sends [`REPLACE_SETUP`] on a real-time `port` and waits (up to [`REAL_TIME_WAIT`]) until its
/// end is reported: whether it was. What a real-time port's [`TestPort::reset`] does.
pub fn replace_setup(port: &mut dyn TestPort) -> bool {
    port.perform_bml(REPLACE_SETUP);
    let deadline = Instant::now() + REAL_TIME_WAIT;
    while Instant::now() < deadline {
        let lines = port.sleep(0.01);
        if lines
            .iter()
            .any(|l| l.contains("blockProgress") && l.contains("\"replacesetup:end\""))
        {
            return true;
        }
    }
    false
}

/// The empty REPLACE block the original fixture sends before every test.
pub const REPLACE_SETUP: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="replacesetup" composition="REPLACE"/>"#;

/// A realizer process speaking the line protocol: one block per stdin line, one feedback element
/// per stdout line, wall clock. Tests of the incremental-speech fixture can run on another command
/// (a realizer configured with retimable speech); the port switches processes when the fixture
/// changes.
pub struct ProcessPort {
    commands: [String; 2],
    running: Fixture,
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<String>,
}

impl ProcessPort {
    /// Starts `command` (with `sh -c`) for every test.
    pub fn spawn(command: &str) -> std::io::Result<Self> {
        Self::spawn_with(command, command)
    }

    /// Whether the process has already ended, with its status: a command that cannot run (not
    /// found, bad arguments) ends at once.
    pub fn exited(&mut self) -> Option<std::process::ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// Starts `standard` (with `sh -c`); the incremental-speech tests run on `incremental`.
    pub fn spawn_with(standard: &str, incremental: &str) -> std::io::Result<Self> {
        let (child, stdin, lines) = Self::start(standard)?;
        Ok(ProcessPort {
            commands: [standard.to_string(), incremental.to_string()],
            running: Fixture::Standard,
            child,
            stdin,
            lines,
        })
    }

    fn start(command: &str) -> std::io::Result<(Child, ChildStdin, Receiver<String>)> {
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(command)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()?;
        let stdin = child.stdin.take().expect("piped stdin");
        let stdout = child.stdout.take().expect("piped stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Ok((child, stdin, lines))
    }

    fn collect_until(&mut self, deadline: Instant) -> Vec<String> {
        let mut out = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(l) => out.push(l),
                Err(RecvTimeoutError::Timeout) => return out,
                Err(RecvTimeoutError::Disconnected) => {
                    std::thread::sleep(left);
                    return out;
                }
            }
        }
    }
}

impl TestPort for ProcessPort {
    fn perform_bml(&mut self, bml: &str) {
        // one block per line: line breaks inside a block are white space in BML
        let line: String = bml
            .chars()
            .map(|c| if c == '\n' || c == '\r' { ' ' } else { c })
            .collect();
        let _ = writeln!(self.stdin, "{line}");
        let _ = self.stdin.flush();
    }

    fn sleep(&mut self, secs: f64) -> Vec<String> {
        let deadline = Instant::now() + Duration::from_secs_f64(secs.max(0.0));
        let mut out = self.collect_until(deadline);
        // whatever is already there
        out.extend(self.lines.try_iter());
        out
    }

    fn step(&mut self) -> Option<Vec<String>> {
        Some(self.sleep(0.01))
    }

    fn real_time(&self) -> bool {
        true
    }

    fn reset(&mut self, fixture: Fixture) -> Result<(), String> {
        let index = |f: Fixture| usize::from(f == Fixture::IncrementalSpeech);
        if fixture != self.running && self.commands[0] != self.commands[1] {
            let (child, stdin, lines) = Self::start(&self.commands[index(fixture)])
                .map_err(|e| format!("cannot start '{}': {e}", self.commands[index(fixture)]))?;
            let _ = self.child.kill();
            let _ = self.child.wait();
            (self.child, self.stdin, self.lines) = (child, stdin, lines);
        }
        self.running = fixture;
        if replace_setup(self) {
            Ok(())
        } else {
            Err("the realizer did not end the REPLACE setup block".into())
        }
    }
}

impl Drop for ProcessPort {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
