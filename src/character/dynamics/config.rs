//! Body configurations for mixed dynamics: which joints are simulated (the physical part P) and
//! which form kinematic chains Kⱼ, each hanging from P at one connector. A configuration is a
//! partition of the skeleton's joints; it is valid when no joint is in two parts, every joint is
//! in one, each chain is one connected subtree (so it has exactly one top joint, whose parent —
//! the connector — is in P), and a non-empty P contains the root. Each frame the realizer takes
//! the smallest valid configuration whose P covers the joints the running physical units need.

use crate::character::body::Skeleton;

/// A partition of the joints (indices into the skeleton).
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// A name (`balance`, `rag doll`, …).
    pub name: String,
    /// The simulated joints.
    pub physical: Vec<usize>,
    /// The kinematic chains.
    pub chains: Vec<Vec<usize>>,
}

impl Configuration {
    /// `physical` simulated, and every other joint in a chain: one chain per subtree of
    /// non-physical joints hanging from a physical one (or one chain of the whole body when
    /// nothing is physical).
    pub fn from_physical(name: &str, skeleton: &Skeleton, physical: &[usize]) -> Configuration {
        let joints = skeleton.joints();
        let is_physical = |i: usize| physical.contains(&i);
        let mut chains: Vec<Vec<usize>> = Vec::new();
        for (i, j) in joints.iter().enumerate() {
            if is_physical(i) || j.parent.is_some_and(|p| !is_physical(p)) {
                continue;
            }
            // a top joint: it and everything below it that is not physical
            let mut chain = vec![i];
            let mut k = 0;
            while k < chain.len() {
                let below: Vec<usize> = skeleton
                    .children(chain[k])
                    .filter(|&c| !is_physical(c))
                    .collect();
                chain.extend(below);
                k += 1;
            }
            chain.sort_unstable();
            chains.push(chain);
        }
        Configuration {
            name: name.to_string(),
            physical: physical.to_vec(),
            chains,
        }
    }

    /// Whether the configuration is a valid partition of `skeleton` (see the module
    /// documentation); the error says what is wrong.
    pub fn validate(&self, skeleton: &Skeleton) -> Result<(), String> {
        let joints = skeleton.joints();
        let name = |i: usize| joints.get(i).map_or("?", |j| j.name.as_str());
        let mut part = vec![None::<usize>; joints.len()];
        let parts = std::iter::once(&self.physical).chain(&self.chains);
        for (k, members) in parts.enumerate() {
            for &i in members {
                match part.get(i).copied() {
                    None => return Err(format!("{}: joint {i} is not in the skeleton", self.name)),
                    Some(Some(_)) => {
                        return Err(format!("{}: joint {} is in two parts", self.name, name(i)))
                    }
                    Some(None) => part[i] = Some(k),
                }
            }
        }
        if let Some(i) = part.iter().position(Option::is_none) {
            return Err(format!("{}: joint {} is in no part", self.name, name(i)));
        }
        let root = joints.iter().position(|j| j.parent.is_none()).unwrap_or(0);
        if !self.physical.is_empty() && part[root] != Some(0) {
            return Err(format!(
                "{}: the physical part must contain the root {}",
                self.name,
                name(root)
            ));
        }
        for (k, chain) in self.chains.iter().enumerate() {
            let tops: Vec<usize> = (chain.iter().copied())
                .filter(|&i| joints[i].parent.is_none_or(|p| part[p] != Some(k + 1)))
                .collect();
            if tops.len() != 1 {
                let named: Vec<&str> = tops.iter().map(|&i| name(i)).collect();
                return Err(format!(
                    "{}: a kinematic chain must be one subtree with one connector; this one starts at {}",
                    self.name,
                    named.join(", ")
                ));
            }
        }
        Ok(())
    }

    /// The connector of chain `k`: the physical joint it hangs from (`None` when nothing is
    /// physical).
    pub fn connector(&self, skeleton: &Skeleton, k: usize) -> Option<usize> {
        let joints = skeleton.joints();
        let chain = self.chains.get(k)?;
        chain
            .iter()
            .find_map(|&i| joints[i].parent.filter(|p| self.physical.contains(p)))
    }
}

