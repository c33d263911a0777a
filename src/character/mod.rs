//! The character floor: a virtual human's body ([`body`]: skeleton, poses, limits, kinematics),
//! its physics ([`dynamics`]), its face ([`face`]), its voice ([`voice`]) and the sound it makes
//! ([`sound`]), each knowing nothing of the others but what sits below it in this list (the
//! voice moves the face's visemes and makes sound). Above them the character as a whole: what
//! couples them each frame ([`assemble`]: the lids following the eyes and
//! blinking, the jaw opened by the mouth's blendshapes, the joints clamped, the body placed
//! where the character stands; [`blink`]: the lids' life), the frames file that writes a
//! character's pose, face and sounds together ([`frames`]), and the mapping of all of it onto
//! a skinned avatar ([`avatar`]).

pub mod body;
pub mod dynamics;
pub mod face;
pub mod sound;
pub mod voice;

pub mod assemble;
pub mod avatar;
pub mod blink;
pub mod frames;
pub mod pose;

pub use assemble::Assembler;
pub use pose::CharacterPose;
