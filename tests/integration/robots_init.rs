//! Bringing up a robot of one's own: `afford robots init` drafts a
//! description that loads, plans and passes the checker; `--package-path`
//! finds meshes elsewhere; `afford robots check` measures a description and
//! refuses one whose collision model leaves a mesh outside.

use std::path::Path;

use crate::toy_robot::{Layout, Toy, write_toy, write_toy_with};
use crate::util::{Run, afford, assert_contains_all, scratch_dir};

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// `afford robots init` of the toy robot into `dir` (description
/// `toy.yaml`, scenario `scene.yaml`), with `extra` arguments.
fn init(toy: &Toy, dir: &Path, srdf: bool, extra: &[&str]) -> Run {
    let (out, scene) = (dir.join("toy.yaml"), dir.join("scene.yaml"));
    let mut args = vec![
        "robots",
        "init",
        s(&toy.urdf),
        "-o",
        s(&out),
        "--scenario",
        s(&scene),
        "--samples",
        "3000",
    ];
    if srdf {
        args.extend(["--srdf", s(&toy.srdf)]);
    }
    args.extend(extra);
    afford(&args)
}

#[test]
fn a_published_urdf_with_an_srdf_becomes_a_description_that_plans() {
    let dir = scratch_dir("robots-init-srdf");
    let toy = write_toy(&dir, Layout::Beside, None);
    let run = init(&toy, &dir, true, &[]);
    run.assert_code(0).assert_no_panic();
    // Every guess is one line on stderr; the SRDF's arm, tool and posture are read.
    assert_contains_all(
        "init's stderr",
        &run.stderr,
        &[
            "guessed: gripper.closing_time",
            "guessed: camera:",
            "guessed: acceleration_limits:",
        ],
    );
    // The SRDF's disabled pair touches in the samples: reported, not dropped.
    assert!(
        run.stderr
            .contains("srdf: SRDF disables [base_link, link2]; the derived matrix checks it"),
        "{}",
        run.stderr
    );
    let text = std::fs::read_to_string(dir.join("toy.yaml")).expect("description written");
    assert_contains_all(
        "the description",
        &text,
        &[
            "name: manipulator",
            "tool: tcp",
            "joints: [joint1, joint2, joint3, joint4, joint5, joint6]",
            "max_opening: 0.06",
            "fingers: [finger_left, finger_right]",
            "Home: the SRDF group_state 'ready'.",
            "allowed_collisions:",
            "camera:",
        ],
    );
    let scene = dir.join("scene.yaml");
    let plan = dir.join("plan.json");
    let planned = afford(&["plan", s(&scene), "-o", s(&plan)]);
    planned.assert_code(0).assert_no_panic();
    afford(&["check", s(&scene), s(&plan)]).assert_code(0);
}

#[test]
fn the_same_urdf_drafts_the_same_description_byte_for_byte() {
    let dir = scratch_dir("robots-init-deterministic");
    let toy = write_toy(&dir, Layout::Beside, None);
    init(&toy, &dir, true, &[]).assert_code(0);
    let first = std::fs::read_to_string(dir.join("toy.yaml")).expect("written");
    init(&toy, &dir, true, &[]).assert_code(0);
    let second = std::fs::read_to_string(dir.join("toy.yaml")).expect("written");
    assert_eq!(first, second);
}

#[test]
fn a_urdf_without_an_srdf_takes_its_longest_chain_without_the_fingers_as_the_arm() {
    let dir = scratch_dir("robots-init-no-srdf");
    let toy = write_toy(&dir, Layout::Beside, None);
    let run = init(&toy, &dir, false, &[]);
    run.assert_code(0);
    assert_contains_all(
        "stderr",
        &run.stderr,
        &[
            "guessed: arms[0]: the longest serial chain",
            "guessed: home: by IK",
        ],
    );
    let text = std::fs::read_to_string(dir.join("toy.yaml")).expect("written");
    assert_contains_all(
        "the description",
        &text,
        &[
            "joints: [joint1, joint2, joint3, joint4, joint5, joint6]",
            "tool: tcp",
            "finger_left_joint: 0.03",
        ],
    );
    let scene = dir.join("scene.yaml");
    let plan = dir.join("plan.json");
    afford(&["plan", s(&scene), "-o", s(&plan)]).assert_code(0);
    afford(&["check", s(&scene), s(&plan)]).assert_code(0);
}

