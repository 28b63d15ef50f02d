//! Where a released piece rests: the lattice, the packing look-ahead, the outlines and the goal's capacity.

use super::*;
use crate::scenario::{PixelBox, default_scenario};

/// The default scene (0.025 m squares, 0.03 m tall, in a 0.10 m box)
/// with the left box (index 0) at `bbox`.
fn scene(bbox: [f64; 4]) -> Scenario {
    let mut s = default_scenario().unwrap();
    s.goals[0].bbox = PixelBox::from(bbox);
    s
}

fn put(s: &mut Scenario, object: usize, at: [f64; 2]) {
    s.objects[object].bbox = s.objects[object].bbox.centred_at(at);
}

/// Gap (m) between the plain footprints of objects `a` and `b`.
fn footprint_gap(s: &Scenario, a: usize, b: usize) -> f64 {
    let outline = Outline::of(s, &s.objects[a]);
    gap(s, &outline, s.objects[a].bbox.centre(), b)
}

/// Releases `object` into the left box and leaves it where it lands.
fn release(s: &mut Scenario, object: usize, opening: Option<[f64; 2]>) -> Release {
    let r = release_spot(
        s,
        object,
        0,
        Room {
            opening,
            later: &[],
        },
        |_| true,
    )
    .unwrap();
    put(s, object, r.spot);
    r
}

#[test]
fn release_spots_fill_rows_from_one_corner_inside_the_inner_walls() {
    let mut s = scene([20.0, 300.0, 160.0, 160.0]);
    let [mu, mv] = s.metres_per_pixel();
    let first = release(&mut s, 0, Some([0.0, 0.04])).spot;
    // Top-left corner: wall + clearance + half the object from each side.
    assert!((first[0] - (20.0 + (GOAL_WALL + WALL_CLEARANCE) / mu + 20.0)).abs() < 1e-9);
    assert!((first[1] - (300.0 + (GOAL_WALL + WALL_CLEARANCE) / mv + 20.0)).abs() < 1e-9);
    let second = release(&mut s, 1, Some([0.0, 0.04])).spot;
    assert_eq!(second[1], first[1], "same row");
    assert!(footprint_gap(&s, 1, 0) >= WALL_CLEARANCE);
}

/// A 75 mm box holds four 25 mm squares (two by two, 5 mm apart and
/// from the walls' clearance); the certificate passes four and
/// refuses the fifth, which the packing indeed finds no spot for.
#[test]
fn over_capacity_certifies_the_fifth_square_the_box_cannot_hold() {
    let mut s = scene([20.0, 300.0, 120.0, 120.0]);
    assert!(!over_capacity(&s, 0, &[0, 1, 2, 3]));
    assert!(over_capacity(&s, 0, &[0, 1, 2, 3, 4]));
    for object in 0..4 {
        release(&mut s, object, None);
    }
    assert_eq!(
        release_spot(&s, 4, 0, Room::default(), |_| true),
        Err(NoSpot::Full)
    );
    assert!(over_capacity(&s, 0, &[4]), "the resting four count");
}

#[test]
fn full_goal_and_too_large_object_have_their_reasons() {
    let mut s = scene([20.0, 300.0, 80.0, 80.0]);
    put(&mut s, 0, [60.0, 340.0]);
    assert_eq!(
        release_spot(&s, 1, 0, Room::default(), |_| true),
        Err(NoSpot::Full)
    );
    assert_eq!(
        NoSpot::Full.reason(&s, 1, 0).to_string(),
        "left box is full"
    );
    let small = scene([20.0, 300.0, 60.0, 60.0]);
    assert_eq!(
        release_spot(&small, 1, 0, Room::default(), |_| true),
        Err(NoSpot::TooLarge)
    );
    let roomy = scene([20.0, 300.0, 160.0, 160.0]);
    assert_eq!(
        release_spot(&roomy, 1, 0, Room::default(), |_| false),
        Err(NoSpot::Covered)
    );
}

/// The fingers' and palm's half-widths `gripper` lowered over a piece as
/// tall as the wall either keep its margin sideways or pass over it by
/// its margin: the piece packs next to it at the plain clearance and
/// the release floor rises to the piece's top plus its margin.
fn tall_neighbour_is_passed_over(gripper: [f64; 2]) {
    let mut s = scene([20.0, 300.0, 200.0, 200.0]);
    let first = release(&mut s, 0, Some(gripper));
    assert_eq!(first.floor, 0.0, "an empty box constrains nothing");
    s.objects[0].height = s.goals[0].height;
    let second = release(&mut s, 1, Some(gripper));
    let margin = s.safety.obstacle_margin;
    assert!((footprint_gap(&s, 1, 0) - WALL_CLEARANCE).abs() < 2e-3);
    let lowered = Outline::lowered(&s, 1, Some(gripper));
    let sideways = gap(&s, &lowered, second.spot, 0) >= margin + WALL_CLEARANCE;
    let over = second.floor >= s.objects[0].height + margin - 1e-12;
    assert!(sideways || over, "{second:?}");
    assert!(over, "the open fingers reach the neighbour sideways here");
}

