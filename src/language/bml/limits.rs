//! The limits on what one block may hold, so that hostile or broken input costs a bounded amount
//! of work and memory and is refused with a diagnostic that names the limit: nesting depth,
//! attributes per element (and namespace declarations in scope), the size of a block, behaviours
//! per block, how far from the block start a sync time may lie, and how often a head repeats.

/// Most repetitions of a `<head>` (each is a stroke of its own, `stroke:N`, in its timing).
pub const MAX_REPETITION: u32 = 1_000;

/// Limits on one block. The defaults are far above anything a behaviour planner writes; the CLI
/// changes each with a flag (`--max-depth`, `--max-attributes`, `--max-block-bytes`,
/// `--max-behaviours`, `--max-time`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Deepest nesting of elements, the `<bml>` root counting as 1.
    pub depth: usize,
    /// Most attributes on one element, and most namespace declarations in scope at once.
    pub attributes: usize,
    /// Largest block, in bytes of its text.
    pub block_bytes: usize,
    /// Most behaviours in one block.
    pub behaviours: usize,
    /// Largest magnitude of a time in a sync reference (an absolute time or an offset), seconds.
    pub time: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            depth: 64,
            attributes: 256,
            block_bytes: 8 << 20,
            behaviours: 50_000,
            time: 1e6,
        }
    }
}
