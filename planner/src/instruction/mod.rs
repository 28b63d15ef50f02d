//! Sub-goals from the instruction text (the paper's Algorithm 1).
//!
//! [`tokens`] normalises the text and recognises goal and object names as
//! whole phrases; the text is split into parts at "and", "then", commas and
//! semicolons; [`clause`] reads each part as a move (objects → goal, with
//! exclusions), an exclusion ("leave the red square", "do not move the
//! circles") or a goal for the previous part; [`resolve`] turns the clauses
//! into ordered (object, goal) pairs; [`guard`] refuses any instruction with
//! a word no construct consumed (a negation, a spatial relation, anything
//! unknown) and any result that moves an object the instruction excludes.
//! The grammar is listed in docs/decisions.md (Sub-goals).
//!
//! Quantifiers: all / every / each / everything, and "the" or no article
//! with a plural, take every match; "the" with a singular takes the first
//! match in scenario order; a / an / any / one, numerals and "some" draw
//! from the seed, as the paper draws at random; "both" takes both of
//! exactly two matches. A clause without a goal takes the goal of the next
//! clause that has one, else of the previous one.

mod clause;
mod guard;
pub(crate) mod lexicon;
mod resolve;
mod tokens;

use clause::{Clause, Exclusion, Parser, Part};
use lexicon::{LEAVE_VERBS, NEGATING_PREFIX, VERBS};
use tokens::{Tok, Token};

use crate::error::InstructionError;
use crate::scenario::Scenario;
use crate::scenario::bounds::MAX_SUBGOALS;

/// The words an instruction reads `name` as (NFKC, lower case, hyphens,
/// underscores and slashes as word breaks, other symbols dropped): two
/// names with the same words cannot be told apart by an instruction, so
/// validation refuses them (`Blue-Square-1` and `blue_square_1`).
pub fn name_words(name: &str) -> Vec<String> {
    tokens::words(name)
}

/// One sub-goal ⟨object, goal⟩ of the set Π.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SubGoal {
    pub object: String,
    pub goal: String,
}

/// What the instruction asks for.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Interpretation {
    /// The sub-goals, clause by clause, objects in scenario order.
    pub subgoals: Vec<SubGoal>,
    /// One sentence per object (or description) the instruction names that
    /// already rests in its goal and is left where it is, e.g.
    /// "green-circle-2 is already in the left box".
    pub skipped: Vec<String>,
}

/// Reads the scenario's instruction. `Ok` with no sub-goals when everything
/// it names already rests in its goal (see [`Interpretation::skipped`]).
///
/// # Errors
/// [`InstructionError`] ("Not executable instruction: …") when the text has
/// no verb, names no objects or goal that exist, asks for more objects than
/// there are or for more than [`MAX_SUBGOALS`] moves, only says what not to do, or holds a word afford cannot read
/// (a negation or exclusion it cannot place, a spatial relation such as
/// "next to", any unknown word): never executed against such a word.
pub fn interpret(scenario: &Scenario, seed: u64) -> Result<Interpretation, InstructionError> {
    let tokens = tokens::tokenize(scenario);
    if !tokens
        .iter()
        .any(|t| t.is_in(VERBS) || t.is_in(LEAVE_VERBS))
    {
        return Err(InstructionError::new(format!(
            "no action verb in \"{}\" (say put, place, move, take, bring or drop)",
            scenario.instruction.trim()
        )));
    }
    let mut parser = Parser::new(scenario, tokens.len());
    let (mut clauses, exclusions) = parse(&mut parser, &tokens);
    guard::consumed(scenario, &tokens, &parser.used, parser.error.take())?;
    if clauses.is_empty() && !exclusions.is_empty() {
        return Err(InstructionError::new(format!(
            "\"{}\" only says what not to move, so there is nothing to do",
            scenario.instruction.trim()
        )));
    }
    fill_goals(&mut clauses)?;
    let resolved = resolve::resolve(scenario, &clauses, &exclusions, seed)?;
    guard::honours_exclusions(scenario, &resolved.picks, &resolved.forbidden)?;
    if resolved.picks.len() > MAX_SUBGOALS {
        return Err(InstructionError::new(format!(
            "it asks for {} moves, but one instruction moves at most {MAX_SUBGOALS} objects: name fewer (\"the blue squares\", \"three of the red ones\") and give the rest in another instruction",
            resolved.picks.len()
        )));
    }
    if resolved.picks.is_empty() && resolved.skipped.is_empty() {
        return Err(InstructionError::new("it asks for nothing to be moved"));
    }
    Ok(Interpretation {
        subgoals: resolved
            .picks
            .iter()
            .map(|&(o, g)| SubGoal {
                object: scenario.objects[o].name.clone(),
                goal: scenario.goals[g].name.clone(),
            })
            .collect(),
        skipped: resolved.skipped,
    })
}

/// Turns the scenario's instruction into ordered sub-goals: [`interpret`]'s
/// sub-goals, or an error when there is nothing to move because everything
/// named already rests in its goal ("nothing to move: every white cube is
/// already in the right box").
///
/// # Errors
/// As [`interpret`], plus "nothing to move".
pub fn subgoals(scenario: &Scenario, seed: u64) -> Result<Vec<SubGoal>, InstructionError> {
    work(scenario, seed).map(|i| i.subgoals)
}

