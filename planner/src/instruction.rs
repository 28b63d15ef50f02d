//! Sub-goals from the instruction text (the paper's Algorithm 1).
//!
//! The instruction is normalised (case, punctuation, hyphens), names of goals
//! and objects are recognised as whole phrases, and the text is split into
//! clauses at "and", "then", commas and semicolons. Each clause says which
//! objects (quantifier + colour and/or shape, a generic noun such as "ones"
//! or "them", or object names) go to which goal (a goal name, or "here" /
//! "there": the goal nearest the pointing pixel). A clause without a goal
//! takes the goal of the next clause that has one, else of the previous one.
//!
//! Quantifiers: all / every / each, and "the" or no article with a plural,
//! take every match; a / an / one, and "the" with a singular, take one;
//! numerals (words or digits) take that many; "some" takes a seeded subset.
//! Where the paper picks at random (a, an, numerals, some), the choice is
//! drawn from the seed; "the" + singular takes the first match in the
//! scenario's order. Objects already resting in the named goal do not match.
//! Sub-goals come out clause by clause, objects in the scenario's order.
//!
//! Also understood: "the red and blue squares" (colours before "and" share
//! the noun after it), "the blue ones" (keeps the previous clause's noun),
//! "from the left box" / "out of the left box" (only objects resting in that
//! goal). Exclusions ("except", "but not", "other than", …) are refused
//! rather than misread.

use std::collections::BTreeSet;

use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::InstructionError;
use crate::scenario::Scenario;

/// One sub-goal ⟨object, goal⟩ of the set Π.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SubGoal {
    pub object: String,
    pub goal: String,
}

const VERBS: &[&str] = &[
    "put", "place", "move", "take", "bring", "drop", "carry", "transfer", "set", "sort", "store",
];
const EXCLUSIONS: &[&str] = &[
    "except",
    "excluding",
    "but",
    "apart",
    "other",
    "besides",
    "without",
];
const PREPOSITIONS: &[&str] = &[
    "in", "into", "to", "onto", "on", "inside", "at", "over", "towards", "toward",
];
const GENERIC_SINGULAR: &[&str] = &["one", "piece", "object", "thing", "block", "item", "it"];
const GENERIC_PLURAL: &[&str] = &[
    "ones", "pieces", "objects", "things", "blocks", "items", "them",
];
const COLOURS: &[&str] = &[
    "red", "green", "blue", "yellow", "orange", "purple", "pink", "black", "white", "grey", "gray",
    "brown", "cyan", "magenta", "violet",
];
const SHAPES: &[&str] = &[
    "square",
    "cube",
    "hexagon",
    "triangle",
    "circle",
    "cylinder",
    "star",
    "rectangle",
    "ball",
    "sphere",
    "cross",
    "pentagon",
    "heart",
    "disc",
    "disk",
    "box",
];
const NUMBERS: &[&str] = &[
    "zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    "eleven", "twelve",
];

/// A token of the normalised instruction.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Word(String),
    Goal(usize),
    Object(usize),
    Here,
    Break,
}

/// How many objects a clause asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Quantity {
    All,
    One,
    Count(usize),
    Some,
}

/// Which objects a clause describes.
#[derive(Debug, Clone, Default, PartialEq)]
struct Description {
    /// Any of these colours (empty: any colour).
    colours: Vec<String>,
    shape: Option<String>,
    named: Vec<usize>,
    generic: bool,
    plural: bool,
}

impl Description {
    fn is_empty(&self) -> bool {
        self.colours.is_empty() && self.shape.is_none() && self.named.is_empty() && !self.generic
    }

    fn text(&self) -> String {
        let noun = self.shape.clone().unwrap_or_else(|| "object".into());
        let noun = if self.plural {
            format!("{noun}s")
        } else {
            noun
        };
        match self.colours.is_empty() {
            true => noun,
            false => format!("{} {noun}", self.colours.join(" or ")),
        }
    }
}

struct Clause {
    quantity: Option<Quantity>,
    description: Description,
    goal: Option<usize>,
    /// "from the left box": only objects resting in this goal match.
    source: Option<usize>,
    text: String,
}

