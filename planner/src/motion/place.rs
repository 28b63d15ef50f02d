//! Where a released object comes to rest in its goal box: a small packing
//! of the box floor, so each piece lies wholly inside the box's inner walls
//! and apart from the pieces already there, and how high it is released.
//!
//! Candidate centres lie on a lattice over the inner rectangle (the goal's
//! pixel box minus the walls, [`afford_collision::GOAL_WALL`], minus
//! [`WALL_CLEARANCE`]) that keeps the whole object footprint inside: steps of
//! [`LATTICE_STEP`] or coarser, at most [`LATTICE_POINTS`] a side (bounded
//! work for any box). They are tried row by row (increasing v, then
//! increasing u), the bottom-left-fill order that packs equal pieces in
//! rows from one corner. A candidate is free when the object's footprint
//! keeps [`WALL_CLEARANCE`] from every piece already in the box.
//!
//! Lookahead ([`Room::later`]): the chain's later pieces for the same box
//! are packed after this one, each by the same rule, so bottom-left fill
//! may put a piece where a later one no longer fits (three round pieces
//! that fit only as two in opposite corners of one side and the third
//! between them). The spot is the first free one (in the fill order, among
//! those the gripper may reach) after which the later pieces still each
//! find a free spot in turn: a depth-first search over their lattices in
//! fill order, each later piece at its first spot from which the rest fit.
//! When no spot leaves room for all of them, the first n that fit (n as
//! large as any spot allows) decide; when none fits, or after
//! [`LOOKAHEAD_GAPS`] footprint distances, the spot is the first free one.
//! Where bottom-left fill leaves room for the later pieces, its spot is
//! kept, so such plans are unchanged; the later call for the next piece
//! finds a spot again (the search's own one, or an earlier one from which
//! the rest fit). Later pieces are tested by their footprints alone (where
//! the gripper may go is their own grid's test).
//!
//! Footprints ([`Outline`]): a piece is its pixel box, or, when round
//! ([`is_round`]), the stadium inside that box — the disc of its narrower
//! side swept along the longer (a disc for a square box), as the collision
//! scene builds it ([`afford_collision::round_parts`]). Both are a
//! rectangle grown by a radius (0 for a box), so the distance between two
//! footprints is the distance between their rectangles minus both radii:
//! exact for box to box, disc to box and disc to disc. A round piece thus
//! packs into the corner a square's box leaves, keeping the clearance from
//! the square's corner.
//!
//! Release height ([`Release::floor`]): the object is released above the
//! wall top, and nothing lowered over the spot reaches below the object's
//! bottom (the fingertips stay above it). Where what is lowered — the
//! object's footprint widened across the grasp axis to the open fingers'
//! span — comes within a piece's safety margin (plus [`WALL_CLEARANCE`])
//! sideways, the release floor rises to that piece's top plus its margin,
//! so the fingers pass over it vertically as the collision check asks.
//! Packing by the object's own footprint and raising the release only where
//! needed fits more pieces than keeping the open fingers' span clear of
//! every tall piece, and keeps drops low elsewhere. Sizes are metres from
//! pixel sizes through `metres_per_pixel`.

use afford_collision::GOAL_WALL;

use crate::error::Refusal;
use crate::geometry::object_margin;
use crate::scenario::{Object, PixelBox, Scenario};

/// Shapes whose outline seen from above is round.
pub const ROUND_SHAPES: [&str; 3] = ["circle", "cylinder", "disc"];

/// Whether `o`'s outline is round (its shape is one of [`ROUND_SHAPES`]).
pub fn is_round(o: &Object) -> bool {
    ROUND_SHAPES
        .iter()
        .any(|s| s.eq_ignore_ascii_case(&o.shape))
}

/// Gap kept between the released footprint and the inner walls, and added
/// to the earlier pieces' margins, m.
pub const WALL_CLEARANCE: f64 = 0.005;
/// Finest lattice step, m.
pub const LATTICE_STEP: f64 = 0.002;
/// Most lattice points along each axis.
pub const LATTICE_POINTS: usize = 64;

/// Why no spot is left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoSpot {
    /// The object's footprint is larger than the inner rectangle.
    TooLarge,
    /// Every spot overlaps a piece already in the box (or its margin).
    Full,
    /// The free spots all lie where the gripper may not go (a hand's or
    /// another obstacle's perimeter).
    Covered,
}

