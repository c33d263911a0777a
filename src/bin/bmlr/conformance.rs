//! `bmlr conformance`: the RealizerTester suite, in process (this realizer on the virtual
//! clock) or against a realizer command or a broker.

use std::io::Write;
use std::process::ExitCode;
use std::time::Duration;

use bml_realizer::ports::conformance::InProcess;
use clap::Args;
use realizer_tests::{run, Outcome, ProcessPort, TestPort};

/// Arguments of `bmlr conformance`.
#[derive(Args)]
pub struct ConformanceArgs {
    /// Test a realizer process speaking the line protocol (e.g. 'bmlr serve --stdio') in real
    /// time, instead of this realizer in process on a virtual clock.
    #[arg(long, value_name = "CMD")]
    realizer: Option<String>,
    /// The realizer command for the incremental-speech tests (a realizer with retimable speech);
    /// defaults to --realizer (with --retimable-speech added if that is `bmlr serve`).
    #[arg(long, value_name = "CMD")]
    incremental_realizer: Option<String>,
    /// Test a realizer reached only through an MQTT broker (mqtt://HOST[:PORT]; `bmlr serve
    /// --mqtt`), in real time.
    #[arg(long, value_name = "URL", conflicts_with = "realizer")]
    mqtt: Option<String>,
    /// Test a realizer reached only through a STOMP broker (stomp://HOST[:PORT]; `bmlr serve
    /// --stomp`), in real time.
    #[arg(long, value_name = "URL", conflicts_with_all = ["realizer", "mqtt"])]
    stomp: Option<String>,
    /// With --stomp: the realizer's topics (IN,OUT; asap.bml.request,asap.bml.feedback by
    /// default).
    #[arg(long, value_name = "IN,OUT", value_delimiter = ',')]
    topics: Vec<String>,
    /// With --stomp: the topics of the realizer for the incremental-speech tests (one with
    /// retimable speech; by default --topics).
    #[arg(long, value_name = "IN,OUT", value_delimiter = ',')]
    incremental_topics: Vec<String>,
    /// With --mqtt: the topics' first level(s).
    #[arg(long, value_name = "PREFIX", default_value = "bml")]
    prefix: String,
    /// With --mqtt: the character the tests address ('_': the realizer's default character).
    #[arg(long, value_name = "ID", default_value = "_")]
    character: String,
    /// With --mqtt: the character of the incremental-speech tests, served by a realizer with
    /// retimable speech (by default --character).
    #[arg(long, value_name = "ID")]
    incremental_character: Option<String>,
    /// Run only the tests whose name contains PAT.
    #[arg(long, value_name = "PAT", default_value = "")]
    filter: String,
    /// In process: the voice that says speech (flite: Debian package `flite`).
    #[arg(
        long,
        value_enum,
        default_value = "builtin",
        conflicts_with = "realizer"
    )]
    tts: crate::setup::TtsArg,
}

/// The command for the incremental-speech tests: the one given, else `cmd` itself — with
/// `--retimable-speech` added when `cmd` is this realizer's `serve --stdio`.
fn incremental_command(cmd: &str, given: Option<&str>) -> String {
    if let Some(g) = given {
        return g.to_string();
    }
    let words: Vec<&str> = cmd.split_whitespace().collect();
    let ours = words.len() >= 2
        && words[0].rsplit('/').next() == Some("bmlr")
        && words[1] == "serve"
        && !words.contains(&"--retimable-speech");
    if ours {
        format!("{cmd} --retimable-speech")
    } else {
        cmd.to_string()
    }
}

/// `cmd` with a leading `bmlr` replaced by the path of this very binary (so that the suite tests
/// this build, not whatever `bmlr` is on the PATH).
fn this_bmlr(cmd: &str) -> String {
    let Some(rest) = cmd.trim_start().strip_prefix("bmlr") else {
        return cmd.to_string();
    };
    match std::env::current_exe() {
        Ok(exe) if rest.is_empty() || rest.starts_with(char::is_whitespace) => {
            format!(
                "'{}'{rest}",
                exe.display().to_string().replace('\'', r"'\''")
            )
        }
        _ => cmd.to_string(),
    }
}

