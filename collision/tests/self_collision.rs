//! Self-collision regressions: pairs a hand-written skip list called "cannot
//! meet" are checked now that the allowed-collision matrix comes from the
//! geometry (tests/collision/cob-self-collision-*.yaml, labelled by the
//! dense reference).

use std::path::PathBuf;

use afford_collision::{HitKind, load_fixture, run_fixture};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../tests/collision/{name}.yaml"))
}

/// The first hit of a fixture: (body, other, penetration in m).
fn first_self_hit(name: &str) -> (String, String, f64) {
    let o = run_fixture(&fixture(name)).unwrap();
    assert!(o.passed, "{}", o.summary);
    let c = o.verdict.first().expect("a hit");
    assert_eq!(c.kind, HitKind::SelfCollision, "{}", o.summary);
    (c.body.clone(), c.other.clone(), c.penetration)
}

#[test]
fn self_collision_cob_arm_into_torso_is_checked() {
    for (name, arm) in [
        ("cob-self-collision-arm-into-torso", "arm_right_3_link"),
        ("cob-self-collision-left-arm-into-torso", "arm_left_3_link"),
    ] {
        let (a, b, depth) = first_self_hit(name);
        let pair = [a.split('#').next().unwrap(), b.split('#').next().unwrap()];
        assert!(
            pair.contains(&"torso_3_link") && pair.contains(&arm),
            "{name}: {pair:?}"
        );
        assert!(depth > 0.02, "{name}: {arm} only {depth} m into the torso");
    }
}

#[test]
fn self_collision_cob_reach_stops_short_is_really_free() {
    // Once labelled free while arm_right_3_link was 28 mm inside the torso;
    // now the reach stops before any checked pair meets (dense reference).
    let f = fixture("cob-arms-reach-stops-short");
    let fx = load_fixture(&f).unwrap();
    assert_eq!(fx.expect.verdict, afford_collision::Verdict::Free);
    let o = run_fixture(&f).unwrap();
    assert!(o.passed && o.verdict.is_free(), "{}", o.summary);
}