/// The smallest of `configurations` (fewest physical joints) whose physical part covers
/// `needed`; `None` if none does.
pub fn smallest_covering<'a>(
    configurations: &'a [Configuration],
    needed: &[usize],
) -> Option<&'a Configuration> {
    (configurations.iter())
        .filter(|c| needed.iter().all(|j| c.physical.contains(j)))
        .min_by_key(|c| c.physical.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::character::body::skeleton::ADULT_SPINE;

    fn joints(s: &Skeleton, names: &[&str]) -> Vec<usize> {
        names.iter().map(|n| s.joint(n).unwrap()).collect()
    }

    const LEGS: &[&str] = &[
        "HumanoidRoot",
        "sacroiliac",
        "l_hip",
        "l_knee",
        "l_talocrural",
        "l_metatarsal",
        "r_hip",
        "r_knee",
        "r_talocrural",
        "r_metatarsal",
    ];

    #[test]
    fn a_simulated_lower_body_leaves_the_upper_body_as_one_chain_on_the_root() {
        let s = Skeleton::adult();
        let c = Configuration::from_physical("balance", &s, &joints(&s, LEGS));
        c.validate(&s).unwrap();
        assert_eq!(
            c.chains.len(),
            1,
            "the spine, arms and head hang from the root"
        );
        assert_eq!(c.connector(&s, 0), s.joint("HumanoidRoot"));
        assert_eq!(c.chains[0].len(), s.len() - LEGS.len());
        // nothing physical: one chain of everything, valid
        let all = Configuration::from_physical("kinematic", &s, &[]);
        all.validate(&s).unwrap();
        assert_eq!((all.chains.len(), all.connector(&s, 0)), (1, None));
    }

    #[test]
    fn invalid_partitions_are_refused_with_the_reason() {
        let s = Skeleton::adult();
        let mut c = Configuration::from_physical("balance", &s, &joints(&s, LEGS));
        let knee = s.joint("l_knee").unwrap();
        c.chains[0].push(knee);
        assert!(c
            .validate(&s)
            .unwrap_err()
            .contains("l_knee is in two parts"));
        // a chain of two pieces (the left arm and the right arm without the spine between)
        let mut arms = joints(&s, LEGS);
        let head = ["temporomandibular", "l_eyeball_joint", "r_eyeball_joint"];
        arms.extend(joints(&s, &[&ADULT_SPINE[..], &head].concat()));
        let mut c = Configuration::from_physical("arms", &s, &arms);
        c.validate(&s).unwrap();
        let (a, b) = (c.chains.remove(0), c.chains.remove(0));
        c.chains.insert(0, [a, b].concat());
        assert!(c
            .validate(&s)
            .unwrap_err()
            .contains("one subtree with one connector"));
        // a physical part without the root
        let c = Configuration::from_physical("no root", &s, &joints(&s, &["l_knee"]));
        assert!(c
            .validate(&s)
            .unwrap_err()
            .contains("must contain the root"));
        // a joint left out
        let mut c = Configuration::from_physical("balance", &s, &joints(&s, LEGS));
        c.chains[0].pop();
        assert!(c.validate(&s).unwrap_err().contains("is in no part"));
    }

    #[test]
    fn the_smallest_configuration_covering_the_physical_units_is_chosen() {
        let s = Skeleton::adult();
        let legs = Configuration::from_physical("balance", &s, &joints(&s, LEGS));
        let everything: Vec<usize> = (0..s.len()).collect();
        let rag = Configuration::from_physical("rag doll", &s, &everything);
        let none = Configuration::from_physical("kinematic", &s, &[]);
        let all = [rag, legs, none];
        assert_eq!(smallest_covering(&all, &[]).unwrap().name, "kinematic");
        assert_eq!(
            smallest_covering(&all, &joints(&s, &["l_knee"]))
                .unwrap()
                .name,
            "balance"
        );
        assert_eq!(
            smallest_covering(&all, &joints(&s, &["r_elbow"]))
                .unwrap()
                .name,
            "rag doll"
        );
    }
}
