//! Resolution: the parsed clauses become (object, goal) pairs. Descriptions
//! match objects by colour, shape and name; a pick (ordinal, size, pointing)
//! narrows them to one; exclusions remove every object they match; objects
//! taken by an earlier clause are not taken again; "the rest" takes what no
//! other clause took; objects already resting in the clause's goal are
//! skipped with a note. Random choices (a, any, numerals, some) are drawn
//! from the seed.

use std::collections::BTreeSet;

use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::clause::{Clause, Description, Exclusion, Pick};
use super::lexicon::Quantity;
use crate::error::InstructionError;
use crate::scenario::Scenario;

/// Pixel boxes of two objects whose sizes are within this ratio are "about
/// the same size": "the big one" does not tell them apart.
const SIZE_RATIO: f64 = 1.1;

/// The resolved instruction.
pub(super) struct Resolved {
    /// (object, goal) indices in clause order.
    pub picks: Vec<(usize, usize)>,
    /// Objects left where they are because they already rest in the goal.
    pub skipped: Vec<String>,
    /// (object, goal) pairs the instruction forbids; `None` forbids every goal.
    pub forbidden: Vec<(usize, Option<usize>)>,
}

fn fail<T>(reason: String) -> Result<T, InstructionError> {
    Err(InstructionError::new(reason))
}

