//! `bmlr`: the command-line front end of the BML realizer.

/// Like std's `eprintln!`, but a closed stderr (`bmlr validate *.xml 2>&1 | head -1`) loses the
/// line instead of panicking, as a closed stdout loses what is written there. Defined before
/// the modules, it is the `eprintln!` of the whole command line.
macro_rules! eprintln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod avatar;
mod broker_port;
mod brokered;
mod conformance;
mod dialect;
mod diff;
mod live;
mod live_frames;
mod outcome;
mod pack;
mod plan;
mod record;
mod run;
mod serve;
mod serve_broker;
mod setup;
mod spool;
mod tcp;
mod view;
mod web;
mod world_share;

use std::path::PathBuf;
use std::process::ExitCode;

use bml_realizer::engines::interface::Registry;
use bml_realizer::language::bml::{self, Diagnostic, Severity};
use bml_realizer::planning::schedule::check::timing_diagnostics;
use bml_realizer::planning::timing::DefaultTimingModels;
use clap::{Parser, Subcommand};

/// The BML realizer command line.
#[derive(Parser)]
#[command(
    name = "bmlr",
    version,
    about = "Realize, plan and check BML 1.0 (+BMLA/BMLT) blocks"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Realize BML: send files in order on a virtual clock (default) and print the feedback.
    Run(run::RunArgs),
    /// Schedule BML files without executing them; print every sync point's time.
    Plan(plan::PlanArgs),
    /// Realize BML on the virtual clock and show it on a web page: the character in 3D, the
    /// timeline and the feedback (--out DIR writes the page, --serve ADDR serves it).
    View(view::ViewArgs),
    /// Draw a feedback log as a timeline picture (SVG).
    Timeline(plan::TimelineArgs),
    /// Compare two feedback logs (XML or JSON lines) modulo clock origin, posix times and jitter.
    Diff(diff::DiffArgs),
    /// Serve the realizer port: one `<bml>` block per input line, one feedback element per output line.
    Serve(serve::ServeArgs),
    /// Run the RealizerTester conformance suite; last line "N passed, M failed".
    Conformance(conformance::ConformanceArgs),
    /// Parse and check BML files; print file:line:col diagnostics. Exit 1 if any file is invalid.
    Validate {
        /// BML files (one `<bml>` block each).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Print nothing for valid files.
        #[arg(short, long)]
        quiet: bool,
        #[command(flatten)]
        limits: setup::LimitArgs,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate {
            files,
            quiet,
            limits,
        } => validate(&files, quiet, &limits.limits()),
        Command::Run(args) => run::run(args),
        Command::Plan(args) => plan::plan(args),
        Command::Diff(args) => diff::run(args),
        Command::View(args) => view::view(args),
        Command::Timeline(args) => plan::timeline(args),
        Command::Serve(args) => serve::serve(args),
        Command::Conformance(args) => conformance::conformance(args),
    }
}

/// Warnings for the behaviours that the built-in engines would play with their timing only (a
/// lexeme no binding defines), where the language check has not warned about the lexeme already.
fn unanimated(block: &bml::Block, models: &Registry, diags: &[Diagnostic]) -> Vec<Diagnostic> {
    block
        .behaviours
        .iter()
        .filter(|b| {
            !diags.iter().any(|d| {
                d.code == bml::Code::UnknownLexeme
                    && (d.pos.line, d.pos.col) == (b.pos.line, b.pos.col)
            })
        })
        .filter_map(|b| {
            let why = models.unanimated(b)?;
            Some(Diagnostic::warning(bml::Code::UnknownLexeme, b.pos, why))
        })
        .collect()
}

fn validate(files: &[PathBuf], quiet: bool, limits: &bml::Limits) -> ExitCode {
    use std::io::Write;
    // a reader that stops early (`| head`) is no error: what is left is not printed
    let mut out = std::io::stdout().lock();
    let models = bml_realizer::engines::default_registry(DefaultTimingModels::default());
    let (mut invalid, mut unreadable) = (0usize, 0usize);
    for f in files {
        let text = match std::fs::read_to_string(f) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("{}: cannot read: {e}", f.display());
                unreadable += 1;
                continue;
            }
        };
        let (block, mut diags) = bml::check_with(&text, limits);
        // what the scheduler would refuse, once the block itself is valid
        if let Some(block) = block.filter(|_| diags.iter().all(|d| d.severity != Severity::Error)) {
            diags.extend(timing_diagnostics(&block, &models));
            diags.extend(unanimated(&block, &models, &diags));
            diags.sort_by_key(|d| (d.pos.line, d.pos.col));
        }
        let errors = diags
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count();
        for d in &diags {
            let _ = writeln!(out, "{}:{d}", f.display());
        }
        if errors > 0 {
            invalid += 1;
        } else if !quiet {
            let warnings = diags.len();
            if warnings == 0 {
                let _ = writeln!(out, "{}: valid", f.display());
            } else {
                let _ = writeln!(
                    out,
                    "{}: valid ({warnings} warning{})",
                    f.display(),
                    if warnings == 1 { "" } else { "s" }
                );
            }
        }
    }
    let total = files.len();
    eprintln!(
        "{} file{} checked: {} valid, {} invalid{}",
        total,
        if total == 1 { "" } else { "s" },
        total - invalid - unreadable,
        invalid,
        if unreadable > 0 {
            format!(", {unreadable} unreadable")
        } else {
            String::new()
        }
    );
    if unreadable > 0 {
        ExitCode::from(2)
    } else if invalid > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
