//! The turns over the target: the travel's last stretch descends from the
//! carry height to the approach height on a quarter ellipse, arriving
//! vertically (and the carry's first stretch rises the same way), where no
//! segment of the stretch needs more than the approach height; where the
//! tool's reach from the base falls toward the target the stretch is that
//! whole fall.

/// The need of every segment of a leg (of its one point when it has one).
pub(super) fn needs(leg: &[[f64; 2]], need: &dyn Fn([f64; 2], [f64; 2]) -> f64) -> Vec<f64> {
    match leg.len() {
        1 => vec![need(leg[0], leg[0])],
        _ => leg.windows(2).map(|w| need(w[0], w[1])).collect(),
    }
}

/// Samples of the quarter ellipse that eases a turn between the route and
/// a vertical move, from the route's end.
pub(super) const EASE_SAMPLES: usize = 16;

/// Longest horizontal span of an eased turn, in drops (`high − low`).
pub(super) const MAX_EASE_SPAN: f64 = 5.0;

/// Rises of the reach from the base (metres) smaller than this do not
/// end a stretch on which it falls toward the target.
pub(super) const REACH_NOISE: f64 = 1e-4;

/// The leg's points (pixels) with their heights (metres above the table):
/// at `high` = `heights[1]`, except that over the stretch nearest the
/// target (the leg's end when `at_end`, else its start) the height follows
/// a quarter ellipse down to `low` = `heights[0]` at the target, arriving
/// vertically. Its horizontal span is the drop `high − low`, or, where
/// the tool's reach from the robot base (`base_of`: pixels to base-frame
/// metres) falls toward the target, the leg's whole last stretch on which
/// it falls, at most [`MAX_EASE_SPAN`] drops (the whole leg when shorter):
/// the height then falls while the reach does, so a joint that the falling
/// reach moves against the descent (the iiwa's shoulder on a leg passing
/// the base tangentially into the target) is carried past that turn by
/// the descent instead of turning at the foot of it and again on the
/// vertical line. A reach that rises into the target moves such joints
/// the descent's way already.
/// The ellipse is used only when no segment of that stretch needs more
/// than `low` (`need`, metres): everything on it is at least as high as
/// its need; when the long stretch is not clear, the drop's length is
/// tried. The stretch is resampled so the curve has `EASE_SAMPLES` points.
pub(super) fn eased(
    leg: &[[f64; 2]],
    metres: [f64; 2],
    need: &dyn Fn([f64; 2], [f64; 2]) -> f64,
    base_of: &dyn Fn([f64; 2]) -> [f64; 2],
    [low, high]: [f64; 2],
    at_end: bool,
) -> Vec<([f64; 2], f64)> {
    let mut points: Vec<[f64; 2]> = leg.to_vec();
    if at_end {
        points.reverse();
    }
    // Arc length from the target (the first point now), metres.
    let mut s = vec![0.0; points.len()];
    for i in 1..points.len() {
        s[i] = s[i - 1] + planar_distance(points[i - 1], points[i], metres);
    }
    let length = s.last().copied().unwrap_or(0.0);
    let drop = high - low;
    let falling = falling_stretch(&points, &s, base_of);
    let needs = needs(&points, need);
    let clear = |reach: f64| {
        needs
            .iter()
            .zip(&s)
            .all(|(n, &from)| from >= reach || *n <= low)
    };
    let reach = [falling.clamp(drop, MAX_EASE_SPAN * drop), drop]
        .map(|r| r.min(length))
        .into_iter()
        .find(|&r| r > 1e-6 && clear(r));
    let mut out: Vec<([f64; 2], f64)> = match reach {
        Some(reach) if high > low => {
            let at = |d: f64| {
                let k = s.partition_point(|&x| x < d).clamp(1, points.len() - 1);
                let t = ((d - s[k - 1]) / (s[k] - s[k - 1]).max(1e-12)).clamp(0.0, 1.0);
                [0, 1].map(|c| points[k - 1][c] + t * (points[k][c] - points[k - 1][c]))
            };
            let curve = (0..=EASE_SAMPLES).map(|i| {
                let phi = i as f64 / EASE_SAMPLES as f64 * std::f64::consts::FRAC_PI_2;
                (at(reach * (1.0 - phi.cos())), low + drop * phi.sin())
            });
            let rest = points
                .iter()
                .zip(&s)
                .filter(|&(_, &d)| d > reach + 1e-9)
                .map(|(&p, _)| (p, high));
            curve.chain(rest).collect()
        }
        _ => points.iter().map(|&p| (p, high)).collect(),
    };
    if at_end {
        out.reverse();
    }
    out
}

/// Arc length (metres, `s`) from the first point (the target) over which
/// the reach from the base (the norm of `base_of`, pixels to base-frame
/// metres, an affine map) grows, i.e. falls toward the target; rises of at
/// most [`REACH_NOISE`] are ignored. On a straight segment the reach is
/// least at the foot of the perpendicular from the base, the one place
/// inside it where the reach can turn.
pub(super) fn falling_stretch(
    points: &[[f64; 2]],
    s: &[f64],
    base_of: &dyn Fn([f64; 2]) -> [f64; 2],
) -> f64 {
    let reach = |p: [f64; 2]| {
        let [x, y] = base_of(p);
        x.hypot(y)
    };
    let mut samples = points
        .first()
        .map(|&p| (0.0, reach(p)))
        .into_iter()
        .collect::<Vec<_>>();
    for k in 1..points.len() {
        let (a, b) = (base_of(points[k - 1]), base_of(points[k]));
        let d = [b[0] - a[0], b[1] - a[1]];
        let t = -(a[0] * d[0] + a[1] * d[1]) / (d[0] * d[0] + d[1] * d[1]).max(1e-18);
        if t > 0.0 && t < 1.0 {
            let foot = [a[0] + t * d[0], a[1] + t * d[1]];
            samples.push((s[k - 1] + t * (s[k] - s[k - 1]), foot[0].hypot(foot[1])));
        }
        samples.push((s[k], reach(points[k])));
    }
    let Some(&(_, first)) = samples.first() else {
        return 0.0;
    };
    let (mut extreme, mut at) = (first, 0.0);
    for &(from, r) in &samples[1..] {
        let change = r - extreme;
        if change.abs() <= REACH_NOISE {
            continue;
        }
        if change < 0.0 {
            return at;
        }
        (extreme, at) = (r, from);
    }
    s.last().copied().unwrap_or(0.0)
}

/// Horizontal distance (metres) between two pixels, `metres` per pixel
/// along u and v.
pub(super) fn planar_distance(a: [f64; 2], b: [f64; 2], [mu, mv]: [f64; 2]) -> f64 {
    ((b[0] - a[0]) * mu).hypot((b[1] - a[1]) * mv)
}
