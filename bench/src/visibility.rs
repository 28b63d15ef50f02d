//! The route oracle of `afford bench routes`: the shortest any-angle path
//! around the safety perimeters, by a visibility graph (Lozano-Pérez and
//! Wesley, 1979), written apart from the planner's grid and route code so it
//! shares none of their arithmetic.
//!
//! Obstacles are the perimeters in pixels, each grown by half the moving
//! footprint (the target's box) on every side — the configuration-space
//! obstacles of a footprint that must stay off the perimeters — as open
//! axis-aligned rectangles. The shortest path between two points among
//! polygonal obstacles bends only at obstacle vertices, so Dijkstra over the
//! start, the end and every rectangle corner (inside the image, not inside
//! another rectangle), joined where the segment meets no rectangle's
//! interior (separating-axis test), gives it exactly. Lengths are metres:
//! each edge is mapped through the calibration's linear part (an affine map
//! keeps straight lines and visibility, so the graph is the same).
//!
//! Relaxations, each making the oracle shorter (the measured ratio can only
//! be pessimistic): an obstacle that contains the start or the end is left
//! out, and so is every obstacle but a hand's connected to one under the
//! gripper ([`Field::escaping`]; the grid clears the connected obstacle
//! region under the gripper and wins the target cell over a perimeter); the tool's point may go anywhere in the image
//! (the planner keeps the whole footprint on the grid); touching rectangles
//! leave a zero-width gap between them.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// An open axis-aligned rectangle, pixels: `lo < p < hi` on both axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    /// The gripper may leave it when it starts inside (everything but a
    /// hand's perimeter; see [`Field::escaping`]).
    pub escapable: bool,
}

impl Rect {
    /// The closed rectangles overlap or touch.
    fn touches(&self, other: &Rect) -> bool {
        (0..2).all(|k| self.lo[k] <= other.hi[k] && other.lo[k] <= self.hi[k])
    }

    fn strictly_contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|k| p[k] > self.lo[k] && p[k] < self.hi[k])
    }

    fn corners(&self) -> [[f64; 2]; 4] {
        let (lo, hi) = (self.lo, self.hi);
        [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]
    }

    /// The closed segment `a`–`b` meets the open rectangle: no separating
    /// axis among u, v and the segment's normal.
    fn meets_segment(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        for k in 0..2 {
            if a[k].max(b[k]) <= self.lo[k] || a[k].min(b[k]) >= self.hi[k] {
                return false;
            }
        }
        let n = [a[1] - b[1], b[0] - a[0]];
        if n == [0.0, 0.0] {
            return self.strictly_contains(a);
        }
        let at = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1];
        let c = at(a);
        let projected = self.corners().map(at);
        let min = projected.iter().copied().fold(f64::INFINITY, f64::min);
        let max = projected.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        min < c && c < max
    }
}

/// The plane the oracle searches: obstacles, the image it stays in, and
/// the linear part of the pixel-to-metre map.
#[derive(Debug, Clone)]
pub struct Field {
    pub obstacles: Vec<Rect>,
    /// Image size `[width, height]`, pixels.
    pub image: [f64; 2],
    /// `pixel_to_base`'s linear part (rows x, y; columns u, v).
    pub metres: [[f64; 2]; 2],
}

impl Field {
    /// The field without the escapable obstacles connected (overlapping or
    /// touching, transitively) to one that contains `start`: the grid clears
    /// the connected obstacle region under the gripper so it can leave.
    pub fn escaping(&self, start: [f64; 2]) -> Field {
        let mut cleared: Vec<bool> = self
            .obstacles
            .iter()
            .map(|r| r.escapable && r.strictly_contains(start))
            .collect();
        let mut grown = true;
        while grown {
            grown = false;
            for i in 0..self.obstacles.len() {
                let reached = (0..self.obstacles.len())
                    .any(|j| cleared[j] && self.obstacles[j].touches(&self.obstacles[i]));
                if !cleared[i] && self.obstacles[i].escapable && reached {
                    cleared[i] = true;
                    grown = true;
                }
            }
        }
        Field {
            obstacles: self
                .obstacles
                .iter()
                .zip(&cleared)
                .filter(|(_, c)| !**c)
                .map(|(r, _)| *r)
                .collect(),
            ..self.clone()
        }
    }

    /// Length in metres of the shortest path from `a` to `b` (pixels) that
    /// enters no obstacle; `None` when there is none.
    pub fn shortest(&self, a: [f64; 2], b: [f64; 2]) -> Option<f64> {
        let kept: Vec<Rect> = self
            .obstacles
            .iter()
            .filter(|r| !r.strictly_contains(a) && !r.strictly_contains(b))
            .copied()
            .collect();
        let in_image = |p: [f64; 2]| (0..2).all(|k| p[k] >= 0.0 && p[k] <= self.image[k]);
        let mut nodes = vec![a, b];
        nodes.extend(
            kept.iter()
                .flat_map(Rect::corners)
                .filter(|&p| in_image(p) && !kept.iter().any(|r| r.strictly_contains(p))),
        );
        let visible =
            |i: usize, j: usize| !kept.iter().any(|r| r.meets_segment(nodes[i], nodes[j]));
        dijkstra(nodes.len(), 0, 1, |i, j| {
            visible(i, j).then(|| self.length(nodes[i], nodes[j]))
        })
    }