/// The port, once its process has shown that it runs: one that ends within half a second (a
/// command that is not found, a bad argument) is an error with its exit status.
fn started(port: std::io::Result<ProcessPort>) -> Result<ProcessPort, String> {
    let mut port = port.map_err(|e| e.to_string())?;
    for _ in 0..25 {
        if let Some(status) = port.exited() {
            let why = if status.code() == Some(127) {
                "the command was not found".to_string()
            } else {
                format!("it exited at once ({status})")
            };
            return Err(why);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Ok(port)
}

/// `bmlr conformance`.
pub fn conformance(args: ConformanceArgs) -> ExitCode {
    let mut port: Box<dyn TestPort> = match (&args.realizer, &args.mqtt) {
        (None, None) if args.stomp.is_some() => {
            let pair = |t: &[String]| match t {
                [] => Ok(crate::serve_broker::ASAP_TOPICS)
                    .map(|(i, o)| (i.to_string(), o.to_string())),
                [i, o] => Ok((i.clone(), o.clone())),
                _ => Err("--topics takes two topics: IN,OUT"),
            };
            let pairs = pair(&args.topics).and_then(|std| {
                let inc = match args.incremental_topics.is_empty() {
                    true => std.clone(),
                    false => pair(&args.incremental_topics)?,
                };
                Ok([std, inc])
            });
            let url = args.stomp.as_deref().unwrap_or_default();
            match pairs
                .map_err(str::to_string)
                .and_then(|p| crate::broker_port::BrokerPort::stomp(url, p))
            {
                Ok(p) => Box::new(p),
                Err(e) => {
                    eprintln!("bmlr conformance: --stomp {e}");
                    return ExitCode::from(2);
                }
            }
        }
        (None, Some(url)) => {
            let incremental =
                (args.incremental_character.clone()).unwrap_or_else(|| args.character.clone());
            let characters = [args.character.clone(), incremental];
            match crate::broker_port::BrokerPort::mqtt(url, &args.prefix, characters) {
                Ok(p) => Box::new(p),
                Err(e) => {
                    eprintln!("bmlr conformance: --mqtt {e}");
                    return ExitCode::from(2);
                }
            }
        }
        (None, None) => match args.tts.timing(None) {
            Ok(t) => Box::new(InProcess::new().with_voice(t.voice)),
            Err(e) => {
                eprintln!("bmlr conformance: --tts: {e}");
                return ExitCode::from(2);
            }
        },
        (Some(cmd), _) => {
            let incremental = incremental_command(cmd, args.incremental_realizer.as_deref());
            if incremental != *cmd {
                eprintln!("bmlr conformance: incremental-speech tests run on '{incremental}'");
            }
            let (cmd, incremental) = (this_bmlr(cmd), this_bmlr(&incremental));
            match started(ProcessPort::spawn_with(&cmd, &incremental)) {
                Ok(p) => Box::new(p),
                Err(e) => {
                    eprintln!("bmlr conformance: cannot start '{cmd}': {e}");
                    return ExitCode::from(2);
                }
            }
        }
    };
    let external = args.realizer.is_some() || args.mqtt.is_some() || args.stomp.is_some();
    let mut out = std::io::stdout().lock();
    let outcomes = run(port.as_mut(), &args.filter, |i, n, o: &Outcome| {
        let line = match &o.failure {
            None => format!("ok     {}", o.name),
            Some(f) => format!(
                "FAILED {}: {}",
                o.name,
                f.lines().next().unwrap_or_default()
            ),
        };
        let _ = writeln!(out, "{line}");
        let _ = out.flush();
        if let Some(f) = &o.failure {
            // the whole story (the feedback seen) for people
            eprintln!("--- {} ---\n{f}", o.name);
        }
        if external {
            eprintln!("[{}/{n}] {}", i + 1, o.name);
        }
    });
    let failed = outcomes.iter().filter(|o| o.failure.is_some()).count();
    let _ = writeln!(out, "{} passed, {} failed", outcomes.len() - failed, failed);
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

#[cfg(test)]
mod tests {
    use super::incremental_command;

    #[test]
    fn our_serve_gets_retimable_speech_for_the_incremental_tests() {
        assert_eq!(
            incremental_command("bmlr serve --stdio", None),
            "bmlr serve --stdio --retimable-speech"
        );
        assert_eq!(
            incremental_command("./target/release/bmlr serve --stdio", None),
            "./target/release/bmlr serve --stdio --retimable-speech"
        );
        assert_eq!(
            incremental_command("java -jar asap.jar", None),
            "java -jar asap.jar"
        );
        assert_eq!(incremental_command("bmlr serve --stdio", Some("x")), "x");
    }
}
