//! Global paths around obstacles: a walker's route from where it stands to its goal that keeps
//! a clearance (its body radius and a margin) from every obstacle. A straight line that keeps
//! the clearance is the path. Otherwise A* (the `pathfinding` crate, over an implicit grid: no
//! graph is built) searches a grid over the obstacles, start and goal, whose cells are free when
//! their centre keeps the clearance, dearer when they keep it by less than half a cell; the
//! route is then pulled tight by line-of-sight checks against the obstacles themselves, so it
//! bends only at obstacle corners. A goal inside an obstacle, or one that no route reaches (an
//! enclosure), is an error the caller reports.

use glam::Vec2;

use super::obstacles::Obstacles;

/// Most cells a path query's grid may have (the cell grows for large worlds).
pub const MAX_CELLS: usize = 400_000;
/// The finest cell (m).
pub const MIN_CELL: f32 = 0.1;

/// Why there is no path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    /// The goal lies inside an obstacle or nearer to one than the clearance.
    #[error("the goal ({x:.2}, {z:.2}) is inside an obstacle or closer to one than the body's {clearance:.2} m")]
    GoalBlocked {
        /// Goal x.
        x: f32,
        /// Goal z.
        z: f32,
        /// The clearance asked for.
        clearance: f32,
    },
    /// No route keeps the clearance all the way (the goal is enclosed, or the start is).
    #[error("no way around the obstacles reaches ({x:.2}, {z:.2}): it is enclosed")]
    Enclosed {
        /// Goal x.
        x: f32,
        /// Goal z.
        z: f32,
    },
    /// A coordinate is not a finite number.
    #[error("a coordinate of the start or goal is not a finite number")]
    NotFinite,
}

/// A grid over a rectangle of the ground.
struct Grid {
    origin: Vec2,
    cell: f32,
    nx: i32,
    nz: i32,
    /// Per cell: 0 free, 1 tight (dearer), 2 blocked.
    cost: Vec<u8>,
}

impl Grid {
    fn centre(&self, (i, j): (i32, i32)) -> Vec2 {
        self.origin + Vec2::new(i as f32 + 0.5, j as f32 + 0.5) * self.cell
    }

    fn cell_of(&self, p: Vec2) -> (i32, i32) {
        let c = ((p - self.origin) / self.cell).floor();
        (
            (c.x as i32).clamp(0, self.nx - 1),
            (c.y as i32).clamp(0, self.nz - 1),
        )
    }

    fn at(&self, (i, j): (i32, i32)) -> u8 {
        if i < 0 || j < 0 || i >= self.nx || j >= self.nz {
            2
        } else {
            self.cost[(j * self.nx + i) as usize]
        }
    }

    /// Marks the cells near each obstacle: blocked where the centre is nearer than
    /// `clearance`, tight where nearer than `clearance` + half a diagonal.
    fn build(obstacles: &Obstacles, lo: Vec2, hi: Vec2, clearance: f32) -> Grid {
        let area = (hi - lo).x.max(1.0) * (hi - lo).y.max(1.0);
        let cell = MIN_CELL.max((area / MAX_CELLS as f32).sqrt() * 1.01);
        let nx = (((hi.x - lo.x) / cell).ceil() as i32).max(1);
        let nz = (((hi.y - lo.y) / cell).ceil() as i32).max(1);
        let mut g = Grid {
            origin: lo,
            cell,
            nx,
            nz,
            cost: vec![0; (nx * nz) as usize],
        };
        let margin = clearance + cell * std::f32::consts::FRAC_1_SQRT_2;
        for ob in obstacles.all() {
            let (blo, bhi) = ob.shape.bounds();
            let (a, b) = (g.cell_of(blo - margin), g.cell_of(bhi + margin));
            for j in a.1..=b.1 {
                for i in a.0..=b.0 {
                    let d = ob.shape.distance(g.centre((i, j))).0;
                    let c = if d < clearance {
                        2
                    } else if d < margin {
                        1
                    } else {
                        0
                    };
                    let k = (j * nx + i) as usize;
                    g.cost[k] = g.cost[k].max(c);
                }
            }
        }
        g
    }
}

