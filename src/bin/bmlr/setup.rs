//! What the commands that run a realizer share (`run`, `view`, `serve`): the arguments that set a
//! realizer up (character, assets, world, voice, sight, nets, limits) and build it, the feedback
//! format, and the reading of the items given (files, directories, `-` for stdin).

use std::path::Path;

use bml_realizer::language::bml::Limits;
use bml_realizer::language::feedback::Format;
use bml_realizer::planning::timing::{SpeechTiming, Voice};
use bml_realizer::realizer::Realizer;
use clap::{Args, ValueEnum};

/// Feedback line format.
#[derive(Clone, Copy, ValueEnum)]
pub enum FormatArg {
    /// BML 1.0 feedback XML, one element per line.
    Xml,
    /// JSON lines.
    Jsonl,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Xml => Format::Xml,
            FormatArg::Jsonl => Format::Jsonl,
        }
    }
}

/// The character, motion data, world, idle layer and limits of a realizer on the virtual clock
/// (`bmlr run` and `bmlr view`).
#[derive(Args)]
pub struct SetupArgs {
    /// Character for blocks without a characterId.
    #[arg(long, value_name = "ID")]
    pub character: Option<String>,
    /// A directory of motion data adding to the embedded defaults: any of units.json (procedural
    /// units), gestures.json, poses.json and heads.json (bindings, which win over the embedded
    /// ones for what they bind) and compounds.json (compound physical controllers).
    #[arg(long, value_name = "DIR")]
    pub assets: Option<std::path::PathBuf>,
    /// A world file (JSON): named points and points moving along keyed paths, as targets of
    /// gaze, pointing and headDirectionShift, added to the built-in scene.
    #[arg(long, value_name = "WORLD.json")]
    pub world: Option<std::path::PathBuf>,
    /// Characters stand still between behaviours: no breathing, no weight shift, no blinks (the
    /// idle layer changes the motion only, never the feedback).
    #[arg(long)]
    pub no_idle: bool,
    /// The voice that says speech: the built-in TTS, flite (Debian package `flite`) or
    /// espeak-ng (Debian package `espeak-ng`).
    #[arg(long, value_enum, default_value = "builtin")]
    pub tts: TtsArg,
    /// The espeak-ng voice or language (`en`, `de`, `fr`, `pt-br`; `espeak-ng --voices` lists
    /// them) for --tts espeak; a speech's xml:lang overrides it.
    #[arg(long, value_name = "NAME")]
    pub voice: Option<String>,
    /// Characters see (synthetic vision, settings from the world file's "vision") and
    /// perception feedback reports what each sees when it changes.
    #[arg(long)]
    pub perception: bool,
    /// PaT-Nets (JSON, docs/nets.md) run with the behaviours; their transitions and the
    /// world variables' changes are reported. Nets that can go on changing keep a run going:
    /// give --until.
    #[arg(long, value_name = "NETS.json")]
    pub nets: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl SetupArgs {
    /// The realizer asked for (`posix_time`: feedback carries wall-clock times); the error
    /// names the option that is wrong.
    pub fn realizer(&self, posix_time: bool) -> Result<Realizer, String> {
        let speech = (self.tts.timing(self.voice.as_deref())).map_err(|e| format!("--tts: {e}"))?;
        let realizer = with_assets(Realizer::new(), self.assets.as_deref(), speech)
            .map_err(|e| format!("--assets {e}"))?;
        let mut realizer = with_world(realizer, self.world.as_deref())
            .map_err(|e| format!("--world {e}"))?
            .with_default_character(self.character.clone())
            .with_posix_time(posix_time)
            .with_idle(!self.no_idle)
            .with_limits(self.limits.limits());
        realizer = with_sight_and_nets(realizer, self.perception, self.nets.as_deref())?;
        Ok(realizer)
    }
}

/// The limits on one block (`docs/cli.md`, "Limits"), shared by the commands that read BML.
#[derive(Args, Clone, Copy)]
pub struct LimitArgs {
    /// Deepest nesting of elements in a block (the `<bml>` root counts as 1).
    #[arg(long, value_name = "N", default_value_t = Limits::default().depth)]
    max_depth: usize,
    /// Most attributes on one element (and namespace declarations in scope).
    #[arg(long, value_name = "N", default_value_t = Limits::default().attributes)]
    max_attributes: usize,
    /// Largest block, in bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::default().block_bytes)]
    max_block_bytes: usize,
    /// Most behaviours in one block.
    #[arg(long, value_name = "N", default_value_t = Limits::default().behaviours)]
    max_behaviours: usize,
    /// Largest absolute time or offset in a sync reference, seconds (at most 1e9).
    #[arg(long, value_name = "SECS", default_value_t = Limits::default().time, value_parser = max_time)]
    max_time: f64,
}

/// A `--max-time` value: a number of seconds above 0 and at most the furthest a schedule may go.
fn max_time(s: &str) -> Result<f64, String> {
    let bound = bml_realizer::planning::schedule::strategy::MAX_SCHEDULED_TIME;
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= bound => Ok(t),
        _ => Err(format!("expected seconds above 0 and at most {bound}")),
    }
}

impl LimitArgs {
    /// The limits asked for.
    pub fn limits(&self) -> Limits {
        Limits {
            depth: self.max_depth,
            attributes: self.max_attributes,
            block_bytes: self.max_block_bytes,
            behaviours: self.max_behaviours,
            time: self.max_time,
        }
    }
}