pub(super) fn resolve(
    s: &Scenario,
    clauses: &[Clause],
    exclusions: &[Exclusion],
    seed: u64,
) -> Result<Resolved, InstructionError> {
    let mut forbidden = Vec::new();
    for e in exclusions {
        let objects = select(s, &e.description, None)?;
        if objects.is_empty() {
            return fail(format!(
                "\"{}\" names no object on the table (no {}); afford refuses rather than move what may be meant",
                e.text,
                e.description.text(false)
            ));
        }
        forbidden.extend(objects.into_iter().map(|i| (i, e.goal)));
    }
    for c in clauses {
        for d in &c.exclusions {
            let objects = select(s, d, None)?;
            if objects.is_empty() {
                return fail(format!(
                    "\"{}\" leaves out {}, but there is none on the table; afford refuses rather than move what may be meant",
                    c.text,
                    d.text(true)
                ));
            }
            forbidden.extend(objects.into_iter().map(|i| (i, c.goal)));
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut taken = BTreeSet::new();
    let mut picks = vec![Vec::new(); clauses.len()];
    let mut skipped = vec![Vec::new(); clauses.len()];
    let rest_last = (0..clauses.len())
        .filter(|&k| !clauses[k].description.rest)
        .chain((0..clauses.len()).filter(|&k| clauses[k].description.rest));
    for k in rest_last {
        let c = &clauses[k];
        let goal = c.goal.expect("every clause has a goal after fill_goals");
        let excluded: BTreeSet<usize> = forbidden
            .iter()
            .filter(|(_, g)| g.is_none_or(|g| g == goal))
            .map(|&(i, _)| i)
            .collect();
        let chosen = choose(s, c, goal, &excluded, &taken, &mut rng)?;
        // What a clause skips because it is already in place is settled:
        // "the rest" does not take it elsewhere.
        taken.extend(chosen.moved.iter().chain(&chosen.settled).copied());
        picks[k] = chosen.moved.into_iter().map(|i| (i, goal)).collect();
        skipped[k] = chosen.notes;
    }
    Ok(Resolved {
        picks: picks.concat(),
        skipped: skipped.concat(),
        forbidden,
    })
}

/// The objects a description names, in scenario order, narrowed by its pick.
fn select(
    s: &Scenario,
    d: &Description,
    source: Option<usize>,
) -> Result<Vec<usize>, InstructionError> {
    let matches: Vec<usize> = (0..s.objects.len())
        .filter(|&i| {
            let o = &s.objects[i];
            (d.named.is_empty() || d.named.contains(&i))
                && (d.colours.is_empty()
                    || d.colours.iter().any(|c| o.color.eq_ignore_ascii_case(c)))
                && d.shape
                    .as_ref()
                    .is_none_or(|c| o.shape.eq_ignore_ascii_case(c))
                && source.is_none_or(|g| s.goal_holding(o) == Some(g))
        })
        .collect();
    let Some(pick) = d.pick.filter(|_| !matches.is_empty()) else {
        return Ok(matches);
    };
    let one = match pick {
        Pick::Nth(k) => *matches.get(k).ok_or_else(|| {
            InstructionError::new(format!(
                "it asks for {} number {} but there {} only {}",
                d.text(false),
                k + 1,
                if matches.len() == 1 { "is" } else { "are" },
                matches.len()
            ))
        })?,
        Pick::Last => matches[matches.len() - 1],
        Pick::Biggest | Pick::Smallest => by_size(s, d, &matches, pick == Pick::Biggest)?,
        Pick::Pointed => nearest_to_pointing(s, d, &matches)?,
    };
    Ok(vec![one])
}

/// Size of an object: pixel-box area × height (px² · m), a proxy for volume.
fn size(s: &Scenario, i: usize) -> f64 {
    let o = &s.objects[i];
    o.bbox.w * o.bbox.l * o.height
}

/// The biggest (or smallest) match, when it is clearly so.
fn by_size(
    s: &Scenario,
    d: &Description,
    matches: &[usize],
    biggest: bool,
) -> Result<usize, InstructionError> {
    let mut sorted = matches.to_vec();
    sorted.sort_by(|&a, &b| match biggest {
        true => size(s, b).total_cmp(&size(s, a)),
        false => size(s, a).total_cmp(&size(s, b)),
    });
    if let [first, second, ..] = sorted[..] {
        let (a, b) = (size(s, first), size(s, second));
        if a.max(b) < SIZE_RATIO * a.min(b) {
            return fail(format!(
                "\"{}\" does not tell the {} apart: {} and {} are about the same size",
                if biggest { "big" } else { "small" },
                d.text(true),
                s.objects[first].name,
                s.objects[second].name
            ));
        }
    }
    Ok(sorted[0])
}

/// The match whose centre is nearest the pointing pixel.
fn nearest_to_pointing(
    s: &Scenario,
    d: &Description,
    matches: &[usize],
) -> Result<usize, InstructionError> {
    let Some(p) = s.pointing else {
        return fail(format!(
            "it points at a {} (\"this\" / \"that\") but no pointing hand was seen",
            d.text(false)
        ));
    };
    let d2 = |i: &usize| {
        let c = s.objects[*i].bbox.centre();
        (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2)
    };
    Ok(*matches
        .iter()
        .min_by(|a, b| d2(a).total_cmp(&d2(b)))
        .expect("matches is not empty"))
}

/// What one clause does.
#[derive(Default)]
struct Chosen {
    moved: Vec<usize>,
    /// Objects it names that already rest in its goal.
    settled: Vec<usize>,
    notes: Vec<String>,
}

/// The objects one clause moves, and the notes for those it skips.
fn choose(
    s: &Scenario,
    clause: &Clause,
    goal: usize,
    excluded: &BTreeSet<usize>,
    taken: &BTreeSet<usize>,
    rng: &mut ChaCha8Rng,
) -> Result<Chosen, InstructionError> {
    let d = &clause.description;
    let goal_name = &s.goals[goal].name;
    let matches = select(s, d, clause.source)?;
    if matches.is_empty() {
        return fail(format!("no {} on the table", d.text(d.plural)));
    }
    let kept: Vec<usize> = matches
        .into_iter()
        .filter(|i| !excluded.contains(i))
        .collect();
    if kept.is_empty() {
        return fail(format!(
            "\"{}\" asks for {} that the instruction also leaves out, so nothing is left to move",
            clause.text,
            d.text(true)
        ));
    }
    let free: Vec<usize> = kept.into_iter().filter(|i| !taken.contains(i)).collect();
    if free.is_empty() {
        return match d.rest {
            true => Ok(Chosen {
                notes: vec![format!("nothing is left for \"{}\"", clause.text)],
                ..Chosen::default()
            }),
            false => fail(format!(
                "every {} it names is already taken by an earlier part of the instruction",
                d.text(false)
            )),
        };
    }
    if d.rest && !d.plural && free.len() > 1 {
        return fail(format!(
            "\"{}\" is ambiguous: {} objects are left",
            clause.text,
            free.len()
        ));
    }
    let (in_goal, candidates): (Vec<usize>, Vec<usize>) = free
        .iter()
        .partition(|&&i| s.goal_holding(&s.objects[i]) == Some(goal));
    let note = |i: &usize| format!("{} is already in the {goal_name}", s.objects[*i].name);
    let default = if d.plural || d.named.len() > 1 {
        Quantity::All
    } else {
        Quantity::One
    };
    let quantity = clause.quantity.unwrap_or(default);
    if quantity == Quantity::Both && free.len() != 2 {
        return fail(format!(
            "it says \"both\" but {} {} match",
            free.len(),
            d.text(true)
        ));
    }
    if matches!(quantity, Quantity::All | Quantity::Both) {
        return Ok(Chosen {
            moved: candidates,
            notes: in_goal.iter().map(note).collect(),
            settled: in_goal,
        });
    }
    if candidates.is_empty() {
        let skipped = match d.named.is_empty() && d.pick.is_none() {
            true => vec![format!(
                "every {} is already in the {goal_name}",
                d.text(false)
            )],
            false => in_goal.iter().map(note).collect(),
        };
        return Ok(Chosen {
            notes: skipped,
            settled: in_goal,
            ..Chosen::default()
        });
    }
    let count = match quantity {
        Quantity::One if clause.quantity.is_none() => {
            return Ok(Chosen {
                moved: vec![candidates[0]],
                ..Chosen::default()
            });
        }
        Quantity::Count(n) => n,
        Quantity::Some => rng.random_range(1..=candidates.len()),
        _ => 1,
    };
    if count > candidates.len() {
        return fail(format!(
            "it asks for {count} {} but {} {} available",
            d.text(true),
            candidates.len(),
            if candidates.len() == 1 { "is" } else { "are" }
        ));
    }
    if count == 0 {
        return fail(format!("it asks for zero {}", d.text(true)));
    }
    let mut picked: Vec<usize> = candidates.choose_multiple(rng, count).copied().collect();
    picked.sort_unstable();
    Ok(Chosen {
        moved: picked,
        ..Chosen::default()
    })
}
