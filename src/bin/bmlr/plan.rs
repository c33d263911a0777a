//! `bmlr plan` and `bmlr timeline`: the planned sync times of blocks without running them, and
//! timeline pictures (SVG) of plans and logs.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use bml_realizer::language::feedback::Feedback;
use bml_realizer::planning::timing::SpeechTiming;
use bml_realizer::ports::timeline::Timeline;
use bml_realizer::realizer::Realizer;
use clap::Args;

use crate::setup::{read_items, with_assets, with_world, Item, LimitArgs};

/// Arguments of `bmlr plan`.
#[derive(Args)]
pub struct PlanArgs {
    /// Character for blocks without a characterId.
    #[arg(long, value_name = "ID")]
    character: Option<String>,
    /// A directory of motion data adding to the embedded defaults (see `bmlr run --assets`).
    #[arg(long, value_name = "DIR")]
    assets: Option<std::path::PathBuf>,
    /// A world file (JSON): named points and points moving along keyed paths, as targets of
    /// gaze, pointing and headDirectionShift, added to the built-in scene.
    #[arg(long, value_name = "WORLD.json")]
    pub world: Option<std::path::PathBuf>,
    /// Also draw the plan as a timeline picture (SVG) with the constraints as links.
    #[arg(long, value_name = "OUT.svg")]
    svg: Option<std::path::PathBuf>,
    #[command(flatten)]
    limits: LimitArgs,
    /// BML files, planned in order as if sent at once.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<String>,
}

/// `bmlr plan`: submits the files at time 0 without running the clock and prints each block's
/// predicted sync times (block-relative, and global in parentheses) and every warning.
pub fn plan(args: PlanArgs) -> ExitCode {
    let items = match read_items(&args.files) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("bmlr plan: {e}");
            return ExitCode::from(2);
        }
    };
    let mut realizer = match with_assets(
        Realizer::new(),
        args.assets.as_deref(),
        SpeechTiming::default(),
    ) {
        Ok(r) => r
            .with_default_character(args.character)
            .with_limits(args.limits.limits()),
        Err(e) => {
            eprintln!("bmlr plan: --assets {e}");
            return ExitCode::from(2);
        }
    };
    realizer = match with_world(realizer, args.world.as_deref()) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("bmlr plan: --world {e}");
            return ExitCode::from(2);
        }
    };
    let mut feedback = Vec::new();
    let mut blocks = Vec::new();
    let mut outcome = crate::outcome::Outcome::default();
    for item in items {
        match item {
            Item::Text(path, text) => {
                let parsed = realizer.perform_bml_from(&text, Some(&path));
                outcome.unparsed += usize::from(parsed.is_err());
                feedback.extend(realizer.tick(0.0).feedback);
                if let Ok(parsed) = bml_realizer::language::bml::load(&text) {
                    blocks.push(parsed.block);
                }
            }
            Item::Advance(_) | Item::Stdin => {
                eprintln!("bmlr plan: only files can be planned");
                return ExitCode::from(2);
            }
        }
    }
    if let Some(path) = &args.svg {
        let mut timeline = Timeline::from_feedback(&feedback);
        for b in &blocks {
            timeline.add_constraints(b);
        }
        if let Err(e) = write_svg(path, &timeline) {
            eprintln!("bmlr plan: {e}");
            return ExitCode::from(2);
        }
    }
    let mut out = std::io::stdout().lock();
    for line in plan_lines(&feedback) {
        if writeln!(out, "{line}").is_err() {
            break;
        }
    }
    outcome.note(&feedback);
    outcome.exit("plan")
}

/// The plan report: for each block's last full prediction, a header and one line per sync;
/// warnings as they came.
fn plan_lines(feedback: &[Feedback]) -> Vec<String> {
    let mut lines = Vec::new();
    for fb in feedback {
        match fb {
            Feedback::Prediction(p) if !p.behaviours.is_empty() => {
                for b in &p.blocks {
                    let start = b.global_start.unwrap_or(0.0);
                    lines.push(format!(
                        "{} start {:.3} end {}",
                        b.id,
                        start,
                        b.global_end
                            .map_or_else(|| "unknown".to_string(), |e| format!("{e:.3}"))
                    ));
                    for x in p.behaviours.iter().filter(|x| x.block == b.id) {
                        for (sync, t) in &x.syncs {
                            lines.push(format!(
                                "  {}:{}:{} {:.3} ({:.3})",
                                x.block,
                                x.behaviour,
                                sync,
                                t,
                                start + t
                            ));
                        }
                    }
                }
            }
            Feedback::Warning(w) => {
                lines.push(format!("warning {} {}: {}", w.id, w.kind.as_str(), w.text))
            }
            _ => {}
        }
    }
    lines
}

/// Writes a timeline picture and says so on stderr.
pub fn write_svg(path: &Path, timeline: &Timeline) -> Result<(), String> {
    std::fs::write(path, timeline.to_svg())
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let lanes: usize = timeline.blocks.iter().map(|b| b.lanes.len()).sum();
    eprintln!(
        "wrote {} ({} block{}, {lanes} behaviour{})",
        path.display(),
        timeline.blocks.len(),
        if timeline.blocks.len() == 1 { "" } else { "s" },
        if lanes == 1 { "" } else { "s" }
    );
    Ok(())
}

/// Arguments of `bmlr timeline`.
#[derive(Args)]
pub struct TimelineArgs {
    /// A feedback log (XML or JSON lines).
    log: std::path::PathBuf,
    /// The picture to write.
    #[arg(long, value_name = "OUT.svg", required = true)]
    svg: std::path::PathBuf,
}

/// `bmlr timeline LOG --svg OUT.svg`: draws what a log reports.
pub fn timeline(args: TimelineArgs) -> ExitCode {
    let text = match std::fs::read_to_string(&args.log) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("bmlr timeline: {}: cannot read: {e}", args.log.display());
            return ExitCode::from(2);
        }
    };
    let log = match bml_realizer::language::feedback::diff::Log::parse(&text) {
        Ok(l) => l,
        Err(e) => {
            eprintln!(
                "bmlr timeline: {}:{}: {}",
                args.log.display(),
                e.line,
                e.error
            );
            return ExitCode::from(2);
        }
    };
    let feedback: Vec<Feedback> = log.messages.into_iter().map(|(_, f)| f).collect();
    match write_svg(&args.svg, &Timeline::from_feedback(&feedback)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bmlr timeline: {e}");
            ExitCode::from(2)
        }
    }
}
