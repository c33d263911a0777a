//! The crowd as the walkers see it in one frame: every placed character's place, velocity and
//! radius as of the end of the previous frame (so that no walker sees another's move of this
//! frame, and the order in which characters step does not matter), and a uniform grid over them
//! to find who is near. Built once a frame for the whole world, shared by every walker.
//!
//! The grid is written here rather than taken from a k-d tree crate: the query is "everyone
//! within r", rebuilt every frame for every agent, where a sorted list of cell keys is built in
//! one sort, visited in a fixed order (the same neighbours in the same order on every run) and
//! needs no allocation per query beyond the caller's buffer.

use glam::Vec2;

use super::doorway::{Passing, Turn};

/// How often walkers among others see where the others are (s): the realizer builds the crowd
/// every this much global time, on a grid of its multiples, so that no result depends on the
/// host's frames.
pub const PERIOD: f64 = 0.05;

/// Whether `t` is a time of the crowd's grid (within a millionth of a period).
pub fn on_grid(t: f64) -> bool {
    let k = t / PERIOD;
    (k - k.round()).abs() < 1e-6
}

/// Side of a grid cell (m).
pub const CELL: f32 = 2.0;
/// Most characters a crowd holds (beyond, the rest are not seen by walkers, with a warning
/// from whoever builds it).
pub const MAX_AGENTS: usize = 20_000;

/// One character as the others see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Agent {
    /// Where it stands (x, z).
    pub at: Vec2,
    /// How it moves (m/s, x and z).
    pub velocity: Vec2,
    /// Its body radius (m).
    pub radius: f32,
}

/// Every character of a world at one time, with a grid to find neighbours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Crowd {
    /// When the places were taken (s).
    pub time: f64,
    ids: Vec<String>,
    agents: Vec<Agent>,
    /// (cell key, agent index), sorted.
    cells: Vec<(u64, u32)>,
    /// The agents' places in the order of `cells` (read together when searching a cell).
    placed: Vec<Vec2>,
    /// (asked, asking), sorted: who asks whom to make room (`crowd::negotiate`).
    asks: Vec<(u32, u32)>,
    /// Who is on a walk of its own (indices, sorted): standing still, it only waits.
    going: Vec<u32>,
    /// Who stands (or walks) off its place to make room and will go back (indices, sorted).
    aside: Vec<u32>,
    /// Who is coming to a narrow to go through it (index, which and how), by index.
    passing: Vec<(u32, Passing)>,
    /// Whose turn it is at each narrow of the world's obstacles (`crowd::doorway`).
    turns: Vec<Turn>,
    /// The way each walker's walk goes (index, unit direction), by index: one standing in a
    /// press still goes somewhere.
    ways: Vec<(u32, Vec2)>,
}

/// Indices as a sorted set (searched by `binary_search`).
fn index_set(indices: impl IntoIterator<Item = usize>) -> Vec<u32> {
    let mut set: Vec<u32> = indices.into_iter().map(|i| i as u32).collect();
    set.sort_unstable();
    set.dedup();
    set
}

fn cell_of(p: Vec2) -> (i32, i32) {
    let c = |v: f32| (v / CELL).floor().clamp(-1e9, 1e9) as i32;
    (c(p.x), c(p.y))
}

fn key(c: (i32, i32)) -> u64 {
    ((c.0 as u32 as u64) << 32) | c.1 as u32 as u64
}

impl Crowd {
    /// The crowd of `agents` (by id; kept in id order, one per id) at `time`; at most
    /// [`MAX_AGENTS`] are kept.
    pub fn new(time: f64, agents: impl IntoIterator<Item = (String, Agent)>) -> Crowd {
        let mut all: Vec<(String, Agent)> = agents
            .into_iter()
            .filter(|(_, a)| a.at.is_finite() && a.velocity.is_finite())
            .take(MAX_AGENTS)
            .collect();
        all.sort_by(|a, b| a.0.cmp(&b.0));
        all.dedup_by(|a, b| a.0 == b.0);
        let (ids, agents): (Vec<String>, Vec<Agent>) = all.into_iter().unzip();
        Crowd::with_cells(time, ids, agents)
    }

    /// The crowd of `agents` without names (agent `i` is index `i`; [`Crowd::index`] finds
    /// none), for simulations of roots only.
    pub fn unnamed(time: f64, mut agents: Vec<Agent>) -> Crowd {
        agents.truncate(MAX_AGENTS);
        for a in &mut agents {
            if !(a.at.is_finite() && a.velocity.is_finite()) {
                // kept in place so that indices stay the agents' own; far away, still
                a.at = Vec2::splat(1e9);
                a.velocity = Vec2::ZERO;
            }
        }
        Crowd::with_cells(time, Vec::new(), agents)
    }

