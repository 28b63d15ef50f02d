//! Any-angle routes through the grid's free space, homotopic to the CQL
//! plan: the learner decides which cells and which way round every
//! obstacle; this module pulls that decision taut.
//!
//! Free space (pixels): the tool's point `p` is free when the footprint —
//! a square the size of one cell (the target's box, as in
//! [`crate::smooth`]) centred at `p` — stays on the grid and overlaps no
//! painted perimeter ([`StateGrid::perimeters`]: other objects, other goals
//! and hands, already grown by their margins) and no blocked cell that no
//! perimeter explains or that a collision check blocked
//! ([`StateGrid::checked`]). The blocked cells hold every perimeter, so the
//! route keeps off what they keep off, without being held a cell's
//! rounding away from it.
//! The perimeters the gripper is in when the sub-goal starts
//! ([`StateGrid::escape`]: it has just released into a box that is an
//! obstacle now, and those meeting it) are open over the cells the grid
//! clears under it ([`StateGrid::cleared`]), as those cells are: only their
//! parts over the other cells count. Other perimeters the clearing's flood
//! fill reached through the grid's rounding stay closed. The forbidden region is those boxes grown by half
//! the footprint (the configuration-space obstacles, open rectangles). A
//! segment is free when it crosses none ([`segment_is_free`]: Liang–Barsky
//! clipping, exact up to a shrink of 1e-6 cell that lets the footprint
//! touch a perimeter). The target's cell, which the grid leaves open over
//! the perimeters reaching into it, stays closed to the route, except as
//! below.
//! Where the route starts (or ends) inside one — a tool over a perimeter
//! (a hand's, or the box it just released into), a target or a resting
//! spot next to a piece — that obstacle is shrunk until the point is on its boundary: the route
//! leaves from the tool itself and never goes deeper.
//!
//! Shortening ([`taut`]): the classical elastic band for the shortest path
//! in a homotopy class. For consecutive vertices `a, b, c`, the
//! configuration-space obstacles reaching into the triangle `abc` are
//! rectangles (they cannot cross the free segments `ab`, `bc`, so the part
//! inside the triangle is the hull of their corners inside it, clipped by
//! `ac`); the shortest way from `a` to `c`
//! that deforms `a-b-c` without crossing them is the convex chain around
//! those corners on `b`'s side (the straight `ac` when there are none). An
//! obstacle that only touches the triangle from outside does not count. Replacing
//! `b` by that chain shortens the path and keeps its homotopy class; at the
//! fixed point every bend wraps an obstacle corner, and a locally shortest
//! path among polygonal obstacles is the shortest of its class. Every new
//! segment is verified with [`segment_is_free`] before it is accepted.

use crate::grid::StateGrid;

/// Shrink (fraction of a cell) of the configuration-space obstacles: the
/// footprint may touch a perimeter, as the smoothing's check.
const SHRINK: f64 = 1e-6;

/// Upper bound on the splices of one [`taut`] call, per vertex of its input
/// (each splice shortens the path or drops a vertex; the bound only guards
/// against rounding).
const SPLICES_PER_VERTEX: usize = 64;

type Point = [f64; 2];

/// An open axis-aligned box, pixels: `lo < p < hi` on both axes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Open {
    lo: Point,
    hi: Point,
}

impl Open {
    /// The common part of two boxes; `None` when it has no area.
    fn meet(&self, other: &Open) -> Option<Open> {
        let lo = [0, 1].map(|k| self.lo[k].max(other.lo[k]));
        let hi = [0, 1].map(|k| self.hi[k].min(other.hi[k]));
        (0..2).all(|k| lo[k] < hi[k]).then_some(Open { lo, hi })
    }
}

/// Where the tool's point may go: inside `lo..=hi` (the footprint on the
/// grid) and outside every configuration-space obstacle.
#[derive(Debug, Clone, PartialEq)]
struct FreeSpace {
    lo: Point,
    hi: Point,
    /// Grown by exactly half the footprint; their corners are where the
    /// band may bend.
    obstacles: Vec<Open>,
    /// How much smaller (pixels) than `obstacles` the boxes are that a free
    /// segment must not cross: the footprint may touch a perimeter.
    shrink: Point,
}

