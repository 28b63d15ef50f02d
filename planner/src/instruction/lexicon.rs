//! The instruction language's word lists: verbs, quantifiers, descriptions,
//! exclusion markers, and the negation and spatial-relation words that the
//! guard refuses when no construct consumed them.

pub(super) const VERBS: &[&str] = &[
    "put", "place", "move", "take", "bring", "drop", "carry", "transfer", "set", "sort", "store",
    "pick", "get", "pack", "load",
];
/// Verbs whose clause names objects to leave alone ("leave the red square").
pub(super) const LEAVE_VERBS: &[&str] = &[
    "leave", "leaving", "keep", "keeping", "skip", "ignore", "avoid",
];
/// Verbs that only make sense negated ("do not touch the red ones"): an
/// exclusion when negated, not understood otherwise.
pub(super) const TOUCH_VERBS: &[&str] = &["touch", "disturb", "handle"];
/// Gerunds after "without" ("without touching the red ones").
pub(super) const GERUNDS: &[&str] = &["touching", "moving", "disturbing", "taking"];
/// Words that may close a leave clause: "alone", "where it is", "out of …".
pub(super) const LEAVE_TAIL: &[&str] = &[
    "alone",
    "where",
    "it",
    "they",
    "is",
    "are",
    "in",
    "place",
    "on",
    "the",
    "table",
    "out",
    "of",
    "untouched",
    "as",
    "there",
    "be",
    "behind",
    "away",
    "from",
];
/// Words before the verb that negate its clause ("do not put", "never move").
pub(super) const NEGATING_PREFIX: &[&str] = &["not", "never", "dont", "doesnt"];
/// Politeness and sequencing words that carry no meaning for the plan.
pub(super) const FILLERS: &[&str] = &[
    "please",
    "kindly",
    "could",
    "can",
    "would",
    "will",
    "you",
    "now",
    "also",
    "just",
    "for",
    "me",
    "robot",
    "carefully",
    "gently",
    "slowly",
    "up",
    "go",
    "ahead",
    "lets",
    "let",
    "us",
    "i",
    "want",
    "so",
    "ok",
    "okay",
    "thanks",
    "finally",
    "lastly",
    "afterwards",
];
/// Sequencing words that are fillers only before the verb ("first put …").
pub(super) const SEQUENCE: &[&str] = &["first", "next", "second", "third"];
pub(super) const PREPOSITIONS: &[&str] = &[
    "in", "into", "to", "onto", "on", "inside", "at", "over", "towards", "toward",
];
/// Nouns that make "this" / "that" point at a goal ("in that box").
pub(super) const GOAL_NOUNS: &[&str] = &["box", "goal", "bin", "container", "tray", "basket"];
pub(super) const GENERIC_SINGULAR: &[&str] =
    &["one", "piece", "object", "thing", "block", "item", "it"];
pub(super) const GENERIC_PLURAL: &[&str] = &[
    "ones", "pieces", "objects", "things", "blocks", "items", "them",
];
/// "the rest", "the others", "everything else", "the remaining ones".
pub(super) const REST: &[&str] = &["rest", "others", "other", "remaining", "else"];
pub(super) const EVERYTHING: &[&str] = &["everything", "anything"];
pub(crate) const COLOURS: &[&str] = &[
    "red", "green", "blue", "yellow", "orange", "purple", "pink", "black", "white", "grey", "gray",
    "brown", "cyan", "magenta", "violet",
];
pub(crate) const SHAPES: &[&str] = &[
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
const ORDINALS: &[&str] = &[
    "zeroth", "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth",
    "tenth",
];
pub(super) const BIG: &[&str] = &["big", "bigger", "biggest", "large", "larger", "largest"];
pub(super) const SMALL: &[&str] = &[
    "small", "smaller", "smallest", "little", "tiny", "tinier", "tiniest",
];
pub(super) const DEICTIC: &[&str] = &["this", "that"];

/// Every word that negates or excludes. A word of this list that no
/// construct consumed makes the guard refuse the instruction.
pub(super) const NEGATIONS: &[&str] = &[
    "not",
    "no",
    "never",
    "none",
    "nothing",
    "nor",
    "neither",
    "dont",
    "doesnt",
    "didnt",
    "cannot",
    "cant",
    "wont",
    "shouldnt",
    "mustnt",
    "except",
    "excepting",
    "excluding",
    "exclude",
    "but",
    "besides",
    "without",
    "leave",
    "leaving",
    "keep",
    "keeping",
    "skip",
    "ignore",
    "avoid",
    "instead",
    "unless",
    "rather",
    "apart",
    "other",
    "save",
];
/// Spatial relations afford cannot plan. A word of this list that no
/// construct consumed makes the guard refuse the instruction.
pub(super) const RELATIONS: &[&str] = &[
    "next",
    "beside",
    "behind",
    "top",
    "near",
    "nearby",
    "close",
    "under",
    "underneath",
    "below",
    "beneath",
    "above",
    "front",
    "left",
    "right",
    "between",
    "around",
    "against",
    "by",
    "outside",
    "opposite",
    "alongside",
    "atop",
    "across",
    "along",
    "beyond",
    "far",
    "away",
    "adjacent",
    "past",
    "after",
    "before",
];

/// How many objects a clause asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Quantity {
    All,
    One,
    Count(usize),
    Some,
    /// "both": every match, and there must be exactly two.
    Both,
}

pub(super) fn is(w: &str, list: &[&str]) -> bool {
    list.contains(&w)
}

/// The quantity a quantifier word asks for ("all", "a", "both", "three", "3").
pub(super) fn quantifier(w: &str) -> Option<Quantity> {
    match w {
        "all" | "every" | "each" => Some(Quantity::All),
        "a" | "an" | "any" => Some(Quantity::One),
        "some" | "several" => Some(Quantity::Some),
        "both" => Some(Quantity::Both),
        _ => numeral(w).map(|n| match n {
            1 => Quantity::One,
            n => Quantity::Count(n),
        }),
    }
}

/// A count written as a word or digits.
pub(super) fn numeral(w: &str) -> Option<usize> {
    NUMBERS
        .iter()
        .position(|n| *n == w)
        .or_else(|| w.parse::<usize>().ok())
}

/// Which match an ordinal names: `Some(Some(k))` for the k-th (0-based),
/// `Some(None)` for "last".
pub(super) fn ordinal(w: &str) -> Option<Option<usize>> {
    if w == "last" {
        return Some(None);
    }
    let digits = ["st", "nd", "rd", "th"]
        .iter()
        .find_map(|s| w.strip_suffix(s))
        .and_then(|d| d.parse::<usize>().ok());
    ORDINALS
        .iter()
        .position(|o| *o == w)
        .or(digits)
        .filter(|&k| k > 0)
        .map(|k| Some(k - 1))
}
