//! Generates the regression fixtures in `tests/collision/` by computing them:
//! configurations by FK, obstacles placed relative to computed link
//! positions, margins of the grazing fixtures from the exact closest approach
//! (dense sampling at 10 µm / 2e-5 rad) ± 1 mm, and every verdict from the
//! dense reference (0.5 mm / 0.001 rad). A fixture is only written when the
//! fast check agrees with the dense reference.
//!
//! `cargo run --release -p afford-collision --example gen_fixtures`

use std::path::PathBuf;

use afford_collision::*;
use afford_kinematics::RobotModel;

const TZ: f64 = -0.2;

fn table() -> Option<TableSpec> {
    Some(TableSpec {
        min: [0.2, -0.6],
        max: [0.95, 0.6],
        margin: 0.0,
    })
}

fn bx(name: &str, kind: BoxKind, c: [f64; 2], size: [f64; 3], margin: f64) -> SceneBox {
    SceneBox {
        name: name.into(),
        kind,
        centre: c,
        size,
        yaw: 0.0,
        margin,
        round: false,
    }
}

fn fixture(name: &str, desc: &str, robot: &str, scene: SceneSpec, path: FixturePath) -> Fixture {
    Fixture {
        name: name.into(),
        description: desc.into(),
        robot: robot.into(),
        arm: None,
        scene,
        path,
        held: None,
        ignore: vec![],
        expect: Expect {
            verdict: Verdict::Free,
            pair: None,
            segment: None,
        },
    }
}

fn dense_of(fx: &Fixture, d: &DenseSettings) -> DenseResult {
    dense_with(fx, d, true)
}

fn dense_with(fx: &Fixture, d: &DenseSettings, self_collision: bool) -> DenseResult {
    let file = PathBuf::from(&fx.name);
    let (g, scene, mut opts) = fx.prepare(&file).expect("prepare");
    opts.settings.self_collision = self_collision;
    match &fx.path {
        FixturePath::Tool(w) => {
            let poses: Vec<_> = w
                .iter()
                .map(|p| afford_kinematics::top_down_pose([p[0], p[1], p[2]].into(), p[3]))
                .collect();
            dense_tool_path(&g, &scene, &poses, &opts, d).expect("dense")
        }
        FixturePath::Arm(q) => {
            let arm = g.model().arms()[0].clone();
            let home = g.model().home().to_vec();
            let full: Vec<Vec<f64>> = q
                .iter()
                .map(|qa| {
                    let mut c = home.clone();
                    arm.insert(&mut c, qa);
                    c
                })
                .collect();
            dense_joint_path(&g, &scene, &full, &opts, d).expect("dense")
        }
        FixturePath::Robot(q) => dense_joint_path(&g, &scene, q, &opts, d).expect("dense"),
    }
}

fn segments(fx: &Fixture) -> usize {
    match &fx.path {
        FixturePath::Tool(w) => w.len() - 1,
        FixturePath::Arm(q) | FixturePath::Robot(q) => q.len() - 1,
    }
}

/// Sets the expectation from the dense reference; returns false (and says
/// why) when the fast check disagrees.
fn settle(fx: &mut Fixture) -> bool {
    let d = dense_of(fx, &DenseSettings::default());
    match &d.first_hit {
        None => {
            fx.expect = Expect {
                verdict: Verdict::Free,
                pair: None,
                segment: None,
            }
        }
        Some((t, a, b, _)) => {
            let n = segments(fx).max(1);
            fx.expect = Expect {
                verdict: Verdict::Collides,
                pair: Some([strip(a), strip(b)]),
                segment: Some((t.floor() as usize).min(n - 1)),
            }
        }
    }
    let file = PathBuf::from(&fx.name);
    let (g, scene, opts) = fx.prepare(&file).expect("prepare");
    let v = fx.check(&g, &scene, &opts, &file).expect("check");
    let ok = v.is_free() != d.collides();
    println!(
        "{:<40} dense: {} (min slack {:.4} m {:?}) fast: {}",
        fx.name,
        d.first_hit.as_ref().map_or("free".to_string(), |h| format!(
            "{} vs {} at t={:.3}",
            h.1, h.2, h.0
        )),
        d.min_slack,
        d.min_pair,
        v.first().map_or("free".to_string(), |c| c.to_string())
    );
    ok
}

