//! The iiwa's fixtures: tool paths over boxes on its table (grazing ones at
//! their closest approach ± 1 mm), and joint paths past obstacles placed by FK.

use afford_collision::*;
use afford_kinematics::RobotModel;

use super::*;

/// Tool-path fixtures.
pub fn tool_paths(fx: &mut Vec<Fixture>) {
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
        fx,
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
        fx,
    );
}

/// Joint-path fixtures.
pub fn joint_paths(iiwa: &RobotModel, fx: &mut Vec<Fixture>) {
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
        fx,
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
}
