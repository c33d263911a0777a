//! The motion data the built-in engines read: the procedural unit library, the bindings of
//! gesture lexemes, posture poses and head lexemes, and the compound physical controllers. The
//! defaults are embedded in the crate (`fixtures/procedural/units.json`,
//! `fixtures/bindings/{gestures,poses,heads}.json`, `fixtures/physics/compounds.json`); a
//! directory with files of the same names adds to them: its units and compounds join the
//! library (replacing those of the same name) and its bindings come before the embedded ones
//! (so they win for the lexemes and poses they bind).

use std::path::Path;

use super::gesture::Lexicon;
use super::head::HeadLexicon;
use super::posture::PoseBindings;
use super::procedural::Library;
use crate::character::body::Skeleton;
use crate::character::dynamics::compound::CompoundLibrary;

/// The data of the motion engines.
#[derive(Debug, Clone)]
pub struct Assets {
    /// Procedural units (`units.json`).
    pub units: Library,
    /// Gesture bindings (`gestures.json`).
    pub gestures: Lexicon,
    /// Posture pose bindings (`poses.json`).
    pub poses: PoseBindings,
    /// Head lexemes (`heads.json`).
    pub heads: HeadLexicon,
    /// Compound physical controllers (`compounds.json`).
    pub compounds: CompoundLibrary,
}

impl Default for Assets {
    fn default() -> Self {
        Assets {
            units: Library::default_library(),
            gestures: Lexicon::default_lexicon(),
            poses: PoseBindings::default_bindings(),
            heads: HeadLexicon::default_lexicon(),
            compounds: CompoundLibrary::default(),
        }
    }
}

impl Assets {
    /// The defaults extended by each of `units.json`, `gestures.json`, `poses.json`,
    /// `heads.json` and `compounds.json` that `dir` has (see the module documentation). The
    /// directory's bindings may name its own units and the embedded ones. The error names the
    /// file and what is wrong.
    pub fn from_dir(dir: &Path) -> Result<Assets, String> {
        if !dir.is_dir() {
            return Err(format!("{} is not a directory", dir.display()));
        }
        let read = |name: &str| -> Result<Option<(String, String)>, String> {
            let path = dir.join(name);
            if !path.exists() {
                return Ok(None);
            }
            let text =
                std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(Some((path.display().to_string(), text)))
        };
        let mut assets = Assets::default();
        let skeleton = Skeleton::adult();
        let unknown = |path: &str, what: String, joint: &str| {
            format!(
                "{path}: {what} names joint '{joint}', which the skeleton does not have (H-Anim \
                 names such as r_shoulder, r_elbow, r_wrist, vc4, skullbase)"
            )
        };
        if let Some((path, text)) = read("units.json")? {
            let units = Library::from_json(&text).map_err(|e| format!("{path}: {e}"))?;
            let mut names: Vec<(&str, &str)> = units
                .units()
                .flat_map(|u| u.joint_names().map(move |j| (u.name.as_str(), j)))
                .collect();
            names.sort_unstable();
            if let Some((unit, joint)) = names.iter().find(|(_, j)| skeleton.joint(j).is_none()) {
                return Err(unknown(&path, format!("unit '{unit}'"), joint));
            }
            assets.units = assets.units.extended(units);
        }
        if let Some((path, text)) = read("gestures.json")? {
            let first =
                Lexicon::from_json(&text, &assets.units).map_err(|e| format!("{path}: {e}"))?;
            let bad = first
                .key_joints()
                .find(|(_, j)| skeleton.joint(j).is_none());
            if let Some((lexeme, joint)) = bad {
                return Err(unknown(&path, format!("the binding of '{lexeme}'"), joint));
            }
            assets.gestures = assets.gestures.extended_by(first);
        }
        if let Some((path, text)) = read("poses.json")? {
            let first = PoseBindings::from_json(&text, &assets.units)
                .map_err(|e| format!("{path}: {e}"))?;
            assets.poses = assets.poses.extended_by(first);
        }
        if let Some((path, text)) = read("heads.json")? {
            let first = HeadLexicon::from_json(&text).map_err(|e| format!("{path}: {e}"))?;
            assets.heads = assets.heads.extended_by(first);
        }
        if let Some((path, text)) = read("compounds.json")? {
            let more = CompoundLibrary::from_json(&text).map_err(|e| format!("{path}: {e}"))?;
            if let Some(s) =
                (more.specs().iter()).find(|s| super::physical::is_built_in_class(&s.name))
            {
                return Err(format!(
                    "{path}: compound '{}' takes the name of a built-in controller class",
                    s.name
                ));
            }
            assets.compounds = assets.compounds.extended(more);
        }
        Ok(assets)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded data passes the check a directory's data must pass.
    #[test]
    fn the_embedded_units_and_bindings_name_only_joints_of_the_skeleton() {
        let (assets, skeleton) = (Assets::default(), Skeleton::adult());
        let units: Vec<&str> = assets.units.units().flat_map(|u| u.joint_names()).collect();
        assert!(units.len() > 10, "{units:?}");
        for j in units {
            assert!(skeleton.joint(j).is_some(), "{j}");
        }
        for (lexeme, j) in assets.gestures.key_joints() {
            assert!(skeleton.joint(j).is_some(), "{lexeme}: {j}");
        }
    }
}
