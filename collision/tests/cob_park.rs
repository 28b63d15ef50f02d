//! The Care-O-bot 4's park posture (robots/care_o_bot4.yaml) is free of
//! self-collision for both arms: with the other arm parked (and the working
//! arm at home) at the upright torso, and over the whole torso range.

use afford_collision::{CheckSettings, PathOptions, RobotGeometry, Scene, SceneSpec};
use afford_kinematics::RobotModel;

fn self_hits(g: &RobotGeometry, q: &[f64]) -> Vec<String> {
    let scene = Scene::from_spec(&SceneSpec {
        table_z: 0.0,
        table: None,
        boxes: vec![],
    })
    .unwrap();
    let opts = PathOptions {
        settings: CheckSettings {
            max_reports: 20,
            ..CheckSettings::default()
        },
        ..PathOptions::default()
    };
    g.check_joint_path(&scene, &[q.to_vec()], &opts)
        .unwrap()
        .collisions
        .iter()
        .map(|c| c.to_string())
        .collect()
}

#[test]
fn care_o_bot4_parked_arm_is_self_collision_free() {
    let m = RobotModel::builtin("care_o_bot4").unwrap();
    let g = RobotGeometry::new(&m).unwrap();
    assert!(self_hits(&g, m.home()).is_empty(), "home collides");
    let (t2, t3) = (
        m.joint_index("torso_2_joint").unwrap(),
        m.joint_index("torso_3_joint").unwrap(),
    );
    for active in ["right", "left"] {
        let parked = m.parked_except(m.home(), active);
        let hits = self_hits(&g, &parked);
        assert!(hits.is_empty(), "parked_except(home, {active}): {hits:?}");
        // Both arms parked, torso anywhere in its range (the working arm moves
        // the shared torso, and with it the parked arm, past the base).
        let both = m.parked_except(&parked, "none");
        for i in 0..=10 {
            for k in 0..=16 {
                let mut q = both.clone();
                q[t2] = -1.0 + 0.2 * i as f64;
                q[t3] = -1.6 + 0.2 * k as f64;
                let hits = self_hits(&g, &q);
                assert!(
                    hits.is_empty(),
                    "parked, torso ({:.1}, {:.1}): {hits:?}",
                    q[t2],
                    q[t3]
                );
            }
        }
    }
}