impl FreeSpace {
    /// The free space of `grid` near the pixel window `window` (`None`: the
    /// whole grid). The forbidden footprint positions are the painted
    /// perimeters ([`StateGrid::perimeters`]) plus every blocked cell no
    /// perimeter explains or that a collision check blocked
    /// ([`StateGrid::checked`]), each grown by half the footprint.
    fn of(grid: &StateGrid, window: Option<[Point; 2]>) -> Self {
        let shrink = [0, 1].map(|k| grid.cell_size[k] * SHRINK);
        let half = [0, 1].map(|k| grid.cell_size[k] * 0.5);
        let lo = [0, 1].map(|k| grid.origin[k] + half[k] - shrink[k]);
        let hi = [0, 1].map(|k| grid.origin[k] + grid_extent(grid, k) - half[k] + shrink[k]);
        let mut explained = vec![false; grid.len()];
        let mut opened = vec![false; grid.len()];
        for &c in grid.cleared.iter().filter(|&&c| !grid.code(c).is_blocked()) {
            opened[grid.index(c)] = true;
        }
        let mut pieces: Vec<Open> = Vec::new();
        for (i, b) in grid.perimeters.iter().enumerate() {
            let perimeter = Open {
                lo: [b.u, b.v],
                hi: [b.u + b.w, b.v + b.l],
            };
            let cells: Vec<(usize, usize)> = match (grid.span(b.v, b.l, 1), grid.span(b.u, b.w, 0))
            {
                (Some((r0, r1)), Some((c0, c1))) => (r0..=r1)
                    .flat_map(|r| (c0..=c1).map(move |c| (r, c)))
                    .collect(),
                _ => Vec::new(),
            };
            for &cell in &cells {
                explained[grid.index(cell)] = true;
            }
            // A perimeter the gripper is in is open over the cells cleared
            // under it, as those cells are: what is left of it is its part
            // over the other cells.
            match grid.escape.contains(&i) {
                false => pieces.push(perimeter),
                true => pieces.extend(
                    cells
                        .iter()
                        .filter(|&&c| !opened[grid.index(c)])
                        .filter_map(|&c| perimeter.meet(&cell_box(grid, c))),
                ),
            }
        }
        pieces.extend(
            (0..grid.len())
                .map(|i| grid.cell(i))
                .filter(|&c| grid.code(c).is_blocked())
                .filter(|c| !explained[grid.index(*c)] || grid.checked.contains(c))
                .map(|c| cell_box(grid, c)),
        );
        let obstacles = pieces
            .into_iter()
            .map(|p| Open {
                lo: [0, 1].map(|k| p.lo[k] - half[k]),
                hi: [0, 1].map(|k| p.hi[k] + half[k]),
            })
            .filter(|o| {
                window.is_none_or(|[wl, wh]| (0..2).all(|k| o.lo[k] < wh[k] && o.hi[k] > wl[k]))
            })
            .collect();
        Self {
            lo,
            hi,
            obstacles,
            shrink,
        }
    }

    /// The same space where the route may leave from (or arrive at) the
    /// points `ends`: an obstacle holding one is shrunk until the point lies
    /// on its boundary (the footprint never goes deeper into a perimeter
    /// than it is there), and the grid's bounds widen to hold it.
    fn leaving(mut self, ends: &[Point]) -> Self {
        for e in ends {
            for o in &mut self.obstacles {
                if (0..2).all(|k| e[k] > o.lo[k] && e[k] < o.hi[k]) {
                    let depth = (0..2)
                        .map(|k| (e[k] - o.lo[k]).min(o.hi[k] - e[k]))
                        .fold(f64::INFINITY, f64::min);
                    o.lo = o.lo.map(|x| x + depth);
                    o.hi = o.hi.map(|x| x - depth);
                }
            }
            self.lo = [0, 1].map(|k| self.lo[k].min(e[k]));
            self.hi = [0, 1].map(|k| self.hi[k].max(e[k]));
        }
        self
    }

    /// The footprint swept from `a` to `b` stays in this space.
    fn segment_is_free(&self, a: Point, b: Point) -> bool {
        let inside = |p: Point| (0..2).all(|k| p[k] >= self.lo[k] && p[k] <= self.hi[k]);
        inside(a) && inside(b) && !self.obstacles.iter().any(|o| self.crosses(a, b, o))
    }

    /// The segment `a`–`b` enters the obstacle `o` (shrunk by `shrink`).
    fn crosses(&self, a: Point, b: Point, o: &Open) -> bool {
        let (lo, hi) = self.shrunk(o);
        crosses_open_box(a, b, lo, hi)
    }

