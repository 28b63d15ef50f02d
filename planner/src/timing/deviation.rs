//! Distance of the tool from the planned tool path: the polyline through
//! the tool positions of the joint waypoints (forward kinematics, robot base
//! frame, metres).

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
