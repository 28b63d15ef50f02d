//! The refusals' messages and JSON, one test per kind of message.

use super::*;
use crate::timing::LimitViolation;

fn json(r: &Refusal) -> serde_json::Value {
    let v = serde_json::to_value(r.explained()).unwrap();
    assert_eq!(v["kind"], r.kind());
    assert_eq!(v["message"], r.to_string());
    v
}

fn collision(kind: HitKind, margin_violation: f64) -> Refusal {
    Refusal::Collides {
        arm: "arm".into(),
        body: "iiwa_link_7".into(),
        other: "red-square-1".into(),
        hit: kind,
        place: HitPlace::Waypoint {
            phase: Phase::Carry,
            waypoint: 3,
        },
        clearance_m: 0.006,
        penetration_m: 0.0,
        margin_m: 0.01,
        depth_m: margin_violation.max(0.0),
    }
}

#[test]
fn refusal_collides_says_waypoint_what_hit_what_and_how_deep() {
    let r = collision(HitKind::Perimeter, 0.004);
    let v = json(&r);
    assert_eq!(v["place"]["during"], "waypoint");
    assert_eq!(v["place"]["waypoint"], 3);
    assert_eq!(
        r.to_string(),
        "the motion of the arm 'arm' collides at carry waypoint 3: iiwa_link_7 comes 4.0 mm \
         inside the 10.0 mm safety perimeter of red-square-1 (6.0 mm from it)"
    );
}

#[test]
fn refusal_collides_never_violated_by_a_negative_amount() {
    let r = collision(HitKind::Perimeter, -0.0001);
    let message = r.to_string();
    assert!(
        !message.contains("violated") && !message.contains("-0"),
        "{message}"
    );
    assert!(
        message.contains("reaches the 10.0 mm safety perimeter"),
        "{message}"
    );
}

#[test]
fn refusal_collides_on_the_trajectory_says_seconds() {
    let Refusal::Collides { place, .. } = &mut collision(HitKind::Contact, 0.01) else {
        unreachable!()
    };
    *place = HitPlace::Trajectory { time_s: 1.25 };
    assert_eq!(place.to_string(), "1.250 s into the timed trajectory");
    assert_eq!(
        HitPlace::ReturningToPark.to_string(),
        "returning to the park posture"
    );
}

#[test]
fn refusal_joint_limit_when_every_arm_fails_on_a_limit() {
    let failure = |arm: &str, cause| ArmFailure {
        arm: arm.into(),
        waypoint: 4,
        phase: Some(Phase::Grasp),
        cause,
    };
    let limit = IkFailure::JointLimit {
        joint: "joint_a4".into(),
    };
    let r = Refusal::unreachable(vec![failure("left", limit.clone())]);
    let v = json(&r);
    assert_eq!(v["kind"], "joint_limit");
    assert_eq!(v["arms"][0]["arm"], "left");
    assert_eq!(v["arms"][0]["phase"], "grasp");
    assert_eq!(v["arms"][0]["cause"]["kind"], "joint_limit");
    assert_eq!(v["arms"][0]["cause"]["joint"], "joint_a4");
    assert_eq!(
        r.to_string(),
        "grasp waypoint 4 is out of reach of the arm 'left': target needs joint 'joint_a4' beyond its limit"
    );
    let far = IkFailure::OutOfReach {
        position_error: 0.2,
    };
    let r = Refusal::unreachable(vec![failure("left", limit), failure("right", far)]);
    assert_eq!(r.kind(), "unreachable");
}

#[test]
fn refusal_timing_solver_and_timing_limit() {
    let solver = Refusal::from_timing(
        &TimingStatus::SolverStopped {
            outcome: SolverOutcome::Infeasible,
        },
        &[],
    );
    assert_eq!(json(&solver)["outcome"], "infeasible");
    let names = vec!["a1".to_string(), "a2".to_string()];
    let violation = LimitViolation {
        kind: LimitKind::Velocity,
        sample: 12,
        joint: 1,
        value: -1.6,
        limit: 1.5,
    };
    let limit = Refusal::from_timing(&TimingStatus::LimitViolated { violation }, &names);
    let v = json(&limit);
    assert_eq!(v["kind"], "timing_limit");
    assert_eq!(v["joint"], "a2");
    assert!(
        limit
            .to_string()
            .contains("joint velocity limit of joint 'a2'")
    );
}

#[test]
fn refusal_too_slow_and_inside_protective_distance_from_timing_errors() {
    let slow = Refusal::from(TimingError::TooManySamples {
        duration_s: 120.0,
        rate_hz: 125.0,
        samples: 15000.0,
    });
    assert_eq!(json(&slow)["duration_s"], 120.0);
    let near = Refusal::from(TimingError::InsideProtectiveDistance {
        s: 0.3,
        distance_m: 0.1,
        required_m: 0.2,
    });
    assert_eq!(json(&near)["kind"], "inside_protective_distance");
    let other = Refusal::from(TimingError::NoWaypoints);
    assert_eq!(json(&other)["stage"], "timing");
}

#[test]
fn refusal_no_route_after_replanning_counts_the_blocked_cells() {
    let r = Refusal::NoRoute {
        object: "x".into(),
        goal: "left box".into(),
        blocked_cells: 3,
    };
    assert_eq!(json(&r)["blocked_cells"], 3);
    assert!(r.to_string().contains("the 3 cells"));
}

#[test]
fn refusal_no_transit_names_each_arm_where_and_why() {
    let r = Refusal::NoTransit {
        arms: vec![TransitFailure {
            arm: "left".into(),
            place: HitPlace::ReturningToPark,
            reason: "budget ran out".into(),
        }],
    };
    let v = json(&r);
    assert_eq!(v["kind"], "no_transit");
    assert_eq!(v["arms"][0]["arm"], "left");
    assert_eq!(v["arms"][0]["place"]["during"], "returning_to_park");
    assert_eq!(
        r.to_string(),
        "no collision-free transit: arm 'left' returning to the park posture: budget ran out"
    );
}

#[test]
fn refusal_kinds_list_every_variant_kind() {
    let samples = [
        Refusal::NoTransit { arms: Vec::new() },
        Refusal::HandCoversGripper,
        Refusal::LearnerBudget { training_steps: 1 },
        Refusal::internal("IK", "x"),
        collision(HitKind::Contact, 0.0),
    ];
    for r in samples {
        assert!(Refusal::KINDS.contains(&r.kind()));
    }
}
