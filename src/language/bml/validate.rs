//! Static validation of a parsed block: ids (missing, duplicate, unusable), references to unknown
//! behaviours and unknown sync points, constraints that relate nothing, lexemes outside BML 1.0.

use smallvec::SmallVec;

use super::constraints::{extract_elements, Anchor, Relation};
use super::diagnostic::{Code, Diagnostic, Pos};
use super::model::{BehaviourKind, Block, ConstraintItem, TextPart, FACE_LEXEMES, HEAD_LEXEMES};
use super::syncref::{SyncPoint, SyncRef};

/// Checks a block's cross-references; returns errors and warnings in source order.
pub fn validate(block: &Block) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    // duplicate ids: sort (id, index) pairs once instead of hashing every id (those of a
    // typical block on the stack)
    // (extended in place: collecting would copy the inline list once more)
    let mut ids: SmallVec<[(&str, usize); 16]> = SmallVec::new();
    ids.extend(
        block
            .behaviours
            .iter()
            .enumerate()
            .map(|(i, b)| (b.id.as_str(), i)),
    );
    ids.sort_unstable();
    duplicate_ids(block, &ids, &mut diags);
    for b in &block.behaviours {
        check_behaviour(block, b, &mut diags);
    }
    check_shorthands(block, &ids, &mut diags);
    check_anticipator_links(block, &mut diags);
    check_constraint_elements(block, &ids, &mut diags);
    diags.sort_by_key(|d| (d.pos.line, d.pos.col));
    diags
}

/// Two behaviours with one id (`ids` sorted, so duplicates are neighbours).
fn duplicate_ids(block: &Block, ids: &Ids, diags: &mut Vec<Diagnostic>) {
    for pair in ids.windows(2) {
        let [(id, first), (next, dup)] = [pair[0], pair[1]];
        if id == next {
            let b = &block.behaviours[dup];
            let first = block.behaviours[first].pos;
            diags.push(Diagnostic::error(
                Code::DuplicateId,
                b.pos,
                format!(
                    "behaviour id '{id}' is already used at {first} in block '{}'",
                    block.id
                ),
            ));
        }
    }
}

/// What one behaviour's own content can get wrong: inline sync ids, lexemes outside BML 1.0,
/// a parameter change's target.
fn check_behaviour(
    block: &Block,
    b: &crate::language::bml::Behaviour,
    diags: &mut Vec<Diagnostic>,
) {
    match &b.kind {
        BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
            for (i, part) in s.text.iter().enumerate() {
                let TextPart::Sync(id) = part else { continue };
                let earlier = &s.text[..i];
                if earlier
                    .iter()
                    .any(|p| matches!(p, TextPart::Sync(e) if e == id))
                {
                    diags.push(Diagnostic::error(
                        Code::DuplicateId,
                        b.pos,
                        format!("speech '{}' has two inline syncs with id '{id}'", b.id),
                    ));
                } else if id == "start" || id == "end" {
                    diags.push(Diagnostic::error(Code::InvalidId, b.pos, format!("speech '{}' has an inline sync named '{id}', which clashes with its standard sync point", b.id)));
                } else if id.contains(['+', '-', ':']) || id.chars().any(char::is_whitespace) {
                    diags.push(Diagnostic::error(Code::InvalidId, b.pos, format!("inline sync id '{id}' of speech '{}' contains '+', '-', ':' or whitespace, so it cannot be referred to", b.id)));
                }
            }
        }
        BehaviourKind::Head(h) if !HEAD_LEXEMES.contains(&h.lexeme.as_str()) => {
            diags.push(Diagnostic::warning(Code::UnknownLexeme, b.pos, format!("head lexeme '{}' of '{}' is not a BML 1.0 lexeme (NOD, SHAKE); it is realized only if a binding defines it", h.lexeme, b.id)));
        }
        BehaviourKind::FaceLexeme(f) | BehaviourKind::FaceShift(f)
            if !f.lexeme.is_empty() && !FACE_LEXEMES.contains(&f.lexeme.as_str()) =>
        {
            diags.push(Diagnostic::warning(Code::UnknownLexeme, b.pos, format!("face lexeme '{}' of '{}' is not a BML 1.0 lexeme; it is realized only if a binding defines it", f.lexeme, b.id)));
        }
        BehaviourKind::ParameterValueChange(p)
            if p.target_block.as_deref().is_none_or(|t| t == block.id)
                && block.behaviour(&p.target_behaviour).is_none() =>
        {
            diags.push(Diagnostic::error(Code::UnknownBehaviour, b.pos, format!("parametervaluechange '{}' targets '{}', which is not a behaviour of block '{}'", b.id, p.target_behaviour, block.id)));
        }
        _ => {}
    }
}

/// The sync attributes of every behaviour: references that resolve, no time before the block.
fn check_shorthands(block: &Block, ids: &Ids, diags: &mut Vec<Diagnostic>) {
    // (the bulk of a block: checked in place, without building constraints)
    for b in &block.behaviours {
        for s in &b.syncs {
            check_ref(block, ids, &s.value, s.pos, diags);
            if matches!(s.value, SyncRef::Time(t) if t < 0.0) {
                diags.push(Diagnostic::error(
                    Code::InvalidConstraint,
                    s.pos,
                    format!(
                        "{}:{} = {} puts a sync point before the start of its block",
                        b.id, s.sync, s.value
                    ),
                ));
            }
        }
    }
}

