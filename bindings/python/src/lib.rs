//! The Python package `bmlr` (its native part, `bmlr._bmlr`): a [`Realizer`] a Python host
//! drives with its own clock — BML in, feedback out as the dicts of `bmlr run --format jsonl`,
//! each character's pose as a numpy array (joints × x y z w), root, and ARKit blendshapes —
//! plus `validate` and `BmlError`. The realizer sits behind a mutex that is only ever waited
//! for with the GIL released, so a realizer shared by Python threads serialises them instead of
//! failing, and `tick` lets other Python threads run while it works.

use std::sync::{Mutex, MutexGuard};

use bml_realizer::character::avatar::{
    animated_glb, default_model, Frame as AvatarFrame, Retarget,
};
use bml_realizer::character::body::Skeleton;
use bml_realizer::character::face::ARKIT;
use bml_realizer::engines::interface::{CharacterPose, Frame};
use bml_realizer::language::feedback::Format;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

create_exception!(
    _bmlr,
    BmlError,
    PyException,
    "A BML block the realizer refused."
);

/// A root: its position (3,) and rotation (4,).
type Root<'py> = (Bound<'py, PyArray1<f32>>, Bound<'py, PyArray1<f32>>);

/// What the realizer holds between calls.
struct State {
    realizer: bml_realizer::realizer::Realizer,
    /// The last tick's frame.
    frame: Option<Frame>,
    /// Every tick's characters, when recording (for `write_glb`).
    recorded: Option<Vec<(f64, Vec<CharacterPose>)>>,
    /// Where the world placed each character when the realizer was made: an avatar's travel
    /// is scaled by leg length from there (its placement moves as it walks).
    start: std::collections::HashMap<String, bml_realizer::world::Placement>,
    /// The frame rate of `step`, and the steps taken.
    fps: f64,
    steps: u64,
}

/// A realizer: `perform` BML blocks, `tick` it with your clock, read feedback and bodies.
#[pyclass(module = "bmlr._bmlr")]
struct Realizer {
    state: Mutex<State>,
    joint_names: Vec<String>,
}

impl State {
    /// Advances to `now`: the frame kept (and recorded), its feedback as JSON lines.
    fn tick(&mut self, now: f64) -> Vec<String> {
        // the last frame goes first: its memory is reused for the new one (see bmlr-c)
        self.frame = None;
        let frame = self.realizer.tick(now);
        let lines = frame
            .feedback
            .iter()
            .map(|f| Format::Jsonl.encode(f))
            .collect();
        if let Some(r) = self.recorded.as_mut() {
            r.push((now, frame.poses.clone()));
        }
        self.frame = Some(frame);
        lines
    }
}

/// Feedback lines as Python dicts.
fn dicts<'py>(py: Python<'py>, lines: &[String]) -> PyResult<Bound<'py, PyList>> {
    if lines.is_empty() {
        return Ok(PyList::empty(py));
    }
    let loads = py.import("json")?.getattr("loads")?;
    let dicts = (lines.iter())
        .map(|l| loads.call1((l,)))
        .collect::<PyResult<Vec<_>>>()?;
    PyList::new(py, dicts)
}

/// Runs `f` on the realizer's state with the GIL released (waiting for another thread's call to
/// finish if there is one).
fn with_state<T: Send>(
    py: Python<'_>,
    state: &Mutex<State>,
    f: impl FnOnce(&mut State) -> Result<T, String> + Send,
) -> PyResult<T> {
    py.detach(|| {
        let mut guard: MutexGuard<State> = state.lock().map_err(|_| {
            "the realizer failed in an earlier call (a bug); make a new one".to_string()
        })?;
        f(&mut guard)
    })
    .map_err(error)
}

/// Character `id`'s pose in the last frame.
fn find_character<'a>(state: &'a State, id: &str) -> Result<&'a CharacterPose, String> {
    let frame = state
        .frame
        .as_ref()
        .ok_or("no frame yet: call tick first")?;
    (frame.character(id)).ok_or_else(|| format!("no character '{id}' in the last frame"))
}

/// A failure as a Python exception: a character that is not there is a KeyError.
fn error(e: String) -> PyErr {
    if e.starts_with("no character") {
        PyKeyError::new_err(e)
    } else {
        PyRuntimeError::new_err(e)
    }
}

