//! The flexible multimodal plan: the peg board ([`pegs`]) and the anticipators whose predictions
//! pegs can hang on ([`anticipator`]). Schedules are put on the board by `schedule::to_pegs`.

pub mod anticipator;
pub mod pegs;
