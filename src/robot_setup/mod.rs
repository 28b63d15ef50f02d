//! Bringing up a robot of one's own: `afford robots init` (a robot
//! description drafted from a URDF and SRDF, [`init`]) and `afford robots
//! check` (reach, postures, IK, mesh coverage, [`check`]). Library code, no
//! clap: the command in `src/cli/robots_init.rs` is a thin wrapper.
//!
//! - `reach`: tool-down reach of a table point, collision-free (shared).
//! - `table`: the suggested tabletop set-up (camera calibration).
//! - `postures`: home and park.
//! - `acm_diff`: the derived allowed-collision matrix against the SRDF's.
//! - `check`, `coverage`: the checks of `robots check`.

mod acm_diff;
pub mod check;
pub mod coverage;
pub mod postures;
pub mod reach;
pub mod table;

use std::fmt::Write;
use std::path::{Path, PathBuf};

use afford_collision::{AcmSettings, AllowedCollisionMatrix};
use afford_kinematics::draft::mount;
use afford_kinematics::{CameraSetup, PackagePaths, RobotModel};

/// What `init` reads and where the description will be.
#[derive(Debug, Clone)]
pub struct InitOptions {
    pub urdf: PathBuf,
    pub srdf: Option<PathBuf>,
    /// The description file to be written (relative paths in it start at
    /// its folder).
    pub output: PathBuf,
    pub packages: PackagePaths,
    /// Samples of the allowed-collision matrix.
    pub acm: AcmSettings,
    /// Mount afford's assumed gripper when the URDF has no fingers below
    /// the tool (written into a copy of the URDF beside the description).
    pub assume_gripper: bool,
}

/// The drafted description and what was guessed.
#[derive(Debug, Clone)]
pub struct InitReport {
    /// The description text (loads as it is).
    pub description: String,
    /// One line per guess.
    pub guesses: Vec<String>,
    /// How the SRDF's disabled pairs differ from the derived matrix.
    pub srdf_differences: Vec<String>,
    pub camera: Option<CameraSetup>,
    /// The loaded model of the description.
    pub model: RobotModel,
    /// The copy of the URDF with the assumed gripper, to be written where
    /// the description names it.
    pub derived_urdf: Option<(PathBuf, String)>,
}

/// Drafts the description (see the module docs and the robots guide).
pub fn init(o: &InitOptions) -> Result<InitReport, String> {
    let e = |e: afford_kinematics::KinematicsError| e.to_string();
    let mut draft =
        afford_kinematics::draft::draft(&o.urdf, o.srdf.as_deref(), &o.packages).map_err(e)?;
    let dir = o
        .output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut urdf_text = afford_kinematics::read_text(&o.urdf).map_err(e)?;
    let mut urdf_path = o.urdf.clone();
    let mut derived_urdf = None;
    let approach_ok = (draft.approach)
        .is_some_and(|a| a.z.acos() <= afford_kinematics::draft::APPROACH_TOLERANCE_RAD);
    if o.assume_gripper && draft.gripper.fingers.is_empty() && approach_ok {
        let path = o.output.with_extension("urdf");
        if same_file(&path, &o.urdf) {
            return Err(format!(
                "{}: the URDF with the assumed gripper would replace the URDF read; name the description elsewhere",
                path.display()
            ));
        }
        let text =
            mount::with_assumed_gripper(&urdf_text, &o.urdf, &o.packages, &draft.arms[0].tool)
                .map_err(e)?;
        let mut redrafted =
            afford_kinematics::draft::draft_text(&text, &path, o.srdf.as_deref(), &o.packages)
                .map_err(e)?;
        redrafted.use_assumed_gripper(&path);
        draft = redrafted;
        (urdf_text, urdf_path) = (text.clone(), path.clone());
        derived_urdf = Some((path, text));
    }
    let load = |text: &str| {
        RobotModel::from_texts_with(text, &o.output, &urdf_text, &urdf_path, &o.packages).map_err(e)
    };
    let first = afford_kinematics::draft::Postures {
        home: draft.finger_open.clone().into_iter().collect(),
        ..Default::default()
    };
    let model = load(&draft.to_yaml(dir, &first))?;
    let mut guesses = std::mem::take(&mut draft.guesses);
    let camera = table::suggest(&model)?;
    match &camera {
        Some(c) => guesses.push(format!(
            "camera: a 640 x 480 image over x {:.3} .. {:.3}, y -{:.3} .. {:.3} at table_z {} ({:.3} mm per pixel): the largest region reached tool-down at 0.05 and 0.25 m above the table",
            c.pixel_to_base[0][2] + c.pixel_to_base[0][1] * 480.0,
            c.pixel_to_base[0][2],
            c.pixel_to_base[1][2],
            c.pixel_to_base[1][2],
            c.table_z,
            -c.pixel_to_base[0][1] * 1000.0
        )),
        None => guesses.push("camera: no table region in reach was found; no camera written (give one in the scenario)".into()),
    }
    let postures = postures::choose(&model, &draft, camera.as_ref(), &mut guesses)?;
    let mut text = draft.to_yaml(dir, &postures);
    if let Some(c) = &camera {
        text.push_str(&camera_yaml(c));
    }
    let model = load(&text)?;
    let matrix = AllowedCollisionMatrix::derive(&model, &o.acm)
        .map_err(|e| format!("allowed-collision matrix: {e}"))?;
    text.push_str(&matrix.to_yaml());
    let srdf_differences = acm_diff::differences(&draft.disabled, &matrix);
    let model = load(&text)?;
    Ok(InitReport {
        description: text,
        guesses,
        srdf_differences,
        camera,
        model,
        derived_urdf,
    })
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// The `camera:` section.
pub fn camera_yaml(c: &CameraSetup) -> String {
    let m = &c.pixel_to_base;
    let mut y = String::new();
    let _ = writeln!(
        y,
        "# The suggested tabletop set-up, a scenario's `camera:` block (afford robots init)."
    );
    let _ = writeln!(y, "camera:\n  width: {}\n  height: {}", c.width, c.height);
    let _ = writeln!(
        y,
        "  pixel_to_base: [[{}, {}, {}], [{}, {}, {}]]",
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2]
    );
    let _ = writeln!(y, "  table_z: {}", c.table_z);
    y
}

/// The default scenario (`afford plan` with no file) for this robot: its
/// `robot.model` the description at `description` (relative to the
/// scenario's folder `dir`), its camera `camera`.
pub fn default_scenario(description: &Path, dir: &Path, camera: &CameraSetup) -> String {
    let model = afford_kinematics::draft::relative(description, dir);
    let m = &camera.pixel_to_base;
    let mut out = String::new();
    for line in afford_planner::scenario::DEFAULT_SCENARIO.lines() {
        let t = line.trim_start();
        let replaced = if t.starts_with("pixel_to_base:") {
            format!(
                "  pixel_to_base: [[{}, {}, {}], [{}, {}, {}]]",
                m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2]
            )
        } else if t.starts_with("table_z:") {
            format!("  table_z: {}", camera.table_z)
        } else if t.starts_with("model:") {
            format!("  model: '{}'", model.to_string_lossy().replace('\'', "''"))
        } else {
            line.to_string()
        };
        out.push_str(&replaced);
        out.push('\n');
    }
    out
}
