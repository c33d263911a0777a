//! The flexible multimodal plan: the peg board ([`pegs`]). Schedules are put on it by
//! `schedule::to_pegs`.

pub mod pegs;
