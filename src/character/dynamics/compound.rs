//! Compound controllers (thesis §4.2.3): one controller made of PD pulls on several joints,
//! each member either required — the compound cannot work without it — or desired — used when
//! the simulated body has that joint. Binding a compound to a simulation fails, saying which,
//! when a required member's part is not simulated, and leaves out desired members whose parts
//! are not; the bound compound then drives like any other controller, its pulls adding to the
//! others' on a shared joint. The thesis' example is the loosely hanging arm: soft pulls toward
//! the arm hanging down on the shoulder and elbow (required) and the wrist (desired).
//!
//! Definitions are data: the embedded `fixtures/physics/compounds.json` (the hanging arms), to
//! which a host or an `--assets` directory adds its own ([`CompoundLibrary`]).

use glam::{DQuat, EulerRot};

use super::controllers::{Controller, Drive};
use super::humanoid::PARTS;
use super::sim::Simulation;

/// Whether a compound needs a member (see the module documentation); `"required"` or
/// `"desired"` in a definitions file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Need {
    /// The compound does not bind without it.
    Required,
    /// Used where the body has it, left out elsewhere.
    Desired,
}

/// One member: a PD pull on a body part's joint toward a rotation relative to its parent part.
#[derive(Debug, Clone, PartialEq)]
pub struct Member {
    /// The body part (a name of `dynamics::humanoid::PARTS`, `l_forearm`).
    pub part: String,
    /// The target rotation relative to the parent part (identity: the rest pose).
    pub target: DQuat,
    /// Stiffness (N m/rad).
    pub kp: f64,
    /// Damping (N m s/rad).
    pub kd: f64,
    /// Required or desired.
    pub need: Need,
}

/// A compound controller's definition: a name and its members.
#[derive(Debug, Clone, PartialEq)]
pub struct CompoundSpec {
    /// The class name BML uses for it.
    pub name: String,
    /// Its members.
    pub members: Vec<Member>,
}

/// A compound bound to a simulation: the members it drives and those it left out.
#[derive(Debug, Clone, PartialEq)]
pub struct Compound {
    /// (part, target, kp, kd) of each bound member.
    pulls: Vec<(usize, DQuat, f64, f64)>,
    /// The parts of the desired members left out.
    pub skipped: Vec<String>,
}

impl CompoundSpec {
    /// Checks that every member names a body part, none twice, with finite, non-negative
    /// gains and at least one member required.
    pub fn validate(&self) -> Result<(), String> {
        let mut seen = Vec::new();
        for m in &self.members {
            if part(&m.part).is_none() {
                let names: Vec<&str> = PARTS.iter().map(|p| p.name).collect();
                return Err(format!(
                    "compound controller {}: no body part '{}' ({})",
                    self.name,
                    m.part,
                    names.join(", ")
                ));
            }
            if seen.contains(&&m.part) {
                return Err(format!(
                    "compound controller {}: part '{}' twice",
                    self.name, m.part
                ));
            }
            seen.push(&m.part);
            if !(m.kp.is_finite() && m.kd.is_finite() && m.kp >= 0.0 && m.kd >= 0.0) {
                return Err(format!(
                    "compound controller {}: gains of '{}' must be finite and not negative",
                    self.name, m.part
                ));
            }
        }
        if self.members.iter().all(|m| m.need != Need::Required) {
            return Err(format!(
                "compound controller {} has no required member",
                self.name
            ));
        }
        Ok(())
    }

    /// The parts of its required members (what a configuration must simulate for it).
    pub fn required(&self) -> Vec<usize> {
        (self.members.iter())
            .filter(|m| m.need == Need::Required)
            .filter_map(|m| part(&m.part))
            .collect()
    }

    /// The parts of all its members.
    pub fn parts(&self) -> Vec<usize> {
        self.members.iter().filter_map(|m| part(&m.part)).collect()
    }

