//! The kind-specific part of each known behaviour (gesture, gaze, face, speech, locomotion,
//! BMLT and BMLA elements) built from its attributes.

use super::*;

/// Builds the kind-specific part of a known behaviour from its attributes.
pub(super) struct KindBuilder<'a, 'i> {
    p: &'a mut Parser<'i>,
    attrs: &'a mut Attrs<'i>,
    on: &'a dyn fmt::Display,
    el: &'a El<'i>,
}

impl<'a, 'i> KindBuilder<'a, 'i> {
    pub(super) fn new(
        p: &'a mut Parser<'i>,
        attrs: &'a mut Attrs<'i>,
        on: &'a dyn fmt::Display,
        el: &'a El<'i>,
    ) -> Self {
        KindBuilder { p, attrs, on, el }
    }

    pub(super) fn req(&mut self, name: &str) -> Option<String> {
        self.p.req_str(self.attrs, name, self.on, self.el.offset)
    }
    pub(super) fn opt(&mut self, name: &str) -> Option<String> {
        self.attrs.take(name).map(|a| a.value.into_owned())
    }
    pub(super) fn f64(&mut self, name: &str) -> Option<f64> {
        self.p.opt_f64(self.attrs, name)
    }
    pub(super) fn u32(&mut self, name: &str) -> Option<u32> {
        self.p.opt_u32(self.attrs, name, u32::MAX)
    }
    pub(super) fn mode(&mut self) -> Option<Mode> {
        self.p
            .opt_enum(self.attrs, "mode", self.on, Mode::parse, Mode::expected)
    }
    pub(super) fn list(&mut self, name: &str) -> Vec<String> {
        self.opt(name)
            .map(|v| split_id_list(&v))
            .unwrap_or_default()
    }
    pub(super) fn gaze(&mut self) -> Option<Gaze> {
        let target = self.req("target");
        let influence = self.p.opt_enum(
            self.attrs,
            "influence",
            self.on,
            Influence::parse,
            Influence::expected,
        );
        let offset_angle = self.f64("offsetAngle");
        let offset_direction = self.p.opt_enum(
            self.attrs,
            "offsetDirection",
            self.on,
            OffsetDirection::parse,
            OffsetDirection::expected,
        );
        Some(Gaze {
            target: target?,
            influence,
            offset_angle,
            offset_direction,
        })
    }
    pub(super) fn face_lexeme(&mut self) -> Option<FaceLexeme> {
        let lexeme = self.req("lexeme");
        let amount = self.f64("amount");
        Some(FaceLexeme {
            lexeme: lexeme?,
            amount,
        })
    }
    pub(super) fn animation(&mut self) -> Animation {
        let name = self.opt("name");
        let file_name = self.opt("fileName").or_else(|| self.opt("filename"));
        Animation {
            name,
            file_name,
            ..Animation::default()
        }
    }

    /// The behaviour kind of the element being read, from its attributes: a BML 1.0 element or
    /// an extension's, each family one arm per element, each a few lines, so that its attribute
    /// grammar reads as one table (and beside `Writer::kind_attrs`, which writes it back).
    pub(super) fn build(&mut self) -> Option<BehaviourKind> {
        match self.el.name {
            "interrupt"
            | "activate"
            | "parametervaluechange"
            | "procanimation"
            | "procanimationgesture"
            | "keyframe"
            | "controller"
            | "audiofile"
            | "noise"
            | "facemorph"
            | "transition" => self.extension(),
            _ => self.core(),
        }
    }

    /// A `faceFacs`: its action unit (required), side and amount.
    fn face_facs(&mut self) -> Option<FaceFacs> {
        let au = match self
            .attrs
            .items
            .iter()
            .flatten()
            .any(|a| a.ns == Ns::None && a.name == "au")
        {
            true => self.u32("au"),
            false => {
                self.req("au");
                None
            }
        };
        let side = self
            .p
            .opt_enum(self.attrs, "side", self.on, Side::parse, Side::expected);
        let amount = self.f64("amount");
        Some(FaceFacs {
            au: au?,
            side,
            amount,
        })
    }

