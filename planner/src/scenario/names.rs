//! One name per thing: no two objects, goals or hands may have names an
//! instruction reads alike. The instruction reader matches names by their
//! words ([`name_words`]: Unicode compatibility form NFKC, so NFC and NFD
//! spellings, fullwidth letters and ligatures are one; lower case; hyphens,
//! underscores and slashes as word breaks; other symbols dropped). Two
//! names with the same words would let "put blue-square-1 in the box"
//! move either, so validation refuses the later one naming both fields.

use std::collections::HashMap;

use crate::instruction::name_words;

/// The names seen so far, by the words an instruction reads them as
/// ([`name_words`]): one name per object, goal and hand, across the three
/// lists.
#[derive(Default)]
pub(super) struct Names {
    /// Words → (field, name) of the first element with them.
    seen: HashMap<Vec<String>, (String, String)>,
}

impl Names {
    /// Why `name` (of element `field`) clashes with an earlier name: the
    /// same name, or one an instruction cannot tell from it (case, Unicode
    /// form, hyphens and underscores); `None` when it does not. A name of
    /// no words (only symbols) is named by no instruction and clashes with
    /// nothing but itself.
    pub(super) fn clash(&mut self, field: &str, name: &str) -> Option<String> {
        let words = name_words(name);
        let key = match words.is_empty() {
            true => vec![name.to_string()],
            false => words,
        };
        let Some((first, earlier)) = self.seen.get(&key) else {
            self.seen
                .insert(key, (format!("{field}.name"), name.to_string()));
            return None;
        };
        Some(match earlier == name {
            true => format!("the name '{name}' is used twice (also {first})"),
            false => format!(
                "'{name}' and '{earlier}' ({first}) read as the same name: an instruction matches names ignoring case, Unicode form (NFKC) and hyphens, underscores and slashes, so it could not tell them apart; give each object, goal and hand a name of its own words"
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clashes(names: &[&str]) -> Vec<Option<String>> {
        let mut seen = Names::default();
        (names.iter().enumerate())
            .map(|(i, n)| seen.clash(&format!("objects[{i}]"), n))
            .collect()
    }

    #[test]
    fn names_differing_only_in_case_clash_naming_both_fields() {
        let found = clashes(&["Blue-Square-1", "blue-square-1"]);
        assert_eq!(found[0], None);
        let message = found[1].as_deref().expect("a clash");
        assert!(
            message.contains("'blue-square-1' and 'Blue-Square-1' (objects[0].name)"),
            "{message}"
        );
    }

    #[test]
    fn names_differing_only_in_unicode_form_or_separators_clash() {
        // "café" composed (NFC) and decomposed (NFD); fullwidth letters;
        // hyphens against underscores and spaces.
        for pair in [
            ["caf\u{e9}", "cafe\u{301}"],
            ["\u{ff42}\u{ff4c}\u{ff55}\u{ff45} box", "blue box"],
            ["blue_square_1", "blue square 1"],
        ] {
            assert!(clashes(&pair)[1].is_some(), "{pair:?} do not clash");
        }
    }

    #[test]
    fn names_of_different_words_do_not_clash() {
        let found = clashes(&["blue-square-1", "blue-square-11", "blue-square", "café"]);
        assert!(found.iter().all(Option::is_none), "{found:?}");
    }

    #[test]
    fn a_name_used_twice_says_so_naming_the_first() {
        let found = clashes(&["piece", "piece"]);
        let message = found[1].as_deref().expect("a clash");
        assert!(
            message.contains("'piece' is used twice (also objects[0].name)"),
            "{message}"
        );
    }

    #[test]
    fn names_of_symbols_only_clash_only_when_equal() {
        assert_eq!(clashes(&["**", "##"]), [None, None]);
        assert!(clashes(&["##", "##"])[1].is_some());
    }
}
