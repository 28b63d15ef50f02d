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

/// A self-collision check at the Care-O-bot's home measures only the link
/// pairs whose bounding spheres come within 5 cm; the rest are bounded by
/// their spheres' distance, and the verdict (free) is unchanged.
#[test]
fn far_apart_links_are_bounded_by_their_spheres_not_measured_exactly() {
    use afford_collision::{PathOptions, RobotGeometry, Scene, SceneSpec};
    let m = afford_kinematics::RobotModel::builtin("care_o_bot4").unwrap();
    let g = RobotGeometry::new(&m).unwrap();
    let scene = Scene::from_spec(&SceneSpec {
        table_z: 0.0,
        table: None,
        boxes: vec![],
    })
    .unwrap();
    let v = g
        .check_joint_path(&scene, &[m.home().to_vec()], &PathOptions::default())
        .unwrap();
    assert!(v.is_free(), "{:?}", v.collisions);
    assert!(
        v.stats.pair_queries * 2 < v.stats.aabb_tests,
        "measured {} of {} pairs",
        v.stats.pair_queries,
        v.stats.aabb_tests
    );
}

/// A yes-or-no check (`describe: false`) finds the same first hit as the
/// full report, without scanning it for its deepest point.
#[test]
fn a_verdict_only_check_finds_the_same_first_hit_with_fewer_queries() {
    for name in [
        "cob-self-collision-arm-into-torso",
        "cob-self-collision-left-arm-into-torso",
    ] {
        let file = fixture(name);
        let fx = load_fixture(&file).unwrap();
        let (g, scene, opts) = fx.prepare(&file).unwrap();
        let full = fx.check(&g, &scene, &opts, &file).unwrap();
        let mut quick = opts.clone();
        quick.settings.describe = false;
        let verdict = fx.check(&g, &scene, &quick, &file).unwrap();
        let (a, b) = (full.first().unwrap(), verdict.first().unwrap());
        assert_eq!(
            (&a.body, &a.other, a.first_t),
            (&b.body, &b.other, b.first_t),
            "{name}"
        );
        assert!(
            verdict.stats.pair_queries < full.stats.pair_queries,
            "{name}: {} vs {}",
            verdict.stats.pair_queries,
            full.stats.pair_queries
        );
    }
}
