//! Conversing groups and the space they hold (Kendon's F-formation, as the "Social Path
//! Following" thesis uses it): the members stand on a ring, the p-space, around a shared
//! o-space they all face; a passer-by walks round the whole of it, never between two people in
//! conversation. A group is declared in the world file (`groups`) or found among the characters
//! the world file places: two standing characters belong together when each one's focus point
//! (0.6 m ahead of it, half a social distance) lies within [`FOCUS_GAP`] of the other's and
//! they stand within [`REACH`] of each other; groups are the connected sets of such pairs. Where
//! a group's space lies is taken from its members' places when a walk starts: the o-space's
//! centre is the mean of their focus points, pushed out to the middle of the ring; the space
//! kept clear is the circle through the members' far sides.

use glam::Vec2;
use serde::Deserialize;

use super::snapshot::{Agent, Crowd};

/// How far ahead of a standing character its focus point lies (m).
pub const FOCUS: f32 = 0.6;
/// Most distance between two members' focus points for them to be found as a group (m).
pub const FOCUS_GAP: f32 = 0.6;
/// Most distance between two members found as a group (m).
pub const REACH: f32 = 3.0;
/// Kept beyond a group's space by walkers going round it (m): their personal space, so that
/// passing the members is not a contact to avoid.
pub const PASSING: f32 = 0.3;
/// A member moving faster than this (m/s) is not standing in conversation: its group holds no
/// space while it moves.
pub const STILL: f32 = 0.2;
/// Most members a group may have.
pub const MAX_MEMBERS: usize = 32;
/// A group whose members stand further than this from its centre holds no space (m): they have
/// walked apart.
pub const SPREAD: f32 = 3.0;

/// The world file's form of a group.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupFile {
    members: Vec<String>,
    #[serde(default = "yes")]
    conversing: bool,
}

fn yes() -> bool {
    true
}

/// A group of characters.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// Its members' ids, sorted.
    pub members: Vec<String>,
    /// Whether they converse (only conversing groups hold a space).
    pub conversing: bool,
    /// Whether it was found among people who happened to stand so ([`found`]), not declared
    /// by the world file: such a group breaks up for good when one of them walks off.
    pub found: bool,
}

/// A member as the group's space needs it: where it stands, which way it faces (unit x, z), its
/// radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Member {
    /// Where it stands (x, z).
    pub at: Vec2,
    /// Which way it faces (unit, x and z).
    pub facing: Vec2,
    /// Its body radius (m).
    pub radius: f32,
}

/// The space a conversing group holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Space {
    /// The o-space's centre (x, z).
    pub centre: Vec2,
    /// The o-space's radius: the free middle of the ring (m).
    pub inner: f32,
    /// The radius of the circle through the members' far sides: all that is kept clear (m).
    pub outer: f32,
}

impl GroupFile {
    /// The group, or why not (`index` names it; `known` tells whether a character exists).
    pub fn group(self, index: usize, known: impl Fn(&str) -> bool) -> Result<Group, String> {
        let at = |what: String| format!("groups[{index}]: {what}");
        let mut members = self.members;
        members.sort();
        members.dedup();
        if members.len() < 2 || members.len() > MAX_MEMBERS {
            return Err(at(format!(
                "a group has 2 to {MAX_MEMBERS} different members, not {}",
                members.len()
            )));
        }
        if let Some(m) = members.iter().find(|m| !known(m)) {
            return Err(at(format!(
                "member '{m}' is not among the world's characters"
            )));
        }
        Ok(Group {
            members,
            conversing: self.conversing,
            found: false,
        })
    }
}

/// A standing character's focus point.
fn focus(m: &Member) -> Vec2 {
    m.at + m.facing * FOCUS
}

impl Group {
    /// The space the group holds with its members standing as `members` say, or `None` when it
    /// does not converse, fewer than two are known or they stand too far apart.
    pub fn space(&self, members: &[Member]) -> Option<Space> {
        if !self.conversing || members.len() < 2 {
            return None;
        }
        let n = members.len() as f32;
        let middle = members.iter().map(|m| m.at).sum::<Vec2>() / n;
        let focal = members.iter().map(focus).sum::<Vec2>() / n;
        // two side by side face a point ahead of them; a ring faces its middle
        let centre = if members.len() == 2 {
            focal
        } else {
            (middle + focal) * 0.5
        };
        let far = |m: &Member| m.at.distance(centre) + m.radius;
        let outer = members.iter().map(far).fold(0.0, f32::max);
        let near = members.iter().map(|m| m.at.distance(centre) - m.radius);
        let inner = near.fold(f32::INFINITY, f32::min).max(0.1);
        (outer - members.iter().map(|m| m.radius).fold(0.0, f32::max) <= SPREAD).then_some(Space {
            centre,
            inner,
            outer,
        })
    }
}

