//! The flexible multimodal plan. So far: the peg board ([`pegs`]); anticipators and plan validity
//! come with the scheduler (issue #3).

pub mod pegs;