/// Turns the scenario's instruction into ordered sub-goals.
pub fn subgoals(scenario: &Scenario, seed: u64) -> Result<Vec<SubGoal>, InstructionError> {
    let tokens = tokenize(scenario);
    if !tokens
        .iter()
        .any(|t| matches!(t, Token::Word(w) if VERBS.contains(&w.as_str())))
    {
        return Err(InstructionError::new(format!(
            "no action verb in \"{}\" (say put, place, move, take, bring or drop)",
            scenario.instruction.trim()
        )));
    }
    if let Some(w) = tokens.iter().find_map(|t| match t {
        Token::Word(w) if EXCLUSIONS.contains(&w.as_str()) => Some(w),
        _ => None,
    }) {
        return Err(InstructionError::new(format!(
            "it excludes objects (\"{w} …\"), which afford does not understand yet; name the objects to move instead"
        )));
    }
    let mut clauses = Vec::new();
    let mut pending: Vec<Token> = Vec::new();
    for part in tokens
        .split(|t| *t == Token::Break)
        .filter(|p| !p.is_empty())
    {
        // "the red and blue squares": a part with colours only lends them
        // to the next part's noun.
        if is_colours_only(scenario, part) {
            pending.extend_from_slice(part);
            continue;
        }
        let part: Vec<Token> = pending.drain(..).chain(part.iter().cloned()).collect();
        let previous = clauses.last().map(|c: &Clause| c.description.clone());
        if let Some(clause) = parse_clause(scenario, &part, previous)? {
            clauses.push(clause);
        }
    }
    if !pending.is_empty() {
        let previous = clauses.last().map(|c: &Clause| c.description.clone());
        if let Some(clause) = parse_clause(scenario, &pending, previous)? {
            clauses.push(clause);
        }
    }
    fill_goals(&mut clauses)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut taken = BTreeSet::new();
    let mut out = Vec::new();
    for clause in &clauses {
        let goal = clause.goal.expect("fill_goals set every goal");
        for object in choose(scenario, clause, goal, &taken, &mut rng)? {
            taken.insert(object);
            out.push(SubGoal {
                object: scenario.objects[object].name.clone(),
                goal: scenario.goals[goal].name.clone(),
            });
        }
    }
    if out.is_empty() {
        return Err(InstructionError::new("it asks for nothing to be moved"));
    }
    Ok(out)
}

fn normalise(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars().flat_map(char::to_lowercase) {
        match ch {
            ',' | ';' | '.' | '!' | '?' | ':' => out.push_str(" , "),
            '-' | '_' | '/' => out.push(' '),
            c if c.is_alphanumeric() || c.is_whitespace() => out.push(c),
            _ => {}
        }
    }
    out
}

fn words(text: &str) -> Vec<String> {
    normalise(text)
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

fn tokenize(s: &Scenario) -> Vec<Token> {
    let mut phrases: Vec<(Vec<String>, Token)> = s
        .goals
        .iter()
        .enumerate()
        .map(|(i, g)| (words(&g.name), Token::Goal(i)))
        .chain(
            s.objects
                .iter()
                .enumerate()
                .map(|(i, o)| (words(&o.name), Token::Object(i))),
        )
        .filter(|(w, _)| !w.is_empty())
        .collect();
    phrases.sort_by_key(|(w, _)| std::cmp::Reverse(w.len()));
    let text = words(&s.instruction);
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if let Some((len, token)) = phrases
            .iter()
            .find(|(w, _)| text[i..].starts_with(w))
            .map(|(w, t)| (w.len(), t.clone()))
        {
            tokens.push(token);
            i += len;
            continue;
        }
        tokens.push(match text[i].as_str() {
            "," | "and" | "then" => Token::Break,
            "here" | "there" => Token::Here,
            w => Token::Word(w.to_string()),
        });
        i += 1;
    }
    tokens
}

/// True when the part's words are only colours, articles and quantifiers.
fn is_colours_only(s: &Scenario, part: &[Token]) -> bool {
    let colours = colour_words(s);
    let mut any = false;
    let only = part.iter().all(|t| match t {
        Token::Word(w) if colours.contains(w) => {
            any = true;
            true
        }
        Token::Word(w) => {
            ["the", "all", "every", "each", "some"].contains(&w.as_str())
                || VERBS.contains(&w.as_str())
        }
        _ => false,
    });
    only && any
}

