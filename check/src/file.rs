//! The plan file as the checker reads it: the parts of `afford plan`'s
//! output a robot executes (start state, per sub-goal the arm, its joint
//! names, the timed samples and the gripper events), read from JSON or YAML
//! with every size bounded before it is allocated.
//!
//! Bounds (checked while parsing, so an oversized file is refused before
//! more than its text is held): the text at most [`MAX_PLAN_BYTES`], at most
//! [`MAX_SUBGOALS`] sub-goals, [`MAX_SAMPLES`] samples in all,
//! [`MAX_JOINTS`] values per vector and [`MAX_GRIPPER_EVENTS`] gripper
//! events per sub-goal. Parsed values take at most about 8 bytes per byte
//! of text (a number of 2 characters becomes an 8-byte `f64`), so reading
//! a plan needs at most ~9 × [`MAX_PLAN_BYTES`] of memory.

use std::fmt;
use std::marker::PhantomData;

use afford_planner::trajectory::GripperEvent;
use serde::de::{self, DeserializeOwned, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

/// Largest plan file accepted, bytes (64 MiB: about 150,000 samples of a
/// 7-joint arm as `afford plan` writes them).
pub const MAX_PLAN_BYTES: usize = 64 << 20;
/// Most trajectory samples in one plan, all sub-goals together (at 100 Hz,
/// 33 minutes of motion).
pub const MAX_SAMPLES: usize = 200_000;
/// Most sub-goals in one plan.
pub const MAX_SUBGOALS: usize = 1_000;
/// Most values in one joint vector (joints of a robot).
pub const MAX_JOINTS: usize = 128;
/// Most gripper events in one sub-goal (a valid one has two).
pub const MAX_GRIPPER_EVENTS: usize = 16;

/// A plan as the checker reads it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanFile {
    /// The whole robot's joint state at t = 0.
    #[serde(default)]
    pub start_state: Option<StartState>,
    #[serde(deserialize_with = "bounded::<_, _, MAX_SUBGOALS>")]
    pub subgoals: Vec<SubgoalFile>,
}

/// The whole robot's joint state (positions only), robot joint order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartState {
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub joint_names: Vec<String>,
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub positions: Vec<f64>,
}

/// One sub-goal: which object goes to which goal, moved by which arm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubgoalFile {
    pub object: String,
    pub goal: String,
    pub arm: String,
    /// The arm's joints, in the order of every vector of the samples.
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub joint_names: Vec<String>,
    pub trajectory: TrajectoryFile,
    /// The execution stopped this sub-goal before its end (`afford run`
    /// after an abort): its gripper events are a prefix of close, open,
    /// and its object is placed only if the gripper opened. A sub-goal cut
    /// short ends the plan.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cut_short: bool,
}

/// Timed samples (linear in between) and gripper events.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryFile {
    #[serde(deserialize_with = "bounded::<_, _, MAX_SAMPLES>")]
    pub points: Vec<Sample>,
    #[serde(deserialize_with = "bounded::<_, _, MAX_GRIPPER_EVENTS>")]
    pub gripper: Vec<GripperEvent>,
}

/// One sample: rad (m for prismatic joints), rad/s, rad/s², s from the
/// sub-goal's start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub positions: Vec<f64>,
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub velocities: Vec<f64>,
    #[serde(deserialize_with = "bounded::<_, _, MAX_JOINTS>")]
    pub accelerations: Vec<f64>,
    pub time_from_start: f64,
}

/// A plan file that cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanFileError {
    #[error("the plan is {bytes} bytes, more than the {limit} bytes accepted")]
    TooLarge { bytes: usize, limit: usize },
    #[error("{samples} trajectory samples in all, more than the {limit} accepted")]
    TooManySamples { samples: usize, limit: usize },
    #[error("{}{message}{}", field_prefix(field), location(*line, *column))]
    Syntax {
        /// Field path, e.g. `subgoals[0].trajectory.points[3].positions`.
        field: String,
        message: String,
        line: Option<usize>,
        column: Option<usize>,
    },
}

fn field_prefix(field: &str) -> String {
    match field.is_empty() {
        true => String::new(),
        false => format!("{field}: "),
    }
}

fn location(line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!(" (line {l}, column {c})"),
        (Some(l), None) => format!(" (line {l})"),
        _ => String::new(),
    }
}

/// Reads a plan from JSON (text starting with `{`) or YAML, bounded as the
/// module says. Errors name the field and, where the parser knows it, the
/// line and column.
pub fn read_plan(text: &str) -> Result<PlanFile, PlanFileError> {
    if text.len() > MAX_PLAN_BYTES {
        return Err(PlanFileError::TooLarge {
            bytes: text.len(),
            limit: MAX_PLAN_BYTES,
        });
    }
    let plan: PlanFile = match text.trim_start().starts_with('{') {
        true => parse_json(text)?,
        false => parse_yaml(text)?,
    };
    let samples: usize = plan
        .subgoals
        .iter()
        .map(|s| s.trajectory.points.len())
        .sum();
    if samples > MAX_SAMPLES {
        return Err(PlanFileError::TooManySamples {
            samples,
            limit: MAX_SAMPLES,
        });
    }
    Ok(plan)
}

fn parse_json<T: DeserializeOwned>(text: &str) -> Result<T, PlanFileError> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner();
        let line = (inner.line() > 0).then_some(inner.line());
        PlanFileError::Syntax {
            field: clean_path(&field),
            message: strip_location(&inner.to_string()),
            line,
            column: line.map(|_| inner.column()),
        }
    })
}