impl NoSpot {
    /// The typed refusal (its `Display` is the message).
    pub fn reason(self, s: &Scenario, object: usize, goal: usize) -> Refusal {
        let (o, g) = (&s.objects[object], &s.goals[goal]);
        let [mu, mv] = s.metres_per_pixel();
        match self {
            Self::TooLarge => Refusal::DoesNotFitGoal {
                object: o.name.clone(),
                goal: g.name.clone(),
                object_m: [o.bbox.w * mu, o.bbox.l * mv],
                inner_m: [
                    g.bbox.w * mu - 2.0 * GOAL_WALL,
                    g.bbox.l * mv - 2.0 * GOAL_WALL,
                ],
                clearance_m: WALL_CLEARANCE,
            },
            Self::Full => Refusal::GoalFull {
                goal: g.name.clone(),
            },
            Self::Covered => Refusal::PerimetersCoverGoal {
                goal: g.name.clone(),
            },
        }
    }
}

/// A release: where the object comes to rest and how high it is let go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Release {
    /// Pixel (u, v) of the object's resting centre.
    pub spot: [f64; 2],
    /// Lowest height above the table top (m) of the object's bottom while
    /// the gripper is over the spot, set by the pieces already in the goal
    /// (see the module doc); 0 when none constrains it (the wall top
    /// always does, see [`crate::lift`]).
    pub floor: f64,
}

/// What a release spot leaves room for besides the object itself.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Room<'a> {
    /// The half-widths of what is lowered around the object (the grasp
    /// region's colliders, at least the open fingers; m, `[along the
    /// object's longer side, across it]`), `None` when unknown.
    pub opening: Option<[f64; 2]>,
    /// Objects (indices) the chain releases into the same goal later, in
    /// order: the spot is the first after which they still fit (see the
    /// module doc). Those already in the goal, the object itself and those
    /// past the first [`LOOKAHEAD_PIECES`] are not looked at.
    pub later: &'a [usize],
}

/// Where `scenario.objects[object]` is released into
/// `scenario.goals[goal]`: the first free lattice spot that `allowed`
/// accepts (the grid's test that the gripper may go there) after which the
/// most of `room.later` still fit, and its release floor under
/// `room.opening`.
pub fn release_spot(
    s: &Scenario,
    object: usize,
    goal: usize,
    room: Room,
    allowed: impl Fn([f64; 2]) -> bool,
) -> Result<Release, NoSpot> {
    let spots = lattice(s, object, goal).ok_or(NoSpot::TooLarge)?;
    let held = Outline::of(s, &s.objects[object]);
    let lowered = Outline::lowered(s, object, room.opening);
    let pieces: Vec<usize> = (0..s.objects.len())
        .filter(|&j| j != object && s.goal_holding(&s.objects[j]) == Some(goal))
        .collect();
    let resting: Vec<Resting> = pieces
        .iter()
        .map(|&j| Resting::of(s, &s.objects[j]))
        .collect();
    let mpp = s.metres_per_pixel();
    let free: Vec<[f64; 2]> = spots
        .into_iter()
        .filter(|&p| held.keeps_clear(mpp, p, &resting))
        .collect();
    if free.is_empty() {
        return Err(NoSpot::Full);
    }
    let open = || free.iter().copied().filter(|&p| allowed(p));
    let first = open().next().ok_or(NoSpot::Covered)?;
    let later: Vec<usize> = room
        .later
        .iter()
        .copied()
        .filter(|&j| j != object && j < s.objects.len() && !pieces.contains(&j))
        .take(LOOKAHEAD_PIECES)
        .collect();
    let mut lookahead = Lookahead::new(s, goal, &later);
    let placed = |p: [f64; 2]| {
        let bbox = s.objects[object].bbox.centred_at(p);
        let mut placed = resting.clone();
        placed.push(Resting {
            outline: held,
            centre: bbox.centre(),
        });
        placed
    };
    let spot = lookahead
        .first_leaving_room(open(), placed)
        .unwrap_or(first);
    let floor = pieces
        .iter()
        .map(|&j| (j, object_margin(s, &s.objects[j])))
        .filter(|&(j, margin)| gap(s, &lowered, spot, j) < margin + WALL_CLEARANCE)
        .map(|(j, margin)| s.top_above_table(&s.objects[j]) + margin)
        .fold(0.0, f64::max);
    Ok(Release { spot, floor })
}

/// Most later pieces a release looks ahead to ([`Room::later`]).
pub const LOOKAHEAD_PIECES: usize = 8;
/// Most footprint distances the lookahead computes for one release: when
/// they run out, the spot is the first free one, as without lookahead.
pub const LOOKAHEAD_GAPS: usize = 1 << 20;