/// Removes "from <goal>" / "out of <goal>" and returns the goal named there.
fn take_source(tokens: &[Token]) -> (Vec<Token>, Option<usize>) {
    let mut out = Vec::new();
    let mut source = None;
    let mut i = 0;
    while i < tokens.len() {
        let word = |k: usize, w: &str| matches!(tokens.get(k), Some(Token::Word(x)) if x == w);
        let lead = if word(i, "from") {
            1
        } else if word(i, "out") && word(i + 1, "of") {
            2
        } else {
            0
        };
        if lead > 0 {
            let article = usize::from(word(i + lead, "the"));
            if let Some(Token::Goal(g)) = tokens.get(i + lead + article) {
                source = Some(*g);
                i += lead + article + 1;
                continue;
            }
        }
        out.push(tokens[i].clone());
        i += 1;
    }
    (out, source)
}

fn parse_clause(
    s: &Scenario,
    tokens: &[Token],
    previous: Option<Description>,
) -> Result<Option<Clause>, InstructionError> {
    let (tokens, source) = take_source(tokens);
    let tokens = tokens.as_slice();
    let split = tokens
        .iter()
        .position(|t| {
            matches!(t, Token::Goal(_) | Token::Here)
                || matches!(t, Token::Word(w) if PREPOSITIONS.contains(&w.as_str()))
        })
        .unwrap_or(tokens.len());
    let (object_part, goal_part) = tokens.split_at(split);
    let text = tokens.iter().map(token_text).collect::<Vec<_>>().join(" ");
    let goal = parse_goal(s, goal_part)?;
    let (quantity, mut description) = parse_objects(s, object_part);
    if description.is_empty() {
        if goal.is_none() && quantity.is_none() {
            return Ok(None); // filler such as "please" or a trailing "then"
        }
        return Err(InstructionError::new(format!(
            "\"{text}\" does not say which objects to move"
        )));
    }
    if description.generic
        && let Some(prev) = previous
    {
        // "the blue ones" keeps the previous noun; "them" keeps all of it.
        description.shape = description.shape.or(prev.shape);
        if description.colours.is_empty() {
            description.colours = prev.colours;
        }
    }
    Ok(Some(Clause {
        quantity,
        description,
        goal,
        source,
        text,
    }))
}

fn token_text(t: &Token) -> String {
    match t {
        Token::Word(w) => w.clone(),
        Token::Goal(i) => format!("<goal {i}>"),
        Token::Object(i) => format!("<object {i}>"),
        Token::Here => "here".into(),
        Token::Break => ",".into(),
    }
}

fn parse_goal(s: &Scenario, tokens: &[Token]) -> Result<Option<usize>, InstructionError> {
    for t in tokens {
        match t {
            Token::Goal(i) => return Ok(Some(*i)),
            Token::Here => return nearest_goal_to_pointing(s).map(Some),
            _ => {}
        }
    }
    let named: Vec<&str> = tokens
        .iter()
        .filter_map(|t| match t {
            Token::Word(w)
                if !PREPOSITIONS.contains(&w.as_str())
                    && !["the", "a", "an"].contains(&w.as_str()) =>
            {
                Some(w.as_str())
            }
            _ => None,
        })
        .collect();
    if named.is_empty() {
        return Ok(None);
    }
    let known: Vec<&str> = s.goals.iter().map(|g| g.name.as_str()).collect();
    Err(InstructionError::new(format!(
        "no goal called '{}' (goals: {})",
        named.join(" "),
        if known.is_empty() {
            "none".to_string()
        } else {
            known.join(", ")
        }
    )))
}

