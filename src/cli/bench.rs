//! `afford bench …`: benchmarks with a progress bar on a terminal.

use std::io::IsTerminal;

use afford_bench::cql::{self, CqlBenchConfig};
use afford_bench::safety::{Finding, Robots, SafetyReport, run_scene};
use afford_bench::{routes, scenes, transits};
use afford_check::PlanFile;
use afford_kinematics::RobotModel;
use afford_planner::{Plan, Scenario};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use afford_bench::timing::{TimingBenchSettings, timing_benchmark};
use afford_planner::PlanOptions;

use super::executed;
use super::output::{note, print};
use super::plan::{base_dir, load};
use super::{
    BenchCqlArgs, BenchIkArgs, BenchMonitorArgs, BenchPipelineArgs, BenchRoutesArgs,
    BenchSafetyArgs, BenchSeedArgs, BenchTransitsArgs, ExitKind, Failure,
};

pub fn cql(args: &BenchCqlArgs) -> Result<(), Failure> {
    count_in(args.scenarios, "scenarios", MAX_SCENES)?;
    let config = CqlBenchConfig {
        scenarios: args.scenarios,
        seed: args.common.seed,
        ..Default::default()
    };
    let bar = progress_bar(args.scenarios as u64, "scenes");
    let report = cql::run(&config, |done| bar.set_position(done as u64));
    bar.finish_and_clear();
    if args.common.json {
        print_report(&report, true)
    } else {
        print(&report.table())
    }
}

pub fn ik(args: &BenchIkArgs) -> Result<(), Failure> {
    count_in(args.poses, "poses", MAX_POSES)?;
    let bar = progress_bar(1, "runs");
    bar.set_message("solving");
    let report = match args.robot.is_empty() {
        true => afford_kinematics::ik_benchmark(args.poses, args.common.seed)
            .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?,
        false => {
            let mut arms = Vec::new();
            for name in &args.robot {
                let model = afford_kinematics::RobotModel::load_with(
                    name,
                    std::path::Path::new("."),
                    &args.packages.paths(),
                )
                .map_err(|e| Failure::new(ExitKind::BadInput, e.to_string()))?;
                for arm in model.arms() {
                    arms.push(afford_kinematics::bench_arm(
                        model.name(),
                        arm,
                        args.poses,
                        args.common.seed,
                    ));
                }
            }
            afford_kinematics::IkBenchReport { arms }
        }
    };
    bar.finish_and_clear();
    if args.common.json {
        return print_report(&report, true);
    }
    let mut out = format!(
        "{:<12} {:<6} {:>7} {:>9} {:>11} {:>11} {:>13}\n",
        "robot", "arm", "poses", "success", "median µs", "k success", "k median µs"
    );
    for a in &report.arms {
        out += &format!(
            "{:<12} {:<6} {:>7} {:>8.2}% {:>11.1} {:>10.2}% {:>13.1}\n",
            a.robot,
            a.arm,
            a.poses,
            a.success_rate * 100.0,
            a.median_us,
            a.k_success_rate * 100.0,
            a.k_median_us
        );
    }
    print(&out)
}

pub fn collision(args: &BenchSeedArgs) -> Result<(), Failure> {
    note(format_args!(
        "afford: cross-checking 1,000 random paths against dense sampling…"
    ));
    let report = afford_collision::collision_benchmark(args.seed)
        .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    if args.json {
        return print_report(&report, true);
    }
    print(&format!(
        "random paths checked:          {}\n\
         collisions the fast check missed: {}\n\
         median ms, 1,000-configuration arm path: {:.3}\n\
         shape-pair queries per second:   {:.0}\n",
        report.paths,
        report.missed_collisions,
        report.median_ms_arm_path_1000,
        report.pair_queries_per_s
    ))
}

pub fn timing(args: &BenchSeedArgs) -> Result<(), Failure> {
    let report = timing_benchmark(&TimingBenchSettings {
        seed: args.seed,
        ..TimingBenchSettings::default()
    });
    print_report(&report, args.json)
}