/// The candidate centres (pixels) of `scenario.objects[object]` in
/// `scenario.goals[goal]`, in fill order (see the module doc); `None` when
/// its footprint is larger than the inner rectangle. At most
/// [`LATTICE_POINTS`] squared.
fn lattice(s: &Scenario, object: usize, goal: usize) -> Option<Vec<[f64; 2]>> {
    let [mu, mv] = s.metres_per_pixel();
    let held = s.objects[object].bbox;
    let g = s.goals[goal].bbox;
    let inset = [
        (GOAL_WALL + WALL_CLEARANCE) / mu + held.w / 2.0,
        (GOAL_WALL + WALL_CLEARANCE) / mv + held.l / 2.0,
    ];
    let lo = [g.u + inset[0], g.v + inset[1]];
    let hi = [g.u + g.w - inset[0], g.v + g.l - inset[1]];
    if lo[0] > hi[0] || lo[1] > hi[1] {
        return None;
    }
    let axis = |k: usize, mpp: f64| {
        let span = hi[k] - lo[k];
        let n = ((span * mpp / LATTICE_STEP).floor() as usize + 1).min(LATTICE_POINTS);
        (0..n)
            .map(move |i| match n {
                1 => lo[k] + span / 2.0,
                _ => lo[k] + span * i as f64 / (n - 1) as f64,
            })
            .collect::<Vec<f64>>()
    };
    let (us, vs) = (axis(0, mu), axis(1, mv));
    Some(
        vs.iter()
            .flat_map(|&v| us.iter().map(move |&u| [u, v]))
            .collect(),
    )
}

/// A footprint where it rests: its outline and its centre (px).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Resting {
    outline: Outline,
    centre: [f64; 2],
}

impl Resting {
    /// Object `o` where it lies.
    fn of(s: &Scenario, o: &Object) -> Self {
        Self {
            outline: Outline::of(s, o),
            centre: o.bbox.centre(),
        }
    }
}

/// The search for room for the later pieces: whether each, in turn, still
/// finds a free lattice spot (its first in fill order from which the rest
/// fit, depth first), within [`LOOKAHEAD_GAPS`] footprint distances.
struct Lookahead {
    /// Each later piece's footprint, box and candidate centres.
    pieces: Vec<(Outline, PixelBox, Vec<[f64; 2]>)>,
    mpp: [f64; 2],
    /// Footprint distances left to compute.
    budget: usize,
}

impl Lookahead {
    /// The later pieces `later` of goal `goal`, those that fit the goal at
    /// all (a larger one is refused on its own).
    fn new(s: &Scenario, goal: usize, later: &[usize]) -> Self {
        let pieces = later
            .iter()
            .filter_map(|&j| {
                let o = &s.objects[j];
                lattice(s, j, goal).map(|spots| (Outline::of(s, o), o.bbox, spots))
            })
            .collect();
        Self {
            pieces,
            mpp: s.metres_per_pixel(),
            budget: LOOKAHEAD_GAPS,
        }
    }

    /// The first of `candidates` (fill order) after which the most later
    /// pieces — the first n, n as large as any spot allows — still fit;
    /// `None` when none does or the budget ran out. `placed(p)`: the
    /// footprints in the goal once the object rests at `p`.
    fn first_leaving_room(
        &mut self,
        candidates: impl Iterator<Item = [f64; 2]> + Clone,
        placed: impl Fn([f64; 2]) -> Vec<Resting>,
    ) -> Option<[f64; 2]> {
        for n in (1..=self.pieces.len()).rev() {
            for p in candidates.clone() {
                if self.fit(&mut placed(p), 0, n)? {
                    return Some(p);
                }
            }
        }
        None
    }

    /// Whether the later pieces `depth..n` each find a spot in turn beside
    /// `placed` (the goal's pieces and the earlier later ones); `None` when
    /// the budget ran out.
    fn fit(&mut self, placed: &mut Vec<Resting>, depth: usize, n: usize) -> Option<bool> {
        if depth == n {
            return Some(true);
        }
        let (outline, bbox) = (self.pieces[depth].0, self.pieces[depth].1);
        for i in 0..self.pieces[depth].2.len() {
            let p = self.pieces[depth].2[i];
            self.budget = self.budget.checked_sub(placed.len().max(1))?;
            if !outline.keeps_clear(self.mpp, p, placed) {
                continue;
            }
            placed.push(Resting {
                outline,
                centre: bbox.centred_at(p).centre(),
            });
            let fits = self.fit(placed, depth + 1, n);
            placed.pop();
            if fits? {
                return Some(true);
            }
        }
        Some(false)
    }
}

/// A footprint on the table: the points within `radius` (m) of a rectangle
/// with half sizes `core` (px) along the image axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outline {
    pub core: [f64; 2],
    pub radius: f64,
}

