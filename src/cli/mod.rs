//! Command-line interface: argument definitions and one function per command.

mod bench;
mod check;
mod executed;
mod export;
pub mod output;
mod plan;
mod robots;
mod robots_init;
mod run;
mod run_svg;
mod summary;
mod validate;

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

/// afford — from an overhead camera scene and a spoken instruction to robot plans.
#[derive(Debug, Parser)]
#[command(name = "afford", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Plan a scenario (the embedded default scenario when no file is given).
    Plan(PlanArgs),
    /// Parse a scenario and explain it (objects, margins, sub-goals, grids) without planning.
    Validate(ValidateArgs),
    /// Re-check a plan file (the output of `afford plan`) against its scenario with an independent checker; exit 0 pass, 1 violations, 2 bad input.
    Check(CheckArgs),
    /// List the built-in robots with their arms, degrees of freedom and reach;
    /// `afford robots acm ROBOT` derives a robot's allowed-collision matrix.
    Robots(RobotsArgs),
    /// Execute a scenario's plan against its observation timeline with the valid-policy detector: wait, slow, replan, take new work; writes the executed timeline and the event log.
    Run(RunArgs),
    /// Run a benchmark.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Write the grid MDPs afford's learner solves (one JSON per sub-goal or generated scene; docs/mdp-export.md), for outside learners.
    ExportMdp(ExportMdpArgs),
}

#[derive(Debug, clap::Args)]
pub struct ExportMdpArgs {
    /// Scenario file: one MDP per sub-goal, on the scene as it is now; omitted (and no --generated): the built-in default scenario.
    #[arg(conflicts_with = "generated")]
    pub scenario: Option<PathBuf>,
    /// Export scenes 0..N of the benchmark's generator instead (the scenes of `afford bench cql`).
    #[arg(long, value_name = "N")]
    pub generated: Option<usize>,
    /// Seed of the generated series and of afford's learner.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// With --generated: also record CQL's and QL's training steps, wall and CPU time (not reproducible byte for byte).
    #[arg(long)]
    pub learner_stats: bool,
    /// Folder to write the files to (created when missing).
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Scenario file with an optional `observations:` timeline; omitted: the built-in default scenario.
    pub scenario: Option<PathBuf>,
    /// Seed for every random choice; same scenario + seed gives byte-identical output (without --timings).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output format: json, yaml or csv (one row per executed sample).
    #[arg(long, value_parser = run_format, default_value = "json")]
    pub format: OutputFormat,
    /// Write the executed run to this file instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also draw the executed run and its events as an SVG picture.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Controller sampling rate, Hz.
    #[arg(long, default_value_t = 100.0)]
    pub rate: f64,
    /// Add each decision's wall-clock time (µs) and replan time (ms) to the events: the output is then no longer reproducible.
    #[arg(long)]
    pub timings: bool,
    #[command(flatten)]
    pub packages: PackageArgs,
}

#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// Scenario file (.yaml, .yml or .json); omitted: the built-in default scenario.
    pub scenario: Option<PathBuf>,
    /// Seed for every random choice; same scenario + same seed gives byte-identical output.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output format [default: summary on a terminal, json when piped or
    /// written with -o].
    #[arg(long, value_enum)]
    pub format: Option<OutputFormat>,
    /// Write the plan to this file instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also draw the plan as an SVG picture: top view (grid, perimeters, paths, arm) and joint curves against their limits.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Controller sampling rate of the trajectory, Hz.
    #[arg(long, default_value_t = 100.0)]
    pub rate: f64,
    /// Stop the pipeline after this stage and print what exists so far.
    #[arg(long, value_enum, default_value_t = Until::Trajectory)]
    pub until: Until,
    #[command(flatten)]
    pub packages: PackageArgs,
}

/// The pipeline stages `--until` accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Until {
    /// Sub-goals, state grids and CQL plans.
    Grid,
    /// Plus tool waypoints in the robot base frame.
    Waypoints,
    /// Plus the arm choice and its collision-checked joint path.
    Joints,
    /// Plus the timed joint trajectory (the whole pipeline).
    Trajectory,
}