/// A route from `start` to `goal` that keeps `clearance` from every obstacle: the points to
/// walk through, the first being `start` and the last `goal`.
pub fn plan(
    obstacles: &Obstacles,
    start: Vec2,
    goal: Vec2,
    clearance: f32,
) -> Result<Vec<Vec2>, PathError> {
    if !(start.is_finite() && goal.is_finite()) {
        return Err(PathError::NotFinite);
    }
    if obstacles.clearance(goal, clearance) < clearance {
        return Err(PathError::GoalBlocked {
            x: goal.x,
            z: goal.y,
            clearance,
        });
    }
    // a start a little too near (pushed against a wall) may still leave along a clear line
    let start_clear = obstacles.clearance(start, clearance).min(clearance);
    let line = clearance.min(start_clear - 1e-3);
    if obstacles.segment_clear(start, goal, line) {
        return Ok(vec![start, goal]);
    }
    let (mut lo, mut hi) = (start.min(goal), start.max(goal));
    for ob in obstacles.all() {
        let (a, b) = ob.shape.bounds();
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let pad = clearance * 2.0 + 0.5;
    let grid = Grid::build(obstacles, lo - pad, hi + pad, clearance);
    let (s, g) = (grid.cell_of(start), grid.cell_of(goal));
    const STEPS: [(i32, i32, u32); 8] = [
        (1, 0, 10),
        (-1, 0, 10),
        (0, 1, 10),
        (0, -1, 10),
        (1, 1, 14),
        (1, -1, 14),
        (-1, 1, 14),
        (-1, -1, 14),
    ];
    let found = pathfinding::directed::astar::astar(
        &s,
        |&(i, j)| {
            let grid = &grid;
            STEPS.iter().filter_map(move |&(di, dj, c)| {
                let n = (i + di, j + dj);
                // the start's and goal's own cells are always allowed
                let cost = if n == g { 0 } else { grid.at(n) };
                // no corner cutting between two blocked cells
                let corner =
                    di != 0 && dj != 0 && (grid.at((i + di, j)) == 2 || grid.at((i, j + dj)) == 2);
                (cost < 2 && !corner).then_some((n, c * (1 + 4 * u32::from(cost))))
            })
        },
        |&(i, j)| {
            let (dx, dz) = ((i - g.0).unsigned_abs(), (j - g.1).unsigned_abs());
            10 * dx.max(dz) + 4 * dx.min(dz)
        },
        |&n| n == g,
    );
    let Some((cells, _)) = found else {
        return Err(PathError::Enclosed {
            x: goal.x,
            z: goal.y,
        });
    };
    let mut raw: Vec<Vec2> = Vec::with_capacity(cells.len() + 2);
    raw.push(start);
    raw.extend(
        cells[1..cells.len().saturating_sub(1)]
            .iter()
            .map(|&c| grid.centre(c)),
    );
    raw.push(goal);
    Ok(pull_tight(obstacles, &raw, clearance, line))
}

/// Drops every point the route can go straight past (line of sight with `clearance`; from the
/// start, `first` as it may stand nearer).
fn pull_tight(obstacles: &Obstacles, raw: &[Vec2], clearance: f32, first: f32) -> Vec<Vec2> {
    let mut out = vec![raw[0]];
    let mut i = 0;
    while i + 1 < raw.len() {
        let c = if i == 0 { first } else { clearance };
        // the farthest point still in sight (the next one always is: neighbouring cells)
        let mut j = i + 1;
        while j + 1 < raw.len() && obstacles.segment_clear(raw[i], raw[j + 1], c) {
            j += 1;
        }
        out.push(raw[j]);
        i = j;
    }
    out
}

/// The length of a route.
pub fn length(points: &[Vec2]) -> f32 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The point `ahead` metres further along `route` than the point of it nearest `at`, searching
/// from segment `from` on (so that progress along the route never goes back), with the
/// segment that point lies on: a carrot for a walker that follows the route loosely. The
/// route's last point once less than `ahead` of it is left.
pub fn carrot(route: &[Vec2], at: Vec2, from: usize, ahead: f32) -> (Vec2, usize) {
    let Some(&last) = route.last() else {
        return (at, 0);
    };
    if route.len() < 2 {
        return (last, 0);
    }
    // the nearest point from segment `from` on
    let first = from.min(route.len() - 2);
    let (mut seg, mut along) = (first, 0.0f32);
    let mut best = f32::INFINITY;
    for i in first..route.len() - 1 {
        let (d, q) = super::distance::point_segment(at, route[i], route[i + 1]);
        if d < best {
            (best, seg, along) = (d, i, q.distance(route[i]));
        }
    }
    // then `ahead` on along the route
    let mut left = ahead + along;
    for i in seg..route.len() - 1 {
        let length = route[i].distance(route[i + 1]);
        if left <= length {
            return (
                route[i] + (route[i + 1] - route[i]).normalize_or_zero() * left,
                seg,
            );
        }
        left -= length;
    }
    (last, seg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::space::{Obstacle, Shape};

    #[test]
    fn the_carrot_runs_ahead_along_the_route_and_never_back() {
        let route = [Vec2::ZERO, Vec2::new(0.0, 4.0), Vec2::new(3.0, 4.0)];
        // beside the first leg: 1.5 m on from the nearest point
        let (p, s) = carrot(&route, Vec2::new(0.5, 1.0), 0, 1.5);
        assert!(p.distance(Vec2::new(0.0, 2.5)) < 1e-5, "{p}");
        assert_eq!(s, 0);
        // round the corner: 3 m from z = 3 is 1 m down the second leg
        let (p, s) = carrot(&route, Vec2::new(0.0, 3.0), 0, 2.0);
        assert!(p.distance(Vec2::new(1.0, 4.0)) < 1e-5, "{p}");
        assert_eq!(s, 0);
        // once on the second leg, a point nearer the first does not take it back
        let (p, s) = carrot(&route, Vec2::new(0.0, 1.0), 1, 1.0);
        assert!(p.distance(Vec2::new(1.0, 4.0)) < 1e-5, "{p}");
        assert_eq!(s, 1);
        // near the end: the end
        assert_eq!(carrot(&route, Vec2::new(2.9, 4.0), 1, 1.0).0, route[2]);
    }

    fn seg(a: (f32, f32), b: (f32, f32)) -> Obstacle {
        Obstacle::wall(Vec2::new(a.0, a.1), Vec2::new(b.0, b.1))
    }

    /// A U open away from the walker: the route leaves the cup round its rim.
    #[test]
    fn a_u_shaped_trap_is_walked_around() {
        let o = Obstacles::new(vec![
            seg((-1.5, 2.0), (1.5, 2.0)),
            seg((-1.5, 2.0), (-1.5, -0.5)),
            seg((1.5, 2.0), (1.5, -0.5)),
        ]);
        let (s, g) = (Vec2::ZERO, Vec2::new(0.0, 5.0));
        let p = plan(&o, s, g, 0.3).unwrap();
        assert_eq!((p[0], *p.last().unwrap()), (s, g));
        for w in p.windows(2) {
            assert!(o.segment_clear(w[0], w[1], 0.3 - 1e-3), "{w:?}");
        }
        // around the rim (x beyond ±1.8) and no longer than the detour needs
        assert!(p.iter().any(|q| q.x.abs() > 1.75), "{p:?}");
        let l = length(&p);
        assert!(l > 7.0 && l < 9.5, "{l} {p:?}");
    }

    #[test]
    fn a_clear_line_is_the_path_and_blocked_goals_are_refused() {
        let o = Obstacles::new(vec![Obstacle {
            shape: Shape::Circle {
                centre: Vec2::new(5.0, 0.0),
                radius: 1.0,
            },
            height: 2.0,
        }]);
        let p = plan(&o, Vec2::ZERO, Vec2::new(0.0, 4.0), 0.25).unwrap();
        assert_eq!(p.len(), 2);
        assert!(matches!(
            plan(&o, Vec2::ZERO, Vec2::new(5.0, 0.5), 0.25),
            Err(PathError::GoalBlocked { .. })
        ));
        // enclosed by a ring of walls
        let ring = Obstacles::new(vec![
            seg((-1.0, -1.0), (1.0, -1.0)),
            seg((1.0, -1.0), (1.0, 1.0)),
            seg((1.0, 1.0), (-1.0, 1.0)),
            seg((-1.0, 1.0), (-1.0, -1.0)),
        ]);
        assert!(matches!(
            plan(&ring, Vec2::new(4.0, 0.0), Vec2::ZERO, 0.25),
            Err(PathError::Enclosed { .. })
        ));
        assert_eq!(
            plan(&ring, Vec2::new(f32::NAN, 0.0), Vec2::ZERO, 0.25),
            Err(PathError::NotFinite)
        );
    }
}
