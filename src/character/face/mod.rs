//! The face: a state of FACS action units per character ([`model`]: which AUs, what each drives
//! among the ARKit blendshapes, the BML face lexemes and the visemes, all as data), the mixing of
//! overlapping expressions with a fading buffer ([`mixer`]). The face engine (`engines::face`)
//! plays face behaviours into it; each frame then turns the AUs into blendshape weights. The
//! face knows nothing of the body: what couples them (lids following the eyes, blinks, the jaw
//! opened by the mouth) is in `character`.

pub mod mixer;
pub mod model;

pub use model::{Face, FaceModel, FaceState, Morphs, ARKIT, VISEMES};