    fn shrunk(&self, o: &Open) -> (Point, Point) {
        (
            [0, 1].map(|k| o.lo[k] + self.shrink[k]),
            [0, 1].map(|k| o.hi[k] - self.shrink[k]),
        )
    }

    /// The corners of every obstacle whose interior reaches into the
    /// triangle's and that lie in it (`inside`), without `a` and `c`: only
    /// those can hold the band (an obstacle that merely touches an edge from
    /// outside cannot).
    fn corners_in(&self, [a, b, c]: [Point; 3], inside: impl Fn(Point) -> bool) -> Vec<Point> {
        let mut points: Vec<Point> = Vec::new();
        for o in &self.obstacles {
            let (lo, hi) = self.shrunk(o);
            if !box_meets_triangle([[lo[0], hi[0]], [lo[1], hi[1]]], [a, b, c]) {
                continue;
            }
            for p in [o.lo, [o.hi[0], o.lo[1]], o.hi, [o.lo[0], o.hi[1]]] {
                if inside(p) && p != a && p != c && !points.contains(&p) {
                    points.push(p);
                }
            }
        }
        points
    }
}

/// The closed pixel box of a cell.
fn cell_box(grid: &StateGrid, (r, c): (usize, usize)) -> Open {
    let lo = [
        grid.origin[0] + c as f64 * grid.cell_size[0],
        grid.origin[1] + r as f64 * grid.cell_size[1],
    ];
    Open {
        lo,
        hi: [lo[0] + grid.cell_size[0], lo[1] + grid.cell_size[1]],
    }
}

/// The footprint swept from `a` to `b` (pixels) stays on the grid and keeps
/// off every perimeter and every blocked cell no perimeter explains (see
/// [`FreeSpace::of`]). `a ==
/// b` checks the footprint at one point.
pub fn segment_is_free(grid: &StateGrid, a: Point, b: Point) -> bool {
    let window = [
        [a[0].min(b[0]), a[1].min(b[1])],
        [a[0].max(b[0]), a[1].max(b[1])],
    ];
    FreeSpace::of(grid, Some(window)).segment_is_free(a, b)
}

/// The segment `a`–`b` meets the open box `(lo, hi)` (Liang–Barsky): a
/// segment that only touches the boundary does not.
pub fn crosses_open_box(a: Point, b: Point, lo: Point, hi: Point) -> bool {
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for k in 0..2 {
        let d = b[k] - a[k];
        if d == 0.0 {
            if a[k] <= lo[k] || a[k] >= hi[k] {
                return false;
            }
            continue;
        }
        let (ta, tb) = ((lo[k] - a[k]) / d, (hi[k] - a[k]) / d);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
        if t0 >= t1 {
            return false;
        }
    }
    t0 < t1
}

/// Width (k = 0) or height (k = 1) of the grid, pixels.
fn grid_extent(grid: &StateGrid, k: usize) -> f64 {
    let n = if k == 0 { grid.cols } else { grid.rows };
    n as f64 * grid.cell_size[k]
}

/// The shortest path homotopic to `points` (pixels; every consecutive
/// segment free by [`segment_is_free`]) with the same end points, by the
/// elastic band of the module docs. Segments of the input that are not free
/// split it: each free run is pulled taut on its own and the others are
/// kept as they are.
pub fn taut(grid: &StateGrid, points: &[Point]) -> Vec<Point> {
    let ends: Vec<Point> = points
        .first()
        .into_iter()
        .chain(points.last())
        .copied()
        .collect();
    let space = FreeSpace::of(grid, None).leaving(&ends);
    let mut out: Vec<Point> = Vec::with_capacity(points.len());
    let mut run: Vec<Point> = Vec::new();
    for &p in points {
        match run.last() {
            Some(&last) if last == p => continue,
            Some(&last) if !space.segment_is_free(last, p) => {
                flush(&space, &mut run, &mut out);
                run.push(last);
            }
            _ => {}
        }
        run.push(p);
    }
    flush(&space, &mut run, &mut out);
    out
}

/// Appends the taut form of `run` to `out` (without repeating the junction
/// point) and empties `run`.
fn flush(space: &FreeSpace, run: &mut Vec<Point>, out: &mut Vec<Point>) {
    let pulled = pull(space, std::mem::take(run));
    let skip = usize::from(out.last().is_some_and(|&l| Some(&l) == pulled.first()));
    out.extend(pulled.into_iter().skip(skip));
}