fn strip(s: &str) -> String {
    s.split('#').next().unwrap_or(s).to_string()
}

/// Closest approach of the path to the scene, finely sampled.
fn closest(fx: &Fixture) -> DenseResult {
    dense_with(
        fx,
        &DenseSettings {
            step_m: 1e-5,
            step_rad: 2e-5,
            stop_at_first: false,
        },
        false,
    )
}

/// Two fixtures from one: the box `name`'s margin set to the exact closest
/// approach +1 mm (collides) and -1 mm (free).
fn graze(base: Fixture, name: &str, out: &mut Vec<Fixture>) {
    let c = closest(&base);
    assert_eq!(
        c.min_pair.1, name,
        "{}: closest pair is {:?}",
        base.name, c.min_pair
    );
    let idx = base
        .scene
        .boxes
        .iter()
        .position(|b| b.name == name)
        .unwrap();
    let m0 = base.scene.boxes[idx].margin;
    let dmin = c.min_slack + m0;
    for (suffix, delta, word) in [
        ("free-by-1mm", -0.001, "outside"),
        ("hit-by-1mm", 0.001, "inside"),
    ] {
        let mut f = base.clone();
        f.name = format!("{}-{suffix}", base.name);
        f.description = format!(
            "{} Closest approach to '{name}' is {:.5} m (dense, 10 um / 2e-5 rad); margin set to {:.5} m so the path stays 1 mm {word} the perimeter.",
            base.description,
            dmin,
            dmin + delta
        );
        f.scene.boxes[idx].margin = dmin + delta;
        out.push(f);
    }
}