/// The conversing groups found among standing characters (`ids` and `members` in the same
/// order; walkers are left out by the caller), each with its members sorted, in the order of
/// their first member.
pub fn found(ids: &[String], members: &[Member]) -> Vec<Group> {
    let agents = members.iter().map(|m| Agent {
        at: m.at,
        velocity: Vec2::ZERO,
        radius: m.radius,
    });
    let crowd = Crowd::unnamed(0.0, agents.collect());
    let mut root: Vec<usize> = (0..members.len()).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    let mut near = Vec::new();
    for (i, m) in members.iter().enumerate() {
        crowd.near(m.at, REACH, &mut near);
        for &j in near.iter().filter(|&&j| j > i) {
            let o = &members[j];
            if m.at.distance(o.at) <= REACH && focus(m).distance(focus(o)) <= FOCUS_GAP {
                let (a, b) = (find(&mut root, i), find(&mut root, j));
                root[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<String>> = Default::default();
    for (i, id) in ids.iter().enumerate().take(members.len()) {
        let r = find(&mut root, i);
        groups.entry(r).or_default().push(id.clone());
    }
    (groups.into_values())
        .filter(|g| g.len() >= 2 && g.len() <= MAX_MEMBERS)
        .map(|mut members| {
            members.sort();
            Group {
                members,
                conversing: true,
                found: true,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn member(x: f32, z: f32, toward: Vec2) -> Member {
        let at = Vec2::new(x, z);
        Member {
            at,
            facing: (toward - at).normalize(),
            radius: 0.25,
        }
    }

    #[test]
    fn three_facing_a_middle_are_found_and_hold_the_ring_around_it() {
        let c = Vec2::new(2.0, 3.0);
        let ring: Vec<Member> = (0..3)
            .map(|k| {
                let a = k as f32 * 2.1;
                member(c.x + 0.8 * a.sin(), c.y + 0.8 * a.cos(), c)
            })
            .collect();
        // a passer-by facing away and one far off are not members
        let mut all = ring.clone();
        all.push(member(c.x + 1.6, c.y, Vec2::new(10.0, 3.0)));
        all.push(member(20.0, 20.0, Vec2::new(20.0, 21.0)));
        let ids: Vec<String> = ["a", "b", "c", "d", "e"].map(String::from).to_vec();
        let groups = found(&ids, &all);
        assert_eq!(groups.len(), 1, "{groups:?}");
        assert_eq!(groups[0].members, ["a", "b", "c"]);
        let s = groups[0].space(&ring).unwrap();
        assert!(s.centre.distance(c) < 0.05, "{s:?}");
        assert!(
            (s.outer - 1.05).abs() < 0.05 && (s.inner - 0.55).abs() < 0.05,
            "{s:?}"
        );
    }

    #[test]
    fn two_facing_each_other_are_a_group_two_side_by_side_are_not() {
        let ids: Vec<String> = ["a", "b"].map(String::from).to_vec();
        let facing = [
            member(0.0, 0.0, Vec2::new(0.0, 1.0)),
            member(0.0, 1.2, Vec2::ZERO),
        ];
        assert_eq!(found(&ids, &facing).len(), 1);
        let abreast = [
            member(0.0, 0.0, Vec2::new(0.0, 1.0)),
            member(1.0, 0.0, Vec2::new(1.0, 1.0)),
        ];
        assert!(found(&ids, &abreast).is_empty());
        let g = Group {
            members: ids,
            conversing: true,
            found: true,
        };
        let s = g.space(&facing).unwrap();
        assert!(s.centre.distance(Vec2::new(0.0, 0.6)) < 1e-4, "{s:?}");
        assert!((s.outer - 0.85).abs() < 1e-4);
        // members who walked apart hold nothing
        let apart = [facing[0], member(0.0, 9.0, Vec2::ZERO)];
        assert!(g.space(&apart).is_none());
    }

    #[test]
    fn a_declared_group_names_only_known_characters() {
        let file = |m: &[&str]| GroupFile {
            members: m.iter().map(|s| s.to_string()).collect(),
            conversing: true,
        };
        let known = |id: &str| id != "ghost";
        let e = file(&["a", "ghost"]).group(2, known).unwrap_err();
        assert!(e.contains("groups[2]") && e.contains("'ghost'"), "{e}");
        let e = file(&["a", "a"]).group(0, known).unwrap_err();
        assert!(e.contains("2 to 32"), "{e}");
        assert_eq!(
            file(&["b", "a"]).group(0, known).unwrap().members,
            ["a", "b"]
        );
    }
}
