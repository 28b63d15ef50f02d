//! Serialising results and writing them whole: a file is written to a
//! temporary sibling and renamed, so no reader ever sees half a plan.

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use super::{ExitKind, Failure, OutputFormat};

pub fn render<T: Serialize>(value: &T, format: OutputFormat) -> Result<String, Failure> {
    let text = match format {
        OutputFormat::Json => serde_json::to_string_pretty(value).map_err(|e| e.to_string()),
        OutputFormat::Yaml => serde_saphyr::to_string(value).map_err(|e| e.to_string()),
    };
    text.map(|t| if t.ends_with('\n') { t } else { t + "\n" })
        .map_err(|e| {
            Failure::new(
                ExitKind::CouldNotPlan,
                format!("cannot serialise the result: {e}"),
            )
        })
}

/// Writes `text` to `path` atomically, or to stdout when `path` is `None`.
pub fn emit(text: &str, path: Option<&Path>) -> Result<(), Failure> {
    let Some(path) = path else {
        std::io::stdout().write_all(text.as_bytes()).map_err(|e| {
            Failure::new(
                ExitKind::CouldNotPlan,
                format!("cannot write to standard output: {e}"),
            )
        })?;
        return Ok(());
    };
    let bad = |e: std::io::Error| {
        Failure::new(
            ExitKind::BadInput,
            format!("{}: cannot write: {e}", path.display()),
        )
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    std::fs::write(&tmp, text).map_err(bad)?;
    std::fs::rename(&tmp, path).map_err(bad)
}
