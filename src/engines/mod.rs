//! The built-in engines and the default registry that maps every BML 1.0, BMLA and BMLT behaviour
//! kind to one of them:
//!
//! - [`interface`]: what every engine is (the `Engine` trait, its capabilities, units), the
//!   registry from kinds to engines, and the frame engines write into;
//! - [`assets`]: the motion data (units and bindings), embedded or read from a directory;
//! - [`audio`]: BMLT `audiofile` as WAV clips, timed by their length;
//! - [`control`]: `wait`, `interrupt`, `activate`, `parametervaluechange`;
//! - [`speech`]: `speech` and `bmlt:text` with the headless speech timing model, `volume` settable
//!   while speaking;
//! - [`timing_only`]: BMLT audio's fallback timing: it plays the scheduled pegs and reports every
//!   sync point;
//! - [`locomotion`]: `locomotion` as a character walking there (steering, paths, a gait);
//! - [`murml`]: MURML gestures and faces, timed from their keyframes (timing only as well);
//! - [`face`]: face, faceLexeme, faceFacs, faceShift and BMLT facemorph as FACS action units and
//!   ARKit blendshapes, mixed through a fading buffer;
//! - [`head`]: head nods, shakes and tilts as real motion of the neck and skull;
//! - [`head_direction`]: `headDirectionShift` turns the head toward a world point, for good;
//! - [`gaze`]: gaze and gaze shifts as real motion of eyes, neck and trunk toward world targets;
//! - [`pointing`]: pointing as real arm motion (two-link IK) toward world targets;
//! - [`keyframe`]: BMLT keyframe animations (SkeletonInterpolator), slerped between exact keys;
//! - [`gesture`]: gesture lexemes as arm motion from a bindings file (the default lexicon);
//! - [`posture`]: posture stances (standing, sitting, crouching, lying) as leg and root motion;
//! - [`procedural`]: BMLT procanimation(gesture) as procedural units from data (expressions, IK);
//! - [`noise`]: BMLT Perlin noise on a joint, added on top of the other engines;
//! - [`transition`]: BMLT transitions from the current pose to the predicted one.

pub mod interface;

pub mod assets;
pub mod audio;
pub mod control;
pub mod expr;
pub mod face;
pub mod gaze;
pub mod gesture;
pub mod head;
pub mod head_direction;
pub mod keyframe;
pub mod locomotion;
pub mod motion;
pub mod murml;
pub mod noise;
pub mod physical;
pub mod pointing;
pub mod posture;
pub mod procedural;
pub mod speech;
pub mod timing_only;
pub mod transition;

use crate::engines::interface::{KindKey, Registry};
use crate::language::bml::{NS_BML, NS_BMLA, NS_BMLT, NS_CORE_EXT};
use crate::planning::timing::DefaultTimingModels;

/// Kinds the face engine realizes (namespace, element).
pub const FACE_KINDS: &[(&str, &str)] = &[
    (NS_BML, "face"),
    (NS_BML, "faceLexeme"),
    (NS_BML, "faceShift"),
    (NS_CORE_EXT, "faceFacs"),
    (NS_BMLT, "facemorph"),
];

fn keys(kinds: &[(&str, &str)]) -> Vec<KindKey> {
    kinds.iter().map(|(ns, n)| KindKey::new(ns, n)).collect()
}

/// A registry with every built-in engine, using `models` for timing and the embedded motion data.
pub fn default_registry(models: DefaultTimingModels) -> Registry {
    registry_with(models, &assets::Assets::default())
}

/// A registry with every built-in engine, using `models` for timing and `assets` for the motion
/// engines' units and bindings.
pub fn registry_with(models: DefaultTimingModels, assets: &assets::Assets) -> Registry {
    let mut r = Registry::new();
    r.register(
        Box::new(control::ControlEngine::default()),
        &keys(&[
            (NS_BML, "wait"),
            (NS_BMLA, "interrupt"),
            (NS_BMLA, "activate"),
            (NS_BMLA, "parametervaluechange"),
        ]),
    );
    r.register(
        Box::new(speech::SpeechEngine::new(models.speech)),
        &keys(&[(NS_BML, "speech"), (NS_BMLT, "text")]),
    );
    r.register(Box::new(face::FaceEngine::default()), &keys(FACE_KINDS));
    r.register(
        Box::new(audio::AudioEngine::default()),
        &keys(&[(NS_BMLT, "audiofile")]),
    );
    // keyframes set joint rotations; the engines after them add to or aim from them
    r.register(
        Box::new(keyframe::KeyframeEngine::default()),
        &keys(&[(NS_BMLT, "keyframe")]),
    );
    r.register(
        Box::new(procedural::ProceduralEngine::new(assets.units.clone())),
        &keys(&[
            (NS_BMLT, "procanimation"),
            (NS_BMLT, "procanimationgesture"),
        ]),
    );
    r.register(
        Box::new(posture::PostureEngine::new(assets.poses.clone())),
        &keys(&[(NS_BML, "posture"), (NS_BML, "postureShift")]),
    );
    // the gait: legs, pelvis and the arms' swing, under the upper-body engines that follow
    r.register(
        Box::new(locomotion::LocomotionEngine::default()),
        &keys(&[(NS_BML, "locomotion")]),
    );
    r.register(
        Box::new(gesture::GestureEngine::new(assets.gestures.clone())),
        &keys(&[(NS_BML, "gesture")]),
    );
    r.register(
        Box::new(head::HeadEngine::new(assets.heads.clone())),
        &keys(&[(NS_BML, "head")]),
    );
    // noise adds to whatever the joint has
    r.register(
        Box::new(noise::NoiseEngine::default()),
        &keys(&[(NS_BMLT, "noise")]),
    );
    r.register(
        Box::new(murml::MurmlEngine::default()),
        &keys(&[
            (murml::NS_MURML, "murmlgesture"),
            (murml::NS_MURML, "murmlface"),
        ]),
    );
    r.register(
        Box::new(pointing::PointingEngine::default()),
        &keys(&[(NS_BML, "pointing")]),
    );
    r.register(
        Box::new(head_direction::HeadDirectionEngine::default()),
        &keys(&[(NS_BML, "headDirectionShift")]),
    );
    // last: the eyes are aimed from the head where the other engines put it
    r.register(
        Box::new(gaze::GazeEngine::default()),
        &keys(&[(NS_BML, "gaze"), (NS_BML, "gazeShift")]),
    );
    // after everything: a transition starts from the frame's final pose and blends over it
    r.register(
        Box::new(transition::TransitionEngine::default()),
        &keys(&[(NS_BMLT, "transition")]),
    );
    // last of all: the simulated body takes the kinematic pose the others made as its input
    r.register(
        Box::new(physical::PhysicalEngine::new(assets.compounds.clone())),
        &keys(&[(NS_BMLT, "controller")]),
    );
    r
}