    /// Binds it to `sim` with every gain times `stiffness` (see the module documentation).
    pub fn bind(&self, sim: &Simulation, stiffness: f64) -> Result<Compound, String> {
        let mut pulls = Vec::new();
        let mut skipped = Vec::new();
        for m in &self.members {
            let simulated = sim.part_named(&m.part).filter(|&i| sim.is_physical(i));
            match (simulated, m.need) {
                (Some(i), _) => pulls.push((i, m.target, m.kp * stiffness, m.kd * stiffness)),
                (None, Need::Desired) => skipped.push(m.part.clone()),
                (None, Need::Required) => {
                    return Err(format!(
                        "compound controller {} needs the part '{}', which is not simulated",
                        self.name, m.part
                    ))
                }
            }
        }
        Ok(Compound { pulls, skipped })
    }
}

impl Controller for Compound {
    fn drive(&self, sim: &Simulation, drive: &mut Drive) {
        for &(i, target, kp, kd) in &self.pulls {
            if sim.is_physical(i) {
                drive.pull(i, target, kp, kd);
            }
        }
    }
}

/// The embedded definitions.
const COMPOUNDS: &str = include_str!("../../../fixtures/physics/compounds.json");

/// Compound definitions by name, in the order defined (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct CompoundLibrary {
    specs: Vec<CompoundSpec>,
}

impl Default for CompoundLibrary {
    /// The embedded definitions (read once per process, then copied): an arm hanging down
    /// loosely, left and right (soft pulls toward rest on the shoulder and elbow, a damper on
    /// the wrist).
    fn default() -> Self {
        static LIBRARY: std::sync::LazyLock<CompoundLibrary> = std::sync::LazyLock::new(|| {
            CompoundLibrary::from_json(COMPOUNDS).expect("the embedded compounds are valid")
        });
        LIBRARY.clone()
    }
}

impl CompoundLibrary {
    /// Reads definitions from JSON: `{"compounds": {NAME: {"members": [{"part", "kp", "kd",
    /// "need": "required" | "desired", "target": [z, x, y] degrees}]}}}`, each checked with
    /// [`CompoundSpec::validate`]. The error names the field or the compound.
    pub fn from_json(text: &str) -> Result<CompoundLibrary, String> {
        let file: CompoundsFile = crate::data::from_json(text)?;
        let specs: Vec<CompoundSpec> = (file.compounds.into_iter())
            .map(|(name, c)| CompoundSpec {
                name,
                members: c.members.into_iter().map(MemberFile::member).collect(),
            })
            .collect();
        for spec in &specs {
            if spec.name.trim().is_empty() {
                return Err("a compound controller needs a name".into());
            }
            spec.validate()?;
        }
        Ok(CompoundLibrary { specs })
    }

    /// These definitions and `more`'s, a definition of `more` replacing one of the same name
    /// (compared as [`CompoundLibrary::find`] does).
    pub fn extended(mut self, more: CompoundLibrary) -> CompoundLibrary {
        for spec in more.specs {
            match self
                .specs
                .iter_mut()
                .find(|s| same_name(&s.name, &spec.name))
            {
                Some(old) => *old = spec,
                None => self.specs.push(spec),
            }
        }
        self
    }

    /// The definition named `class`: in any case, with or without a `Controller` suffix.
    pub fn find(&self, class: &str) -> Option<&CompoundSpec> {
        self.specs.iter().find(|s| same_name(&s.name, class))
    }

    /// Every definition, in order.
    pub fn specs(&self) -> &[CompoundSpec] {
        &self.specs
    }
}

/// Whether two controller class names are the same: in any case, with or without the
/// `Controller` suffix (`HangingLeftArm`, `hangingleftarmcontroller`).
pub fn same_name(a: &str, b: &str) -> bool {
    let short = |n: &str| {
        let lower = n.to_ascii_lowercase();
        match lower.strip_suffix("controller") {
            Some(s) => s.to_string(),
            None => lower,
        }
    };
    short(a) == short(b)
}

