//! Any-angle routes through the grid's free space, homotopic to the CQL
//! plan: the learner decides which cells and which way round every
//! obstacle; this module pulls that decision taut.
//!
//! Free space (pixels): the tool's point `p` is free when the footprint —
//! a square the size of one cell (the target's box, as in
//! [`crate::smooth`]) centred at `p` — overlaps no 0.2/0.4 cell and stays on
//! the grid. So the forbidden region is the union of the blocked cells
//! grown by one footprint (closed squares of twice the cell size around
//! the blocked cells' centres, the configuration-space obstacles), whose
//! corners are cell centres. A segment is free when the footprint swept
//! along it overlaps no blocked cell ([`segment_is_free`]: the segment
//! against every grown blocked cell, Liang–Barsky clipping, exact up to a
//! shrink of 1e-6 cell that lets the footprint touch a blocked cell).
//!
//! Shortening ([`taut`]): the classical elastic band for the shortest path
//! in a homotopy class. For consecutive vertices `a, b, c`, the
//! configuration-space obstacles reaching into the triangle `abc` are grown
//! blocked cells whose corners are cell centres (they cannot cross the free
//! segments `ab`, `bc`, so the part inside the triangle is the hull of their
//! corners inside it, clipped by `ac`); the shortest way from `a` to `c`
//! that deforms `a-b-c` without crossing them is the convex chain around
//! those corners on `b`'s side (the straight `ac` when there are none). A
//! grown cell that only touches the triangle from outside does not count. Replacing
//! `b` by that chain shortens the path and keeps its homotopy class; at the
//! fixed point every bend wraps an obstacle corner, and a locally shortest
//! path among polygonal obstacles is the shortest of its class. Every new
//! segment is verified with [`segment_is_free`] before it is accepted.

use crate::grid::StateGrid;

/// Shrink (fraction of a cell) of the grown blocked cells: the footprint may
/// touch a blocked cell, as the smoothing's check.
const SHRINK: f64 = 1e-6;

/// Upper bound on the splices of one [`taut`] call, per vertex of its input
/// (each splice shortens the path or drops a vertex; the bound only guards
/// against rounding).
const SPLICES_PER_VERTEX: usize = 64;

type Point = [f64; 2];

/// The footprint swept from `a` to `b` (pixels) stays on the grid and
/// overlaps no blocked cell. `a == b` checks the footprint at one point.
pub fn segment_is_free(grid: &StateGrid, a: Point, b: Point) -> bool {
    let half = [0, 1].map(|k| grid.cell_size[k] * (0.5 - SHRINK));
    let lo = [0, 1].map(|k| grid.origin[k] + half[k]);
    let hi = [0, 1].map(|k| grid.origin[k] + grid_extent(grid, k) - half[k]);
    let on_grid = |p: Point| (0..2).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
    if !on_grid(a) || !on_grid(b) {
        return false;
    }
    let reach = [0, 1].map(|k| grid.cell_size[k] * (1.0 - SHRINK));
    let (r0, c0) = grid.cell_at([a[0].min(b[0]) - reach[0], a[1].min(b[1]) - reach[1]]);
    let (r1, c1) = grid.cell_at([a[0].max(b[0]) + reach[0], a[1].max(b[1]) + reach[1]]);
    (r0..=r1).all(|r| {
        (c0..=c1).all(|c| {
            if !grid.code((r, c)).is_blocked() {
                return true;
            }
            let centre = grid.centre((r, c));
            let lo = [0, 1].map(|k| centre[k] - reach[k]);
            let hi = [0, 1].map(|k| centre[k] + reach[k]);
            !crosses_open_box(a, b, lo, hi)
        })
    })
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
    let mut out: Vec<Point> = Vec::with_capacity(points.len());
    let mut run: Vec<Point> = Vec::new();
    for &p in points {
        match run.last() {
            Some(&last) if last == p => continue,
            Some(&last) if !segment_is_free(grid, last, p) => {
                flush(grid, &mut run, &mut out);
                run.push(last);
            }
            _ => {}
        }
        run.push(p);
    }
    flush(grid, &mut run, &mut out);
    out
}

