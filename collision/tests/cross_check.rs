//! Brute-force cross-check: on 1,000 random joint paths in random scenes the
//! continuous check never calls a path free that dense sampling
//! (0.001 rad) finds colliding.

use afford_collision::cross_check;
use afford_kinematics::RobotModel;

#[test]
fn fast_check_never_misses_a_dense_collision() {
    let model = RobotModel::builtin("kuka_iiwa14").unwrap();
    let t = std::time::Instant::now();
    let cc = cross_check(&model, 1000, 42).unwrap();
    println!("{cc:?} in {:.1} s", t.elapsed().as_secs_f64());
    assert_eq!(cc.paths, 1000);
    assert!(
        cc.dense_collisions > 100,
        "too few colliding cases to mean anything"
    );
    assert!(cc.paths - cc.dense_collisions > 100, "too few free cases");
    assert_eq!(cc.missed, 0, "missed: {:?}", cc.missed_seeds);
}

#[test]
fn care_o_bot_cross_check() {
    let model = RobotModel::builtin("care_o_bot4").unwrap();
    // Random paths around home; the fast check must not miss dense hits.
    let cc = cross_check(&model, 100, 7).unwrap();
    println!("{cc:?}");
    assert_eq!(cc.missed, 0, "missed: {:?}", cc.missed_seeds);
}