/// A sync point may be at-linked to at most one anticipator sync.
fn check_anticipator_links(block: &Block, diags: &mut Vec<Diagnostic>) {
    // (checked only when the block names an anticipator, to keep validation allocation-free
    // otherwise)
    let anticipator = |r: &SyncRef| {
        matches!(
            r,
            SyncRef::Point {
                point: SyncPoint::Anticipator { .. },
                ..
            }
        )
    };
    let names_anticipator = block
        .behaviours
        .iter()
        .any(|b| b.syncs.iter().any(|s| anticipator(&s.value)))
        || block
            .constraints
            .iter()
            .flat_map(|c| &c.items)
            .any(|item| match item {
                ConstraintItem::Synchronize {
                    reference, syncs, ..
                } => {
                    reference.as_ref().is_some_and(anticipator)
                        || syncs.iter().any(|s| anticipator(&s.reference))
                }
                ConstraintItem::Before {
                    reference, syncs, ..
                }
                | ConstraintItem::After {
                    reference, syncs, ..
                } => anticipator(reference) || syncs.iter().any(|s| anticipator(&s.reference)),
            });
    let all = if names_anticipator {
        super::constraints::extract(block)
    } else {
        Vec::new()
    };
    for (i, c) in all.iter().enumerate() {
        let (
            Anchor::Point(l @ SyncPoint::Local { .. }),
            Anchor::Point(a @ SyncPoint::Anticipator { .. }),
            Relation::At,
        ) = (&c.left, &c.right, c.relation)
        else {
            continue;
        };
        let earlier = all[..i].iter().find(|d| {
            d.relation == Relation::At
                && d.left == c.left
                && matches!(&d.right, Anchor::Point(b @ SyncPoint::Anticipator { .. }) if b != a)
        });
        if let Some(d) = earlier {
            diags.push(Diagnostic::error(
                Code::InvalidConstraint,
                c.pos,
                format!("{l} is already synchronised to {} at {}; a sync point may follow only one anticipator sync", d.right, d.pos),
            ));
        }
    }
}

/// `<constraint>` elements, checked on their normalised form.
fn check_constraint_elements(block: &Block, ids: &Ids, diags: &mut Vec<Diagnostic>) {
    for c in extract_elements(block) {
        if c.is_constant() {
            diags.push(Diagnostic::error(
                Code::InvalidConstraint,
                c.pos,
                format!("constraint '{c}' relates two absolute times and constrains no behaviour"),
            ));
            continue;
        }
        for side in [&c.left, &c.right] {
            if let Anchor::Point(p) = side {
                check_point(block, ids, p, c.pos, diags);
            }
        }
        // normalisation puts the block start on the right: left REL block + offset
        if c.right == Anchor::BlockStart && c.offset < 0.0 && c.relation != Relation::After {
            diags.push(Diagnostic::error(
                Code::InvalidConstraint,
                c.pos,
                format!("constraint '{c}' puts a sync point before the start of its block"),
            ));
        }
    }
}

/// The behaviours' (id, position) pairs, sorted: found by binary search, so that checking every
/// reference of a large block stays O(n log n).
type Ids<'a> = [(&'a str, usize)];

fn check_ref(block: &Block, ids: &Ids, r: &SyncRef, pos: Pos, diags: &mut Vec<Diagnostic>) {
    if let SyncRef::Point { point, .. } = r {
        check_point(block, ids, point, pos, diags);
    }
}

/// A reference to a behaviour of this block must name an existing behaviour and one of its sync
/// points; references to other blocks and to anticipators are resolved at scheduling time.
fn check_point(block: &Block, ids: &Ids, p: &SyncPoint, pos: Pos, diags: &mut Vec<Diagnostic>) {
    let (behaviour, sync) = match p {
        SyncPoint::Local { behaviour, sync } => (behaviour, sync),
        SyncPoint::External {
            block: blk,
            behaviour,
            sync,
        } if *blk == block.id => (behaviour, sync),
        _ => return,
    };
    // the first behaviour with the id (pairs of equal ids are in position order)
    let at = ids.partition_point(|(id, _)| *id < behaviour.as_str());
    let found = ids
        .get(at)
        .filter(|(id, _)| *id == behaviour.as_str())
        .map(|&(_, i)| &block.behaviours[i]);
    match found {
        None => diags.push(Diagnostic::error(
            Code::UnknownBehaviour,
            pos,
            format!("'{behaviour}:{sync}' refers to '{behaviour}', which is not a behaviour of block '{}'", block.id),
        )),
        Some(b) if !b.has_sync(sync) => diags.push(Diagnostic::error(
            Code::UnknownSyncPoint,
            pos,
            format!(
                "<{}> '{behaviour}' has no sync point '{sync}'; its sync points are {}{}",
                b.kind.element_name(),
                b.sync_points().join(", "),
                if super::stroke_iteration_of(sync).is_some() {
                    super::STROKE_ITERATION_HINT
                } else {
                    ""
                }
            ),
        )),
        Some(_) => {}
    }
}