fn main() {
    let out_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/collision");
    std::fs::create_dir_all(&out_dir).unwrap();
    let iiwa = RobotModel::builtin("kuka_iiwa14").unwrap();
    let cob = RobotModel::builtin("care_o_bot4").unwrap();
    let mut fx: Vec<Fixture> = Vec::new();
    let scene = |boxes: Vec<SceneBox>| SceneSpec {
        table_z: TZ,
        table: table(),
        boxes,
    };
    let tool = |w: &[[f64; 4]]| FixturePath::Tool(w.to_vec());

    // --- tool paths, iiwa -------------------------------------------------
    let low = vec![
        bx(
            "red-square-1",
            BoxKind::Object,
            [0.3, 0.35],
            [0.04, 0.04, 0.03],
            0.02,
        ),
        bx(
            "blue-square-1",
            BoxKind::Object,
            [0.8, -0.4],
            [0.04, 0.04, 0.03],
            0.02,
        ),
    ];
    fx.push(fixture(
        "tool-free-over-table",
        "Gripper crosses the table 0.10 m up, objects off the path.",
        "kuka_iiwa14",
        scene(low.clone()),
        tool(&[[0.4, -0.3, -0.1, 0.0], [0.7, 0.3, -0.1, 0.5]]),
    ));
    let hand = bx(
        "hand-1",
        BoxKind::Hand,
        [0.55, 0.0],
        [0.08, 0.18, 0.05],
        0.10,
    );
    // Finger tips reach 0.015 m beyond the TCP.
    let over_hand = |gap: f64| TZ + 0.05 + 0.015 + gap;
    fx.push(fixture(
        "tool-hand-perimeter-entered",
        "Gripper passes 0.07 m over a hand whose perimeter is 0.10 m.",
        "kuka_iiwa14",
        scene(vec![hand.clone()]),
        tool(&[
            [0.55, -0.3, over_hand(0.07), 0.0],
            [0.55, 0.3, over_hand(0.07), 0.0],
        ]),
    ));
    fx.push(fixture(
        "tool-hand-perimeter-kept",
        "Gripper passes 0.13 m over a hand whose perimeter is 0.10 m.",
        "kuka_iiwa14",
        scene(vec![hand.clone()]),
        tool(&[
            [0.55, -0.3, over_hand(0.13), 0.0],
            [0.55, 0.3, over_hand(0.13), 0.0],
        ]),
    ));
    fx.push(fixture(
        "tool-hand-beside-path",
        "Gripper passes low beside a hand, 0.16 m from its side.",
        "kuka_iiwa14",
        scene(vec![hand.clone()]),
        tool(&[[0.79, -0.3, TZ + 0.06, 0.0], [0.79, 0.3, TZ + 0.06, 0.0]]),
    ));
    let sens = bx(
        "yellow-circle-1",
        BoxKind::Object,
        [0.6, 0.1],
        [0.05, 0.05, 0.04],
        0.06,
    );
    let over_sens = |gap: f64| TZ + 0.04 + 0.015 + gap;
    fx.push(fixture(
        "tool-sensitive-perimeter-entered",
        "Gripper passes 0.04 m over a sensitive object (perimeter 0.06 m).",
        "kuka_iiwa14",
        scene(vec![sens.clone()]),
        tool(&[
            [0.6, -0.2, over_sens(0.04), 0.0],
            [0.6, 0.4, over_sens(0.04), 0.0],
        ]),
    ));
    fx.push(fixture(
        "tool-sensitive-perimeter-kept",
        "Gripper passes 0.08 m over a sensitive object (perimeter 0.06 m).",
        "kuka_iiwa14",
        scene(vec![sens.clone()]),
        tool(&[
            [0.6, -0.2, over_sens(0.08), 0.0],
            [0.6, 0.4, over_sens(0.08), 0.0],
        ]),
    ));
    let goal = |m: f64| bx("right box", BoxKind::Goal, [0.6, 0.2], [0.2, 0.2, 0.10], m);
    let held = HeldSpec {
        name: "red-square-1".into(),
        size: [0.04, 0.04, 0.06],
        offset: [0.0, 0.0, 0.01],
    };
    // Held box bottom is 0.04 below the TCP; finger tips 0.015.
    let inside = TZ + GOAL_WALL + 0.04 + 0.01;
    for (name, desc, travel, m) in [
        (
            "tool-held-object-hits-goal-wall",
            "Carrying a cube at a height where the fingers clear the goal wall by 1 cm but the cube's bottom is 1.5 cm below its top.",
            TZ + 0.10 + 0.025,
            0.0,
        ),
        (
            "tool-held-object-over-goal-wall",
            "Carrying a cube 2 cm over the goal wall, then down into the open box.",
            TZ + 0.10 + 0.06,
            0.0,
        ),
        (
            "tool-held-object-in-wall-perimeter",
            "Carrying a cube 1.5 cm over the goal wall when the goal's perimeter is 2 cm.",
            TZ + 0.10 + 0.055,
            0.02,
        ),
    ] {
        let mut f = fixture(
            name,
            desc,
            "kuka_iiwa14",
            scene(vec![goal(m)]),
            tool(&[
                [0.45, -0.1, travel, 0.0],
                [0.6, 0.2, travel, 0.0],
                [0.6, 0.2, inside, 0.0],
            ]),
        );
        f.held = Some(held.clone());
        fx.push(f);
    }
    let target = bx(
        "blue-square-2",
        BoxKind::Object,
        [0.5, -0.2],
        [0.04, 0.04, 0.04],
        0.02,
    );
    let mut f = fixture(
        "tool-grasp-descent-target-ignored",
        "Descent to grasp: the fingers close around the target, which the check ignores.",
        "kuka_iiwa14",
        scene(vec![target.clone()]),
        tool(&[[0.5, -0.2, TZ + 0.15, 0.0], [0.5, -0.2, TZ + 0.02, 0.0]]),
    );
    f.ignore = vec!["blue-square-2".into()];
    fx.push(f.clone());
    f.name = "tool-grasp-descent-target-not-ignored".into();
    f.description =
        "The same descent with the target still in the scene: the fingers enter it.".into();
    f.ignore.clear();
    fx.push(f);
    fx.push(fixture(
        "tool-descends-into-table",
        "Descent too low: the finger tips go below the table top.",
        "kuka_iiwa14",
        scene(vec![]),
        tool(&[[0.6, 0.0, TZ + 0.1, 0.0], [0.6, 0.0, TZ + 0.005, 0.0]]),
    ));
    graze(
        fixture(
            "tool-graze-object",
            "Gripper passes diagonally over an object.",
            "kuka_iiwa14",
            SceneSpec {
                table_z: TZ,
                table: None,
                boxes: vec![bx(
                    "green-square-1",
                    BoxKind::Object,
                    [0.6, 0.0],
                    [0.05, 0.05, 0.05],
                    0.0,
                )],
            },
            tool(&[[0.5, -0.2, TZ + 0.12, 0.0], [0.7, 0.2, TZ + 0.10, 0.3]]),
        ),
        "green-square-1",
        &mut fx,
    );
    graze(
        fixture(
            "tool-graze-hand",
            "Gripper passes beside a hand.",
            "kuka_iiwa14",
            SceneSpec {
                table_z: TZ,
                table: None,
                boxes: vec![bx(
                    "hand-1",
                    BoxKind::Hand,
                    [0.55, 0.0],
                    [0.08, 0.18, 0.05],
                    0.0,
                )],
            },
            tool(&[[0.7, -0.3, TZ + 0.05, 0.0], [0.72, 0.3, TZ + 0.08, 0.0]]),
        ),
        "hand-1",
        &mut fx,
    );

    // --- joint paths, iiwa ------------------------------------------------
    let home: Vec<f64> = iiwa.home().to_vec();
    let rot = |a1: f64| {
        let mut q = home.clone();
        q[0] += a1;
        q
    };
    let sweep: Vec<Vec<f64>> = (0..=4).map(|i| rot(0.2 * i as f64)).collect();
    // A tall obstacle where the elbow passes (computed by FK), far from the tool.
    let elbow = iiwa
        .link_pose(&rot(0.6), "link_4")
        .unwrap()
        .translation
        .vector;
    let tool_r = iiwa.arms()[0].fk(&home).translation.vector.xy().norm();
    println!("elbow at {elbow:?}; tool radius {tool_r:.3}");
    let tall = |h: f64| {
        bx(
            "tall-bottle",
            BoxKind::Object,
            [elbow.x, elbow.y],
            [0.06, 0.06, h],
            0.02,
        )
    };
    let tall_h = elbow.z - TZ + 0.05;
    fx.push(fixture(
        "arm-elbow-hits-tall-obstacle",
        "Shoulder sweep: the tool stays 0.2 m away from a tall bottle, but the elbow passes through it.",
        "kuka_iiwa14",
        scene(vec![tall(tall_h)]),
        FixturePath::Arm(sweep.clone()),
    ));
    let tool_wps: Vec<[f64; 4]> = (0..=16)
        .map(|i| {
            let q = rot(0.05 * i as f64);
            let p = iiwa.arms()[0].fk(&q);
            let x = p.rotation * nalgebra::Vector3::x();
            [
                p.translation.x,
                p.translation.y,
                p.translation.z,
                x.y.atan2(x.x),
            ]
        })
        .collect();
    fx.push(fixture(
        "tool-path-avoids-tall-obstacle",
        "The gripper path of the shoulder sweep (FK every 0.05 rad) in the same scene: the gripper alone is free.",
        "kuka_iiwa14",
        scene(vec![tall(tall_h)]),
        tool(&tool_wps),
    ));
    fx.push(fixture(
        "arm-sweep-short-obstacle",
        "The same shoulder sweep with the bottle only 0.1 m tall.",
        "kuka_iiwa14",
        scene(vec![tall(0.1)]),
        FixturePath::Arm(sweep.clone()),
    ));
    fx.push(fixture(
        "arm-sweep-free",
        "Shoulder sweep over a table with low objects away from the tool's arc.",
        "kuka_iiwa14",
        scene(vec![
            bx(
                "blue-square-1",
                BoxKind::Object,
                [0.8, -0.4],
                [0.04, 0.04, 0.03],
                0.02,
            ),
            bx(
                "red-square-2",
                BoxKind::Object,
                [0.6, -0.3],
                [0.04, 0.04, 0.03],
                0.02,
            ),
        ]),
        FixturePath::Arm(sweep.clone()),
    ));
    graze(
        fixture(
            "arm-graze-forearm",
            "Shoulder sweep past a tall post beside the forearm's path.",
            "kuka_iiwa14",
            SceneSpec {
                table_z: TZ,
                table: None,
                boxes: vec![bx(
                    "post",
                    BoxKind::Object,
                    [elbow.x + 0.35, elbow.y + 0.05],
                    [0.04, 0.04, 0.9],
                    0.0,
                )],
            },
            FixturePath::Arm(sweep.clone()),
        ),
        "post",
        &mut fx,
    );
    // Lowering the arm (a2 forward) with a held cube onto an object.
    let lower: Vec<Vec<f64>> = (0..=3)
        .map(|i| {
            let mut q = home.clone();
            q[1] += 0.06 * i as f64;
            q
        })
        .collect();
    let under = iiwa.arms()[0].fk(&lower[3]).translation.vector;
    let mut f = fixture(
        "arm-held-object-lowered-onto-box",
        "Lowering the arm while holding a cube onto a box below the tool.",
        "kuka_iiwa14",
        scene(vec![bx(
            "crate",
            BoxKind::Object,
            [under.x, under.y],
            [0.1, 0.1, 0.02],
            0.0,
        )]),
        FixturePath::Arm(lower.clone()),
    );
    f.held = Some(HeldSpec {
        name: "cube".into(),
        size: [0.04, 0.04, 0.04],
        offset: [0.0, 0.0, 0.0],
    });
    fx.push(f);
    // Self-collision: fold the elbow fully.
    let mut fold = home.clone();
    fold[3] = -2.0;
    fold[5] = 2.0;
    fold[1] = 1.6;
    fx.push(fixture(
        "arm-folds-into-itself",
        "Folding elbow and wrist to their limits: a wrist/gripper link meets the upper arm.",
        "kuka_iiwa14",
        SceneSpec {
            table_z: -1.5,
            table: None,
            boxes: vec![],
        },
        FixturePath::Arm(vec![home.clone(), fold]),
    ));

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
        &mut fx,
    );

    // --- random cases (iiwa), verdicts from the dense reference -----------
    let mut taken = 0;
    for seed in 0..200u64 {
        if taken >= 10 {
            break;
        }
        let case = random_case(&iiwa, 7_000 + seed);
        let mut f = fixture(
            &format!("random-iiwa-{}", 7_000 + seed),
            "Random scene and joint path (bench::random_case); verdict from dense sampling.",
            "kuka_iiwa14",
            case.scene,
            FixturePath::Robot(case.path),
        );
        if let Some(a) = case.attached {
            f.held = Some(HeldSpec {
                name: a.name,
                size: [
                    2.0 * a.half_extents[0],
                    2.0 * a.half_extents[1],
                    2.0 * a.half_extents[2],
                ],
                offset: [0.0, 0.0, 0.02],
            });
        }
        if settle(&mut f) {
            write(&out_dir, &f);
            taken += 1;
        }
    }

    let mut bad = 0;
    for mut f in fx {
        if settle(&mut f) {
            write(&out_dir, &f);
        } else {
            println!(
                "  !! fast check disagrees with dense on {}; not written",
                f.name
            );
            bad += 1;
        }
    }
    if bad > 0 {
        std::process::exit(1);
    }
}

fn write(dir: &std::path::Path, f: &Fixture) {
    let text = serde_saphyr::to_string(f).unwrap();
    let header = format!(
        "# Collision regression fixture, generated by collision/examples/gen_fixtures.rs.\n# {}\n",
        f.description
    );
    std::fs::write(dir.join(format!("{}.yaml", f.name)), header + &text).unwrap();
}
