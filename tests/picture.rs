//! `afford::picture::plan_svg` on the default scenario: a real SVG with one
//! cell path and one tool path per sub-goal, the legend text, joint panels
//! against limits, byte-identical across renders; a grid-only plan draws the
//! top view alone.

use afford::kinematics::RobotModel;
use afford::picture::{plan_svg, subgoal_colour};
use afford::planner::plan::Plan;
use afford::planner::scenario::{Scenario, default_scenario};
use afford::planner::{PlanOptions, Stage, plan};

fn planned(until: Stage) -> (Scenario, Plan) {
    let scenario = default_scenario().expect("default scenario parses");
    let options = PlanOptions {
        until,
        ..PlanOptions::default()
    };
    let plan = plan(&scenario, &options).expect("default scenario plans");
    (scenario, plan)
}

fn hex(k: usize) -> String {
    let c = subgoal_colour(k);
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// Every `<polyline …>` tag with its stroke colour and number of points.
fn polylines(svg: &str) -> Vec<(String, usize, String)> {
    svg.split("<polyline")
        .skip(1)
        .map(|tag| {
            let tag = &tag[..tag.find("/>").expect("polyline closes")];
            let attr = |name: &str| {
                let start = tag.find(&format!("{name}=\"")).expect("attribute") + name.len() + 2;
                tag[start..start + tag[start..].find('"').unwrap()].to_string()
            };
            let points = attr("points").split_whitespace().count();
            (attr("stroke"), points, attr("stroke-width"))
        })
        .collect()
}

/// Cells drawn: the path without consecutive repeats (picking and the
/// GOAL macro stay in a cell).
fn distinct_cells(path: &[[f64; 2]]) -> usize {
    1 + path.windows(2).filter(|w| w[0] != w[1]).count()
}

fn render() -> (Scenario, Plan, String) {
    let (scenario, plan) = planned(Stage::Trajectory);
    let robot = RobotModel::builtin("kuka_iiwa14").expect("built-in robot");
    let svg = plan_svg(&scenario, &plan, Some(&robot)).expect("plan draws");
    (scenario, plan, svg)
}

#[test]
fn full_plan_is_one_svg_document() {
    let (_, plan, svg) = render();
    assert!(svg.trim_start().starts_with("<svg"), "{}", &svg[..80]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<svg").count(), 1);
    assert!(
        plan.subgoals.len() >= 2,
        "default scenario has several sub-goals"
    );
}

#[test]
fn each_subgoal_has_its_cell_path_and_tool_path() {
    let (_, plan, svg) = render();
    let lines = polylines(&svg);
    for (k, sub) in plan.subgoals.iter().enumerate() {
        let colour = hex(k);
        let mine: Vec<_> = lines.iter().filter(|(c, _, _)| *c == colour).collect();
        let cells = mine
            .iter()
            .filter(|(_, n, w)| *n == distinct_cells(&sub.path_px) && w == "2")
            .count();
        assert_eq!(cells, 1, "sub-goal {k}: one cell path");
        let tool = mine.iter().filter(|(_, n, w)| *n >= 2 && w == "6").count();
        assert_eq!(tool, 1, "sub-goal {k}: one smoothed tool path");
    }
}

#[test]
fn legend_names_objects_goals_and_arms() {
    let (scenario, plan, svg) = render();
    for object in &scenario.objects {
        assert!(
            svg.contains(&object.name),
            "object {} labelled",
            object.name
        );
    }
    for (k, sub) in plan.subgoals.iter().enumerate() {
        let arm = sub.arm.as_deref().expect("trajectory plans choose an arm");
        let line = format!(
            "{}. {} → {} · arm: {arm} of kuka_iiwa14",
            k + 1,
            sub.object,
            sub.goal
        );
        assert!(svg.contains(&line), "legend line {line:?}");
    }
}

#[test]
fn joint_panels_show_every_joint_against_its_limits() {
    let (_, plan, svg) = render();
    let names = plan.subgoals[0].joint_names.as_ref().expect("joint names");
    for name in names {
        assert!(
            svg.contains(&format!(">\n{name}\n<")) || svg.contains(name),
            "row {name}"
        );
    }
    assert!(svg.contains("dashed: position limits"));
    assert!(svg.contains("dashed: ± velocity limits"));
    assert!(svg.contains("time (s)"));
    // One position and one velocity curve per sub-goal and joint: long
    // polylines in the sub-goal's colour.
    let lines = polylines(&svg);
    for (k, sub) in plan.subgoals.iter().enumerate() {
        let samples = sub.trajectory.as_ref().expect("trajectory").points.len();
        let curves = lines
            .iter()
            .filter(|(c, n, w)| *c == hex(k) && *n > samples / 2 && w == "2")
            .count();
        assert_eq!(curves, 2 * names.len(), "sub-goal {k}: curves");
    }
}

#[test]
fn same_plan_renders_same_bytes() {
    let (scenario, plan, svg) = render();
    let robot = RobotModel::builtin("kuka_iiwa14").expect("built-in robot");
    let again = plan_svg(&scenario, &plan, Some(&robot)).expect("plan draws");
    assert_eq!(svg, again);
}

#[test]
fn grid_only_plan_draws_the_top_view_alone() {
    let (scenario, plan) = planned(Stage::Grid);
    let robot = RobotModel::builtin("kuka_iiwa14").expect("built-in robot");
    for robot in [None, Some(&robot)] {
        let svg = plan_svg(&scenario, &plan, robot).expect("grid plan draws");
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(
            !svg.contains("joint velocity"),
            "no joint panels without a trajectory"
        );
        assert!(svg.contains("no arm chosen"));
        let lines = polylines(&svg);
        for (k, sub) in plan.subgoals.iter().enumerate() {
            let cells = lines
                .iter()
                .filter(|(c, n, w)| *c == hex(k) && *n == distinct_cells(&sub.path_px) && w == "2")
                .count();
            assert_eq!(cells, 1, "sub-goal {k}: cell path");
        }
    }
}

#[test]
fn hands_and_sensitive_objects_are_marked() {
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let grid_only = PlanOptions {
        until: Stage::Grid,
        ..PlanOptions::default()
    };
    let scenario = afford::planner::scenario::load(&examples.join("hand-on-route.yaml"))
        .expect("hand scenario loads");
    let planned = plan(&scenario, &grid_only).expect("hand scenario plans");
    let svg = plan_svg(&scenario, &planned, None).expect("draws");
    assert!(svg.contains("hand: hand-1"));
    assert!(
        svg.contains("fill=\"#F57C00\""),
        "hand filled in the warning colour"
    );
    let scenario = afford::planner::scenario::load(&examples.join("sensitive-yellow.yaml"))
        .expect("sensitive scenario loads");
    let planned = plan(&scenario, &grid_only).expect("sensitive scenario plans");
    let svg = plan_svg(&scenario, &planned, None).expect("draws");
    for o in scenario.objects.iter().filter(|o| scenario.is_sensitive(o)) {
        assert!(svg.contains(&format!("! {} (sensitive)", o.name)));
    }
}

/// Writes the pictures to `$AFFORD_SVG_DIR` when set (to look at them).
#[test]
fn write_pictures_when_asked() {
    let Ok(dir) = std::env::var("AFFORD_SVG_DIR") else {
        return;
    };
    let (_, _, svg) = render();
    std::fs::write(format!("{dir}/default.svg"), svg).expect("write");
    let (scenario, grid_plan) = planned(Stage::Grid);
    let svg = plan_svg(&scenario, &grid_plan, None).expect("grid plan draws");
    std::fs::write(format!("{dir}/grid.svg"), svg).expect("write");
    for file in std::env::var("AFFORD_SVG_SCENARIOS")
        .unwrap_or_default()
        .split_whitespace()
    {
        let path = std::path::Path::new(file);
        let scenario = afford::planner::scenario::load(path).expect("scenario loads");
        let options = PlanOptions {
            base_dir: path.parent().expect("folder").to_path_buf(),
            ..PlanOptions::default()
        };
        let Ok(planned) = plan(&scenario, &options) else {
            eprintln!("{file}: does not plan, not drawn");
            continue;
        };
        let robot = afford::kinematics::RobotModel::load(&scenario.robot.model, &options.base_dir)
            .expect("robot loads");
        let svg = plan_svg(&scenario, &planned, Some(&robot)).expect("draws");
        let stem = path.file_stem().expect("name").to_string_lossy();
        std::fs::write(format!("{dir}/{stem}.svg"), svg).expect("write");
    }
}