/// `realizer` with the motion data of `dir` (units and bindings), if given, and speech timed by
/// `speech`.
pub fn with_assets(
    realizer: Realizer,
    dir: Option<&Path>,
    speech: SpeechTiming,
) -> Result<Realizer, String> {
    let Some(dir) = dir else {
        if speech == SpeechTiming::default() {
            return Ok(realizer);
        }
        return Ok(realizer.with_speech_timing(speech));
    };
    let assets = bml_realizer::engines::assets::Assets::from_dir(dir)?;
    Ok(realizer.with_engines(move || {
        bml_realizer::engines::registry_with(
            bml_realizer::planning::timing::DefaultTimingModels { speech },
            &assets,
        )
    }))
}

/// The voice that says speech (`--tts`).
#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Default)]
pub enum TtsArg {
    /// The built-in TTS: timing and lips, no sound.
    #[default]
    Builtin,
    /// CMU Flite as a program (Debian package `flite`): its timing and its sound.
    Flite,
    /// espeak-ng as a program (Debian package `espeak-ng`): its sound in its languages (--voice,
    /// or xml:lang on a speech), its phonemes timed to it.
    Espeak,
}

impl TtsArg {
    /// The speech timing of this voice (espeak-ng's `voice`, else its English); for flite and
    /// espeak-ng, an error if the program is not installed or lacks the voice, and a voice
    /// asked of another TTS is an error too.
    pub fn timing(self, voice: Option<&str>) -> Result<SpeechTiming, String> {
        use bml_realizer::character::voice::espeak::{Espeak, VoiceName};
        if voice.is_some() && self != TtsArg::Espeak {
            return Err("--voice names an espeak-ng voice: give --tts espeak".into());
        }
        let voice = match self {
            TtsArg::Builtin => Voice::Builtin,
            TtsArg::Flite => {
                bml_realizer::character::voice::flite::Flite::default().check()?;
                Voice::Flite
            }
            TtsArg::Espeak => {
                let name = voice.map_or(Ok(VoiceName::default()), VoiceName::new)?;
                Espeak::new(name).check()?;
                Voice::Espeak(name)
            }
        };
        Ok(SpeechTiming {
            voice,
            ..SpeechTiming::default()
        })
    }
}

/// `realizer` with sight reported (`perception`) and the nets of the file at `nets`, if
/// given. The error names the option and the file.
pub fn with_sight_and_nets(
    mut realizer: Realizer,
    perception: bool,
    nets: Option<&Path>,
) -> Result<Realizer, String> {
    if perception {
        let vision = realizer.world().vision();
        realizer.set_perception(Some(vision), true)?;
    }
    if let Some(path) = nets {
        let at = path.display();
        let text = std::fs::read_to_string(path).map_err(|e| format!("--nets {at}: {e}"))?;
        let nets = bml_realizer::world::nets::file::read(&text, realizer.limits())
            .map_err(|e| format!("--nets {at}: {e}"))?;
        let variables = realizer.world().variables().clone();
        let nets = bml_realizer::world::nets::Nets::new(nets, variables);
        realizer.set_nets(Some(nets), true)?;
    }
    Ok(realizer)
}

/// `realizer` in the world of the file at `path`, if given. The error names the file.
pub fn with_world(mut realizer: Realizer, path: Option<&Path>) -> Result<Realizer, String> {
    let Some(path) = path else {
        return Ok(realizer);
    };
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (world, _obstacles) = bml_realizer::world::World::from_json(&text)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    *realizer.world_mut() = world;
    Ok(realizer)
}

/// An item of the command line, read before anything runs.
pub enum Item {
    /// A file's name and text.
    Text(String, String),
    Advance(f64),
    Stdin,
}

/// Most `.xml` files a directory on the command line may hold.
pub const MAX_DIRECTORY_FILES: usize = 20_000;

/// The `.xml` files in directory `dir`, by name, or why not.
fn xml_files(dir: &Path) -> Result<Vec<String>, String> {
    let cannot = |e: std::io::Error| format!("{}: cannot read the directory: {e}", dir.display());
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(cannot)? {
        let path = entry.map_err(cannot)?.path();
        if path.is_file() && path.extension().is_some_and(|x| x == "xml") {
            files.push(path.to_string_lossy().into_owned());
        }
    }
    if files.is_empty() || files.len() > MAX_DIRECTORY_FILES {
        return Err(format!(
            "{}: a directory must hold 1 to {MAX_DIRECTORY_FILES} .xml files, not {}",
            dir.display(),
            files.len()
        ));
    }
    files.sort();
    Ok(files)
}

/// The items of a command line: files read (a directory: its `.xml` files by name), clock
/// advances checked.
pub fn read_items(items: &[String]) -> Result<Vec<Item>, String> {
    let mut expanded = Vec::new();
    for a in items {
        if Path::new(a).is_dir() {
            expanded.extend(xml_files(Path::new(a))?);
        } else {
            expanded.push(a.clone());
        }
    }
    expanded
        .iter()
        .map(|a| {
            if a == "-" {
                Ok(Item::Stdin)
            } else if a.starts_with('+') {
                bml_realizer::language::bml::advance(a)
                    .map(Item::Advance)
                    .ok_or_else(|| {
                        format!(
                            "'{a}' is not a clock advance: expected +SECS with SECS a number >= 0"
                        )
                    })
            } else {
                std::fs::read_to_string(Path::new(a))
                    .map(|text| Item::Text(a.clone(), text))
                    .map_err(|e| format!("{a}: cannot read: {e}"))
            }
        })
        .collect()
}