fn parse_yaml<T: DeserializeOwned>(text: &str) -> Result<T, PlanFileError> {
    let mut field = String::new();
    let options = serde_saphyr::options! { with_snippet: false };
    let result = serde_saphyr::with_deserializer_from_str_with_options(text, options, |de| {
        serde_path_to_error::deserialize(de).map_err(|e| {
            field = e.path().to_string();
            e.into_inner()
        })
    });
    result.map_err(|e| {
        let at = e.location();
        PlanFileError::Syntax {
            field: clean_path(&field),
            message: strip_location(&e.to_string()),
            line: at.map(|l| l.line() as usize),
            column: at.map(|l| l.column() as usize),
        }
    })
}

/// serde_path_to_error writes `.` for the document root.
fn clean_path(path: &str) -> String {
    match path {
        "." | "?" => String::new(),
        _ => path.to_string(),
    }
}

/// Parsers append " at line L column C"; the error prints its own location.
fn strip_location(message: &str) -> String {
    match message.find(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

/// A sequence of at most `N` elements; refused as soon as element `N + 1`
/// appears, before it is allocated.
fn bounded<'de, D, T, const N: usize>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct Bounded<T, const N: usize>(PhantomData<T>);
    impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for Bounded<T, N> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "a list of at most {N} entries")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(N).min(4096));
            while let Some(value) = seq.next_element()? {
                if out.len() == N {
                    return Err(de::Error::custom(format!("more than {N} entries")));
                }
                out.push(value);
            }
            Ok(out)
        }
    }
    d.deserialize_seq(Bounded::<T, N>(PhantomData))
}

impl From<&afford_planner::Plan> for PlanFile {
    /// The plan as a file would hold it (no JSON round trip). A sub-goal
    /// without a trajectory (a plan stopped before the `trajectory` stage)
    /// becomes one without samples, which the check reports.
    fn from(plan: &afford_planner::Plan) -> Self {
        let subgoals = plan
            .subgoals
            .iter()
            .map(|s| SubgoalFile {
                object: s.object.clone(),
                goal: s.goal.clone(),
                arm: s.arm.clone().unwrap_or_default(),
                joint_names: s.joint_names.clone().unwrap_or_default(),
                trajectory: TrajectoryFile {
                    points: s
                        .trajectory
                        .iter()
                        .flat_map(|t| &t.points)
                        .map(|p| Sample {
                            positions: p.positions.clone(),
                            velocities: p.velocities.clone(),
                            accelerations: p.accelerations.clone(),
                            time_from_start: p.time_from_start,
                        })
                        .collect(),
                    gripper: s
                        .trajectory
                        .as_ref()
                        .map_or_else(Vec::new, |t| t.gripper.clone()),
                },
                cut_short: false,
            })
            .collect();
        Self {
            start_state: plan.start_state.as_ref().map(|s| StartState {
                joint_names: s.joint_names.clone(),
                positions: s.positions.clone(),
            }),
            subgoals,
        }
    }
}

/// One joint's samples along `q(t)` at `times`, with velocity and
/// acceleration fields 0 (the checks under test recompute them).
#[cfg(test)]
pub(crate) fn one_joint_samples(q: impl Fn(f64) -> f64, times: &[f64]) -> Vec<Sample> {
    times
        .iter()
        .map(|&t| Sample {
            positions: vec![q(t)],
            velocities: vec![0.0],
            accelerations: vec![0.0],
            time_from_start: t,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: &str = r#"{"start_state": {"joint_names": ["a"], "positions": [0.0]},
        "subgoals": [{"object": "o", "goal": "g", "arm": "arm", "joint_names": ["a"],
        "trajectory": {"points": [{"positions": [0.0], "velocities": [0.0],
        "accelerations": [0.0], "time_from_start": 0.0}],
        "gripper": [{"command": "close", "start": 0.0, "end": 0.0}]}}]}"#;

    #[test]
    fn reads_json_and_yaml_alike() {
        let json = read_plan(ONE).unwrap();
        let yaml = read_plan(&serde_saphyr::to_string(&json).unwrap()).unwrap();
        assert_eq!(json, yaml);
        assert_eq!(json.subgoals[0].trajectory.points.len(), 1);
    }

    #[test]
    fn a_missing_field_is_named() {
        let text = ONE.replace(r#""time_from_start": 0.0"#, r#""time": 0.0"#);
        let e = read_plan(&text).unwrap_err().to_string();
        assert!(e.contains("subgoals[0].trajectory.points[0]"), "{e}");
        assert!(e.contains("time_from_start"), "{e}");
    }

    #[test]
    fn an_oversized_joint_vector_is_refused_while_parsing() {
        let values = vec!["0.0"; MAX_JOINTS + 1].join(",");
        let text = ONE.replacen(
            r#""positions": [0.0]"#,
            &format!(r#""positions": [{values}]"#),
            2,
        );
        let e = read_plan(&text).unwrap_err().to_string();
        assert!(e.contains("more than 128 entries"), "{e}");
        assert!(e.contains("positions"), "{e}");
    }

    #[test]
    fn an_oversized_file_is_refused_before_parsing() {
        let text = " ".repeat(MAX_PLAN_BYTES + 1);
        assert!(matches!(
            read_plan(&text),
            Err(PlanFileError::TooLarge { .. })
        ));
    }
}
