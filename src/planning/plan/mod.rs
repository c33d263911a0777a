//! The flexible multimodal plan: the peg board ([`pegs`]), schedules put on it and checked after
//! run-time changes ([`to_pegs`]), and the anticipators whose predictions pegs can hang on
//! ([`anticipator`]).

pub mod anticipator;
pub mod pegs;
pub mod to_pegs;
