//! The Care-O-bot 4's fixtures: an arm reaching across to the other one,
//! the torso's reach, and its mirror image for the left arm.

use afford_collision::*;
use afford_kinematics::RobotModel;

use super::*;

/// The Care-O-bot's fixtures.
pub fn fixtures(cob: &RobotModel, fx: &mut Vec<Fixture>) {
    // --- Care-O-bot 4 -----------------------------------------------------
    let ch = cob.home().to_vec();
    let r1 = cob.joint_index("arm_right_1_joint").unwrap();
    let cob_scene = SceneSpec {
        table_z: 0.75,
        table: Some(TableSpec {
            min: [0.4, -0.6],
            max: [1.2, 0.6],
            margin: 0.0,
        }),
        boxes: vec![],
    };
    let cob_air = SceneSpec {
        table_z: 0.0,
        table: None,
        boxes: vec![],
    };
    // The right gripper reaching over to where the left gripper is: arm
    // joints 1-4 moved from home by CROSS (found by an FK grid search for a
    // right-arm posture whose tool is within 0.12 m of the left tool).
    const CROSS: [f64; 4] = [0.4, -1.2, -0.8, 0.8];
    let arm_r = cob.arm("right").unwrap();
    let arm_l = cob.arm("left").unwrap();
    let mut q_cross = ch.clone();
    for (k, v) in CROSS.iter().enumerate() {
        q_cross[arm_r.joint_indices[2 + k]] += v;
    }
    let tcp_gap = (arm_r.fk(&arm_r.extract(&q_cross)).translation.vector
        - arm_l.fk(&arm_l.extract(&ch)).translation.vector)
        .norm();
    assert!(
        tcp_gap < 0.12,
        "CROSS no longer reaches the left tool: {tcp_gap}"
    );
    let part = |s: f64| -> Vec<f64> {
        ch.iter()
            .zip(&q_cross)
            .map(|(a, b)| a + s * (b - a))
            .collect()
    };
    fx.push(fixture(
        "cob-arms-cross",
        "Care-O-bot: the right arm reaches over to the left gripper; on the way its link 3 enters the torso, then the arms meet.",
        "care_o_bot4",
        cob_air.clone(),
        FixturePath::Robot(vec![ch.clone(), part(0.5), q_cross.clone()]),
    ));
    // The reach stopped where a hand-written skip list ("torso vs arm link 3
    // cannot meet") called it free: arm_right_3_link ~28 mm inside torso_3_link.
    fx.push(fixture(
        "cob-self-collision-arm-into-torso",
        "Care-O-bot: the same reach stopped half way: arm_right_3_link enters torso_3_link (a pair the old hand-written list skipped).",
        "care_o_bot4",
        cob_air.clone(),
        FixturePath::Robot(vec![ch.clone(), part(0.25), part(0.5)]),
    ));
    // The mirror image for the left arm (left = right with every value negated).
    let mirror = |q: &[f64]| -> Vec<f64> {
        let mut m = q.to_vec();
        for (r, l) in arm_r.joint_indices[2..]
            .iter()
            .zip(&arm_l.joint_indices[2..])
        {
            m[*l] = -q[*r];
            m[*r] = ch[*r];
        }
        m
    };
    fx.push(fixture(
        "cob-self-collision-left-arm-into-torso",
        "Care-O-bot: the mirror image of cob-self-collision-arm-into-torso for the left arm: arm_left_3_link enters torso_3_link.",
        "care_o_bot4",
        cob_air.clone(),
        FixturePath::Robot(vec![ch.clone(), mirror(&part(0.25)), mirror(&part(0.5))]),
    ));
    let mut frac = 0.5;
    while frac > 0.01 {
        let f = fixture(
            "probe",
            "",
            "care_o_bot4",
            cob_air.clone(),
            FixturePath::Robot(vec![ch.clone(), part(frac)]),
        );
        if !dense_of(&f, &DenseSettings::default()).collides() {
            break;
        }
        frac -= 0.01;
    }
    println!("cob: right arm free up to {frac:.2} of the crossing motion");
    fx.push(fixture(
        "cob-arms-reach-stops-short",
        "Care-O-bot: the same reach stopped before any link meets another (dense reference, every pair the allowed-collision matrix does not skip).",
        "care_o_bot4",
        cob_air.clone(),
        FixturePath::Robot(vec![ch.clone(), part(0.5 * frac), part(frac)]),
    ));
    let cob_tcp = cob
        .arm("right")
        .unwrap()
        .fk(&cob.arm("right").unwrap().extract(&ch))
        .translation
        .vector;
    for (name, gap, desc) in [
        (
            "cob-right-tool-hand-perimeter-entered",
            -0.06,
            "Right gripper descends to 0.09 m (TCP) over a hand's top (perimeter 0.10 m); the fingers reach 0.016 m below the TCP.",
        ),
        (
            "cob-right-tool-hand-perimeter-kept",
            0.05,
            "Right gripper descends to 0.20 m (TCP) over a hand's top (perimeter 0.10 m).",
        ),
    ] {
        let mut s = cob_scene.clone();
        s.boxes.push(bx(
            "hand-1",
            BoxKind::Hand,
            [cob_tcp.x, cob_tcp.y],
            [0.08, 0.18, 0.05],
            0.10,
        ));
        let mut f = fixture(
            name,
            desc,
            "care_o_bot4",
            s,
            tool(&[
                [cob_tcp.x, cob_tcp.y - 0.1, cob_tcp.z + 0.1 + gap, 0.0],
                [cob_tcp.x, cob_tcp.y, cob_tcp.z + gap, 0.0],
            ]),
        );
        f.arm = Some("right".into());
        fx.push(f);
    }
    let right = cob.arm("right").unwrap();
    let cob_sweep: Vec<Vec<f64>> = (0..=3)
        .map(|i| {
            let mut q = ch.clone();
            q[r1] -= 0.15 * i as f64;
            q
        })
        .collect();
    let _ = right;
    let wrist = cob
        .link_pose(&cob_sweep[2], "arm_right_5_link")
        .unwrap()
        .translation
        .vector;
    graze(
        fixture(
            "cob-graze-right-arm",
            "Right shoulder sweep outward past a post.",
            "care_o_bot4",
            SceneSpec {
                table_z: 0.75,
                table: None,
                boxes: vec![bx(
                    "post",
                    BoxKind::Object,
                    [wrist.x + 0.05, wrist.y - 0.15],
                    [0.04, 0.04, wrist.z - 0.75 + 0.1],
                    0.0,
                )],
            },
            FixturePath::Robot(cob_sweep.clone()),
        ),
        "post",
        fx,
    );
}
