//! Constraint extraction: every shorthand sync attribute and every `<constraint>` child of a block,
//! normalised into one list of difference constraints `left REL right + offset` — the scheduler's
//! input. Each constraint remembers where it came from and whether it is required.

use std::fmt;

use super::diagnostic::Pos;
use super::model::Id;
use super::model::{Block, ConstraintItem, ConstraintSync};
use super::syncref::{fmt_seconds, SyncPoint, SyncRef};

/// The relation of a difference constraint `left REL right + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Relation {
    /// `left = right + offset`.
    At,
    /// `left ≤ right + offset`.
    Before,
    /// `left ≥ right + offset`.
    After,
}

impl Relation {
    fn flipped(self) -> Relation {
        match self {
            Relation::At => Relation::At,
            Relation::Before => Relation::After,
            Relation::After => Relation::Before,
        }
    }

    /// The operator symbol: `=`, `<=`, `>=`.
    pub fn symbol(self) -> &'static str {
        match self {
            Relation::At => "=",
            Relation::Before => "<=",
            Relation::After => ">=",
        }
    }
}

/// One side of a constraint: the block's start, or a sync point.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Anchor {
    /// The start of the block (absolute constraints).
    BlockStart,
    /// A sync point: local (relative), external (another block) or anticipator.
    Point(SyncPoint),
}

impl Anchor {
    /// Normal orientation puts the most local side left: local sync, external, anticipator, block.
    fn rank(&self) -> u8 {
        match self {
            Anchor::Point(SyncPoint::Local { .. }) => 0,
            Anchor::Point(SyncPoint::External { .. }) => 1,
            Anchor::Point(SyncPoint::Anticipator { .. }) => 2,
            Anchor::BlockStart => 3,
        }
    }
}

impl fmt::Display for Anchor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Anchor::BlockStart => f.write_str("@block"),
            Anchor::Point(p) => write!(f, "{p}"),
        }
    }
}

/// Where a constraint was written.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// A shorthand sync attribute, e.g. `<gesture id="g1" stroke="s1:w">`.
    Attribute {
        /// Index in `Block::behaviours` of the behaviour carrying the attribute (its own sync point
        /// is always the constraint's left side).
        behaviour: usize,
        /// The attribute (sync point) name.
        sync: &'static str,
    },
    /// A child of a `<constraint>` element.
    Element {
        /// The `<constraint>`'s id, if any.
        constraint: Option<String>,
    },
}

/// A normalised difference constraint `left REL right + offset` (seconds).
#[derive(Debug, Clone, PartialEq)]
pub struct Constraint {
    /// The relation.
    pub relation: Relation,
    /// Left side.
    pub left: Anchor,
    /// Right side.
    pub right: Anchor,
    /// Offset added to the right side, in seconds.
    pub offset: f64,
    /// Whether it comes from a BML 1.0 `<required>` element (or a required behaviour's attribute).
    pub required: bool,
    /// Where it was written.
    pub source: Source,
    /// Source position (attribute or `<sync>` element).
    pub pos: Pos,
}

impl Constraint {
    /// Builds `a REL b` from two anchored times, normalised so that the more local side is left.
    fn between(
        (la, lo): (Anchor, f64),
        relation: Relation,
        (ra, ro): (Anchor, f64),
        required: bool,
        source: Source,
        pos: Pos,
    ) -> Constraint {
        // la + lo REL ra + ro  <=>  la REL ra + (ro - lo)
        let c = Constraint {
            relation,
            left: la,
            right: ra,
            offset: ro - lo,
            required,
            source,
            pos,
        };
        if c.right.rank() < c.left.rank() {
            Constraint {
                relation: c.relation.flipped(),
                left: c.right,
                right: c.left,
                offset: -c.offset,
                ..c
            }
        } else {
            c
        }
    }

    /// Whether both sides are the block start (the constraint relates two absolute times).
    pub fn is_constant(&self) -> bool {
        self.left == Anchor::BlockStart && self.right == Anchor::BlockStart
    }
}

fn anchor(r: &SyncRef) -> (Anchor, f64) {
    match r {
        SyncRef::Time(t) => (Anchor::BlockStart, *t),
        SyncRef::Point { point, offset } => (Anchor::Point(point.clone()), *offset),
    }
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", self.left, self.relation.symbol(), self.right)?;
        if self.offset > 0.0 {
            f.write_str(" + ")?;
            fmt_seconds(f, self.offset)
        } else if self.offset < 0.0 {
            f.write_str(" - ")?;
            fmt_seconds(f, -self.offset)
        } else {
            Ok(())
        }
    }
}

/// Extracts the normalised constraints of a block: first the shorthand attributes (behaviour by
/// behaviour, in document order), then the `<constraint>` elements.
pub fn extract(block: &Block) -> Vec<Constraint> {
    let attributes: usize = block.behaviours.iter().map(|b| b.syncs.len()).sum();
    let mut out = Vec::with_capacity(attributes + block.constraints.len());
    for (index, b) in block.behaviours.iter().enumerate() {
        for s in &b.syncs {
            // the behaviour's id is shared, the standard sync name is static: nothing copied
            let own = Anchor::Point(SyncPoint::Local {
                behaviour: b.id.clone(),
                sync: Id::new_static(s.sync),
            });
            out.push(Constraint::between(
                (own, 0.0),
                Relation::At,
                anchor(&s.value),
                b.required,
                Source::Attribute {
                    behaviour: index,
                    sync: s.sync,
                },
                s.pos,
            ));
        }
    }
    extract_elements_into(block, &mut out);
    out
}

/// The constraints of the `<constraint>` elements only.
pub(crate) fn extract_elements(block: &Block) -> Vec<Constraint> {
    let mut out = Vec::new();
    extract_elements_into(block, &mut out);
    out
}

fn extract_elements_into(block: &Block, out: &mut Vec<Constraint>) {
    for c in &block.constraints {
        let source = || Source::Element {
            constraint: c.id.clone(),
        };
        for item in &c.items {
            let (relation, reference, syncs): (Relation, Option<&SyncRef>, &[ConstraintSync]) =
                match item {
                    ConstraintItem::Synchronize {
                        reference, syncs, ..
                    } => (Relation::At, reference.as_ref(), syncs),
                    ConstraintItem::Before {
                        reference, syncs, ..
                    } => (Relation::Before, Some(reference), syncs),
                    ConstraintItem::After {
                        reference, syncs, ..
                    } => (Relation::After, Some(reference), syncs),
                };
            // Without a ref, the first <sync> of a <synchronize> is the reference for the others.
            let (reference, rest) = match reference {
                Some(r) => (r, syncs),
                None => match syncs.split_first() {
                    Some((first, rest)) => (&first.reference, rest),
                    None => continue,
                },
            };
            for s in rest {
                out.push(Constraint::between(
                    anchor(&s.reference),
                    relation,
                    anchor(reference),
                    c.required,
                    source(),
                    s.pos,
                ));
            }
        }
    }
}
