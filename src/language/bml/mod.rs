//! The BML language layer: the typed model of BML 1.0 blocks with the BMLA/BMLT extensions, the
//! streaming parser, static validation, constraint extraction and the writer.
//!
//! ```
//! use bml_realizer::language::bml;
//! let parsed = bml::load(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b1">
//!     <speech id="s1"><text>Hello <sync id="w"/>world</text></speech>
//!     <gesture id="g1" lexeme="BEAT" stroke="s1:w"/>
//! </bml>"#).unwrap();
//! let constraints = bml::extract(&parsed.block);
//! assert_eq!(constraints[0].to_string(), "g1:stroke = s1:w");
//! ```

mod constraints;
mod diagnostic;
mod id;
mod kinds;
mod limits;
mod model;
mod parser;
mod stream;
mod syncref;
mod validate;
mod writer;
mod xml;

pub use constraints::{extract, Anchor, Constraint, Relation, Source};
pub use diagnostic::{BmlError, Code, Diagnostic, LineIndex, Pos, Severity};
pub use kinds::{
    ALL_STANDARD_SYNCS, BMLT_BEHAVIOURS, BUILTIN_KINDS, CONTROL_BEHAVIOURS, CORE_BEHAVIOURS,
    FACE_SYNCS, GAZE_SYNCS, GESTURE_SYNCS, START_END,
};
pub use limits::{Limits, MAX_REPETITION};
pub use model::*;
pub use parser::{parse, parse_with_diagnostics, Parsed};
pub use stream::{advance, lines, BadLine, BlockStream, StreamItem};
pub use syncref::{
    stroke_iteration_of, stroke_name, SyncPoint, SyncRef, SyncRefError, ANTICIPATORS,
    STROKE_ITERATION_HINT,
};
pub use validate::validate;
pub use writer::write;

/// Parses and validates one block: the block plus warnings, or every diagnostic if any is an error.
pub fn load(src: &str) -> Result<Parsed, BmlError> {
    let mut block = None;
    let diags = check_into(src, &mut block, &Limits::default());
    parser::parsed(&mut block, diags)
}

/// Parses and validates as far as possible, returning the block (if the text is a `<bml>`
/// document) and every diagnostic in source order.
pub fn check(src: &str) -> (Option<Block>, Vec<Diagnostic>) {
    check_with(src, &Limits::default())
}

/// [`check`] within `limits`: a block that passes one is refused with a `limit-exceeded` error.
pub fn check_with(src: &str, limits: &Limits) -> (Option<Block>, Vec<Diagnostic>) {
    let mut block = None;
    let diags = check_into(src, &mut block, limits);
    (block, diags)
}

/// A block read and checked, ready to hand to a realizer
/// ([`Realizer::perform_checked`](crate::realizer::Realizer::perform_checked)). Checking is the
/// part of a submission that needs no realizer, so a port can do it on the thread that reads
/// the text, and the realizer's thread only schedules and starts the block.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The block, if the text is a `<bml>` document.
    pub block: Option<Block>,
    /// Every diagnostic, in source order.
    pub diagnostics: Vec<Diagnostic>,
    /// For a block with errors: its id as far as the text can be read (see [`root_id`]).
    pub id_hint: Option<String>,
}

impl Checked {
    /// Parses and validates `src` within `limits`.
    pub fn new(src: &str, limits: &Limits) -> Self {
        let (block, diagnostics) = check_with(src, limits);
        let failed = block.is_none() || diagnostics.iter().any(Diagnostic::is_error);
        let id_hint = match &block {
            Some(b) if failed => Some(b.id.to_string()),
            None => root_id(src),
            Some(_) => None,
        };
        Checked {
            block,
            diagnostics,
            id_hint,
        }
    }

    /// Whether the block can be performed (it was read and has no errors).
    pub fn is_valid(&self) -> bool {
        self.block.is_some() && !self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// [`check_with`] with the block written into `block` (`None` before): the block is not copied
/// up the return values. The diagnostics come sorted by position either way.
fn check_into(src: &str, block: &mut Option<Block>, limits: &Limits) -> Vec<Diagnostic> {
    if src.len() > limits.block_bytes {
        let message = format!(
            "the block is {} bytes long, more than the limit of {} (--max-block-bytes)",
            src.len(),
            limits.block_bytes
        );
        return vec![Diagnostic::error(
            Code::LimitExceeded,
            Pos { line: 1, col: 1 },
            message,
        )];
    }
    let mut diags = parser::parse_into(src, block, limits);
    if let Some(b) = block {
        diags.extend(validate(b));
        diags.sort_by_key(|d| (d.pos.line, d.pos.col));
    }
    diags
}

/// The `id` of the first element in `src`: for naming a block in a warning when the rest of it is
/// not well-formed. `None` if the first element's tag cannot be read or has no id.
pub fn root_id(src: &str) -> Option<String> {
    let mut reader = xml::Reader::new(src, &Limits::default());
    loop {
        match reader.next() {
            Ok(xml::Event::Start(_)) => {
                let id = reader.attrs().iter().find(|a| a.key == "id")?;
                return id.value().ok().map(|v| v.into_owned());
            }
            Ok(xml::Event::Eof) | Err(_) => return None,
            Ok(_) => {}
        }
    }
}