#[test]
fn package_paths_find_meshes_the_urdfs_folders_do_not_hold() {
    let dir = scratch_dir("robots-init-package-path");
    let toy = write_toy(&dir, Layout::Apart, None);
    let lost = init(&toy, &dir, true, &[]);
    lost.assert_code(2);
    assert_contains_all(
        "the refusal",
        &lost.stderr,
        &["toy_arm.urdf", "package://toy_description/meshes/base.stl"],
    );
    let packages = s(&toy.packages).to_string();
    init(&toy, &dir, true, &["--package-path", &packages]).assert_code(0);
    let (description, scene, plan) = (
        dir.join("toy.yaml"),
        dir.join("scene.yaml"),
        dir.join("plan.json"),
    );
    // Every command that loads the robot takes the same folders.
    afford(&["plan", s(&scene), "-o", s(&plan)]).assert_code(2);
    afford(&[
        "plan",
        s(&scene),
        "-o",
        s(&plan),
        "--package-path",
        &packages,
    ])
    .assert_code(0);
    afford(&["check", s(&scene), s(&plan), "--package-path", &packages]).assert_code(0);
    afford(&["validate", s(&scene), "--package-path", &packages]).assert_code(0);
    let acm = afford(&[
        "robots",
        "acm",
        s(&description),
        "--samples",
        "100",
        "--package-path",
        &packages,
    ]);
    acm.assert_code(0);
    assert!(acm.stdout.contains("allowed_collisions:"), "{}", acm.stdout);
    afford(&[
        "robots",
        "check",
        s(&description),
        "--poses",
        "20",
        "--package-path",
        &packages,
    ])
    .assert_code(0);
}

#[test]
fn robots_check_measures_reach_postures_ik_and_mesh_coverage() {
    let dir = scratch_dir("robots-check-pass");
    let toy = write_toy(&dir, Layout::Beside, None);
    init(&toy, &dir, true, &[]).assert_code(0);
    let run = afford(&[
        "robots",
        "check",
        s(&dir.join("toy.yaml")),
        "--poses",
        "50",
        "--json",
    ]);
    run.assert_code(0);
    let r = run.json();
    assert_eq!(r["passed"], true, "{r}");
    assert_eq!(
        r["reach"]["fraction"], 1.0,
        "the suggested region is reached everywhere: {r}"
    );
    assert!(
        r["postures"]
            .as_array()
            .is_some_and(|p| p.iter().all(|p| p["self_collision_free"] == true)),
        "{r}"
    );
    assert!(
        r["ik"][0]["success_rate"].as_f64().is_some_and(|x| x > 0.9),
        "{r}"
    );
    let coverage = r["coverage"].as_array().expect("coverage rows");
    assert_eq!(coverage.len(), 7, "one row per mesh: {r}");
    // A collision mesh lies in its own hull.
    assert!(
        coverage
            .iter()
            .all(|c| c["max_outside_m"].as_f64().is_some_and(|d| d < 1e-9)),
        "{r}"
    );
}

#[test]
fn robots_check_refuses_a_collision_model_that_leaves_a_mesh_outside() {
    let dir = scratch_dir("robots-check-outside");
    // link3's visual mesh is 1 cm wider on each side than its collision box.
    let toy = write_toy(&dir, Layout::Beside, Some([0.035, 0.035, 0.15]));
    init(&toy, &dir, true, &[]).assert_code(0);
    let run = afford(&["robots", "check", s(&dir.join("toy.yaml")), "--poses", "20"]);
    run.assert_code(1).assert_no_panic();
    assert_contains_all(
        "the refusal",
        &run.stderr,
        &["link 'link3'", "visual mesh", "outside the collision model"],
    );
    assert!(run.stdout.contains("FAILED"), "{}", run.stdout);
}

#[test]
fn init_refuses_a_folder_as_its_output_and_names_a_broken_urdf() {
    let dir = scratch_dir("robots-init-bad");
    let toy = write_toy(&dir, Layout::Beside, None);
    let folder = afford(&["robots", "init", s(&toy.urdf), "-o", s(&dir)]);
    folder.assert_code(3);
    assert!(folder.stderr.contains("is a folder"), "{}", folder.stderr);
    let broken = dir.join("broken.urdf");
    std::fs::write(
        &broken,
        "<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" type=\"revolute\"></robot>",
    )
    .expect("write");
    let out = dir.join("broken.yaml");
    let run = afford(&["robots", "init", s(&broken), "-o", s(&out)]);
    run.assert_code(2).assert_no_panic();
    assert!(run.stderr.contains("broken.urdf"), "{}", run.stderr);
    assert!(!out.exists(), "nothing written for a broken URDF");
}

