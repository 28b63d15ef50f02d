//! The taut route: free segments, pulled and wrapped paths, and the grid helpers other modules' tests share.

use super::*;
use crate::grid::CellCode;
use crate::scenario::PixelBox;

/// A grid from rows of characters: `#` obstacle, `T` target, `G` goal,
/// anything else empty; the gripper starts in cell (0, 0).
pub(crate) fn grid(rows: &[&str]) -> StateGrid {
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

/// Samples every `1/n` of each segment: the footprint (a `half`-sized
/// half-width square) at each sample never overlaps the open box
/// `(lo, hi)` by more than `depth` — an independent check of the route.
fn deepest_into(route: &[Point], lo: Point, hi: Point, half: f64) -> f64 {
    let n = 200;
    route
        .windows(2)
        .flat_map(|w| {
            (0..=n).map(move |i| {
                let t = i as f64 / n as f64;
                [0, 1].map(|k| w[0][k] + t * (w[1][k] - w[0][k]))
            })
        })
        .map(|p| {
            (0..2)
                .map(|k| (p[k] + half - lo[k]).min(hi[k] - (p[k] - half)))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// A perimeter that covers only part of its cell: the route keeps the
/// footprint off the perimeter itself, not off the whole cell (campaign
/// scene 56: cells 77 × 67 px kept the route 55 px further out than the
/// perimeter needed).
#[test]
fn route_keeps_off_the_perimeter_not_the_whole_cell() {
    let mut g = grid(&["T..", ".#.", "..."]);
    let perimeter = PixelBox {
        u: 1.0,
        v: 1.0,
        w: 0.2,
        l: 1.0,
    };
    let cells = [(0, 0), (0, 1), (0, 2), (1, 2), (2, 2)];
    let by_cells = taut(&g, &centres(&g, &cells));
    g.perimeters.push(perimeter);
    let route = taut(&g, &centres(&g, &cells));
    assert_eq!(by_cells, centres(&g, &[(0, 0), (0, 2), (2, 2)]));
    assert_eq!(route.len(), 3, "{route:?}");
    assert!((route[1][0] - 1.7).abs() < 1e-9 && (route[1][1] - 0.5).abs() < 1e-9);
    assert!(path_length(&route) < path_length(&by_cells) - 0.5);
    let depth = deepest_into(&route, [1.0, 1.0], [1.2, 2.0], 0.5);
    assert!(
        depth <= 1e-5,
        "the footprint enters the perimeter by {depth}"
    );
}

/// A tool that starts inside a perimeter (a hand's, which the grid never
/// clears) leaves it without going deeper, straight from where it is
/// rather than through its cell's centre (campaign scene 7).
#[test]
fn route_leaves_a_perimeter_it_starts_in_never_deeper() {
    let mut g = grid(&[".#..", ".#..", "...T"]);
    g.perimeters.push(PixelBox {
        u: 1.0,
        v: 0.0,
        w: 1.0,
        l: 2.0,
    });
    let start = [0.7, 0.5];
    let mut points = vec![start];
    points.extend(centres(&g, &[(1, 0), (2, 0), (2, 1), (2, 2), (2, 3)]));
    let route = taut(&g, &points);
    assert_eq!(route[0], start);
    assert_eq!(route.len(), 3, "{route:?}");
    // Grown by half the footprint the perimeter spans u 0.5..2.5: the
    // start is 0.2 inside, and no point of the route is deeper.
    let depth = deepest_into(&route, [1.0, 0.0], [2.0, 2.0], 0.5);
    assert!(depth <= 0.2 + 1e-9, "{depth}");
    assert!(path_length(&route) < path_length(&points) - 0.3);
}

/// The gripper starts over a box it has just released into, an
/// obstacle now: the grid clears that connected region of cells, and
/// the route crosses the perimeters over it as the cells do instead of
/// keeping the staircase through them (campaign scene 140, sub-goal 3:
/// 1.34 times the oracle's path); a perimeter over cells the grid did
/// not clear still holds the band.
#[test]
fn route_crosses_the_perimeters_cleared_under_the_gripper() {
    let mut g = grid(&["T....", ".....", ".##..", ".##..", "....."]);
    let boxed = |u, v, w, l| PixelBox { u, v, w, l };
    g.perimeters.extend([
        boxed(3.2, 3.2, 1.6, 1.6), // the box released into
        boxed(3.3, 1.1, 1.5, 2.2), // a piece whose perimeter meets it
        boxed(1.2, 2.2, 1.6, 1.6), // not cleared: cells (2..=3, 1..=2)
    ]);
    let cells = [
        (4, 4),
        (3, 4),
        (2, 4),
        (1, 4),
        (0, 4),
        (0, 3),
        (0, 2),
        (0, 1),
        (0, 0),
    ];
    let points = centres(&g, &cells);
    let kept = taut(&g, &points);
    g.cleared = (1..5).flat_map(|r| [(r, 3), (r, 4)]).collect();
    // The grid cleared the cells, but the gripper is in no perimeter:
    // the route keeps them closed.
    assert_eq!(taut(&g, &points), kept);
    g.escape = vec![0, 1];
    let route = taut(&g, &points);
    assert!(route.windows(2).all(|w| segment_is_free(&g, w[0], w[1])));
    // One bend, at the corner of the uncleared perimeter grown by half
    // the footprint, on the side the cells went round.
    assert_eq!(route.len(), 3, "{route:?}");
    assert!((route[1][0] - 3.3).abs() < 1e-9 && (route[1][1] - 1.7).abs() < 1e-9);
    assert!(
        path_length(&kept) > path_length(&route) + 1.0,
        "{kept:?} against {route:?}"
    );
    assert!(deepest_into(&route, [1.2, 2.2], [2.8, 3.8], 0.5) <= 1e-5);
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