impl Outline {
    /// The footprint of object `o` (see the module doc).
    pub fn of(s: &Scenario, o: &Object) -> Self {
        let [mu, mv] = s.metres_per_pixel();
        let b = o.bbox;
        let radius = match is_round(o) {
            true => (b.w * mu).min(b.l * mv) / 2.0,
            false => 0.0,
        };
        Self {
            core: [b.w / 2.0 - radius / mu, b.l / 2.0 - radius / mv],
            radius,
        }
    }

    /// What is lowered over the spot: the object's box (a round one's too:
    /// the fingers around it reach its box), widened to the gripper's
    /// half-widths `[along, across]` the grasp axis (m; the fingers close
    /// across its narrower side in metres).
    fn lowered(s: &Scenario, object: usize, opening: Option<[f64; 2]>) -> Self {
        let [mu, mv] = s.metres_per_pixel();
        let b = s.objects[object].bbox;
        let mut half = [b.w / 2.0, b.l / 2.0];
        if let Some([along, across]) = opening {
            let across_u = b.w * mu <= b.l * mv;
            let (gu, gv) = if across_u {
                (across, along)
            } else {
                (along, across)
            };
            half = [half[0].max(gu / mu), half[1].max(gv / mv)];
        }
        Self {
            core: half,
            radius: 0.0,
        }
    }

    /// Distance (m) between this footprint centred at `p` and `other`
    /// centred at `q` (pixels), 0 when they overlap.
    pub fn gap(&self, s: &Scenario, p: [f64; 2], other: &Self, q: [f64; 2]) -> f64 {
        self.gap_at(s.metres_per_pixel(), p, other, q)
    }

    /// [`Self::gap`] with the scene's metres per pixel `[mu, mv]`.
    fn gap_at(&self, [mu, mv]: [f64; 2], p: [f64; 2], other: &Self, q: [f64; 2]) -> f64 {
        let apart = |k: usize| (p[k] - q[k]).abs() - self.core[k] - other.core[k];
        let (du, dv) = (apart(0).max(0.0) * mu, apart(1).max(0.0) * mv);
        (du.hypot(dv) - self.radius - other.radius).max(0.0)
    }

    /// Whether this footprint centred at `p` keeps [`WALL_CLEARANCE`] from
    /// every one of `placed` (metres per pixel `mpp`).
    fn keeps_clear(&self, mpp: [f64; 2], p: [f64; 2], placed: &[Resting]) -> bool {
        placed
            .iter()
            .all(|r| self.gap_at(mpp, p, &r.outline, r.centre) >= WALL_CLEARANCE)
    }
}

/// Whether the pieces `arriving` (object indices) cannot all lie in
/// `scenario.goals[goal]` beside the pieces already resting there, under
/// this module's rules, wherever they are put: footprints [`WALL_CLEARANCE`]
/// apart and inside the inner walls less [`WALL_CLEARANCE`]. Grown by half
/// the clearance the footprints may not overlap and lie within that floor
/// grown the same, so their areas cannot add up to more than its area. A
/// certificate that a chain overfills the box (true: no planner can place
/// them all), not a packing (false does not mean they fit).
pub fn over_capacity(s: &Scenario, goal: usize, arriving: &[usize]) -> bool {
    let [mu, mv] = s.metres_per_pixel();
    let grow = WALL_CLEARANCE / 2.0;
    let g = s.goals[goal].bbox;
    let inset = 2.0 * (GOAL_WALL + WALL_CLEARANCE);
    let floor = (g.w * mu - inset + 2.0 * grow).max(0.0) * (g.l * mv - inset + 2.0 * grow).max(0.0);
    let resting = (0..s.objects.len()).filter(|&j| s.goal_holding(&s.objects[j]) == Some(goal));
    let pieces: Vec<usize> = resting.chain(arriving.iter().copied()).collect();
    let area: f64 = pieces
        .iter()
        .enumerate()
        .filter(|&(k, j)| !pieces[..k].contains(j))
        .map(|(_, &j)| {
            let o = Outline::of(s, &s.objects[j]);
            let (a, b, r) = (o.core[0] * mu, o.core[1] * mv, o.radius + grow);
            4.0 * a * b + 4.0 * r * (a + b) + std::f64::consts::PI * r * r
        })
        .sum();
    area > floor
}

/// Distance (m) between the footprint `outline` centred at `p` and piece
/// `j` where it lies (0 when they overlap).
fn gap(s: &Scenario, outline: &Outline, p: [f64; 2], j: usize) -> f64 {
    let o = &s.objects[j];
    outline.gap(s, p, &Outline::of(s, o), o.bbox.centre())
}

#[cfg(test)]
mod tests;