    /// The behaviours of BML 1.0 itself.
    fn core(&mut self) -> Option<BehaviourKind> {
        let placeholder_posture = || Posture {
            stance: StanceType::Standing,
            poses: Vec::new(),
        };
        Some(match self.el.name {
            "speech" => BehaviourKind::Speech(Speech::default()),
            "text" => BehaviourKind::Text(Speech::default()),
            "gesture" => {
                let lexeme = self.req("lexeme");
                let mode = self.mode();
                BehaviourKind::Gesture(Gesture {
                    lexeme: lexeme?,
                    mode,
                })
            }
            "pointing" => {
                let target = self.req("target");
                let mode = self.mode();
                BehaviourKind::Pointing(Pointing {
                    target: target?,
                    mode,
                })
            }
            "head" => {
                let lexeme = self.req("lexeme");
                let repetition = self.p.opt_u32(
                    self.attrs,
                    "repetition",
                    crate::language::bml::MAX_REPETITION,
                );
                let amount = self.f64("amount");
                BehaviourKind::Head(Head {
                    lexeme: lexeme?,
                    repetition,
                    amount,
                })
            }
            "headDirectionShift" => BehaviourKind::HeadDirectionShift {
                target: self.req("target")?,
            },
            "gaze" => BehaviourKind::Gaze(self.gaze()?),
            "gazeShift" => BehaviourKind::GazeShift(self.gaze()?),
            "face" => {
                let lexeme = self.opt("lexeme");
                let au = self.u32("au");
                let side =
                    self.p
                        .opt_enum(self.attrs, "side", self.on, Side::parse, Side::expected);
                let amount = self.f64("amount");
                // without lexeme and au, a <lexeme> child must give them (checked after it)
                BehaviourKind::Face(Face {
                    lexeme,
                    au,
                    side,
                    amount,
                })
            }
            "faceLexeme" => BehaviourKind::FaceLexeme(self.face_lexeme()?),
            // the lexeme may come from a <lexeme> child instead (checked after the children)
            "faceShift" => BehaviourKind::FaceShift(FaceLexeme {
                lexeme: self.opt("lexeme").unwrap_or_default(),
                amount: self.f64("amount"),
            }),
            "faceFacs" => BehaviourKind::FaceFacs(self.face_facs()?),
            "posture" => BehaviourKind::Posture(placeholder_posture()),
            "postureShift" => BehaviourKind::PostureShift(placeholder_posture()),
            "locomotion" => {
                let target = self.req("target");
                let manner = self.opt("manner");
                BehaviourKind::Locomotion(Locomotion {
                    target: target?,
                    manner,
                })
            }
            "wait" => BehaviourKind::Wait(Wait {
                max_wait: self.f64("max-wait"),
            }),
            _ => return None,
        })
    }

    /// The behaviours of the BMLA and BMLT extensions.
    fn extension(&mut self) -> Option<BehaviourKind> {
        Some(match self.el.name {
            "interrupt" => {
                let target = self.req("target");
                let include = self.list("include");
                let exclude = self.list("exclude");
                BehaviourKind::Interrupt(Interrupt {
                    target: target?,
                    include,
                    exclude,
                })
            }
            "activate" => BehaviourKind::Activate(Activate {
                target: self.req("target")?,
            }),
            "parametervaluechange" => {
                let target = self.req("target");
                let param_id = self.req("paramId");
                let target = target?;
                let (target_block, target_behaviour) = match target.split_once(':') {
                    Some((b, beh)) => (
                        Some(b.trim_ascii().to_string()),
                        beh.trim_ascii().to_string(),
                    ),
                    None => (None, target.trim_ascii().to_string()),
                };
                BehaviourKind::ParameterValueChange(ParameterValueChange {
                    target_block,
                    target_behaviour,
                    param_id: param_id?,
                    trajectory: Trajectory {
                        kind: TrajectoryType::Linear,
                        initial_value: None,
                        target_value: 0.0,
                    },
                })
            }
            "procanimation" => BehaviourKind::ProcAnimation(self.animation()),
            "procanimationgesture" => BehaviourKind::ProcAnimationGesture(self.animation()),
            "keyframe" => BehaviourKind::Keyframe(self.animation()),
            "controller" => {
                let class = self.req("class");
                let name = self.opt("name");
                BehaviourKind::Controller(Controller {
                    class: class?,
                    name,
                    params: Vec::new(),
                })
            }
            "audiofile" => {
                let file = self.opt("fileName").or_else(|| self.opt("filename"));
                match file {
                    Some(file_name) => BehaviourKind::AudioFile { file_name },
                    None => {
                        self.req("fileName");
                        return None;
                    }
                }
            }
            "noise" => {
                let joint = self.req("joint");
                let kind = self.req("type");
                BehaviourKind::Noise(Noise {
                    joint: joint?,
                    kind: kind?,
                    params: Vec::new(),
                })
            }
            "facemorph" => {
                let target_name = self.req("targetname");
                let intensity = self.f64("intensity");
                BehaviourKind::FaceMorph(FaceMorph {
                    target_name: target_name?,
                    intensity,
                })
            }
            "transition" => BehaviourKind::Transition(Transition {
                class: self.req("class")?,
                params: Vec::new(),
            }),
            _ => return None,
        })
    }
}