pub fn pipeline(args: &BenchPipelineArgs) -> Result<(), Failure> {
    count_in(args.runs, "runs", MAX_RUNS)?;
    let scenario = load(args.scenario.as_deref())?;
    let options = PlanOptions {
        base_dir: base_dir(args.scenario.as_deref()),
        ..PlanOptions::default()
    };
    let bar = progress_bar(args.runs as u64, "runs");
    let report = afford_bench::pipeline::run(&scenario, &options, args.runs, |k| {
        bar.set_position(k as u64)
    })
    .map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    bar.finish_and_clear();
    print_report(&report, args.json)
}

pub fn safety(args: &BenchSafetyArgs) -> Result<(), Failure> {
    let seed = args.common.seed;
    count_in(args.scenarios, "scenarios", MAX_SCENES)?;
    if let Some(dir) = &args.write_scenes {
        write_scenes(dir, seed, args.scenarios)?;
    }
    let robots = Robots::load().map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))?;
    let outcomes = scenes_in_parallel(args.scenarios, |k| run_scene(&robots, seed, k, &recheck));
    let report = SafetyReport::of(seed, &outcomes);
    if args.common.json {
        print_report(&report, true)
    } else {
        print(&report.table())
    }
}

pub fn transits(args: &BenchTransitsArgs) -> Result<(), Failure> {
    let seed = args.common.seed;
    count_in(args.scenes, "scenes", MAX_SCENES)?;
    let outcomes = scenes_in_parallel(args.scenes, |k| {
        transits::run_scene(seed, transits::scene_index(k))
    });
    let report = transits::TransitBenchReport::of(seed, &outcomes);
    print_report(&report, args.common.json)
}

pub fn routes(args: &BenchRoutesArgs) -> Result<(), Failure> {
    let seed = args.common.seed;
    count_in(args.scenarios, "scenarios", MAX_SCENES)?;
    let measured = scenes_in_parallel(args.scenarios, |k| routes::run_scene(seed, k));
    let report = routes::RoutesReport::of(seed, args.scenarios, &measured);
    print_report(&report, args.common.json)
}

/// `run(k)` for scenes `0..count` in parallel under a progress bar,
/// collected in scene order: the result does not depend on the thread count.
fn scenes_in_parallel<T: Send>(count: usize, run: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let bar = progress_bar(count as u64, "scenes");
    let outcomes = (0..count)
        .into_par_iter()
        .map(|k| {
            let outcome = run(k);
            bar.inc(1);
            outcome
        })
        .collect();
    bar.finish_and_clear();
    outcomes
}

/// Most scenes a scene benchmark (`cql`, `safety`, `routes`, `transits`,
/// `monitor`) runs: its outcomes are held in memory (100,000 safety scenes
/// take about a day on 2 cores).
const MAX_SCENES: usize = 100_000;
/// Most `bench pipeline --runs` (each plans the whole scenario).
const MAX_RUNS: usize = 10_000;
/// Most `bench ik --poses` per arm (their solve times are held in memory).
const MAX_POSES: usize = 1_000_000;

/// A count option must lie in `1..=max` (a larger one overflowed a
/// vector's capacity, a panic): `--{flag} must be …`.
fn count_in(count: usize, flag: &str, max: usize) -> Result<(), Failure> {
    if (1..=max).contains(&count) {
        return Ok(());
    }
    Err(Failure::new(
        ExitKind::BadInput,
        format!("--{flag} must be between 1 and {max}, got {count}"),
    ))
}

/// Writes scenes `0..count` of the series `seed` as YAML scenario files.
fn write_scenes(dir: &std::path::Path, seed: u64, count: usize) -> Result<(), Failure> {
    let fail = |e: String| {
        Failure::new(
            ExitKind::BadInput,
            format!("--write-scenes {}: {e}", dir.display()),
        )
    };
    std::fs::create_dir_all(dir).map_err(|e| fail(e.to_string()))?;
    for k in 0..count {
        let text =
            serde_saphyr::to_string(&scenes::scene(seed, k)).map_err(|e| fail(e.to_string()))?;
        super::output::emit(&text, Some(&dir.join(format!("safety-{seed}-{k}.yaml"))))?;
    }
    Ok(())
}

