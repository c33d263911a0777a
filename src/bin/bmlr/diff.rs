//! `bmlr diff A.log B.log [--tolerance SECS]`: compares two feedback logs (XML or JSON lines)
//! modulo clock origin, posix times and timing jitter (`feedback::diff`).

use std::path::PathBuf;
use std::process::ExitCode;

use bml_realizer::language::feedback::diff::{diff, Log};
use clap::Args;

/// Arguments of `bmlr diff`.
#[derive(Args)]
pub struct DiffArgs {
    /// The reference log.
    a: PathBuf,
    /// The log compared with it.
    b: PathBuf,
    /// Times closer than this (seconds) are equal.
    #[arg(long, value_name = "SECS", default_value_t = 0.1)]
    tolerance: f64,
}

fn read(path: &PathBuf) -> Result<Log, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    Log::parse(&text).map_err(|e| format!("{}:{}: {}", path.display(), e.line, e.error))
}

/// `bmlr diff`: exit 0 equal, 1 different, 2 unreadable input.
pub fn run(args: DiffArgs) -> ExitCode {
    use std::io::Write;
    // a reader that stops early (`| head`) is no error: what is left is not printed
    let mut out = std::io::stdout().lock();
    if !(args.tolerance.is_finite() && args.tolerance >= 0.0) {
        eprintln!("bmlr diff: --tolerance must be a number of seconds >= 0");
        return ExitCode::from(2);
    }
    let (a, b) = match (read(&args.a), read(&args.b)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("bmlr diff: {e}");
            return ExitCode::from(2);
        }
    };
    let differences = diff(&a, &b, args.tolerance);
    let _ = writeln!(out, "A = {}", args.a.display());
    let _ = writeln!(out, "B = {}", args.b.display());
    for d in &differences {
        let _ = writeln!(out, "{d}");
    }
    if differences.is_empty() {
        let _ = writeln!(
            out,
            "equal: {} messages, times within {} s",
            a.messages.len(),
            args.tolerance
        );
        ExitCode::SUCCESS
    } else {
        let n = differences.len();
        let _ = writeln!(out, "{n} difference{}", if n == 1 { "" } else { "s" });
        ExitCode::from(1)
    }
}
