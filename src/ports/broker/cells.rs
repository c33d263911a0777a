//! The floor cut into square cells, so that realizers sharing one world exchange states by area:
//! a character's state goes to the topic of the cell it stands in, and a realizer listens to
//! the cells near its own characters ([`Cells::around`]), so that what it hears grows with the
//! number of characters near its own, not with the number in the world. A cell is named `i_j`:
//! the floor of x and of z over the cell's size (`-1_0` is the cell west of the origin's).

use std::collections::BTreeSet;
use std::fmt;

/// The size of a cell unless `--cell` says otherwise (m).
pub const CELL_SIZE: f32 = 10.0;

/// The smallest and largest cell sizes taken (m): a cell much smaller than a walker's
/// surroundings only multiplies the topics. Size 0 is taken too: the floor is not cut, everyone
/// stands in cell `0_0` and every realizer hears every state (the everyone-to-everyone design,
/// for comparison).
pub const CELL_SIZES: (f32, f32) = (1.0, 1_000_000.0);

/// How far around its characters a realizer listens (m): the distance within which a walker
/// avoids others, and 1 m more for the moves it makes before it hears a new cell (a walker
/// takes 0.7 s for a metre; the subscription is made within 0.05 s and the cell's states come
/// 20 times a second).
pub const LISTEN_RADIUS: f32 = crate::world::crowd::avoid::NEIGHBOUR_RADIUS + 1.0;

/// How much farther than [`LISTEN_RADIUS`] a cell may be before a realizer stops listening to
/// it (m), so that a character walking along a cell's edge does not subscribe and unsubscribe
/// at every step.
pub const KEEP_MARGIN: f32 = 2.0;

/// One cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Cell {
    /// The floor of x over the cell size.
    pub i: i64,
    /// The floor of z over the cell size.
    pub j: i64,
}

impl fmt::Display for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}_{}", self.i, self.j)
    }
}

impl Cell {
    /// Reads a cell's name (`i_j`).
    pub fn parse(name: &str) -> Option<Cell> {
        let (i, j) = name.split_once('_')?;
        Some(Cell {
            i: i.parse().ok()?,
            j: j.parse().ok()?,
        })
    }
}

/// Cells of one size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cells {
    size: f32,
}

impl Cells {
    /// Cells of `size` metres (0: one cell, the whole floor); `Err` says why a size is not
    /// taken.
    pub fn new(size: f32) -> Result<Cells, String> {
        let (least, most) = CELL_SIZES;
        if !((least..=most).contains(&size) || size == 0.0) {
            return Err(format!(
                "'{size}' is not a cell size ({least} to {most} metres, or 0 for one cell)"
            ));
        }
        Ok(Cells { size })
    }

    /// The cell's size (m; 0: the floor is one cell).
    pub fn size(&self) -> f32 {
        self.size
    }

    /// The cell the point (x, z) is in.
    pub fn of(&self, x: f32, z: f32) -> Cell {
        if self.size == 0.0 {
            return Cell { i: 0, j: 0 };
        }
        // (-0.0 and 0.0 are the same cell; coordinates far beyond any floor saturate)
        Cell {
            i: (x / self.size).floor() as i64,
            j: (z / self.size).floor() as i64,
        }
    }

