//! Parsing: one part of the instruction (between clause breaks) becomes a
//! move clause (objects → goal, with exclusions), an exclusion ("leave the
//! red square", "do not move the circles", ", not the red ones") or a goal
//! for the previous clause (", in the left box"). Every word a construct
//! reads is marked consumed; the guard refuses the words left over.

use std::collections::BTreeSet;

use super::lexicon::{
    BIG, COLOURS, DEICTIC, EVERYTHING, FILLERS, GENERIC_PLURAL, GENERIC_SINGULAR, GERUNDS,
    GOAL_NOUNS, LEAVE_TAIL, LEAVE_VERBS, NEGATING_PREFIX, NEGATIONS, PREPOSITIONS, Quantity,
    RELATIONS, REST, SEQUENCE, SHAPES, SMALL, TOUCH_VERBS, VERBS, is, numeral, ordinal, quantifier,
};
use super::tokens::{Tok, Token};
use crate::error::InstructionError;
use crate::scenario::Scenario;

/// Picks one object out of a description's matches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Pick {
    /// "the second blue square": the k-th match (0-based) in scenario order.
    Nth(usize),
    Last,
    /// "the big one": the largest pixel-box area × height.
    Biggest,
    Smallest,
    /// "this one" / "that square": the match nearest the pointing pixel.
    Pointed,
}

/// Which objects a description names.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Description {
    /// Any of these colours (empty: any colour).
    pub colours: Vec<String>,
    pub shape: Option<String>,
    pub named: Vec<usize>,
    pub generic: bool,
    /// "it" / "them": the previous clause's objects.
    pub pronoun: bool,
    pub plural: bool,
    /// "the rest", "the others": what no other clause takes.
    pub rest: bool,
    /// "the other one(s)": the rest of the previous noun.
    pub others: bool,
    pub pick: Option<Pick>,
}

impl Description {
    pub fn is_empty(&self) -> bool {
        self.colours.is_empty()
            && self.shape.is_none()
            && self.named.is_empty()
            && !self.generic
            && self.pick.is_none()
    }

    /// "blue squares", "red or blue square", "objects".
    pub fn text(&self, plural: bool) -> String {
        let noun = self.shape.clone().unwrap_or_else(|| "object".into());
        let noun = if plural { format!("{noun}s") } else { noun };
        match self.colours.is_empty() {
            true => noun,
            false => format!("{} {noun}", self.colours.join(" or ")),
        }
    }
}

/// Objects to move to one goal.
pub(super) struct Clause {
    pub quantity: Option<Quantity>,
    pub description: Description,
    pub goal: Option<usize>,
    /// "from the left box": only objects resting in this goal match.
    pub source: Option<usize>,
    /// "except the red ones": every object these match stays put.
    pub exclusions: Vec<Description>,
    /// False for a part without a verb ("… and the blue ones in the box").
    pub has_verb: bool,
    pub text: String,
}

/// Objects the instruction says to leave alone (anywhere, or only out of
/// `goal`).
pub(super) struct Exclusion {
    pub description: Description,
    pub goal: Option<usize>,
    pub text: String,
}

/// What one part of the instruction says.
pub(super) enum Part {
    Move(Clause),
    Exclude(Exclusion),
    /// ", not the red ones": exclusions for the previous clause.
    ExcludePrevious(Vec<Description>, String),
    /// ", in the left box" or "… and put it in the left box": a clause
    /// that gives its goal to the previous clause when that has none.
    GoalOf(Clause),
}

/// The parser's state: the scenario's vocabulary, the consumed words and
/// the first parse error (parsing goes on so the guard sees every word).
pub(super) struct Parser<'a> {
    pub s: &'a Scenario,
    pub used: Vec<bool>,
    pub error: Option<InstructionError>,
    colours: BTreeSet<String>,
    shapes: BTreeSet<String>,
}

impl<'a> Parser<'a> {
    pub fn new(s: &'a Scenario, tokens: usize) -> Self {
        let lower = |list: &[&str], extra: &mut dyn Iterator<Item = String>| {
            list.iter()
                .map(|w| w.to_string())
                .chain(extra)
                .collect::<BTreeSet<_>>()
        };
        Self {
            s,
            used: vec![false; tokens],
            error: None,
            colours: lower(
                COLOURS,
                &mut s.objects.iter().map(|o| o.color.to_lowercase()),
            ),
            shapes: lower(
                SHAPES,
                &mut s.objects.iter().map(|o| o.shape.to_lowercase()),
            ),
        }
    }

