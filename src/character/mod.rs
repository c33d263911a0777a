//! A character as a whole, above its body (`body/`) and its face (`face/`), which know nothing
//! of each other: what couples them each frame ([`assemble`]: the lids following the eyes and
//! blinking, the jaw opened by the mouth's blendshapes, the joints clamped, the body placed
//! where the character stands; [`blink`]: the lids' life), the frames file that writes a
//! character's pose, face and sounds together ([`frames`]), and the mapping of all of it onto
//! a skinned avatar ([`avatar`]).

pub mod assemble;
pub mod avatar;
pub mod blink;
pub mod frames;

pub use assemble::Assembler;
