//! The tool's distance from the planned tool path.
//!
//! The planned tool path is what the collision stage checked: the tool
//! (forward kinematics, robot base frame, metres) along the joint polyline,
//! linear in joint space between the waypoints. Each segment's image is kept
//! as a polyline of tool positions at most [`FK_STEP`] rad apart in joint
//! space (its chord error is far below a millimetre). A sample on the path
//! piece that follows waypoint segments `k0..=k1` is measured against those
//! segments' images. The corner blends of [`spline`](super::spline) are
//! narrowed so that each blend's middle, its farthest point from the joint
//! polyline, moves the tool by at most half the tolerance.

use super::spline::apex_offset;

/// The arm's forward kinematics: joint positions (the path's joints, in
/// order) → tool-centre position, robot base frame, metres.
pub type ToolFk<'a> = &'a dyn Fn(&[f64]) -> [f64; 3];

/// Joint-space step between the tool positions that trace one segment, rad.
pub const FK_STEP: f64 = 0.01;

/// Most tool positions traced on one waypoint segment (bounds the work on a
/// long segment; 10,000 × [`FK_STEP`] = 100 rad of joint-space length).
const MAX_TRACE: usize = 10_000;

/// Narrows each corner radius so that the blend's middle moves the tool by
/// at most `target` metres from the corner's tool position (`radii` as from
/// [`widest_radii`](super::spline::widest_radii)).
pub fn narrow_radii(points: &[&[f64]], knots: &[f64], radii: &mut [f64], fk: ToolFk, target: f64) {
    for k in 1..points.len().saturating_sub(1) {
        let r = radii[k];
        let offset = apex_offset(points, knots, k);
        let apex: Vec<f64> = points[k]
            .iter()
            .zip(&offset)
            .map(|(p, e)| p + r * e)
            .collect();
        let moved = distance(fk(&apex), fk(points[k]));
        if moved > target {
            radii[k] = r * target / moved;
        }
    }
}

/// The planned tool path, segment by segment, and the tolerance.
pub struct ToolPathCheck<'a> {
    fk: ToolFk<'a>,
    /// `traces[k]`: tool positions along joint segment `k`, both ends included.
    traces: Vec<Vec<[f64; 3]>>,
    /// Largest allowed distance, metres.
    pub tolerance_m: f64,
}

impl<'a> ToolPathCheck<'a> {
    /// Traces the tool along the joint polyline through `points`.
    pub fn new(points: &[&[f64]], fk: ToolFk<'a>, tolerance_m: f64) -> Self {
        let traces = points
            .windows(2)
            .map(|w| {
                let length = w[0]
                    .iter()
                    .zip(w[1])
                    .map(|(a, b)| (b - a).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let steps = ((length / FK_STEP).ceil() as usize).clamp(1, MAX_TRACE);
                (0..=steps)
                    .map(|m| {
                        let u = m as f64 / steps as f64;
                        let q: Vec<f64> = w[0]
                            .iter()
                            .zip(w[1])
                            .map(|(a, b)| a + u * (b - a))
                            .collect();
                        fk(&q)
                    })
                    .collect()
            })
            .collect();
        Self {
            fk,
            traces,
            tolerance_m,
        }
    }

    /// The tool position at joint positions `q`, metres.
    pub fn fk_of(&self, q: &[f64]) -> [f64; 3] {
        (self.fk)(q)
    }

    /// Distance, metres, from `tool` to the planned tool path of waypoint
    /// segments `first..=last`.
    pub fn distance(&self, tool: [f64; 3], (first, last): (usize, usize)) -> f64 {
        self.traces[first..=last]
            .iter()
            .flat_map(|trace| trace.windows(2))
            .map(|w| point_segment_distance(tool, w[0], w[1]))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Euclidean distance from `p` to the segment `[a, b]`, metres.
pub fn point_segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let len_sq = ab.iter().map(|x| x * x).sum::<f64>();
    let u = if len_sq > 0.0 {
        (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|k| (ap[k] - u * ab[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    point_segment_distance(a, b, b)
}