    fn length(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        let d = [b[0] - a[0], b[1] - a[1]];
        let m = &self.metres;
        (m[0][0] * d[0] + m[0][1] * d[1]).hypot(m[1][0] * d[0] + m[1][1] * d[1])
    }
}

/// Dijkstra on a complete graph of `n` nodes whose edge weights `edge(i, j)`
/// are computed when needed (`None`: no edge); the distance from `from` to `to`.
fn dijkstra(
    n: usize,
    from: usize,
    to: usize,
    edge: impl Fn(usize, usize) -> Option<f64>,
) -> Option<f64> {
    let mut best = vec![f64::INFINITY; n];
    let mut done = vec![false; n];
    let mut queue = BinaryHeap::new();
    best[from] = 0.0;
    queue.push(Entry(0.0, from));
    while let Some(Entry(d, i)) = queue.pop() {
        if done[i] {
            continue;
        }
        if i == to {
            return Some(d);
        }
        done[i] = true;
        for j in (0..n).filter(|&j| !done[j]) {
            if let Some(w) = edge(i, j).filter(|w| d + w < best[j]) {
                best[j] = d + w;
                queue.push(Entry(d + w, j));
            }
        }
    }
    None
}

/// A queue entry ordered by distance, smallest first.
#[derive(Debug, PartialEq)]
struct Entry(f64, usize);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(obstacles: Vec<Rect>) -> Field {
        Field {
            obstacles,
            image: [100.0, 100.0],
            metres: [[0.01, 0.0], [0.0, 0.01]],
        }
    }

    #[test]
    fn oracle_open_table_is_the_straight_line() {
        let d = field(Vec::new()).shortest([0.0, 0.0], [30.0, 40.0]);
        assert!((d.expect("path") - 0.5).abs() < 1e-12);
    }

    #[test]
    fn oracle_goes_round_the_nearer_corner() {
        // A wall from v = 20 to 80 at u 40..60: from (50, 10) to (50, 90)
        // the path bends at two corners on one side.
        let wall = Rect {
            lo: [40.0, 20.0],
            hi: [60.0, 80.0],
            escapable: true,
        };
        let d = field(vec![wall]).shortest([50.0, 10.0], [50.0, 90.0]);
        let want = 2.0 * 10.0f64.hypot(10.0) + 60.0;
        assert!((d.expect("path") - want * 0.01).abs() < 1e-9, "{d:?}");
    }

    #[test]
    fn oracle_may_slide_along_an_edge_but_not_through() {
        let r = Rect {
            lo: [10.0, 10.0],
            hi: [20.0, 20.0],
            escapable: true,
        };
        assert!(
            !r.meets_segment([0.0, 10.0], [30.0, 10.0]),
            "along the edge"
        );
        assert!(!r.meets_segment([0.0, 0.0], [10.0, 10.0]), "to the corner");
        assert!(
            r.meets_segment([0.0, 0.0], [30.0, 30.0]),
            "diagonal through"
        );
        assert!(
            r.meets_segment([15.0, 0.0], [15.0, 30.0]),
            "straight through"
        );
    }

    #[test]
    fn oracle_escapes_the_region_under_the_gripper_but_not_a_hand() {
        let rect = |lo: [f64; 2], hi: [f64; 2], escapable: bool| Rect { lo, hi, escapable };
        // The start is inside a box that touches a second one; a hand's
        // perimeter touches both.
        let f = field(vec![
            rect([0.0, 0.0], [20.0, 20.0], true),
            rect([20.0, 0.0], [40.0, 20.0], true),
            rect([40.0, 0.0], [60.0, 20.0], false),
            rect([0.0, 50.0], [20.0, 60.0], true),
        ]);
        let left = f.escaping([10.0, 10.0]).obstacles;
        assert_eq!(left.len(), 2);
        assert!(!left[0].escapable && left[1].lo == [0.0, 50.0]);
    }

    #[test]
    fn oracle_uses_the_metric_of_the_calibration() {
        // 1 px along u is 2 mm, along v 1 mm: the same pixel path is longer
        // along u.
        let mut f = field(Vec::new());
        f.metres = [[0.0, 0.001], [0.002, 0.0]];
        let along_u = f.shortest([0.0, 0.0], [10.0, 0.0]).expect("path");
        let along_v = f.shortest([0.0, 0.0], [0.0, 10.0]).expect("path");
        assert!((along_u - 0.02).abs() < 1e-12 && (along_v - 0.01).abs() < 1e-12);
    }
}
