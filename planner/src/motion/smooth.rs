//! Smoothing the route (the paper applies spline interpolation to the
//! optimal policy's actions, Algorithm 3's last line) without ever trading
//! safety for it.
//!
//! The route — the CQL cell path pulled taut by [`crate::motion::route`] —
//! is interpolated by a cubic Hermite spline through its vertices: at each
//! bend the tangent is the bisector of the two directions, with a handle of
//! at most one cell (and at most the span), so the curve turns within about
//! a cell of the bend and runs straight between bends (a Catmull–Rom
//! spline with span-long tangents bulged up to half a cell off a long
//! span). The ends keep the chord's direction. Sampled at least every
//! quarter cell. Every chord between consecutive
//! samples is checked with the swept footprint of
//! [`route::segment_is_free`] (the held object's footprint, a cell-sized
//! square, must overlap no 0.2/0.4 cell); a span whose curve fails falls
//! back to the straight segment, which the route already proved free.

use crate::grid::StateGrid;
use crate::motion::route;

/// Fewest samples per span between two route vertices.
pub const MIN_SAMPLES_PER_SPAN: usize = 4;
/// Most samples per span (a long span is sampled every quarter cell up to this).
pub const MAX_SAMPLES_PER_SPAN: usize = 64;

/// Pixel points of the smoothed route through `vertices` (consecutive
/// segments free), starting at the first vertex and ending at the last.
pub fn smooth_route(grid: &StateGrid, vertices: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let Some(&first) = vertices.first() else {
        return Vec::new();
    };
    let step = grid.cell_size[0].min(grid.cell_size[1]) / 4.0;
    let mut out = vec![first];
    for k in 0..vertices.len().saturating_sub(1) {
        let (p1, p2) = (vertices[k], vertices[k + 1]);
        let length = (p2[0] - p1[0]).hypot(p2[1] - p1[1]);
        let handle = length.min(grid.cell_size[0].max(grid.cell_size[1]));
        let (m1, m2) = (tangent(vertices, k), tangent(vertices, k + 1));
        let samples =
            ((length / step).ceil() as usize).clamp(MIN_SAMPLES_PER_SPAN, MAX_SAMPLES_PER_SPAN);
        let mut curve: Vec<[f64; 2]> = (1..samples)
            .map(|i| hermite(p1, p2, m1, m2, handle, i as f64 / samples as f64))
            .collect();
        curve.push(p2);
        let mut prev = p1;
        let free = curve.iter().all(|&p| {
            let ok = route::segment_is_free(grid, prev, p);
            prev = p;
            ok
        });
        match free {
            true => out.extend(curve),
            false => out.push(p2),
        }
    }
    out
}

/// Unit tangent at vertex `k`: the bisector of the directions in and out
/// (the one direction at an end; zero where the route turns back).
fn tangent(vertices: &[[f64; 2]], k: usize) -> [f64; 2] {
    let unit = |a: [f64; 2], b: [f64; 2]| {
        let d = [b[0] - a[0], b[1] - a[1]];
        let n = d[0].hypot(d[1]);
        if n > 0.0 {
            [d[0] / n, d[1] / n]
        } else {
            [0.0, 0.0]
        }
    };
    let last = vertices.len() - 1;
    let inward = if k > 0 {
        unit(vertices[k - 1], vertices[k])
    } else {
        [0.0, 0.0]
    };
    let outward = if k < last {
        unit(vertices[k], vertices[k + 1])
    } else {
        [0.0, 0.0]
    };
    unit([0.0, 0.0], [inward[0] + outward[0], inward[1] + outward[1]])
}

/// Cubic Hermite between `p1` and `p2` at t ∈ [0, 1] with unit tangents
/// `m1`, `m2` scaled by `handle`.
fn hermite(
    p1: [f64; 2],
    p2: [f64; 2],
    m1: [f64; 2],
    m2: [f64; 2],
    handle: f64,
    t: f64,
) -> [f64; 2] {
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    [0, 1].map(|k| h00 * p1[k] + h10 * handle * m1[k] + h01 * p2[k] + h11 * handle * m2[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::CellCode;
    use crate::motion::route::{segment_is_free, taut};

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

    fn all_free(g: &StateGrid, path: &[[f64; 2]]) -> bool {
        path.windows(2).all(|w| segment_is_free(g, w[0], w[1]))
    }

    #[test]
    fn curve_passes_through_every_route_vertex() {
        let g = grid(&["T....", ".....", "....G"]);
        let vertices = [g.centre((0, 0)), g.centre((1, 2)), g.centre((2, 4))];
        let path = smooth_route(&g, &vertices);
        for v in vertices {
            assert!(
                path.iter()
                    .any(|p| (p[0] - v[0]).abs() < 1e-9 && (p[1] - v[1]).abs() < 1e-9),
                "{v:?} missing from {path:?}"
            );
        }
        assert!(all_free(&g, &path));
    }

    #[test]
    fn a_corner_next_to_an_obstacle_is_not_cut() {
        // Around the obstacle at (1,0): the taut route bends at its grown
        // corner, and no chord of the curve may let the footprint clip it.
        let g = grid(&["T.", "#.", "G."]);
        let cells = [(0, 0), (0, 1), (1, 1), (2, 1)];
        let route = taut(&g, &cells.map(|c| g.centre(c)));
        let path = smooth_route(&g, &route);
        assert!(all_free(&g, &path), "every chord keeps the footprint clear");
    }

    #[test]
    fn free_corner_is_rounded() {
        let g = grid(&[".....", ".T...", ".....", ".....", "....."]);
        let corner = g.centre((1, 3));
        let vertices = [g.centre((1, 1)), corner, g.centre((3, 3))];
        let path = smooth_route(&g, &vertices);
        let at = path
            .iter()
            .position(|&p| p == corner)
            .expect("passes the corner");
        // The sample just before the corner leaves the straight line, by
        // less than a cell.
        let off = (path[at - 1][1] - corner[1]).abs();
        assert!(off > 1e-6 && off < 1.0, "{:?}", path[at - 1]);
        assert!(all_free(&g, &path));
    }
}