fn nearest_goal_to_pointing(s: &Scenario) -> Result<usize, InstructionError> {
    let p = s
        .pointing
        .ok_or_else(|| InstructionError::new("it says \"here\" but no pointing hand was seen"))?;
    let d2 = |c: [f64; 2]| (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
    (0..s.goals.len())
        .min_by(|&a, &b| d2(s.goals[a].bbox.centre()).total_cmp(&d2(s.goals[b].bbox.centre())))
        .ok_or_else(|| InstructionError::new("it says \"here\" but the scene has no goal"))
}

/// Known colour words: the built-in list and every object's colour.
fn colour_words(s: &Scenario) -> BTreeSet<String> {
    COLOURS
        .iter()
        .map(|c| c.to_string())
        .chain(s.objects.iter().map(|o| o.color.to_lowercase()))
        .collect()
}

fn parse_objects(s: &Scenario, tokens: &[Token]) -> (Option<Quantity>, Description) {
    let colours = colour_words(s);
    let shapes: BTreeSet<String> = SHAPES
        .iter()
        .map(|c| c.to_string())
        .chain(s.objects.iter().map(|o| o.shape.to_lowercase()))
        .collect();
    let mut quantity = None;
    let mut d = Description::default();
    let mut adjective_seen = false;
    for t in tokens {
        let w = match t {
            Token::Object(i) => {
                d.named.push(*i);
                continue;
            }
            Token::Word(w) => w.as_str(),
            _ => continue,
        };
        if colours.contains(w) {
            d.colours.push(w.to_string());
            adjective_seen = true;
        } else if let Some(shape) = singular_of(w, &shapes) {
            d.shape = Some(shape);
            d.plural = shape_is_plural(w, &shapes);
        } else if (w == "one" && adjective_seen) || (w != "one" && GENERIC_SINGULAR.contains(&w)) {
            d.generic = true;
        } else if GENERIC_PLURAL.contains(&w) {
            d.generic = true;
            d.plural = true;
        } else if let Some(q) = quantifier(w) {
            quantity = quantity.or(Some(q));
        }
    }
    (quantity, d)
}

fn quantifier(w: &str) -> Option<Quantity> {
    match w {
        "all" | "every" | "each" => Some(Quantity::All),
        "a" | "an" => Some(Quantity::One),
        "some" | "several" => Some(Quantity::Some),
        "both" => Some(Quantity::Count(2)),
        "the" => None,
        _ => NUMBERS
            .iter()
            .position(|n| *n == w)
            .or_else(|| w.parse::<usize>().ok())
            .map(|n| {
                if n == 1 {
                    Quantity::One
                } else {
                    Quantity::Count(n)
                }
            }),
    }
}

fn singular_of(w: &str, shapes: &BTreeSet<String>) -> Option<String> {
    [Some(w), w.strip_suffix("es"), w.strip_suffix('s')]
        .into_iter()
        .flatten()
        .find(|c| shapes.contains(*c))
        .map(str::to_string)
}

fn shape_is_plural(w: &str, shapes: &BTreeSet<String>) -> bool {
    !shapes.contains(w)
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

fn choose(
    s: &Scenario,
    clause: &Clause,
    goal: usize,
    taken: &BTreeSet<usize>,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<usize>, InstructionError> {
    let d = &clause.description;
    let goal_name = &s.goals[goal].name;
    let matches = |i: &usize| {
        let o = &s.objects[*i];
        (d.named.is_empty() || d.named.contains(i))
            && (d.colours.is_empty() || d.colours.iter().any(|c| o.color.eq_ignore_ascii_case(c)))
            && clause.source.is_none_or(|g| s.goal_holding(o) == Some(g))
            && d.shape
                .as_ref()
                .is_none_or(|c| o.shape.eq_ignore_ascii_case(c))
            && !taken.contains(i)
    };
    let all: Vec<usize> = (0..s.objects.len()).filter(matches).collect();
    let candidates: Vec<usize> = all
        .iter()
        .copied()
        .filter(|&i| s.goal_holding(&s.objects[i]) != Some(goal))
        .collect();
    if candidates.is_empty() {
        let reason = if all.is_empty() {
            format!("no {} on the table", d.text())
        } else {
            format!(
                "every {} is already in the {goal_name}",
                Description {
                    plural: false,
                    ..d.clone()
                }
                .text()
            )
        };
        return Err(InstructionError::new(reason));
    }
    let default = if d.plural || d.named.len() > 1 {
        Quantity::All
    } else {
        Quantity::One
    };
    let count = match clause.quantity.unwrap_or(default) {
        Quantity::All => return Ok(candidates),
        Quantity::One if clause.quantity.is_none() => return Ok(vec![candidates[0]]),
        Quantity::One => 1,
        Quantity::Count(n) => n,
        Quantity::Some => rng.random_range(1..=candidates.len()),
    };
    if count > candidates.len() {
        return Err(InstructionError::new(format!(
            "it asks for {count} {} but {} {} available",
            Description {
                plural: true,
                ..d.clone()
            }
            .text(),
            candidates.len(),
            if candidates.len() == 1 { "is" } else { "are" }
        )));
    }
    if count == 0 {
        return Err(InstructionError::new(format!(
            "it asks for zero {}",
            Description {
                plural: true,
                ..d.clone()
            }
            .text()
        )));
    }
    let mut picked: Vec<usize> = candidates.choose_multiple(rng, count).copied().collect();
    picked.sort_unstable();
    Ok(picked)
}
