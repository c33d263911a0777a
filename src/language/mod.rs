//! The language floor, the lowest: BML itself ([`bml`]: the typed model, parser, validation,
//! constraints and writer) and the feedback a realizer answers with ([`feedback`]), with the
//! XML names both check. Everything above reads blocks and writes feedback through these.

pub mod bml;
pub mod feedback;
pub(crate) mod xmlname;
