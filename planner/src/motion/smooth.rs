//! Smoothing the discrete cell path (the paper applies spline interpolation
//! to the optimal policy's actions, Algorithm 3's last line) without ever
//! trading safety for it.
//!
//! The travel legs are interpolated by a centripetal Catmull–Rom spline
//! through the cell centres (it passes through every centre and does not
//! overshoot on sharp turns). Every sample is checked: the held object's
//! footprint — a cell-sized square around the sample, the target's box —
//! must overlap no 0.2/0.4 cell. A span between two centres whose curve
//! fails the check falls back to the straight segment, which the grid plan
//! already proved free (consecutive cells are 4-adjacent and free).

use crate::grid::{Cell, StateGrid};

/// Samples per span between two cell centres.
pub const SAMPLES_PER_SPAN: usize = 8;

/// Pixel points of the smoothed path through `cells` (consecutive,
/// 4-adjacent, free cells), starting at the first centre and ending at the
/// last, `SAMPLES_PER_SPAN` points per span.
pub fn smooth_path(grid: &StateGrid, cells: &[Cell]) -> Vec<[f64; 2]> {
    let centres: Vec<[f64; 2]> = cells.iter().map(|&c| grid.centre(c)).collect();
    let Some(&first) = centres.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    for k in 0..centres.len().saturating_sub(1) {
        let p0 = centres[k.saturating_sub(1)];
        let (p1, p2) = (centres[k], centres[k + 1]);
        let p3 = centres[(k + 2).min(centres.len() - 1)];
        let curve: Vec<[f64; 2]> = (1..=SAMPLES_PER_SPAN)
            .map(|i| catmull_rom(p0, p1, p2, p3, i as f64 / SAMPLES_PER_SPAN as f64))
            .collect();
        if curve.iter().all(|&p| footprint_is_free(grid, p)) {
            out.extend(curve);
        } else {
            out.extend(
                (1..=SAMPLES_PER_SPAN).map(|i| lerp(p1, p2, i as f64 / SAMPLES_PER_SPAN as f64)),
            );
        }
    }
    out
}

/// A cell-sized square centred at `p` overlaps no blocked cell and stays on
/// the grid.
pub fn footprint_is_free(grid: &StateGrid, p: [f64; 2]) -> bool {
    const SHRINK: f64 = 1e-6;
    let half = [
        grid.cell_size[0] * (0.5 - SHRINK),
        grid.cell_size[1] * (0.5 - SHRINK),
    ];
    let extent = [
        grid.origin[0] + grid.cols as f64 * grid.cell_size[0],
        grid.origin[1] + grid.rows as f64 * grid.cell_size[1],
    ];
    if (0..2).any(|k| p[k] - half[k] < grid.origin[k] || p[k] + half[k] > extent[k]) {
        return false;
    }
    let (r0, c0) = grid.cell_at([p[0] - half[0], p[1] - half[1]]);
    let (r1, c1) = grid.cell_at([p[0] + half[0], p[1] + half[1]]);
    (r0..=r1).all(|r| (c0..=c1).all(|c| !grid.code((r, c)).is_blocked()))
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

    #[test]
    fn curve_passes_through_every_cell_centre() {
        let g = grid(&["T....", ".....", "....G"]);
        let cells = [(0, 0), (0, 1), (1, 1), (1, 2), (2, 2)];
        let path = smooth_path(&g, &cells);
        assert_eq!(path.len(), 1 + 4 * SAMPLES_PER_SPAN);
        for (k, &cell) in cells.iter().enumerate() {
            let p = path[k * SAMPLES_PER_SPAN];
            let c = g.centre(cell);
            assert!(
                (p[0] - c[0]).abs() < 1e-9 && (p[1] - c[1]).abs() < 1e-9,
                "span {k}: {p:?} vs {c:?}"
            );
        }
    }

    #[test]
    fn a_corner_next_to_an_obstacle_is_not_cut() {
        // Around the obstacle at (1,0): the turn at (0,1) -> (1,1) -> (2,1)
        // must not let the footprint clip (1,0) or the corner cell.
        let g = grid(&["T.", "#.", "G."]);
        let cells = [(0, 0), (0, 1), (1, 1), (2, 1)];
        let path = smooth_path(&g, &cells);
        assert!(
            path.iter().all(|&p| footprint_is_free(&g, p)),
            "every sample keeps the footprint clear"
        );
    }

    #[test]
    fn free_corner_is_rounded() {
        let g = grid(&[".....", ".T...", ".....", "...G.", "....."]);
        let cells = [(1, 1), (1, 2), (1, 3), (2, 3), (3, 3)];
        let path = smooth_path(&g, &cells);
        let corner = g.centre((1, 3));
        let near_corner = path[2 * SAMPLES_PER_SPAN - 1];
        // The sample just before the corner centre leaves the straight line,
        // and every sample keeps the footprint clear.
        assert!((near_corner[1] - corner[1]).abs() > 1e-6, "{near_corner:?}");
        assert!(path.iter().all(|&p| footprint_is_free(&g, p)));
    }
}