    /// The crowd of `agents` named `ids` (or unnamed), with its grid.
    fn with_cells(time: f64, ids: Vec<String>, agents: Vec<Agent>) -> Crowd {
        let mut cells: Vec<(u64, u32)> = (agents.iter().enumerate())
            .map(|(i, a)| (key(cell_of(a.at)), i as u32))
            .collect();
        cells.sort_unstable();
        let placed = cells.iter().map(|&(_, i)| agents[i as usize].at).collect();
        Crowd {
            time,
            ids,
            agents,
            cells,
            placed,
            asks: Vec::new(),
            going: Vec::new(),
            aside: Vec::new(),
            passing: Vec::new(),
            turns: Vec::new(),
            ways: Vec::new(),
        }
    }

    /// Notes the way each walker's walk goes (index, unit direction).
    pub fn set_ways(&mut self, ways: impl IntoIterator<Item = (usize, Vec2)>) {
        self.ways = (ways.into_iter()).map(|(i, w)| (i as u32, w)).collect();
        self.ways.sort_by_key(|(i, _)| *i);
    }

    /// The way character `i`'s walk goes, if it walks somewhere.
    pub fn way(&self, i: usize) -> Option<Vec2> {
        (self
            .ways
            .binary_search_by_key(&(i as u32), |(k, _)| *k)
            .ok())
        .map(|k| self.ways[k].1)
    }

    /// Notes who is coming to a narrow to go through it (index, which and how).
    pub fn set_passing(&mut self, passing: impl IntoIterator<Item = (usize, Passing)>) {
        self.passing = (passing.into_iter()).map(|(i, p)| (i as u32, p)).collect();
        self.passing.sort_by_key(|(i, _)| *i);
    }

    /// Who is coming to a narrow to go through it, by index.
    pub fn passing(&self) -> &[(u32, Passing)] {
        &self.passing
    }

    /// Notes whose turn it is at each narrow.
    pub fn set_turns(&mut self, turns: Vec<Turn>) {
        self.turns = turns;
    }

    /// Whose turn it is at narrow `n` (free when the crowd knows of none).
    pub fn turn(&self, n: u32) -> Turn {
        self.turns.get(n as usize).copied().unwrap_or_default()
    }

    /// Whose turn it is at every narrow.
    pub fn turns(&self) -> &[Turn] {
        &self.turns
    }

    /// Notes who asks whom to make room: for each asking character (index), the place of the
    /// one it asks, taken to be whoever stands within 0.15 m of it (the nearest; nobody else).
    pub fn set_asks(&mut self, asking: impl IntoIterator<Item = (usize, Vec2)>) {
        let mut near = Vec::new();
        let mut pairs = Vec::new();
        for (who, place) in asking {
            self.near(place, 0.15, &mut near);
            let asked = (near.iter().copied())
                .filter(|&i| i != who)
                .min_by(|&a, &b| {
                    let d = |i: usize| self.agents[i].at.distance_squared(place);
                    d(a).total_cmp(&d(b)).then(a.cmp(&b))
                });
            if let Some(asked) = asked {
                pairs.push((asked, who));
            }
        }
        self.set_ask_pairs(pairs);
    }

    /// Notes who is on a walk of its own (indices): standing still, such a one waits, and
    /// does not stand on anyone's goal for good.
    pub fn set_on_their_way(&mut self, going: impl IntoIterator<Item = usize>) {
        self.going = index_set(going);
    }

    /// Whether character `i` is on a walk of its own.
    pub fn on_its_way(&self, i: usize) -> bool {
        self.going.binary_search(&(i as u32)).is_ok()
    }

    /// Notes who is off its place to make room for someone (indices): standing there, such a
    /// one goes back, and does not stand on anyone's goal for good.
    pub fn set_aside(&mut self, aside: impl IntoIterator<Item = usize>) {
        self.aside = index_set(aside);
    }

    /// Whether character `i` is off its place to make room.
    pub fn is_aside(&self, i: usize) -> bool {
        self.aside.binary_search(&(i as u32)).is_ok()
    }

    /// Notes who asks whom to make room, as (asked, asking) indices.
    pub fn set_ask_pairs(&mut self, pairs: impl IntoIterator<Item = (usize, usize)>) {
        self.asks = (pairs.into_iter())
            .map(|(asked, who)| (asked as u32, who as u32))
            .collect();
        self.asks.sort_unstable();
        self.asks.dedup();
    }

