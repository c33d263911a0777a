//! The RealizerTester conformance suite (thesis ch. 9), as a
//! reusable crate that knows nothing of any particular realizer:
//!
//! - [`record`]: the feedback recorder — the five arrival-ordered lists of the original handler,
//!   filled from BML 1.0 feedback XML through the same mapping as its XML port;
//! - [`check`]: the assertion vocabulary with its exact semantics;
//! - [`port`]: how the harness drives a realizer (`TestPort`), waits and sleeps, and a port to an
//!   external realizer process speaking the line protocol (`bmlr serve --stdio`);
//! - [`suite`]: the 41 tests, each with the catalogued files, order, waits and assertions;
//! - [`files`]: the RealizerTester BML files (MIT, `fixtures/realizertester/license.txt`).

pub mod check;
pub mod files;
pub mod port;
pub mod record;
pub mod suite;

pub use check::Failure;
pub use port::{Ctx, Fixture, ProcessPort, TestPort};
pub use record::Recorder;
pub use suite::{run, Outcome, Test, TESTS};