/// The campaign's re-check of one plan: the independent checker
/// (`afford-check`, no code shared with the planner's own checks), in
/// memory, each violation a finding of its class.
fn recheck(scenario: &Scenario, robot: &RobotModel, plan: &Plan) -> Vec<Finding> {
    afford_check::check_plan(scenario, robot, &PlanFile::from(plan))
        .violations
        .into_iter()
        .map(|v| Finding {
            class: v.class.name().to_string(),
            subgoal: v.subgoal,
            message: v.message,
        })
        .collect()
}

/// A report as pretty JSON, or as indented YAML for people.
fn print_report<T: serde::Serialize>(report: &T, json: bool) -> Result<(), Failure> {
    let text = if json {
        serde_json::to_string_pretty(report).map_err(|e| e.to_string())
    } else {
        serde_saphyr::to_string(report).map_err(|e| e.to_string())
    };
    let text = text.map_err(|e| Failure::new(ExitKind::CouldNotPlan, e))?;
    print(&format!("{}\n", text.trim_end()))
}

/// A progress bar on stderr when it is a terminal, hidden otherwise.
fn progress_bar(len: u64, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let template = format!("{{bar:40}} {{pos}}/{{len}} {unit} ({{eta}} left)");
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

pub fn monitor(args: &BenchMonitorArgs) -> Result<(), Failure> {
    use afford_bench::monitor::{MonitorBenchConfig, ROBOT, Rechecked, run};
    use afford_planner::monitor::Monitor;
    count_in(args.scenes, "scenes", MAX_SCENES)?;
    let bar = progress_bar(args.scene.map_or(args.scenes, |_| 1) as u64, "scene pairs");
    let config = MonitorBenchConfig {
        scenes: args.scenes,
        seed: args.common.seed,
        only: args.scene,
    };
    let robots = [ROBOT, "care_o_bot4"].map(|name| {
        RobotModel::builtin(name).map_err(|e| Failure::new(ExitKind::CouldNotPlan, e.to_string()))
    });
    let robots: Vec<RobotModel> = robots.into_iter().collect::<Result<_, _>>()?;
    let recheck = |monitor: &Monitor| {
        let model = &monitor.scene().robot.model;
        let Some(robot) = robots.iter().find(|r| r.name() == model) else {
            return Rechecked {
                violations: vec![format!("no built-in robot {model}")],
                ..Rechecked::default()
            };
        };
        match executed::files(monitor, robot) {
            Ok(files) => {
                let people = executed::people(&files, monitor, robot);
                Rechecked {
                    violations: executed::check(&files, robot),
                    physics: executed::replay(&files, robot).failures(),
                    hand_contacts: people.hand_contacts,
                    perimeter_entries: people.perimeter_entries,
                    stops: people
                        .stops
                        .iter()
                        .map(|s| (s.travel_m, s.term_m))
                        .collect(),
                }
            }
            Err(e) => Rechecked {
                violations: vec![e],
                ..Rechecked::default()
            },
        }
    };
    let report = run(
        &config,
        |done| bar.set_position(done as u64),
        Some(&recheck),
    );
    bar.finish_and_clear();
    if args.common.json {
        return print_report(&report, true);
    }
    let mut out = format!(
        "relevant {} (detected {}), irrelevant {} (false triggers {})\nmedian observe {:.0} µs, median replan {:.1} ms\nexecutions re-checked {} ({} cut short by an abort): check failures {}, physics failures {}\n",
        report.relevant,
        report.detected,
        report.irrelevant,
        report.false_triggers,
        report.median_observe_us,
        report.median_replan_ms,
        report.physics_runs.unwrap_or(0),
        report.cut_short_runs.unwrap_or(0),
        report.check_failures.unwrap_or(0),
        report.physics_failures.unwrap_or(0),
    );
    for (kind, [n, triggered]) in &report.kinds {
        out += &format!("  {kind:<22} {n:>4} perturbations, {triggered:>4} triggered\n");
    }
    out += &format!("near people ({} panics):\n", report.panics);
    for (kind, p) in &report.people {
        out += &format!(
            "  {kind:<22} {:>4} executions: {} hand contacts, {} perimeter entries, {} stops (largest {:.2} of the term, longest {:.0} mm), {} wrong outcomes\n",
            p.executions,
            p.hand_contacts,
            p.perimeter_entries,
            p.stops,
            p.largest_stop_ratio,
            p.longest_stop_m * 1e3,
            p.wrong_outcomes
        );
    }
    print(&out)
}
