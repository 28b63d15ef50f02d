//! The safety guard: an instruction is never executed against a word it
//! holds. Two checks, independent of how the parser reads phrases:
//! 1. every word must have been consumed by a construct the parser
//!    understands; a negation or exclusion word left over ("not", "never",
//!    "except", …) or a spatial relation ("next to", "behind", …) refuses
//!    the instruction with its reason, and so does any other word left over;
//! 2. no resolved (object, goal) pair may be one the instruction forbids.

use super::lexicon::{NEGATIONS, RELATIONS};
use super::tokens::{Tok, Token};
use crate::error::InstructionError;
use crate::scenario::Scenario;

/// Check 1: refuses the words no construct consumed. A negation or a
/// relation outranks `parse_error` (it is the cause); `parse_error`
/// outranks other unknown words.
pub(super) fn consumed(
    s: &Scenario,
    tokens: &[Tok],
    used: &[bool],
    parse_error: Option<InstructionError>,
) -> Result<(), InstructionError> {
    let left: Vec<&Tok> = tokens
        .iter()
        .filter(|t| !used[t.at] && t.token != Token::Break)
        .collect();
    if let Some(t) = left.iter().find(|t| t.is_in(NEGATIONS)) {
        return Err(InstructionError::new(format!(
            "\"{}\" negates or excludes in a way afford cannot read (in \"{}\"), so it refuses rather than risk doing the opposite; to leave objects out say \"… except the red ones …\" or \"… and leave the red square\"",
            t.text(s),
            context(s, tokens, t.at)
        )));
    }
    if let Some(t) = left.iter().find(|t| t.is_in(RELATIONS)) {
        return Err(InstructionError::new(format!(
            "\"{}\" is a spatial relation afford cannot do: it only puts objects into a goal ({})",
            relation(s, tokens, t.at),
            s.goals
                .iter()
                .map(|g| g.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    if let Some(e) = parse_error {
        return Err(e);
    }
    if !left.is_empty() {
        let words: Vec<String> = left.iter().map(|t| format!("\"{}\"", t.text(s))).collect();
        return Err(InstructionError::new(format!(
            "afford does not understand {} here, and refuses rather than guess",
            words.join(", ")
        )));
    }
    Ok(())
}

/// Check 2: refuses a resolution that moves an object into a goal the
/// instruction excludes it from.
pub(super) fn honours_exclusions(
    s: &Scenario,
    picks: &[(usize, usize)],
    forbidden: &[(usize, Option<usize>)],
) -> Result<(), InstructionError> {
    match picks.iter().find(|(i, g)| {
        forbidden
            .iter()
            .any(|(j, h)| i == j && h.is_none_or(|h| h == *g))
    }) {
        Some(&(i, g)) => Err(InstructionError::new(format!(
            "it would move {} into the {}, which the instruction excludes",
            s.objects[i].name, s.goals[g].name
        ))),
        None => Ok(()),
    }
}

/// Up to two tokens either side of token `at`.
fn context(s: &Scenario, tokens: &[Tok], at: usize) -> String {
    tokens[at.saturating_sub(2)..(at + 3).min(tokens.len())]
        .iter()
        .filter(|t| t.token != Token::Break)
        .map(|t| t.text(s))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The relation word and what it relates to: "next to the left box".
fn relation(s: &Scenario, tokens: &[Tok], at: usize) -> String {
    let mut end = at + 1;
    while tokens
        .get(end)
        .is_some_and(|t| t.is_in(&["to", "of", "from", "the", "top", "front"]))
    {
        end += 1;
    }
    if tokens
        .get(end)
        .is_some_and(|t| matches!(t.token, Token::Goal(_) | Token::Object(_)))
    {
        end += 1;
    }
    let start = match at > 0 && tokens[at - 1].is_in(&["on", "in", "to"]) {
        true => at - 1,
        false => at,
    };
    tokens[start..end]
        .iter()
        .map(|t| t.text(s))
        .collect::<Vec<_>>()
        .join(" ")
}
