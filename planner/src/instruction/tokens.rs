//! Lexing: the instruction is normalised (Unicode form, case, punctuation,
//! contractions) and goal and object names are recognised as whole phrases
//! before any word is read, so a goal called "left box" or "black and white box" is one
//! token. Every token keeps its position, so the guard can tell which words
//! no construct consumed.

use unicode_normalization::UnicodeNormalization;

use crate::scenario::Scenario;

/// A token of the normalised instruction.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Token {
    Word(String),
    Goal(usize),
    Object(usize),
    /// "here" / "there": the goal nearest the pointing pixel.
    Here,
    /// "and", "then", commas and other clause breaks.
    Break,
}

/// A token and its position in the instruction.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Tok {
    pub token: Token,
    pub at: usize,
}

impl Tok {
    /// The word, when the token is one.
    pub fn word(&self) -> Option<&str> {
        match &self.token {
            Token::Word(w) => Some(w),
            _ => None,
        }
    }

    pub fn is_word(&self, w: &str) -> bool {
        self.word() == Some(w)
    }

    pub fn is_in(&self, list: &[&str]) -> bool {
        self.word().is_some_and(|w| list.contains(&w))
    }

    /// The token as the user wrote it (names for goals and objects).
    pub fn text(&self, s: &Scenario) -> String {
        match &self.token {
            Token::Word(w) => w.clone(),
            Token::Goal(i) => s.goals[*i].name.clone(),
            Token::Object(i) => s.objects[*i].name.clone(),
            Token::Here => "here".into(),
            Token::Break => ",".into(),
        }
    }
}

/// Unicode compatibility form (NFKC: "é" typed as one character or as "e"
/// and an accent, fullwidth "ｂｌｕｅ", ligatures read alike), then lower
/// case, then NFKC again (lower-casing can undo it); "n't" becomes " not";
/// clause punctuation becomes a comma token; hyphens, underscores and
/// slashes separate words, but a minus sign (a hyphen starting a word,
/// before a digit) stays, so "-3" is no count; other symbols are dropped.
fn normalise(text: &str) -> String {
    let lower: String = text.nfkc().collect::<String>().to_lowercase();
    let text = lower
        .nfkc()
        .collect::<String>()
        .replace("n't", " not")
        .replace("n’t", " not");
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(ch) = chars.next() {
        let starts_word = out.chars().last().is_none_or(char::is_whitespace);
        match ch {
            ',' | ';' | '.' | '!' | '?' | ':' => out.push_str(" , "),
            '-' if starts_word && chars.peek().is_some_and(char::is_ascii_digit) => out.push('-'),
            '-' | '_' | '/' => out.push(' '),
            c if c.is_alphanumeric() || c.is_whitespace() => out.push(c),
            _ => {}
        }
    }
    out
}

/// The words of `text` as the instruction reader sees them: two names
/// with the same words are one name to an instruction.
pub(super) fn words(text: &str) -> Vec<String> {
    normalise(text)
        .split_whitespace()
        .map(str::to_string)
        .collect()
}

/// The scenario's instruction as tokens, names matched longest first.
pub(super) fn tokenize(s: &Scenario) -> Vec<Tok> {
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
        let (len, token) = phrases
            .iter()
            .find(|(w, _)| text[i..].starts_with(w))
            .map(|(w, t)| (w.len(), t.clone()))
            .unwrap_or_else(|| {
                let token = match text[i].as_str() {
                    "," | "and" | "then" => Token::Break,
                    "here" | "there" => Token::Here,
                    w => Token::Word(w.to_string()),
                };
                (1, token)
            });
        tokens.push(Tok {
            token,
            at: tokens.len(),
        });
        i += len;
    }
    tokens
}