#[test]
fn an_arm_without_a_gripper_gets_the_assumed_one_in_a_copy_of_its_urdf() {
    let dir = scratch_dir("robots-init-bare-flange");
    let toy = write_toy_with(&dir, Layout::Beside, None, false);
    let original = std::fs::read_to_string(&toy.urdf).expect("urdf");
    // No SRDF: its end effector names `tcp`, which this URDF lacks.
    let run = init(&toy, &dir, false, &[]);
    run.assert_code(0);
    assert!(
        run.stderr.contains("guessed: gripper: the URDF has none"),
        "{}",
        run.stderr
    );
    assert_eq!(
        std::fs::read_to_string(&toy.urdf).expect("urdf"),
        original,
        "the URDF read is untouched"
    );
    let copy = std::fs::read_to_string(dir.join("toy.urdf"))
        .expect("the URDF with the gripper, beside the description");
    assert_contains_all(
        "the copy",
        &copy,
        &["<link name=\"afford_gripper\">", "<parent link=\"link6\"/>"],
    );
    let text = std::fs::read_to_string(dir.join("toy.yaml")).expect("written");
    assert_contains_all(
        "the description",
        &text,
        &[
            "urdf: toy.urdf",
            "tool: afford_tcp",
            "fingers: [afford_gripper#1]",
        ],
    );
    let (scene, plan) = (dir.join("scene.yaml"), dir.join("plan.json"));
    afford(&["plan", s(&scene), "-o", s(&plan)]).assert_code(0);
    afford(&["check", s(&scene), s(&plan)]).assert_code(0);
    // --no-assumed-gripper keeps the flange as the tool.
    let bare = dir.join("bare.yaml");
    afford(&[
        "robots",
        "init",
        s(&toy.urdf),
        "-o",
        s(&bare),
        "--samples",
        "500",
        "--no-assumed-gripper",
    ])
    .assert_code(0);
    let text = std::fs::read_to_string(&bare).expect("written");
    assert!(
        text.contains("tool: link6") && text.contains("fingers: []"),
        "{text}"
    );
}

#[test]
fn bench_ik_measures_a_description_file() {
    let dir = scratch_dir("robots-bench-ik");
    let toy = write_toy(&dir, Layout::Beside, None);
    init(&toy, &dir, true, &[]).assert_code(0);
    let run = afford(&[
        "bench",
        "ik",
        "--robot",
        s(&dir.join("toy.yaml")),
        "--poses",
        "30",
        "--json",
    ]);
    run.assert_code(0);
    let r = run.json();
    assert_eq!(r["arms"].as_array().map(Vec::len), Some(1), "{r}");
    assert_eq!(r["arms"][0]["robot"], "toy_arm", "{r}");
    assert_eq!(r["arms"][0]["poses"], 30, "{r}");
}

#[test]
fn a_tool_frame_whose_z_is_not_the_approach_axis_is_named_with_the_fix() {
    let dir = scratch_dir("robots-init-turned-tool");
    let toy = write_toy(&dir, Layout::Beside, None);
    let urdf = std::fs::read_to_string(&toy.urdf).expect("urdf");
    // The grasp frame turned a quarter turn about x: its +z points sideways.
    let turned = urdf.replace(
        "<child link=\"tcp\"/><origin xyz=\"0 0 0.1\"/>",
        "<child link=\"tcp\"/><origin xyz=\"0 0 0.1\" rpy=\"1.5708 0 0\"/>",
    );
    assert_ne!(turned, urdf, "the tcp joint was edited");
    std::fs::write(&toy.urdf, turned).expect("write");
    let run = init(&toy, &dir, true, &[]);
    assert_contains_all(
        "init's stderr",
        &run.stderr,
        &[
            "arms[0].tool: 'tcp'",
            "90° from its +z",
            "add a fixed link to the URDF turned so",
        ],
    );
}