    /// Every cell with a point within `radius` of (x, z), in order.
    pub fn around(&self, x: f32, z: f32, radius: f32) -> impl Iterator<Item = Cell> + '_ {
        let (low, high) = (
            self.of(x - radius, z - radius),
            self.of(x + radius, z + radius),
        );
        (low.i..=high.i)
            .flat_map(move |i| (low.j..=high.j).map(move |j| Cell { i, j }))
            .filter(move |c| self.distance(*c, x, z) <= radius)
    }

    /// How far (x, z) is from cell `c` (0 inside it).
    pub fn distance(&self, c: Cell, x: f32, z: f32) -> f32 {
        if self.size == 0.0 {
            return 0.0;
        }
        let gap = |v: f32, k: i64| {
            let (from, to) = (k as f32 * self.size, (k + 1) as f32 * self.size);
            (from - v).max(v - to).max(0.0)
        };
        gap(x, c.i).hypot(gap(z, c.j))
    }

    /// The cells to listen to for characters standing at `places`, given those listened to
    /// now: every cell within [`LISTEN_RADIUS`] of one of them, and those listened to that are
    /// still within [`KEEP_MARGIN`] more.
    pub fn listened(&self, places: &[(f32, f32)], now: &BTreeSet<Cell>) -> BTreeSet<Cell> {
        let mut wanted: BTreeSet<Cell> = (places.iter())
            .flat_map(|&(x, z)| self.around(x, z, LISTEN_RADIUS))
            .collect();
        let keep = LISTEN_RADIUS + KEEP_MARGIN;
        wanted.extend(now.iter().filter(|c| {
            places
                .iter()
                .any(|&(x, z)| self.distance(**c, x, z) <= keep)
        }));
        wanted
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_named_by_the_floor_of_x_and_z_over_their_size() {
        let cells = Cells::new(10.0).unwrap();
        assert_eq!(cells.of(0.0, 0.0).to_string(), "0_0");
        assert_eq!(cells.of(-0.0, 9.99).to_string(), "0_0");
        assert_eq!(cells.of(-0.1, 10.0).to_string(), "-1_1");
        assert_eq!(cells.of(25.0, -31.0).to_string(), "2_-4");
        assert_eq!(Cell::parse("2_-4"), Some(Cell { i: 2, j: -4 }));
        assert_eq!(Cell::parse("2-4"), None);
        assert_eq!(Cell::parse("a_1"), None);
        assert!(Cells::new(0.5).is_err());
        assert!(Cells::new(f32::NAN).is_err());
        assert!(Cells::new(2e6).unwrap_err().contains("1 to 1000000 metres"));
        assert!(Cells::new(-1.0).is_err());
        // size 0: one cell, the whole floor; everyone hears everyone
        let world = Cells::new(0.0).unwrap();
        let near: Vec<Cell> = world.around(-3e5, 1.0, LISTEN_RADIUS).collect();
        assert_eq!(near, [Cell { i: 0, j: 0 }]);
        for (x, z) in [(-300.0, 450.0), (300.0, -450.0), (5e5, 5e5)] {
            assert_eq!(world.of(x, z), near[0]);
        }
    }

    #[test]
    fn around_a_point_are_the_cells_a_disc_touches() {
        let cells = Cells::new(10.0).unwrap();
        // in the middle of a cell, a disc of 4 m touches only it
        assert_eq!(cells.around(5.0, 5.0, 4.0).count(), 1);
        // of 10 m: the cell and its four sides' neighbours and the four corners' (each
        // corner 7.07 m away)
        assert_eq!(cells.around(5.0, 5.0, 10.0).count(), 9);
        // of 6 m: the four sides' neighbours (5 m away) but not the corners' (7.07 m)
        assert_eq!(cells.around(5.0, 5.0, 6.0).count(), 5);
        assert_eq!(cells.distance(Cell { i: 1, j: 1 }, 5.0, 5.0), 50f32.sqrt());
        assert_eq!(cells.distance(Cell { i: 0, j: 0 }, 5.0, 5.0), 0.0);
    }

    #[test]
    fn cells_listened_to_follow_the_characters_and_are_kept_for_a_margin() {
        let cells = Cells::new(10.0).unwrap();
        let at_start = cells.listened(&[(5.0, 5.0)], &BTreeSet::new());
        assert!(at_start.contains(&Cell { i: 1, j: 1 }));
        assert!(!at_start.contains(&Cell { i: 2, j: 0 }));
        // on to where cell -1_0 is beyond the radius but within the margin: kept (its corner
        // neighbours, farther, are let go)
        let x = LISTEN_RADIUS + KEEP_MARGIN / 2.0;
        assert!(LISTEN_RADIUS + KEEP_MARGIN < x.hypot(5.0));
        let on = cells.listened(&[(x, 5.0)], &at_start);
        assert!(on.contains(&Cell { i: -1, j: 0 }));
        assert!(!on.contains(&Cell { i: -1, j: 1 }));
        let fresh = cells.listened(&[(x, 5.0)], &BTreeSet::new());
        assert!(!fresh.contains(&Cell { i: -1, j: 0 }));
        assert_eq!(fresh.len() + 1, on.len());
        // far on, it is let go
        let far = cells.listened(&[(30.0, 5.0)], &on);
        assert!(!far.contains(&Cell { i: -1, j: 0 }));
        assert!(far.contains(&Cell { i: 3, j: 0 }));
        assert!(cells.listened(&[], &on).is_empty());
    }
}