/// A stream's refusal: an unknown stream is a KeyError, a refused chunk a ValueError.
fn refusal(e: String) -> PyErr {
    if e.starts_with("no stream") {
        PyKeyError::new_err(e)
    } else {
        PyValueError::new_err(e)
    }
}

#[pymethods]
impl Realizer {
    /// A realizer in `world` (a dict as in a world file, or a path to one), speaking with `tts`
    /// ("builtin" or "flite"), alive between behaviours when `idle`, blocks without a
    /// characterId for `character`; `record=True` keeps every frame for `write_glb`.
    #[new]
    #[pyo3(signature = (world=None, tts="builtin", idle=true, character=None, record=false, fps=60.0))]
    fn new(
        world: Option<&Bound<'_, PyAny>>,
        tts: &str,
        idle: bool,
        character: Option<String>,
        record: bool,
        fps: f64,
    ) -> PyResult<Realizer> {
        let world: Option<serde_json::Value> = match world {
            None => None,
            Some(w) if w.is_instance_of::<PyDict>() => {
                let json = w.py().import("json")?.call_method1("dumps", (w,))?;
                let text: String = json.extract()?;
                Some(
                    serde_json::from_str(&text)
                        .map_err(|e| PyValueError::new_err(e.to_string()))?,
                )
            }
            Some(w) => {
                let path: std::path::PathBuf = w.extract()?;
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    PyValueError::new_err(format!("{}: cannot read it: {e}", path.display()))
                })?;
                Some(serde_json::from_str(&text).map_err(|e| {
                    PyValueError::new_err(format!("{}: not JSON: {e}", path.display()))
                })?)
            }
        };
        let mut options =
            serde_json::json!({"tts": tts, "idle": idle, "character": character, "fps": fps});
        if let Some(w) = world {
            options["world"] = w;
        }
        let (realizer, fps) = bml_realizer::realizer::from_options(&options.to_string())
            .map_err(PyValueError::new_err)?;
        let start = (realizer.world().placements())
            .map(|(id, at)| (id.to_string(), at))
            .collect();
        Ok(Realizer {
            state: Mutex::new(State {
                start,
                realizer,
                frame: None,
                recorded: record.then(Vec::new),
                fps,
                steps: 0,
            }),
            joint_names: Skeleton::adult()
                .joints()
                .iter()
                .map(|j| j.name.clone())
                .collect(),
        })
    }

    /// Hands the realizer one `<bml>` block; a block it refuses raises `BmlError` (its
    /// warning feedback also comes with the next tick).
    fn perform(&self, py: Python<'_>, text: String) -> PyResult<()> {
        let refused = with_state(py, &self.state, |s| {
            Ok(s.realizer.perform_bml(&text).err().map(|e| e.to_string()))
        })?;
        match refused {
            Some(e) => Err(BmlError::new_err(e)),
            None => Ok(()),
        }
    }

    /// Advances to `now` (seconds on your clock): what is due happens; returns the feedback
    /// sent since the last tick, as dicts (the JSON lines of `bmlr run --format jsonl`).
    fn tick<'py>(&self, py: Python<'py>, now: f64) -> PyResult<Bound<'py, PyList>> {
        if !now.is_finite() {
            return Err(PyValueError::new_err(format!("now is {now}")));
        }
        let lines = with_state(py, &self.state, |s| Ok(s.tick(now)))?;
        dicts(py, &lines)
    }

    /// Advances by one frame at `fps` (the first step at time 0, the k-th at k / fps), for a
    /// host without a clock of its own: (the step's time, its feedback as dicts). Use either
    /// this or `tick`.
    fn step<'py>(&self, py: Python<'py>) -> PyResult<(f64, Bound<'py, PyList>)> {
        let (t, lines) = with_state(py, &self.state, |s| {
            let t = s.steps as f64 / s.fps;
            s.steps += 1;
            Ok((t, s.tick(t)))
        })?;
        Ok((t, dicts(py, &lines)?))
    }

    /// For the overhead bench (`benches/tick.py`): `n` ticks from `start`, `dt` apart, made in
    /// Rust without returning to Python; the seconds they took.
    fn _rust_ticks(&self, py: Python<'_>, start: f64, n: usize, dt: f64) -> PyResult<f64> {
        with_state(py, &self.state, |s| {
            let clock = std::time::Instant::now();
            for k in 0..n {
                std::hint::black_box(s.realizer.tick(start + k as f64 * dt));
            }
            Ok(clock.elapsed().as_secs_f64())
        })
    }

    /// Opens the audio stream `name` for `character` (None: blocks without a characterId);
    /// open it before performing the block whose `<speech bmlt:stream="NAME">` plays it, timed
    /// by `start="anticipators:NAME:start" end="anticipators:NAME:end"`. Opening a name again
    /// replaces the stream.
    #[pyo3(signature = (name, character=None))]
    fn open_stream(&self, py: Python<'_>, name: String, character: Option<String>) -> PyResult<()> {
        if name.is_empty() {
            return Err(PyValueError::new_err("the stream's name is empty"));
        }
        with_state(py, &self.state, |s| {
            let character = character.as_deref().filter(|c| !c.is_empty());
            s.realizer.open_stream(character, &name);
            Ok(())
        })
    }

    /// Adds a chunk to the stream `name`: `pcm` mono 16-bit samples (a numpy int16 array) at
    /// `rate` Hz (every chunk of a stream at the same rate), with the chunk's `marks` (Amazon
    /// Polly speech marks as JSON lines, or a word list as JSON; times in the stream's time,
    /// from its first sample). A chunk the stream refuses (another rate, the stream ended or
    /// full, marks that do not parse) raises ValueError; an unknown name KeyError.
    #[pyo3(signature = (name, pcm, rate, marks=None))]
    fn push_audio(
        &self,
        py: Python<'_>,
        name: String,
        pcm: PyReadonlyArray1<'_, i16>,
        rate: u32,
        marks: Option<String>,
    ) -> PyResult<()> {
        let pcm = pcm.as_slice()?.to_vec();
        let refused = with_state(py, &self.state, |s| {
            Ok(s.realizer
                .push_audio(&name, &pcm, rate, marks.as_deref())
                .err())
        })?;
        refused.map_or(Ok(()), |e| Err(refusal(e)))
    }

    /// Ends the stream `name`: the speech playing it ends with its sound.
    fn end_audio(&self, py: Python<'_>, name: String) -> PyResult<()> {
        let refused = with_state(py, &self.state, |s| Ok(s.realizer.end_audio(&name).err()))?;
        refused.map_or(Ok(()), |e| Err(refusal(e)))
    }

    /// The sounds character `character` makes in the last frame: (id, seconds into the
    /// sound) each, the id being `block:behaviour`.
    #[pyo3(signature = (character=""))]
    fn sounds(&self, py: Python<'_>, character: &str) -> PyResult<Vec<(String, f64)>> {
        with_state(py, &self.state, |s| {
            let now = s.frame.as_ref().map_or(0.0, |f| f.time);
            Ok((find_character(s, character)?.sounds.iter())
                .map(|p| (p.id.clone(), now - p.start))
                .collect())
        })
    }

    /// When the next thing is due, or None when nothing more is scheduled.
    fn next_event(&self, py: Python<'_>) -> PyResult<Option<f64>> {
        with_state(py, &self.state, |s| Ok(s.realizer.next_event()))
    }

    /// The characters in the last frame ("" is the default one).
    fn characters(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        with_state(py, &self.state, |s| {
            Ok((s.frame.iter().flat_map(|f| &f.poses))
                .map(|p| p.character.clone().unwrap_or_default())
                .collect())
        })
    }

    /// The joints' H-Anim names, in the order of `pose`'s rows.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joint_names.clone()
    }

    /// The 52 ARKit blendshape names, in the order `morphs` uses.
    #[getter]
    fn morph_names(&self) -> Vec<&'static str> {
        ARKIT.to_vec()
    }

    /// Character `character`'s local joint rotations in the last frame, relative to the rest
    /// pose: a float32 array of (joints, 4), quaternions x y z w in `joint_names` order.
    #[pyo3(signature = (character=""))]
    fn pose<'py>(&self, py: Python<'py>, character: &str) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let values = with_state(py, &self.state, |s| {
            let p = find_character(s, character)?;
            Ok(p.pose
                .rotations
                .iter()
                .flat_map(|q| q.normalize().to_array())
                .collect::<Vec<f32>>())
        })?;
        let n = values.len() / 4;
        let array = Array2::from_shape_vec((n, 4), values).expect("4 floats a joint");
        Ok(array.into_pyarray(py))
    }

    /// Character `character`'s root (HumanoidRoot) in the world in the last frame: (position
    /// (3,), rotation x y z w (4,)).
    #[pyo3(signature = (character=""))]
    fn root<'py>(&self, py: Python<'py>, character: &str) -> PyResult<Root<'py>> {
        let (p, q) = with_state(py, &self.state, |s| {
            let c = find_character(s, character)?;
            let world = c.pose.world(&Skeleton::adult());
            Ok((
                world.positions[0].to_array(),
                world.orientations[0].normalize().to_array(),
            ))
        })?;
        Ok((p.to_vec().into_pyarray(py), q.to_vec().into_pyarray(py)))
    }

    /// Character `character`'s ARKit blendshape weights in the last frame, by name (all 52,
    /// in `morph_names` order).
    #[pyo3(signature = (character=""))]
    fn morphs<'py>(&self, py: Python<'py>, character: &str) -> PyResult<Bound<'py, PyDict>> {
        let w = with_state(py, &self.state, |s| {
            Ok(find_character(s, character)?.face.morphs.0)
        })?;
        let dict = PyDict::new(py);
        for (name, weight) in ARKIT.iter().zip(w) {
            dict.set_item(name, weight)?;
        }
        Ok(dict)
    }

    /// Writes character `character`'s recorded motion and face on the default avatar as a
    /// binary glTF (needs `record=True`).
    #[pyo3(signature = (path, character=""))]
    fn write_glb(&self, py: Python<'_>, path: std::path::PathBuf, character: &str) -> PyResult<()> {
        let bytes = with_state(py, &self.state, |s| {
            let recorded = s
                .recorded
                .as_ref()
                .ok_or("write_glb needs Realizer(record=True)")?;
            let model = default_model();
            let mut retarget =
                Retarget::new(&model, &Skeleton::adult(), None).map_err(|e| e.to_string())?;
            retarget.place_at(s.start.get(character).copied().unwrap_or_default());
            let poses: Vec<(f64, &CharacterPose)> = (recorded.iter())
                .filter_map(|(t, ps)| {
                    let p = ps
                        .iter()
                        .find(|p| p.character.as_deref().unwrap_or("") == character)?;
                    Some((*t, p))
                })
                .collect();
            if poses.is_empty() {
                return Err(format!(
                    "no frames of character '{character}' were recorded"
                ));
            }
            let frames: Vec<AvatarFrame> = (poses.iter())
                .map(|(t, p)| AvatarFrame {
                    time: *t,
                    pose: &p.pose,
                    face: &p.face,
                })
                .collect();
            let name = if character.is_empty() {
                "bml"
            } else {
                character
            };
            Ok(animated_glb(&model, &retarget, &frames, name))
        })?;
        std::fs::write(&path, bytes)
            .map_err(|e| PyRuntimeError::new_err(format!("{}: {e}", path.display())))
    }
}

/// The problems of one BML block, as dicts: line, col, severity ("error" or "warning"),
/// code, message. An empty list: the block is valid.
#[pyfunction]
fn validate(py: Python<'_>, text: String) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let (_, diags) = py.detach(|| bml_realizer::language::bml::check(&text));
    diags
        .iter()
        .map(|d| {
            let dict = PyDict::new(py);
            dict.set_item("line", d.pos.line)?;
            dict.set_item("col", d.pos.col)?;
            dict.set_item("severity", if d.is_error() { "error" } else { "warning" })?;
            dict.set_item("code", d.code.as_str())?;
            dict.set_item("message", &d.message)?;
            Ok(dict)
        })
        .collect()
}

/// The native module.
#[pymodule]
fn _bmlr(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Realizer>()?;
    m.add_function(wrap_pyfunction!(validate, m)?)?;
    m.add("BmlError", m.py().get_type::<BmlError>())?;
    Ok(())
}