    fn take(&mut self, t: &Tok) {
        self.used[t.at] = true;
    }

    pub fn fail(&mut self, reason: String) {
        self.error.get_or_insert(InstructionError::new(reason));
    }

    fn text(&self, toks: &[Tok]) -> String {
        toks.iter()
            .map(|t| t.text(self.s))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// True when the part's words are only colours, articles and
    /// quantifiers: "the red" of "the red and blue squares".
    pub fn is_colours_only(&self, part: &[Tok]) -> bool {
        let colour = |t: &Tok| t.word().is_some_and(|w| self.colours.contains(w));
        part.iter().any(colour)
            && part.iter().all(|t| {
                colour(t)
                    || t.is_in(&["the", "all", "every", "each", "some", "both"])
                    || t.is_in(VERBS)
            })
    }

    /// Reads one part (the tokens between two clause breaks).
    pub fn part(&mut self, part: &[Tok], previous: Option<&Description>) -> Option<Part> {
        // Politeness carries no meaning anywhere ("… in the left box, please").
        part.iter()
            .filter(|t| t.is_in(FILLERS))
            .for_each(|t| self.used[t.at] = true);
        let Some(v) = part
            .iter()
            .position(|t| t.is_in(VERBS) || t.is_in(LEAVE_VERBS) || t.is_in(TOUCH_VERBS))
        else {
            return self.verbless(part, previous);
        };
        let (prefix, body) = part.split_at(v);
        let leave = body[0].is_in(LEAVE_VERBS);
        let negated = prefix.iter().any(|t| t.is_in(NEGATING_PREFIX));
        if (negated && leave) || (!negated && body[0].is_in(TOUCH_VERBS)) {
            return None; // "don't leave …", "touch …": left to the guard
        }
        for t in prefix {
            let negation = negated && (t.is_in(NEGATING_PREFIX) || t.is_in(&["do", "does"]));
            // "… but put": a contrast with what came before, if anything did.
            let contrast = t.is_word("but") && t.at > 0;
            if t.is_in(SEQUENCE) || negation || contrast {
                self.take(t);
            }
        }
        self.take(&body[0]);
        if leave {
            return self.leave(&body[1..]).map(Part::Exclude);
        }
        let mut clause = self.clause(&body[1..], previous, negated)?;
        clause.has_verb = true;
        if !negated {
            return self.move_or_goal(clause, previous);
        }
        if !clause.exclusions.is_empty() || clause.description.rest {
            self.fail(format!(
                "\"{}\" negates an exclusion, which afford cannot turn into a move",
                self.text(part)
            ));
        }
        Some(Part::Exclude(Exclusion {
            description: clause.description,
            goal: clause.goal,
            text: self.text(part),
        }))
    }

    /// A part without a verb: ", not the red ones", "the blue ones in the
    /// right box", or fillers.
    fn verbless(&mut self, part: &[Tok], previous: Option<&Description>) -> Option<Part> {
        if marker_len(part, 0).is_some() {
            let (_, exclusions) = self.split_markers(part);
            return Some(Part::ExcludePrevious(exclusions, self.text(part)));
        }
        if part.iter().all(|t| t.is_in(FILLERS) || t.is_in(SEQUENCE)) {
            // "first", "next" standing alone: sequencing, no meaning.
            part.iter().for_each(|t| self.take(t));
            return None;
        }
        let clause = self.clause(part, previous, false)?;
        self.move_or_goal(clause, previous)
    }

    /// A clause that names only a goal (", in the left box") or only a
    /// pronoun for the previous clause's objects ("pick up the red square
    /// and put it in the left box") gives that goal to the previous clause.
    /// A clause naming no objects at all does not say which to move.
    fn move_or_goal(&mut self, clause: Clause, previous: Option<&Description>) -> Option<Part> {
        let d = &clause.description;
        let bare = d.is_empty() && clause.quantity.is_none();
        let pronoun = d.pronoun && previous.is_some() && clause.exclusions.is_empty();
        if clause.goal.is_some() && (bare || pronoun) {
            return Some(Part::GoalOf(clause));
        }
        if d.is_empty() {
            self.fail(format!(
                "\"{}\" does not say which objects to move",
                clause.text
            ));
            return None;
        }
        Some(Part::Move(clause))
    }

    /// "leave the red square [alone | where it is | out of the left box]".
    fn leave(&mut self, toks: &[Tok]) -> Option<Exclusion> {
        const TAIL_START: &[&str] = &[
            "alone",
            "where",
            "in",
            "on",
            "out",
            "untouched",
            "as",
            "there",
            "behind",
            "away",
        ];
        let end = toks
            .iter()
            .position(|t| t.is_in(TAIL_START) || matches!(t.token, Token::Goal(_) | Token::Here))
            .unwrap_or(toks.len());
        let (_, description) = self.objects(&toks[..end]);
        let tail = &toks[end..];
        let mut goal = None;
        for (k, t) in tail.iter().enumerate() {
            match t.token {
                Token::Goal(g) => {
                    self.take(t);
                    let out_of = tail[..k].iter().any(|t| t.is_word("out"));
                    goal = goal.or(Some(g).filter(|_| out_of));
                }
                _ if t.is_in(LEAVE_TAIL) => self.take(t),
                _ => {}
            }
        }
        let text = format!("leave {}", self.text(toks));
        if description.is_empty() {
            self.fail(format!("\"{text}\" does not say which objects to leave"));
            return None;
        }
        Some(Exclusion {
            description,
            goal,
            text,
        })
    }

    /// Objects [exclusions] [preposition goal] [exclusions]. A generic word
    /// ("the blue ones") takes the previous clause's noun, except in an
    /// exclusion (`excludes`), where only "it" / "them" do: "do not move the
    /// blue ones" leaves every blue object, the broader and safer reading.
    fn clause(
        &mut self,
        toks: &[Tok],
        previous: Option<&Description>,
        excludes: bool,
    ) -> Option<Clause> {
        let text = self.text(toks);
        let (toks, source) = self.source(toks);
        let (head_end, goal, tail_start) = self.goal_phrase(&toks);
        let (objects, mut exclusions) = self.split_markers(&toks[..head_end]);
        let tail = &toks[tail_start.min(toks.len())..];
        if marker_len(tail, 0).is_some() {
            exclusions.extend(self.split_markers(tail).1);
        }
        let (quantity, mut description) = self.objects(&objects);
        if description.is_empty() && goal.is_none() && quantity.is_none() {
            return None; // filler such as "please" or a trailing "then"
        }
        let d = &description;
        let inherits = d.generic && (!d.rest || d.others) && (!excludes || d.pronoun);
        if let Some(prev) = previous.filter(|_| inherits) {
            // "the blue ones" keeps the previous noun; "them" and "the other
            // one" keep all of it; "the other hexagons" keep nothing.
            if description.colours.is_empty() && description.shape.is_none() {
                description.colours = prev.colours.clone();
            }
            description.shape = description.shape.or(prev.shape.clone());
            if description.pronoun && description.named.is_empty() {
                description.named = prev.named.clone();
            }
        }
        Some(Clause {
            quantity,
            description,
            goal,
            source,
            exclusions,
            has_verb: false,
            text,
        })
    }

    /// Removes "from <goal>" / "out of <goal>" and returns the goal named.
    fn source(&mut self, toks: &[Tok]) -> (Vec<Tok>, Option<usize>) {
        let mut out = Vec::new();
        let mut source = None;
        let mut i = 0;
        while i < toks.len() {
            let word = |k: usize, w: &str| toks.get(k).is_some_and(|t| t.is_word(w));
            let lead = match (word(i, "from"), word(i, "out") && word(i + 1, "of")) {
                (true, _) => 1,
                (_, true) => 2,
                _ => 0,
            };
            let article = usize::from(word(i + lead, "the"));
            if let (true, Some(Token::Goal(g))) =
                (lead > 0, toks.get(i + lead + article).map(|t| &t.token))
            {
                source = Some(*g);
                toks[i..=i + lead + article]
                    .iter()
                    .for_each(|t| self.used[t.at] = true);
                i += lead + article + 1;
                continue;
            }
            out.push(toks[i].clone());
            i += 1;
        }
        (out, source)
    }

    /// Finds the goal: a goal name, "here" / "there", or "this / that box"
    /// (nearest the pointing pixel), with the prepositions and articles just
    /// before it. Returns where the objects end, the goal, and where the
    /// words after the goal start.
    fn goal_phrase(&mut self, toks: &[Tok]) -> (usize, Option<usize>, usize) {
        let pointed_box = |k: usize| {
            k > 0
                && toks[k].is_in(DEICTIC)
                && toks.get(k + 1).is_some_and(|t| t.is_in(GOAL_NOUNS))
                && toks[k - 1].is_in(PREPOSITIONS)
        };
        let found = (0..toks.len()).find_map(|k| match toks[k].token {
            Token::Goal(g) => Some((k, 1, Some(g))),
            Token::Here => Some((k, 1, None)),
            _ if pointed_box(k) => Some((k, 2, None)),
            _ => None,
        });
        let Some((at, len, named)) = found else {
            return self.unknown_goal(toks);
        };
        toks[at..at + len]
            .iter()
            .for_each(|t| self.used[t.at] = true);
        let goal = named.or_else(|| self.pointed_goal(&toks[at].text(self.s)));
        let mut start = at;
        while start > 0 && (toks[start - 1].is_in(PREPOSITIONS) || toks[start - 1].is_word("the")) {
            start -= 1;
            self.take(&toks[start]);
        }
        (start, goal, at + len)
    }

    /// No goal token: "in the middle box" names a goal that does not exist.
    fn unknown_goal(&mut self, toks: &[Tok]) -> (usize, Option<usize>, usize) {
        let Some(p) = toks.iter().position(|t| t.is_in(PREPOSITIONS)) else {
            return (toks.len(), None, toks.len());
        };
        let end = (p + 1..toks.len())
            .find(|&k| marker_len(toks, k).is_some())
            .unwrap_or(toks.len());
        let name: Vec<&Tok> = toks[p + 1..end]
            .iter()
            .filter(|t| !t.is_in(&["the", "a", "an"]))
            .collect();
        // "on top of the star": a relation, not a goal name; the guard says so.
        let relation = name
            .iter()
            .any(|t| t.is_in(RELATIONS) || t.is_in(NEGATIONS));
        if name.is_empty() || relation {
            return (toks.len(), None, toks.len());
        }
        toks[p..end].iter().for_each(|t| self.used[t.at] = true);
        let named = name.iter().map(|t| t.text(self.s)).collect::<Vec<_>>();
        let known: Vec<&str> = self.s.goals.iter().map(|g| g.name.as_str()).collect();
        self.fail(format!(
            "no goal called '{}' (goals: {})",
            named.join(" "),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        ));
        (p, None, end)
    }

    /// The goal nearest the pointing pixel, for "here", "there", "that box".
    fn pointed_goal(&mut self, word: &str) -> Option<usize> {
        let Some(p) = self.s.pointing else {
            self.fail(format!("it says \"{word}\" but no pointing hand was seen"));
            return None;
        };
        let d2 = |c: [f64; 2]| (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
        let goals = &self.s.goals;
        let nearest = (0..goals.len())
            .min_by(|&a, &b| d2(goals[a].bbox.centre()).total_cmp(&d2(goals[b].bbox.centre())));
        if nearest.is_none() {
            self.fail(format!("it says \"{word}\" but the scene has no goal"));
        }
        nearest
    }

    /// Splits at exclusion markers: the words before the first marker, and
    /// one description per marker.
    fn split_markers(&mut self, toks: &[Tok]) -> (Vec<Tok>, Vec<Description>) {
        let mut starts = Vec::new();
        let mut k = 0;
        while k < toks.len() {
            match marker_len(toks, k) {
                Some(len) => {
                    starts.push((k, len));
                    k += len;
                }
                None => k += 1,
            }
        }
        let first = starts.first().map_or(toks.len(), |&(k, _)| k);
        let mut exclusions = Vec::new();
        for (n, &(k, len)) in starts.iter().enumerate() {
            // "without touching the red ones": the gerund adds nothing.
            let len = len + usize::from(toks.get(k + len).is_some_and(|t| t.is_in(GERUNDS)));
            toks[k..k + len].iter().for_each(|t| self.used[t.at] = true);
            let end = starts.get(n + 1).map_or(toks.len(), |&(next, _)| next);
            let (_, d) = self.objects(&toks[k + len..end]);
            if d.is_empty() || d.rest {
                let marker = self.text(&toks[k..k + len]);
                self.fail(format!(
                    "\"{marker}\" is not followed by the objects to leave out"
                ));
                continue;
            }
            exclusions.push(d);
        }
        (toks[..first].to_vec(), exclusions)
    }

    /// Quantifier and description of the objects; marks the words read.
    fn objects(&mut self, toks: &[Tok]) -> (Option<Quantity>, Description) {
        let mut word_quantity = None;
        let mut count = None;
        let mut d = Description::default();
        let mut adjective = false;
        for t in toks {
            let w = match &t.token {
                Token::Object(i) => {
                    d.named.push(*i);
                    self.take(t);
                    continue;
                }
                Token::Word(w) => w.as_str(),
                _ => continue,
            };
            let read = if self.colours.contains(w) {
                d.colours.push(w.to_string());
                adjective = true;
                true
            } else if let Some(shape) = singular_of(w, &self.shapes) {
                d.plural = !self.shapes.contains(w);
                d.shape = Some(shape);
                true
            } else if (w == "one" && adjective) || (w != "one" && is(w, GENERIC_SINGULAR)) {
                d.generic = true;
                d.pronoun |= w == "it";
                true
            } else if is(w, GENERIC_PLURAL) {
                (d.generic, d.plural) = (true, true);
                d.pronoun |= w == "them";
                true
            } else if is(w, EVERYTHING) {
                (d.generic, d.plural) = (true, true);
                word_quantity = word_quantity.or(Some(Quantity::All));
                true
            } else if is(w, REST) {
                (d.generic, d.rest) = (true, true);
                d.plural |= w == "rest" || w == "others";
                d.others |= w == "other";
                adjective = true;
                true
            } else if let Some(k) = ordinal(w) {
                adjective = true;
                set_pick(&mut d, k.map_or(Pick::Last, Pick::Nth))
            } else if is(w, BIG) || is(w, SMALL) || is(w, DEICTIC) {
                adjective = true;
                let p = match w {
                    _ if is(w, BIG) => Pick::Biggest,
                    _ if is(w, SMALL) => Pick::Smallest,
                    _ => Pick::Pointed,
                };
                set_pick(&mut d, p)
            } else if w == "the" || w == "of" {
                true
            } else if let Some(n) = numeral(w) {
                count = count.or(Some(quantifier(w).unwrap_or(Quantity::Count(n))));
                true
            } else if let Some(q) = quantifier(w) {
                word_quantity = word_quantity.or(Some(q));
                true
            } else {
                false
            };
            if read {
                self.take(t);
            }
        }
        let quantity = count.or(word_quantity);
        if d.is_empty() && quantity == Some(Quantity::All) {
            (d.generic, d.plural) = (true, true); // "put all in the left box"
        }
        (quantity, d)
    }
}

/// Length of the exclusion marker starting at `k`, if one does: "except
/// (for)", "excluding", "excepting", "besides", "without", "not", "but
/// (not)", "other than", "apart from", "save for".
pub(super) fn marker_len(toks: &[Tok], k: usize) -> Option<usize> {
    let next = |w: &str| toks.get(k + 1).is_some_and(|t| t.is_word(w));
    match toks.get(k)?.word()? {
        "except" => Some(1 + usize::from(next("for"))),
        "excluding" | "excepting" | "besides" | "without" | "not" => Some(1),
        "but" => Some(1 + usize::from(next("not"))),
        "other" if next("than") => Some(2),
        "apart" if next("from") => Some(2),
        "save" if next("for") => Some(2),
        _ => None,
    }
}

/// Sets the description's pick unless it has one: a second pick word
/// ("this big one") stays unconsumed and the guard refuses it.
fn set_pick(d: &mut Description, pick: Pick) -> bool {
    let free = d.pick.is_none();
    if free {
        d.pick = Some(pick);
    }
    free
}

fn singular_of(w: &str, shapes: &BTreeSet<String>) -> Option<String> {
    [Some(w), w.strip_suffix("es"), w.strip_suffix('s')]
        .into_iter()
        .flatten()
        .find(|c| shapes.contains(*c))
        .map(str::to_string)
}
