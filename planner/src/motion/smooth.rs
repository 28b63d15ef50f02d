//! Smoothing the route (the paper applies spline interpolation to the
//! optimal policy's actions, Algorithm 3's last line) without ever trading
//! safety for it.
//!
//! The route — the CQL cell path pulled taut by [`crate::motion::route`] —
//! is interpolated by a centripetal Catmull–Rom spline through its vertices
//! (it passes through every vertex and does not overshoot on sharp turns),
//! sampled at least every quarter cell. Every chord between consecutive
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
        let p0 = vertices[k.saturating_sub(1)];
        let (p1, p2) = (vertices[k], vertices[k + 1]);
        let p3 = vertices[(k + 2).min(vertices.len() - 1)];
        let length = (p2[0] - p1[0]).hypot(p2[1] - p1[1]);
        let samples = ((length / step).ceil() as usize)
            .clamp(MIN_SAMPLES_PER_SPAN, MAX_SAMPLES_PER_SPAN);
        let mut curve: Vec<[f64; 2]> = (1..samples)
            .map(|i| catmull_rom(p0, p1, p2, p3, i as f64 / samples as f64))
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

fn lerp(a: [f64; 2], b: [f64; 2], t: f64) -> [f64; 2] {
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

/// Centripetal Catmull–Rom (α = ½) between p1 and p2 at t ∈ [0, 1]
/// (Barry–Goldman pyramidal form). Repeated end points are handled by
/// nudging the knot spacing away from zero.
fn catmull_rom(p0: [f64; 2], p1: [f64; 2], p2: [f64; 2], p3: [f64; 2], t: f64) -> [f64; 2] {
    let knot = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).hypot(a[1] - b[1])).sqrt().max(1e-9);
    let t0 = 0.0;
    let t1 = t0 + knot(p0, p1);
    let t2 = t1 + knot(p1, p2);
    let t3 = t2 + knot(p2, p3);
    let u = t1 + t * (t2 - t1);
    let mix = |a: [f64; 2], b: [f64; 2], ta: f64, tb: f64| lerp(a, b, (u - ta) / (tb - ta));
    let a1 = mix(p0, p1, t0, t1);
    let a2 = mix(p1, p2, t1, t2);
    let a3 = mix(p2, p3, t2, t3);
    let b1 = mix(a1, a2, t0, t2);
    let b2 = mix(a2, a3, t1, t3);
    mix(b1, b2, t1, t2)
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
                path.iter().any(|p| (p[0] - v[0]).abs() < 1e-9 && (p[1] - v[1]).abs() < 1e-9),
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
        let at = path.iter().position(|&p| p == corner).expect("passes the corner");
        // The sample just before the corner leaves the straight line.
        assert!((path[at - 1][1] - corner[1]).abs() > 1e-6, "{:?}", path[at - 1]);
        assert!(all_free(&g, &path));
    }
}