    /// Every (asked, asking) pair, in order.
    pub fn ask_pairs(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.asks.iter()).map(|&(t, w)| (t as usize, w as usize))
    }

    /// Whom character `i` asks to make room, if anyone.
    pub fn asked_by(&self, i: usize) -> Option<usize> {
        self.ask_pairs().find(|&(_, w)| w == i).map(|(t, _)| t)
    }

    /// Who asks character `i` to make room (indices, in order).
    pub fn askers(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let from = self.asks.partition_point(|&(t, _)| (t as usize) < i);
        (self.asks[from..].iter())
            .take_while(move |&&(t, _)| t as usize == i)
            .map(|&(_, w)| w as usize)
    }

    /// How many characters it holds.
    pub fn len(&self) -> usize {
        self.agents.len()
    }

    /// Whether it holds nobody.
    pub fn is_empty(&self) -> bool {
        self.agents.is_empty()
    }

    /// The index of character `id`.
    pub fn index(&self, id: &str) -> Option<usize> {
        self.ids.binary_search_by(|i| i.as_str().cmp(id)).ok()
    }

    /// Character `i`.
    pub fn agent(&self, i: usize) -> Agent {
        self.agents[i]
    }

    /// The id of character `i`.
    pub fn id(&self, i: usize) -> &str {
        self.ids.get(i).map_or("", String::as_str)
    }

    /// Every character, in id order.
    pub fn agents(&self) -> &[Agent] {
        &self.agents
    }

    /// The indices of the characters within `r` of `p` (by their place in the snapshot), into
    /// `out` (cleared first), in a fixed order.
    pub fn near(&self, p: Vec2, r: f32, out: &mut Vec<usize>) {
        out.clear();
        if !p.is_finite() || !r.is_finite() {
            return;
        }
        let (lo, hi) = (cell_of(p - Vec2::splat(r)), cell_of(p + Vec2::splat(r)));
        for cx in lo.0..=hi.0 {
            let (from, to) = (key((cx, lo.1)), key((cx, hi.1)));
            // (cells of one column are contiguous keys unless z crosses zero; then two runs)
            let runs: [(u64, u64); 2] = if from <= to {
                [(from, to), (1, 0)]
            } else {
                [(from, key((cx, -1))), (key((cx, 0)), to)]
            };
            for (a, b) in runs {
                if a > b {
                    continue;
                }
                let start = self.cells.partition_point(|c| c.0 < a);
                let run = self.cells[start..].iter().zip(&self.placed[start..]);
                for (&(k, i), at) in run {
                    if k > b {
                        break;
                    }
                    if at.distance_squared(p) <= r * r {
                        out.push(i as usize);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_finds_exactly_those_within_reach_across_cell_and_sign_boundaries() {
        let mut agents = Vec::new();
        let mut k = 0u32;
        for x in -10..10 {
            for z in -10..10 {
                let at = Vec2::new(x as f32 * 0.7 + 0.05, z as f32 * 0.9 - 0.03);
                let a = Agent {
                    at,
                    velocity: Vec2::ZERO,
                    radius: 0.25,
                };
                agents.push((format!("a{k:04}"), a));
                k += 1;
            }
        }
        let crowd = Crowd::new(0.0, agents);
        let mut out = Vec::new();
        for (p, r) in [
            (Vec2::ZERO, 1.5),
            (Vec2::new(-3.1, 2.2), 2.7),
            (Vec2::new(5.0, -5.0), 0.1),
        ] {
            crowd.near(p, r, &mut out);
            let mut got = out.clone();
            got.sort();
            let want: Vec<usize> = (0..crowd.len())
                .filter(|&i| crowd.agent(i).at.distance(p) <= r)
                .collect();
            assert_eq!(got, want, "{p} {r}");
        }
        assert_eq!(crowd.index("a0021"), Some(21));
    }

    #[test]
    fn an_ask_goes_to_whoever_stands_at_the_place_asked() {
        let at = |x: f32| Agent {
            at: Vec2::new(x, 0.0),
            velocity: Vec2::ZERO,
            radius: 0.25,
        };
        let mut crowd = Crowd::unnamed(0.0, vec![at(0.0), at(1.0), at(2.0), at(3.0)]);
        // 0 and 2 ask the one at x = 1 (2 from a place 10 cm off); 3 asks an empty place
        crowd.set_asks([
            (0, Vec2::new(1.0, 0.0)),
            (2, Vec2::new(1.1, 0.0)),
            (3, Vec2::new(5.0, 0.0)),
        ]);
        assert_eq!(crowd.askers(1).collect::<Vec<_>>(), vec![0, 2]);
        for nobody in [0, 2, 3] {
            assert_eq!(crowd.askers(nobody).count(), 0);
        }
        assert_eq!(
            (0..4).map(|i| crowd.asked_by(i)).collect::<Vec<_>>(),
            [Some(1), None, Some(1), None]
        );
        // asking the place where it stands itself asks nobody
        crowd.set_asks([(1, Vec2::new(1.0, 0.0))]);
        assert_eq!((0..4).map(|i| crowd.askers(i).count()).sum::<usize>(), 0);
    }
}