/// [`interpret`], refusing an instruction that leaves nothing to move.
///
/// # Errors
/// As [`interpret`], plus "nothing to move".
pub fn work(scenario: &Scenario, seed: u64) -> Result<Interpretation, InstructionError> {
    let i = interpret(scenario, seed)?;
    if i.subgoals.is_empty() {
        return Err(InstructionError::new(format!(
            "nothing to move: {}",
            i.skipped.join("; ")
        )));
    }
    Ok(i)
}

/// The parts of the instruction: split at clause breaks, and before a
/// "but" that opens a clause ("… but leave the red one", "… but do not
/// move the circles", "… but put the blue ones …").
fn parts(tokens: &[Tok]) -> Vec<Vec<Tok>> {
    let opens_clause = |t: Option<&Tok>| {
        t.is_some_and(|t| {
            t.is_in(VERBS)
                || t.is_in(LEAVE_VERBS)
                || t.is_in(NEGATING_PREFIX)
                || t.is_in(&["do", "does"])
        })
    };
    let mut parts = Vec::new();
    for part in tokens.split(|t| t.token == Token::Break) {
        let mut start = 0;
        for k in 1..part.len() {
            if part[k].is_word("but") && opens_clause(part.get(k + 1)) {
                parts.push(part[start..k].to_vec());
                start = k;
            }
        }
        parts.push(part[start..].to_vec());
    }
    parts.retain(|p| !p.is_empty());
    parts
}

/// What the previous part was, for reading a part without a verb.
#[derive(Clone, Copy)]
enum Previous {
    Nothing,
    Move {
        excludes: bool,
    },
    /// An exclusion part, and the goal it is scoped to.
    Exclude(Option<usize>),
}

/// Reads the parts in order: move clauses and exclusions.
fn parse(p: &mut Parser, tokens: &[Tok]) -> (Vec<Clause>, Vec<Exclusion>) {
    let mut clauses: Vec<Clause> = Vec::new();
    let mut exclusions: Vec<Exclusion> = Vec::new();
    let mut pending: Vec<Tok> = Vec::new();
    let mut before = Previous::Nothing;
    let parts = parts(tokens);
    for (k, part) in parts.iter().enumerate() {
        // "the red and blue squares": a part with colours only lends them to
        // the next part's noun.
        if k + 1 < parts.len() && p.is_colours_only(part) {
            pending.extend_from_slice(part);
            continue;
        }
        let part: Vec<Tok> = pending.drain(..).chain(part.iter().cloned()).collect();
        let previous = clauses.last().map(|c| c.description.clone());
        before = match p.part(&part, previous.as_ref()) {
            Some(Part::Move(c)) if !c.has_verb => match before {
                // "leave the red square and the blue hexagon": one more to leave.
                Previous::Exclude(goal) if c.goal.is_none() => {
                    exclusions.push(Exclusion {
                        description: c.description,
                        goal,
                        text: c.text,
                    });
                    before
                }
                Previous::Exclude(_) | Previous::Move { excludes: true }
                    if c.goal.is_none() || clauses.last().is_none_or(|l| l.goal.is_none()) =>
                {
                    p.fail(format!(
                        "\"{}\" after an exclusion is ambiguous (to move or to leave out?); repeat the verb (\"and put …\") or the exclusion (\"and except …\")",
                        c.text
                    ));
                    before
                }
                _ => push_move(&mut clauses, c),
            },
            Some(Part::Move(c)) => push_move(&mut clauses, c),
            Some(Part::Exclude(e)) => {
                let goal = e.goal;
                exclusions.push(e);
                Previous::Exclude(goal)
            }
            Some(Part::ExcludePrevious(ds, text)) => match clauses.last_mut() {
                Some(c) => {
                    c.exclusions.extend(ds);
                    Previous::Move { excludes: true }
                }
                None => {
                    p.fail(format!(
                        "\"{text}\" leaves out objects before saying which to move"
                    ));
                    before
                }
            },
            Some(Part::GoalOf(c)) => match clauses.last_mut() {
                Some(last) if last.goal.is_none() => {
                    last.goal = c.goal;
                    before
                }
                _ if !c.description.is_empty() => push_move(&mut clauses, c),
                _ => {
                    p.fail(format!("\"{}\" does not say which objects to move", c.text));
                    before
                }
            },
            None => before,
        };
    }
    (clauses, exclusions)
}

fn push_move(clauses: &mut Vec<Clause>, c: Clause) -> Previous {
    let excludes = !c.exclusions.is_empty();
    clauses.push(c);
    Previous::Move { excludes }
}

fn fill_goals(clauses: &mut [Clause]) -> Result<(), InstructionError> {
    for i in 0..clauses.len() {
        if clauses[i].goal.is_none() {
            let later = clauses[i + 1..].iter().find_map(|c| c.goal);
            let earlier = clauses[..i].iter().rev().find_map(|c| c.goal);
            clauses[i].goal = later.or(earlier);
        }
        if clauses[i].goal.is_none() {
            return Err(InstructionError::new(format!(
                "\"{}\" does not say where to put them",
                clauses[i].text
            )));
        }
    }
    Ok(())
}