#[test]
fn open_fingers_pass_over_a_neighbour_as_tall_as_the_wall() {
    tall_neighbour_is_passed_over([0.0, 0.04]);
}

#[test]
fn a_palm_wider_than_the_object_passes_over_a_tall_neighbour() {
    // A palm reaching 0.064 m to either side along the object (the
    // Care-O-bot's palm capsule), 0.04 m across.
    tall_neighbour_is_passed_over([0.064, 0.04]);
}

#[test]
fn goal_full_does_not_count_the_open_fingers_span_against_tall_pieces() {
    // Pieces as tall as the wall in a 0.10 m box: each is packed by its
    // own footprint (a 0.025 m square: three a row with 5 mm gaps
    // inside 0.09 m), not by the open fingers' 0.08 m span.
    let mut s = scene([20.0, 300.0, 160.0, 160.0]);
    let [mu, _] = s.metres_per_pixel();
    let gripper = Some([0.02, 0.04]);
    let wall = s.goals[0].height;
    let mut placed = 0;
    for object in 0..s.objects.len() {
        if release_spot(
            &s,
            object,
            0,
            Room {
                opening: gripper,
                later: &[],
            },
            |_| true,
        )
        .is_err()
        {
            break;
        }
        release(&mut s, object, gripper);
        s.objects[object].height = wall;
        placed += 1;
    }
    let side = s.objects[0].bbox.w * mu;
    assert!(side <= 0.026, "{side}");
    assert!(placed >= s.objects.len().min(3), "{placed} placed");
}

/// Scene 265 of the transits bench (sizes in mm): a 49.0 x 53.6 square
/// and a 38.6 x 39.3 piece of `shape` for a 105.4 x 112.7 box, the
/// square already released into the box's first corner.
fn square_then(shape: &str) -> Scenario {
    let mut s = default_scenario().unwrap();
    let [mu, mv] = s.metres_per_pixel();
    let px = |w: f64, l: f64| [w / 1e3 / mu, l / 1e3 / mv];
    let [gw, gl] = px(105.4, 112.7);
    s.goals[0].bbox = PixelBox::from([20.0, 300.0, gw, gl]);
    let [w, l] = px(49.0, 53.6);
    s.objects[0].bbox = PixelBox::from([300.0, 60.0, w, l]);
    let [w, l] = px(38.6, 39.3);
    s.objects[1].bbox = PixelBox::from([400.0, 60.0, w, l]);
    s.objects[1].shape = shape.into();
    release(&mut s, 0, None);
    s
}

#[test]
fn round_piece_packs_into_the_corner_beside_a_square() {
    let mut s = square_then("circle");
    let spot = release(&mut s, 1, None).spot;
    let gap = footprint_gap(&s, 1, 0);
    assert!(gap >= WALL_CLEARANCE, "{gap}");
    // The boxes alone would not keep the clearance there: it is the
    // disc's room in the corner the square's box leaves.
    let [mu, mv] = s.metres_per_pixel();
    let (a, b) = (s.objects[0].bbox, s.objects[1].bbox);
    let apart = |d: f64, wa: f64, wb: f64, mpp: f64| (d.abs() - (wa + wb) / 2.0).max(0.0) * mpp;
    let du = apart(spot[0] - a.centre()[0], a.w, b.w, mu);
    let dv = apart(spot[1] - a.centre()[1], a.l, b.l, mv);
    assert!(du.hypot(dv) < WALL_CLEARANCE, "{du} {dv}");
    // A square of the same box finds no spot.
    let square = square_then("square");
    assert_eq!(
        release_spot(&square, 1, 0, Room::default(), |_| true),
        Err(NoSpot::Full)
    );
}

/// Scene 195 of the transits bench (sizes in mm): circles of 27.7 x
/// 29.7, 31.6 x 32.2 and 44.5 x 46.2 for a box of 91.4 x 86.1 inside
/// its walls, released in that order.
fn three_circles() -> Scenario {
    let mut s = default_scenario().unwrap();
    let [mu, mv] = s.metres_per_pixel();
    let px = |w: f64, l: f64| [w / 1e3 / mu, l / 1e3 / mv];
    let wall = 2e3 * GOAL_WALL;
    let [gw, gl] = px(91.4 + wall, 86.1 + wall);
    s.goals[0].bbox = PixelBox::from([20.0, 300.0, gw, gl]);
    for (i, (w, l)) in [(27.7, 29.7), (31.6, 32.2), (44.5, 46.2)]
        .into_iter()
        .enumerate()
    {
        let [w, l] = px(w, l);
        s.objects[i].bbox = PixelBox::from([300.0 + 100.0 * i as f64, 60.0, w, l]);
        s.objects[i].shape = "circle".into();
    }
    s
}

/// Releases `object` into the left box leaving room for `later`.
fn release_before(s: &mut Scenario, object: usize, later: &[usize]) -> Release {
    let room = Room {
        opening: None,
        later,
    };
    let r = release_spot(s, object, 0, room, |_| true).unwrap();
    put(s, object, r.spot);
    r
}