impl From<Until> for afford_planner::Stage {
    fn from(until: Until) -> Self {
        match until {
            Until::Grid => Self::Grid,
            Until::Waypoints => Self::Waypoints,
            Until::Joints => Self::Joints,
            Until::Trajectory => Self::Trajectory,
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// The scenario the trajectories were planned for.
    pub scenario: PathBuf,
    /// The plan file with trajectories (JSON or YAML), as written by `afford plan`.
    pub plan: PathBuf,
    /// Print the verdict and every violation as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also replay the plan physically (rapier3d): pieces pushed or dropped
    /// outside their goal and links touching a hand, the table or a piece are
    /// `physics` violations.
    #[arg(long)]
    pub physics: bool,
    #[command(flatten)]
    pub packages: PackageArgs,
}

#[derive(Debug, clap::Args)]
pub struct RobotsArgs {
    #[command(subcommand)]
    pub command: Option<RobotsCommand>,
    /// Print the list as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum RobotsCommand {
    /// Derive the allowed-collision matrix (which link pairs the self-collision check skips) from
    /// the robot's geometry and print the `allowed_collisions:` block for its description file.
    Acm(AcmArgs),
    /// Draft a complete robot description from a URDF (and MoveIt SRDF): arms, tool, gripper, limits, home and park, the allowed-collision matrix and a tabletop camera set-up; every guess is a line on stderr.
    Init(RobotsInitArgs),
    /// Measure a robot description: reach over its table region, self-collision at home and park, IK success on random reachable poses, and how far its meshes lie outside the collision model (exit 1 above the tolerance).
    Check(RobotsCheckArgs),
}

#[derive(Debug, clap::Args)]
pub struct RobotsInitArgs {
    /// The robot's URDF.
    pub urdf: PathBuf,
    /// Its MoveIt SRDF: planning groups, end effector, group states, disabled collisions.
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<PathBuf>,
    /// The description file to write (a regular file, replaced whole); omitted: standard output, paths relative to the current folder.
    #[arg(short, long, value_name = "DESCRIPTION")]
    pub output: Option<PathBuf>,
    /// Also write the default scenario (`afford plan`'s) for this robot and its camera set-up to this file.
    #[arg(long, value_name = "FILE")]
    pub scenario: Option<PathBuf>,
    /// Random configurations the allowed-collision matrix is derived from.
    #[arg(long, default_value_t = afford_collision::AcmSettings::default().samples)]
    pub samples: u64,
    /// Keep the bare flange as the tool when the URDF has no gripper (by default afford's assumed gripper is mounted in a copy of the URDF beside the description).
    #[arg(long)]
    pub no_assumed_gripper: bool,
    #[command(flatten)]
    pub packages: PackageArgs,
}

#[derive(Debug, clap::Args)]
pub struct RobotsCheckArgs {
    /// The robot description file (.yaml).
    pub description: PathBuf,
    /// Random reachable poses per arm for the IK success rate.
    #[arg(long, default_value_t = 1000)]
    pub poses: usize,
    /// Seed of the random poses and IK starts.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub packages: PackageArgs,
}

#[derive(Debug, clap::Args)]
pub struct AcmArgs {
    /// A built-in robot name or a robot description file (.yaml, or a .urdf with its .yaml beside it).
    pub robot: String,
    /// Random configurations to sample (uniform within the joint limits).
    #[arg(long, default_value_t = afford_collision::AcmSettings::default().samples)]
    pub samples: u64,
    /// Seed of the sampler.
    #[arg(long, default_value_t = afford_collision::AcmSettings::default().seed)]
    pub seed: u64,
    /// A pair is skipped as `never` only when it stays farther apart than this in every sample, metres.
    #[arg(long, default_value_t = afford_collision::AcmSettings::default().clearance)]
    pub clearance: f64,
    #[command(flatten)]
    pub packages: PackageArgs,
}

#[derive(Debug, clap::Args)]
pub struct ValidateArgs {
    /// Scenario file (.yaml, .yml or .json); omitted: the built-in default scenario.
    pub scenario: Option<PathBuf>,
    /// Seed for instructions that choose at random ("some", "two of them").
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub packages: PackageArgs,
}

/// `--package-path DIR` (repeatable), on every command that loads a robot.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PackageArgs {
    /// A folder to look for `package://NAME` meshes in (the folder NAME itself or one holding a sub-folder NAME), before ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and the URDF's folders; repeatable.
    #[arg(long = "package-path", value_name = "DIR")]
    pub package_path: Vec<PathBuf>,
}

impl PackageArgs {
    /// The package search path: these folders first, then the environment's.
    pub fn paths(&self) -> afford_kinematics::PackagePaths {
        afford_kinematics::PackagePaths::new(self.package_path.clone())
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    Json,
    Yaml,
    /// One row per trajectory sample.
    Csv,
    /// A few lines for a person (`afford plan` only).
    Summary,
}

/// `afford run --format`: json, yaml or csv. The summary is `afford
/// plan`'s only (it was accepted and printed YAML).
fn run_format(text: &str) -> Result<OutputFormat, String> {
    match OutputFormat::from_str(text, true)? {
        OutputFormat::Summary => {
            Err("`summary` is for `afford plan`; `afford run` writes json, yaml or csv".into())
        }
        format => Ok(format),
    }
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// CQL against plain Q-learning on seeded scenes, measured against the BFS oracle (the paper's Table 1).
    Cql(BenchCqlArgs),
    /// Inverse kinematics of every built-in arm on random reachable poses, afford's solver beside k's.
    Ik(BenchIkArgs),
    /// Collision checks: the fast continuous check against dense sampling on random paths, and its speed.
    Collision(BenchSeedArgs),
    /// Time-optimal path parameterisation: the examples' real paths against the exact reference (ratio, jerk cost, reversals, jerk ratio) and seeded 7-joint paths (speed).
    Timing(BenchSeedArgs),
    /// The whole pipeline on a scenario (default: the embedded one), stage by stage.
    Pipeline(BenchPipelineArgs),
    /// The safety campaign: random scenes for both robots, planned and every trajectory re-checked.
    Safety(BenchSafetyArgs),
    /// Care-O-bot campaign scenes: each sub-goal planned alone, then the instruction chained.
    Transits(BenchTransitsArgs),
    /// Planned tool routes on the safety campaign's scenes against the shortest any-angle paths around the perimeters.
    Routes(BenchRoutesArgs),
    /// The valid-policy detector on seeded planned scenes, both robots: perturbations relevant or irrelevant by construction, and adversarial ones (tall and flickering hands ahead of the tool, jitter); every execution re-checked (independent check, physical replay, hand check, stops against the stopping term).
    Monitor(BenchMonitorArgs),
}

#[derive(Debug, clap::Args)]
pub struct BenchTransitsArgs {
    /// Number of Care-O-bot scenes (the odd scenes of the safety campaign's series).
    #[arg(long, default_value_t = 200)]
    pub scenes: usize,
    #[command(flatten)]
    pub common: BenchSeedArgs,
}

#[derive(Debug, clap::Args)]
pub struct BenchRoutesArgs {
    /// Number of generated scenes (the safety campaign's series).
    #[arg(long, default_value_t = 200)]
    pub scenarios: usize,
    #[command(flatten)]
    pub common: BenchSeedArgs,
}

#[derive(Debug, clap::Args)]
pub struct BenchMonitorArgs {
    /// Scene pairs (a KUKA scene and a Care-O-bot scene each) to plan and perturb: four moments of the perturbations by construction, six of the adversarial ones.
    #[arg(long, default_value_t = afford_bench::monitor::MonitorBenchConfig::default().scenes)]
    pub scenes: usize,
    /// Run scene pair K alone (0-based; the same scenes as in a full run).
    #[arg(long, value_name = "K")]
    pub scene: Option<usize>,
    #[command(flatten)]
    pub common: BenchSeedArgs,
}

#[derive(Debug, clap::Args)]
pub struct BenchSafetyArgs {
    /// Number of generated scenes (even ones kuka_iiwa14, odd ones care_o_bot4).
    #[arg(long, default_value_t = 100)]
    pub scenarios: usize,
    #[command(flatten)]
    pub common: BenchSeedArgs,
    /// Also write every generated scene to this folder as `safety-SEED-K.yaml`, to replay one with `afford plan`.
    #[arg(long, value_name = "DIR")]
    pub write_scenes: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub struct BenchPipelineArgs {
    /// Scenario file; omitted: the built-in default scenario.
    pub scenario: Option<PathBuf>,
    /// Repetitions.
    #[arg(long, default_value_t = 21)]
    pub runs: usize,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The options every seeded benchmark takes.
#[derive(Debug, clap::Args)]
pub struct BenchSeedArgs {
    /// Seed of the benchmark's random draws (scenes, paths, poses, learners); same seed, same report (wall-clock times aside).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, clap::Args)]
pub struct BenchIkArgs {
    /// Random reachable poses per arm.
    #[arg(long, default_value_t = 10_000)]
    pub poses: usize,
    /// Measure this robot (a built-in name or a description file) instead of the built-in ones; repeatable.
    #[arg(long, value_name = "ROBOT")]
    pub robot: Vec<String>,
    #[command(flatten)]
    pub packages: PackageArgs,
    #[command(flatten)]
    pub common: BenchSeedArgs,
}

#[derive(Debug, clap::Args)]
pub struct BenchCqlArgs {
    /// Number of generated scenes.
    #[arg(long, default_value_t = 100)]
    pub scenarios: usize,
    #[command(flatten)]
    pub common: BenchSeedArgs,
}

/// A command's failure: exit code and the message for stderr.
#[derive(Debug)]
pub struct Failure {
    pub code: ExitKind,
    pub message: String,
}

/// Documented exit codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitKind {
    /// 1: the input was fine but no plan could be made.
    CouldNotPlan = 1,
    /// 2: bad input (unreadable or invalid scenario, bad arguments).
    BadInput = 2,
    /// 3: the result could not be written (standard output, or the file of
    /// `-o`/`--svg`: a full disk, a missing folder, a path that is a
    /// folder, a socket or a block device).
    Output = 3,
}

impl Failure {
    pub fn new(code: ExitKind, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }
}

pub fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Plan(args) => plan::run(&args),
        Command::Validate(args) => validate::run(&args),
        Command::Robots(RobotsArgs {
            command: Some(RobotsCommand::Acm(args)),
            ..
        }) => robots::acm(&args),
        Command::Robots(RobotsArgs {
            command: Some(RobotsCommand::Init(args)),
            ..
        }) => robots_init::init(&args),
        Command::Robots(RobotsArgs {
            command: Some(RobotsCommand::Check(args)),
            ..
        }) => robots_init::check(&args),
        Command::Robots(args) => robots::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Run(args) => run::run(&args),
        Command::Bench(BenchCommand::Cql(args)) => bench::cql(&args),
        Command::Bench(BenchCommand::Ik(args)) => bench::ik(&args),
        Command::Bench(BenchCommand::Collision(args)) => bench::collision(&args),
        Command::Bench(BenchCommand::Timing(args)) => bench::timing(&args),
        Command::Bench(BenchCommand::Pipeline(args)) => bench::pipeline(&args),
        Command::Bench(BenchCommand::Safety(args)) => bench::safety(&args),
        Command::Bench(BenchCommand::Transits(args)) => bench::transits(&args),
        Command::ExportMdp(args) => export::run(&args),
        Command::Bench(BenchCommand::Routes(args)) => bench::routes(&args),
        Command::Bench(BenchCommand::Monitor(args)) => bench::monitor(&args),
    }
}
