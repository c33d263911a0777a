//! Static validation of a parsed block: ids (missing, duplicate, unusable), references to unknown
//! behaviours and unknown sync points, constraints that relate nothing, lexemes outside BML 1.0.

use std::collections::HashMap;

use super::constraints::{extract, Anchor};
use super::diagnostic::{Code, Diagnostic, Pos};
use super::model::{BehaviourKind, Block, TextPart, FACE_LEXEMES, HEAD_LEXEMES};
use super::syncref::SyncPoint;

/// Checks a block's cross-references; returns errors and warnings in source order.
pub fn validate(block: &Block) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let mut seen: HashMap<&str, Pos> = HashMap::new();
    for b in &block.behaviours {
        if let Some(first) = seen.get(b.id.as_str()) {
            diags.push(Diagnostic::error(
                Code::DuplicateId,
                b.pos,
                format!(
                    "behaviour id '{}' is already used at {first} in block '{}'",
                    b.id, block.id
                ),
            ));
        } else {
            seen.insert(&b.id, b.pos);
        }
        match &b.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                let mut ids: Vec<&str> = Vec::new();
                for part in &s.text {
                    let TextPart::Sync(id) = part else { continue };
                    if ids.contains(&id.as_str()) {
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
                    ids.push(id);
                }
            }
            BehaviourKind::Head(h) if !HEAD_LEXEMES.contains(&h.lexeme.as_str()) => {
                diags.push(Diagnostic::warning(Code::UnknownLexeme, b.pos, format!("head lexeme '{}' of '{}' is not a BML 1.0 lexeme (NOD, SHAKE); it is realized only if a binding defines it", h.lexeme, b.id)));
            }
            BehaviourKind::FaceLexeme(f) | BehaviourKind::FaceShift(f)
                if !FACE_LEXEMES.contains(&f.lexeme.as_str()) =>
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

    for c in extract(block) {
        if c.is_constant() {
            diags.push(Diagnostic::error(
                Code::InvalidConstraint,
                c.pos,
                format!("constraint '{c}' relates two absolute times and constrains no behaviour"),
            ));
            continue;
        }
        for side in [&c.left, &c.right] {
            let (behaviour, sync) = match side {
                Anchor::Point(SyncPoint::Local { behaviour, sync }) => (behaviour, sync),
                Anchor::Point(SyncPoint::External {
                    block: blk,
                    behaviour,
                    sync,
                }) if *blk == block.id => (behaviour, sync),
                _ => continue,
            };
            match block.behaviour(behaviour) {
                None => diags.push(Diagnostic::error(
                    Code::UnknownBehaviour,
                    c.pos,
                    format!("'{behaviour}:{sync}' refers to '{behaviour}', which is not a behaviour of block '{}'", block.id),
                )),
                Some(b) if !b.has_sync(sync) => diags.push(Diagnostic::error(
                    Code::UnknownSyncPoint,
                    c.pos,
                    format!(
                        "<{}> '{behaviour}' has no sync point '{sync}'; its sync points are {}",
                        b.kind.element_name(),
                        b.sync_points().join(", ")
                    ),
                )),
                Some(_) => {}
            }
        }
        if c.left == Anchor::BlockStart || c.right == Anchor::BlockStart {
            // absolute time: left = block + offset (normalisation puts the block on the right)
            let t = c.offset;
            if t < 0.0 && c.relation != super::constraints::Relation::After {
                diags.push(Diagnostic::error(
                    Code::InvalidConstraint,
                    c.pos,
                    format!("constraint '{c}' puts a sync point before the start of its block"),
                ));
            }
        }
    }
    diags.sort_by_key(|d| (d.pos.line, d.pos.col));
    diags
}
