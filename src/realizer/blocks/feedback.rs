//! The feedback a block manager sends: block progress, predictions, sync points, warnings (as
//! `docs/cli.md` lists them), and the parser's warnings about a submitted block.

use super::*;

impl BlockManager {
    pub(super) fn emit(&mut self, fb: Feedback) {
        self.out.push(fb);
    }

    pub(super) fn warn(&mut self, id: impl Into<String>, kind: KnownWarning, text: String) {
        let character_id = self.character.clone();
        self.emit(Feedback::Warning(WarningFeedback {
            id: id.into(),
            kind: kind.into(),
            character_id,
            text,
        }));
    }

    pub(super) fn predict(&mut self, i: BlockKey, with_behaviours: bool) {
        let fb = self.prediction(&self.blocks[i], with_behaviours);
        self.emit(fb);
    }

    pub(super) fn prediction(&self, b: &LiveBlock, with_behaviours: bool) -> Feedback {
        let end = b.predicted_end();
        // the feedback is kept until the host takes it: every list gets its exact size
        let behaviours = if with_behaviours {
            let live = || b.behaviours.iter().filter(|x| x.phase != Phase::Removed);
            let mut v = Vec::with_capacity(live().count());
            v.extend(live().map(|x| {
                // (a persistent behaviour's end is infinite: not a prediction)
                let syncs = if x.syncs.iter().all(|s| s.1.is_finite()) {
                    x.syncs.clone()
                } else {
                    x.syncs
                        .iter()
                        .filter(|s| s.1.is_finite())
                        .cloned()
                        .collect()
                };
                BehaviourPrediction {
                    kind: b.source.behaviours[x.index].kind.element_id(),
                    block: b.id.clone(),
                    behaviour: x.id.clone(),
                    syncs,
                    attributes: Vec::new(),
                }
            }));
            v
        } else {
            Vec::new()
        };
        let fb = PredictionFeedback {
            character_id: self.character.clone(),
            blocks: vec![BlockPrediction {
                id: b.id.clone(),
                global_start: Some(b.start),
                // unknown while scheduling (the harness waits for a known end)
                global_end: end.filter(|e| e.is_finite() && b.status != BlockStatus::InPrep),
                status: Some(b.status),
            }],
            behaviours,
        };
        Feedback::Prediction(fb)
    }

    pub(super) fn progress(
        &mut self,
        block: &bml::Id,
        sync: &'static str,
        t: f64,
        status: BlockStatus,
    ) {
        let character_id = self.character.clone();
        self.emit(Feedback::BlockProgress(BlockProgress {
            block: block.clone(),
            sync: bml::Id::new_static(sync),
            global_time: t,
            character_id,
            status: Some(status),
            posix_time: None,
        }));
    }

    // submitting a block

    /// Reports what of an accepted block will not be interpreted: extension attributes that no
    /// engine reads (CUSTOM_ATTRIBUTE_NOT_SUPPORTED) and extension content the parser ignored.
    /// Unknown behaviour kinds are reported when scheduling finds no engine for them; lexemes when
    /// an engine cannot realize them.
    pub(super) fn parse_warnings(&mut self, block: &bml::Block, warnings: &[Diagnostic]) {
        for a in &block.foreign_attrs {
            self.warn(
                block.id.to_string(),
                KnownWarning::CustomAttributeNotSupported,
                format!(
                    "attribute '{}' (namespace {}) on <bml id=\"{}\"> is not interpreted and is ignored",
                    a.name, a.ns, block.id
                ),
            );
        }
        for b in &block.behaviours {
            let Some(engine) = self.registry.engine_for(b) else {
                continue;
            };
            for a in &b.foreign_attrs {
                if !self.registry.engine(engine).interprets(&a.ns, &a.name) {
                    self.warn(
                        format!("{}:{}", block.id, b.id),
                        KnownWarning::CustomAttributeNotSupported,
                        format!(
                            "attribute '{}' (namespace {}) on <{} id=\"{}\"> is not interpreted and is ignored",
                            a.name,
                            a.ns,
                            b.kind.element_name(),
                            b.id
                        ),
                    );
                }
            }
        }
        for d in warnings {
            let ignored_content = d.code == bml::Code::UnsupportedExtension
                && !block
                    .behaviours
                    .iter()
                    .any(|b| (b.pos.line, b.pos.col) == (d.pos.line, d.pos.col));
            if ignored_content {
                self.warn(
                    block.id.to_string(),
                    KnownWarning::BehaviorTypeNotSupported,
                    format!("{}:{}: {}", d.pos.line, d.pos.col, d.message),
                );
            }
        }
    }

    pub(super) fn sync_feedback(
        &mut self,
        block: &bml::Id,
        behaviour: &bml::Id,
        sync: &bml::Id,
        local: f64,
        t: f64,
        skipped: bool,
    ) {
        let character_id = self.character.clone();
        self.emit(Feedback::SyncPointProgress(SyncPointProgress {
            block: block.clone(),
            behaviour: behaviour.clone(),
            sync: sync.clone(),
            time: local,
            global_time: t,
            character_id,
            posix_time: None,
            skipped,
        }));
    }
}