/// The definitions file as written.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CompoundsFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    #[serde(default, rename = "units")]
    _units: crate::data::Note,
    compounds: indexmap::IndexMap<String, CompoundFile>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CompoundFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    members: Vec<MemberFile>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MemberFile {
    part: String,
    kp: f64,
    kd: f64,
    need: Need,
    /// z, x, y Euler degrees (ZXY); the rest pose when omitted.
    #[serde(default)]
    target: Option<[f64; 3]>,
}

impl MemberFile {
    fn member(self) -> Member {
        let target = self.target.map_or(DQuat::IDENTITY, |[z, x, y]| {
            DQuat::from_euler(
                EulerRot::ZXY,
                z.to_radians(),
                x.to_radians(),
                y.to_radians(),
            )
        });
        Member {
            part: self.part,
            target,
            kp: self.kp,
            kd: self.kd,
            need: self.need,
        }
    }
}

/// The index of the body part `name` in [`PARTS`].
fn part(name: &str) -> Option<usize> {
    PARTS.iter().position(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::character::body::{Pose, Skeleton};
    use crate::character::dynamics::sim::STEP;

    /// The embedded definitions: `HangingLeftArm`, then `HangingRightArm`.
    fn built_in() -> Vec<CompoundSpec> {
        CompoundLibrary::default().specs().to_vec()
    }

    /// Lower body and trunk, and the left arm without its hand.
    const WITH_LEFT_ARM: [usize; 10] = [0, 1, 3, 4, 9, 10, 11, 12, 13, 14];

    fn sim(parts: &[usize]) -> Simulation {
        let s = Skeleton::adult();
        Simulation::new(&s, &Pose::rest(&s), parts, STEP).unwrap()
    }

    #[test]
    fn a_compound_leaves_out_a_desired_member_the_body_does_not_simulate() {
        let spec = &built_in()[0];
        let s = sim(&WITH_LEFT_ARM);
        let c = spec.bind(&s, 1.0).unwrap();
        assert_eq!(c.skipped, vec!["l_hand".to_string()]);
        let mut d = Drive::new(15);
        c.drive(&s, &mut d);
        let pulled: Vec<usize> = (0..15).filter(|&i| d.pulls[i].is_some()).collect();
        assert_eq!(pulled, vec![3, 4]);
        assert_eq!(d.pulls[3].unwrap().kp, 15.0);
    }

    #[test]
    fn a_compound_does_not_bind_without_a_required_member() {
        let spec = &built_in()[0];
        let lower = sim(&[0, 1, 9, 10, 11, 12, 13, 14]);
        let e = spec.bind(&lower, 1.0).unwrap_err();
        assert!(
            e.contains("HangingLeftArm") && e.contains("l_upperarm"),
            "{e}"
        );
    }

    #[test]
    fn the_whole_arm_binds_every_member_and_the_gains_scale() {
        let spec = &built_in()[1];
        let s = sim(&[0, 1, 6, 7, 8, 9, 10, 11, 12, 13, 14]);
        let c = spec.bind(&s, 2.0).unwrap();
        assert!(c.skipped.is_empty());
        let mut d = Drive::new(15);
        c.drive(&s, &mut d);
        assert_eq!(d.pulls[8].unwrap().kd, 0.4);
    }

    #[test]
    fn definitions_are_checked() {
        for spec in built_in() {
            spec.validate().unwrap();
            assert_eq!(spec.required().len(), 2);
            assert_eq!(spec.parts().len(), 3);
        }
        let mut bad = built_in()[0].clone();
        bad.members[0].part = "l_wing".into();
        assert!(bad.validate().unwrap_err().contains("l_wing"));
        let mut none = built_in()[0].clone();
        none.members.iter_mut().for_each(|m| m.need = Need::Desired);
        assert!(none.validate().unwrap_err().contains("no required"));
        let mut twice = built_in()[0].clone();
        twice.members[1].part = "l_upperarm".into();
        assert!(twice.validate().unwrap_err().contains("twice"));
    }
}