/// Appends the taut form of `run` to `out` (without repeating the junction
/// point) and empties `run`.
fn flush(grid: &StateGrid, run: &mut Vec<Point>, out: &mut Vec<Point>) {
    let pulled = pull(grid, std::mem::take(run));
    let skip = usize::from(out.last().is_some_and(|&l| Some(&l) == pulled.first()));
    out.extend(pulled.into_iter().skip(skip));
}

/// The elastic band on one run of free segments.
fn pull(grid: &StateGrid, mut path: Vec<Point>) -> Vec<Point> {
    let mut budget = SPLICES_PER_VERTEX * path.len().max(1);
    let mut i = 1;
    while i + 1 < path.len() && budget > 0 {
        let (a, b, c) = (path[i - 1], path[i], path[i + 1]);
        let chain = wrap(grid, a, b, c);
        let (after, before) = (
            polyline_length(a, &chain, c),
            distance(a, b) + distance(b, c),
        );
        // Shorter, or as long with b dropped (b on the straight a–c).
        let shorter = after < before - 1e-9 || (chain.is_empty() && after <= before + 1e-9);
        let free = || {
            let mut prev = a;
            chain.iter().chain([&c]).all(|&p| {
                let ok = segment_is_free(grid, prev, p);
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
/// obstacle centres inside the triangle `abc`, on `b`'s side (empty: the
/// straight `ac` deforms `a-b-c` without crossing an obstacle).
fn wrap(grid: &StateGrid, a: Point, b: Point, c: Point) -> Vec<Point> {
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
    let reach = [0, 1].map(|k| grid.cell_size[k] * (1.0 - SHRINK));
    let lo = [0, 1].map(|k| a[k].min(b[k]).min(c[k]) - reach[k]);
    let hi = [0, 1].map(|k| a[k].max(b[k]).max(c[k]) + reach[k]);
    let (r0, c0) = grid.cell_at(lo);
    let (r1, c1) = grid.cell_at(hi);
    // The corners of every grown blocked cell whose interior reaches into
    // the triangle's: only those can hold the band (a cell that merely
    // touches an edge from outside cannot).
    let mut points: Vec<Point> = Vec::new();
    for r in r0..=r1 {
        for col in c0..=c1 {
            if !grid.code((r, col)).is_blocked() {
                continue;
            }
            let centre = grid.centre((r, col));
            let shrunk = [0, 1].map(|k| [centre[k] - reach[k], centre[k] + reach[k]]);
            if !box_meets_triangle(shrunk, [a, b, c]) {
                continue;
            }
            for du in [-1.0, 1.0] {
                for dv in [-1.0, 1.0] {
                    let p = [
                        centre[0] + du * grid.cell_size[0],
                        centre[1] + dv * grid.cell_size[1],
                    ];
                    if inside(p) && p != a && p != c && !points.contains(&p) {
                        points.push(p);
                    }
                }
            }
        }
    }
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
mod tests {
    use super::*;
    use crate::grid::CellCode;

    fn grid(rows: &[&str]) -> StateGrid {
        let codes = rows
            .iter()
            .flat_map(|r| r.chars())
            .map(|ch| match ch {
                '#' => CellCode::Obstacle,
                'T' => CellCode::Target,
                'G' => CellCode::Goal,
                _ => CellCode::Empty,
            })
            .collect();
        StateGrid::from_codes(rows.len(), rows[0].len(), codes, (0, 0)).expect("valid test grid")
    }

    fn centres(g: &StateGrid, cells: &[(usize, usize)]) -> Vec<Point> {
        cells.iter().map(|&c| g.centre(c)).collect()
    }

    /// A staircase through open space becomes the straight line.
    #[test]
    fn route_staircase_in_open_space_pulls_straight() {
        let g = grid(&["T....", ".....", ".....", "....G"]);
        let cells = [
            (0, 0),
            (0, 1),
            (1, 1),
            (1, 2),
            (2, 2),
            (2, 3),
            (3, 3),
            (3, 4),
        ];
        let route = taut(&g, &centres(&g, &cells));
        assert_eq!(route, vec![g.centre((0, 0)), g.centre((3, 4))]);
    }

    /// Around an obstacle the route bends only at the grown obstacle's
    /// corner (a cell centre diagonal to it), never through it.
    #[test]
    fn route_wraps_the_obstacle_corner_it_went_round() {
        let g = grid(&["T.....", "......", "..##..", "..##..", "......", ".....G"]);
        // Round the obstacle's right-hand side: right along row 0, down col 5.
        let mut cells: Vec<(usize, usize)> = (0..6).map(|c| (0, c)).collect();
        cells.extend((1..6).map(|r| (r, 5)));
        let route = taut(&g, &centres(&g, &cells));
        assert!(route.windows(2).all(|w| segment_is_free(&g, w[0], w[1])));
        assert!(
            path_length(&route) < path_length(&centres(&g, &cells)) - 1.0,
            "{route:?}"
        );
        // Still right of the obstacle: one bend, at the grown block's corner
        // (the centre of (1, 4)).
        assert_eq!(
            route,
            vec![g.centre((0, 0)), g.centre((1, 4)), g.centre((5, 5))]
        );
        // The same plan round the left-hand side stays on the left.
        let mut left: Vec<(usize, usize)> = (0..6).map(|r| (r, 0)).collect();
        left.extend((1..6).map(|c| (5, c)));
        let route = taut(&g, &centres(&g, &left));
        assert_eq!(
            route,
            vec![g.centre((0, 0)), g.centre((4, 1)), g.centre((5, 5))]
        );
    }

    /// An island the plan went round is not crossed even when the straight
    /// segment between the plan's ends would miss every blocked cell's
    /// centre: the swept footprint counts, not the centre line.
    #[test]
    fn route_never_cuts_a_blocked_cell_with_the_footprint() {
        let g = grid(&["T...", "..#.", "...G"]);
        let a = g.centre((0, 0));
        let b = g.centre((2, 3));
        assert!(!segment_is_free(&g, a, b), "the footprint clips (1, 2)");
        let cells = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (2, 3)];
        let route = taut(&g, &centres(&g, &cells));
        assert!(route.windows(2).all(|w| segment_is_free(&g, w[0], w[1])));
        assert_eq!(route, vec![a, g.centre((2, 1)), b]);
    }

    /// A bend where one obstacle lies inside the turn and another only
    /// touches the path from outside: the outside one must not hold the band
    /// (found on a campaign scene, where the route kept the staircase).
    #[test]
    fn route_is_not_held_by_an_obstacle_touching_it_from_outside() {
        let g = grid(&[
            "T....", ".....", ".###.", ".....", ".....", "###..", "###..", "###..",
        ]);
        let cells = [
            (7, 3),
            (6, 3),
            (5, 3),
            (4, 3),
            (4, 2),
            (4, 1),
            (4, 0),
            (3, 0),
            (2, 0),
            (1, 0),
            (0, 0),
        ];
        let route = taut(&g, &centres(&g, &cells));
        assert_eq!(route, vec![[3.5, 7.5], [3.5, 4.5], [0.5, 3.5], [0.5, 0.5]]);
        assert!(route.windows(2).all(|w| segment_is_free(&g, w[0], w[1])));
    }

    #[test]
    fn route_segment_touching_a_grown_cell_is_free() {
        let g = grid(&["T..", ".#.", "..."]);
        // Along row 0 the footprint's bottom edge touches (1, 1)'s top edge.
        assert!(segment_is_free(&g, g.centre((0, 0)), g.centre((0, 2))));
        // Off the grid or over the blocked cell: not free.
        assert!(!segment_is_free(&g, [0.2, 0.5], [2.5, 0.5]));
        assert!(!segment_is_free(&g, g.centre((0, 0)), g.centre((2, 2))));
        assert!(!segment_is_free(&g, [1.2, 0.8], [1.2, 0.8]));
    }
}