#[test]
fn chained_round_pieces_leave_room_for_the_later_ones() {
    // Bottom-left fill alone puts the second circle beside the first:
    // the third finds no spot.
    let mut plain = three_circles();
    release(&mut plain, 0, None);
    release(&mut plain, 1, None);
    let third = release_spot(&plain, 2, 0, Room::default(), |_| true);
    assert_eq!(third, Err(NoSpot::Full));
    // Looking ahead, the first keeps its corner (after it the others
    // fit), the second leaves room for the third, and all three rest
    // apart by the clearance.
    let mut s = three_circles();
    assert_eq!(
        release_before(&mut s, 0, &[1, 2]).spot,
        s.objects[0].bbox.centre()
    );
    let first = plain.objects[0].bbox.centre();
    assert_eq!(
        s.objects[0].bbox.centre(),
        first,
        "the first spot unchanged"
    );
    let second = release_before(&mut s, 1, &[2]).spot;
    assert_ne!(second, plain.objects[1].bbox.centre());
    release_before(&mut s, 2, &[]);
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let gap = footprint_gap(&s, a, b);
        assert!(gap >= WALL_CLEARANCE, "{a} {b}: {gap}");
    }
}

#[test]
fn lookahead_without_room_for_the_later_pieces_keeps_the_first_free_spot() {
    // The large circle twice: never both with the others.
    let mut s = three_circles();
    s.objects[3].bbox = s.objects[2].bbox.centred_at([600.0, 60.0]);
    s.objects[3].shape = "circle".into();
    let plain = release_spot(&s, 0, 0, Room::default(), |_| true).unwrap();
    let room = Room {
        opening: None,
        later: &[2, 3],
    };
    assert_eq!(release_spot(&s, 0, 0, room, |_| true), Ok(plain));
    // The object itself, pieces already in the goal and unknown indices
    // are not looked ahead to.
    put(&mut s, 2, plain.spot);
    let room = Room {
        opening: None,
        later: &[1, 1, 2, 99],
    };
    let with = release_spot(&s, 1, 0, room, |_| true).unwrap();
    let without = release_spot(&s, 1, 0, Room::default(), |_| true).unwrap();
    assert_eq!(with, without);
}

#[test]
fn outline_gap_is_exact_for_boxes_discs_and_stadiums() {
    let s = default_scenario().unwrap();
    let [mu, mv] = s.metres_per_pixel();
    let at = |x: f64, y: f64| [x / mu, y / mv];
    let square = Outline {
        core: [0.02 / mu, 0.01 / mv],
        radius: 0.0,
    };
    let disc = Outline {
        core: [0.0, 0.0],
        radius: 0.015,
    };
    let stadium = Outline {
        core: [0.005 / mu, 0.0],
        radius: 0.015,
    };
    let o = at(0.0, 0.0);
    let cases = [
        // Box to box, side by side and past a corner.
        (square, at(0.1, 0.0), square, 0.06),
        (square, at(0.1, 0.05), square, 0.06f64.hypot(0.03)),
        // Disc to box: beside a side, past a corner.
        (disc, at(0.05, 0.0), square, 0.015),
        (disc, at(0.05, 0.04), square, 0.03f64.hypot(0.03) - 0.015),
        // Disc to disc, stadium to disc along the stadium's axis.
        (disc, at(0.03, 0.04), disc, 0.02),
        (stadium, at(0.1, 0.0), disc, 0.1 - 0.005 - 0.03),
        // Overlapping: 0.
        (disc, at(0.02, 0.0), square, 0.0),
    ];
    for (a, q, b, expected) in cases {
        let d = a.gap(&s, o, &b, q);
        assert!((d - expected).abs() < 1e-12, "{a:?} {b:?} at {q:?}: {d}");
        assert!((b.gap(&s, q, &a, o) - d).abs() < 1e-15, "symmetric");
    }
}

#[test]
fn a_round_piece_is_the_stadium_inside_its_box() {
    let mut s = default_scenario().unwrap();
    let [mu, mv] = s.metres_per_pixel();
    s.objects[0].bbox = PixelBox::from([100.0, 100.0, 0.04 / mu, 0.05 / mv]);
    for shape in ["circle", "Cylinder", "disc"] {
        s.objects[0].shape = shape.into();
        let o = Outline::of(&s, &s.objects[0]);
        assert!((o.radius - 0.02).abs() < 1e-12, "{shape}: {o:?}");
        assert!(o.core[0].abs() < 1e-9 && (o.core[1] * mv - 0.005).abs() < 1e-12);
    }
    s.objects[0].shape = "hexagon".into();
    let o = Outline::of(&s, &s.objects[0]);
    assert_eq!(o.radius, 0.0);
    assert!((o.core[0] * mu - 0.02).abs() < 1e-12 && (o.core[1] * mv - 0.025).abs() < 1e-12);
}
