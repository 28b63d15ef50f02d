//! Reading scenario files: YAML or JSON by extension, parsed with serde and
//! then validated. Errors name the file, the field path and, where the parser
//! gives it, the line and column.

use std::cell::RefCell;
use std::io::Read;
use std::path::Path;

use serde::de::DeserializeOwned;

use super::bounds::MAX_FILE_BYTES;
use super::{Scenario, validate};
use crate::error::{FieldIssue, ScenarioError};

/// Text format of a scenario file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Yaml,
    Json,
}

impl Format {
    /// The format a file name's extension stands for.
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "yaml" | "yml" => Some(Self::Yaml),
            "json" => Some(Self::Json),
            _ => None,
        }
    }
}

/// Reads, parses and validates the scenario at `path`.
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    let file = path.display().to_string();
    let format =
        Format::from_path(path).ok_or_else(|| ScenarioError::Extension { file: file.clone() })?;
    let io = |e: std::io::Error| ScenarioError::Io {
        file: file.clone(),
        message: match e.kind() {
            std::io::ErrorKind::InvalidData => {
                "the file is not UTF-8 text (save it as UTF-8; UTF-16 and Latin-1 are not read)"
                    .to_string()
            }
            _ => e.to_string(),
        },
    };
    // Read one byte more than allowed: a larger file is refused unread.
    let mut text = String::new();
    afford_kinematics::open_regular(path)
        .map_err(io)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(io)?;
    parse(&text, format, &file)
}

/// Validates a scenario built in code (parsing validates files already);
/// `file` names it in the error.
pub fn check(scenario: &Scenario, file: &str) -> Result<(), ScenarioError> {
    let issues = validate::validate(scenario);
    if issues.is_empty() {
        Ok(())
    } else {
        Err(ScenarioError::Invalid {
            file: file.to_string(),
            issues,
        })
    }
}

/// Parses and validates scenario text; `file` is the name used in errors.
/// Text longer than [`MAX_FILE_BYTES`] is refused before parsing. A leading
/// UTF-8 byte-order mark (Windows editors write one) is skipped: the JSON
/// reader stopped at it with "expected value" at 1:1.
pub fn parse(text: &str, format: Format, file: &str) -> Result<Scenario, ScenarioError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(ScenarioError::Parse {
            file: file.to_string(),
            issue: FieldIssue::new(
                "",
                format!(
                    "the file is larger than {MAX_FILE_BYTES} bytes, the largest scenario read"
                ),
            ),
            line: None,
            column: None,
        });
    }
    let scenario: Scenario = match format {
        Format::Json => parse_json(text, file)?,
        Format::Yaml => parse_yaml(text, file)?,
    };
    check(&scenario, file)?;
    Ok(scenario)
}

fn parse_json<T: DeserializeOwned>(text: &str, file: &str) -> Result<T, ScenarioError> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = field_path(e.path());
        let inner = e.into_inner();
        let (line, column) = (inner.line() as u64, inner.column() as u64);
        let message = strip_location(&inner.to_string());
        ScenarioError::Parse {
            file: file.to_string(),
            issue: FieldIssue::new(field, message),
            line: (line > 0).then_some(line),
            column: (line > 0).then_some(column),
        }
    })
}

fn parse_yaml<T: DeserializeOwned>(text: &str, file: &str) -> Result<T, ScenarioError> {
    let path = RefCell::new(String::new());
    let options = serde_saphyr::options! { with_snippet: false };
    let result = serde_saphyr::with_deserializer_from_str_with_options(text, options, |de| {
        serde_path_to_error::deserialize(de).map_err(|e| {
            *path.borrow_mut() = field_path(e.path());
            e.into_inner()
        })
    });
    result.map_err(|e| {
        let location = e.location();
        ScenarioError::Parse {
            file: file.to_string(),
            issue: FieldIssue::new(path.into_inner(), yaml_message(&e)),
            line: location.map(|l| l.line()),
            column: location.map(|l| l.column()),
        }
    })
}

/// The YAML reader's error in a scenario author's terms: its duplicate-key
/// and size-budget errors name the reader's own options and types
/// ("DuplicateKeyPolicy", "budget breached: Nodes { .. }").
fn yaml_message(e: &serde_saphyr::Error) -> String {
    use serde_saphyr::Error as E;
    match e {
        E::DuplicateMappingKey { key: Some(k), .. } => {
            format!("`{k}` is given twice (a duplicate key); give each field once")
        }
        E::DuplicateMappingKey { key: None, .. } => {
            "a field is given twice (a duplicate key); give each field once".to_string()
        }
        E::InvalidScalar { ty, .. } => match integer_max(ty) {
            Some(max) => format!(
                "invalid number: must be a whole number from 0 to {max} (no sign, no fraction, no exponent)"
            ),
            None => format!("is not a valid {ty}"),
        },
        E::Budget { breach, .. } => format!(
            "the file is too large for a scenario: {}",
            budget_breach(breach)
        ),
        other => strip_location(&other.to_string()),
    }
}

/// The largest value of an unsigned integer type named by the YAML reader
/// ("invalid u32" told a user neither the type's meaning nor its range).
fn integer_max(ty: &str) -> Option<u64> {
    match ty {
        "u8" => Some(u8::MAX.into()),
        "u16" => Some(u16::MAX.into()),
        "u32" => Some(u32::MAX.into()),
        "u64" | "usize" => Some(u64::MAX),
        _ => None,
    }
}

/// Which of the YAML reader's size limits a file broke, in words.
fn budget_breach(breach: &serde_saphyr::budget::BudgetBreach) -> String {
    use serde_saphyr::budget::BudgetBreach as B;
    match breach {
        B::Nodes { nodes } => format!(
            "more than {} values (lists, mappings and scalars)",
            nodes - 1
        ),
        B::Depth { depth } => format!("lists or mappings nested {depth} deep"),
        B::Aliases { aliases } => format!("{aliases} alias references (*name)"),
        B::Anchors { anchors } => format!("{anchors} anchors (&name)"),
        B::Events { events } => format!("more than {} YAML events", events - 1),
        B::Documents { documents } => format!("{documents} YAML documents; a scenario is one"),
        other => format!("a YAML size limit ({})", breach_name(other)),
    }
}

/// The limit's name without its counters ("ScalarBytes").
fn breach_name(breach: &serde_saphyr::budget::BudgetBreach) -> String {
    let debug = format!("{breach:?}");
    debug
        .split(|c: char| !c.is_alphanumeric())
        .next()
        .unwrap_or_default()
        .to_string()
}

/// `objects[2].box` style path; empty at the document root.
fn field_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(key);
            }
            Segment::Unknown => {}
        }
    }
    out
}

/// Parsers append " at line L column C"; the error prints its own location.
fn strip_location(message: &str) -> String {
    match message.find(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}