/// The elastic band on one run of free segments.
fn pull(space: &FreeSpace, mut path: Vec<Point>) -> Vec<Point> {
    let mut budget = SPLICES_PER_VERTEX * path.len().max(1);
    let mut i = 1;
    while i + 1 < path.len() && budget > 0 {
        let (a, b, c) = (path[i - 1], path[i], path[i + 1]);
        let chain = wrap(space, a, b, c);
        let (after, before) = (
            polyline_length(a, &chain, c),
            distance(a, b) + distance(b, c),
        );
        // Shorter, or as long with b dropped (b on the straight a–c).
        let shorter = after < before - 1e-9 || (chain.is_empty() && after <= before + 1e-9);
        let free = || {
            let mut prev = a;
            chain.iter().chain([&c]).all(|&p| {
                let ok = space.segment_is_free(prev, p);
                prev = p;
                ok
            })
        };
        if shorter && free() {
            path.splice(i..=i, chain);
            budget -= 1;
            i = i.saturating_sub(1).max(1);
        } else {
            i += 1;
        }
    }
    path
}

/// The vertices strictly between `a` and `c` of the convex chain around the
/// obstacle corners inside the triangle `abc`, on `b`'s side (empty: the
/// straight `ac` deforms `a-b-c` without crossing an obstacle).
fn wrap(space: &FreeSpace, a: Point, b: Point, c: Point) -> Vec<Point> {
    let side = cross(a, c, b);
    let scale = distance(a, c).max(distance(a, b)).max(1.0);
    if side.abs() <= 1e-12 * scale * scale {
        return Vec::new();
    }
    let sign = side.signum();
    // The triangle a, b, c turns the other way round from a, c, b.
    let inside = |p: Point| {
        let tol = 1e-9 * scale * scale;
        [cross(a, b, p), cross(b, c, p), cross(c, a, p)]
            .iter()
            .all(|&x| -sign * x >= -tol)
    };
    let mut points = space.corners_in([a, b, c], inside);
    // Gift wrapping from a to c: each next vertex leaves every remaining
    // point on the far side from b (the chain bulges towards b).
    let mut chain = Vec::new();
    let mut current = a;
    let bound = points.len() + 1;
    for _ in 0..bound {
        let mut best = c;
        for &p in &points {
            let turn = sign * cross(current, best, p);
            let further = distance(current, p) > distance(current, best);
            if turn > 1e-9 * scale * scale || (turn.abs() <= 1e-9 * scale * scale && further) {
                best = p;
            }
        }
        if best == c {
            return chain;
        }
        chain.push(best);
        points.retain(|&p| p != best && sign * cross(best, c, p) > 1e-9 * scale * scale);
        current = best;
    }
    chain
}

/// The box (`[[u_lo, u_hi], [v_lo, v_hi]]`) and the triangle overlap with
/// positive area: no separating axis among u, v and the triangle's edge
/// normals (touching counts as apart).
fn box_meets_triangle(bx: [[f64; 2]; 2], triangle: [Point; 3]) -> bool {
    let corners = [
        [bx[0][0], bx[1][0]],
        [bx[0][1], bx[1][0]],
        [bx[0][1], bx[1][1]],
        [bx[0][0], bx[1][1]],
    ];
    let mut axes = vec![[1.0, 0.0], [0.0, 1.0]];
    for k in 0..3 {
        let (p, q) = (triangle[k], triangle[(k + 1) % 3]);
        axes.push([p[1] - q[1], q[0] - p[0]]);
    }
    axes.iter().all(|n| {
        let project = |pts: &[Point]| {
            pts.iter()
                .map(|p| n[0] * p[0] + n[1] * p[1])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x), hi.max(x))
                })
        };
        let (b_lo, b_hi) = project(&corners);
        let (t_lo, t_hi) = project(&triangle);
        b_hi > t_lo && t_hi > b_lo
    })
}

/// Length of `a`, `via…`, `c`.
fn polyline_length(a: Point, via: &[Point], c: Point) -> f64 {
    let mut prev = a;
    let mut length = 0.0;
    for &p in via.iter().chain([&c]) {
        length += distance(prev, p);
        prev = p;
    }
    length
}

/// Length of a polyline, pixels.
pub fn path_length(points: &[Point]) -> f64 {
    points.windows(2).map(|w| distance(w[0], w[1])).sum()
}

fn distance(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// z of (b − a) × (p − a): > 0 when p is left of a→b (pixel axes).
fn cross(a: Point, b: Point, p: Point) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

#[cfg(test)]
pub(crate) mod tests;
