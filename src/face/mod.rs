//! The face: a state of FACS action units per character ([`model`]: which AUs, what each drives
//! among the ARKit blendshapes, the BML face lexemes and the visemes, all as data), the mixing of
//! overlapping expressions with a fading buffer ([`mixer`]), and the lids' own life: blinks and
//! lids that follow the eyes ([`blink`]). The face engine (`engines::face`) plays face
//! behaviours into it; each frame then turns the AUs into blendshape weights and opens the jaw.

pub mod blink;
pub mod mixer;
pub mod model;

pub use model::{Face, FaceModel, FaceState, Morphs, ARKIT, VISEMES};

/// How far the jaw joint (temporomandibular) opens at `jawOpen` = 1 (radians, about +x).
pub const JAW_OPEN: f32 = 0.35; // 20°
