//! The planning floor: how long each behaviour's phases want to be ([`timing`]), the sync
//! times a block's constraints give ([`schedule`]), and the flexible plan of time pegs those
//! times are put on and moved along at run time ([`plan`]). It uses the language below it and
//! the voices' timing of speech; it moves nothing.

pub mod plan;
pub mod schedule;
pub mod timing;
