//! Every relative link in `README.md` and `docs/**/*.md` resolves: the file
//! (or folder) it names exists, and a `#anchor` names a heading of the
//! target Markdown file, with GitHub's heading slugs (lower case, characters
//! other than letters, digits, `_`, `-` and spaces dropped, spaces turned
//! into `-`, a repeated slug suffixed `-1`, `-2`, …). Links in code blocks
//! and code spans are not links; absolute URLs are not checked.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// `README.md` and every `.md` under `docs/`, sorted.
fn documentation_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md")];
    markdown_under(&root.join("docs"), &mut files);
    files.sort();
    files
}

fn markdown_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            markdown_under(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// The lines of a Markdown text outside fenced code blocks, with their
/// 1-based numbers and with code spans blanked out.
fn prose_lines(text: &str) -> Vec<(usize, String)> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            lines.push((i + 1, without_code_spans(line)));
        }
    }
    lines
}

/// `line` with every `` `code span` `` replaced by nothing.
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    for (i, part) in line.split('`').enumerate() {
        if i % 2 == 0 {
            out.push_str(part);
        }
    }
    out
}

/// The targets of the inline links and images `[text](target "title")` and
/// of reference definitions `[label]: target` on one line.
fn link_targets(line: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let end = after.find(')').unwrap_or(after.len());
        let inside = after[..end].trim();
        let target = inside.split_whitespace().next().unwrap_or("");
        targets.push(target.trim_matches(['<', '>']).to_string());
        rest = &after[end..];
    }
    let trimmed = line.trim_start();
    if trimmed.starts_with('[')
        && let Some(close) = trimmed.find("]:")
    {
        let target = trimmed[close + 2..].split_whitespace().next();
        targets.extend(target.map(str::to_string));
    }
    targets
}

/// Absolute URLs and mail addresses are outside the repository.
fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:")
}

/// GitHub's anchor for a heading's text.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// Link text `[text](target)` of a heading reduced to `text`, as GitHub
/// reads it for the slug.
fn heading_text(raw: &str) -> String {
    let mut out = String::new();
    let mut rest = raw;
    while let Some(open) = rest.find('[') {
        let Some(mid) = rest[open..].find("](") else {
            break;
        };
        let Some(close) = rest[open + mid..].find(')') else {
            break;
        };
        out.push_str(&rest[..open]);
        out.push_str(&rest[open + 1..open + mid]);
        rest = &rest[open + mid + close + 1..];
    }
    out.push_str(rest);
    out.replace(['`', '*'], "")
}

/// Every anchor a Markdown file's headings define.
fn anchors(text: &str) -> HashSet<String> {
    let mut seen = HashSet::new();
    let mut fenced = false;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        let level = trimmed.chars().take_while(|&c| c == '#').count();
        if fenced || level == 0 || level > 6 || !trimmed[level..].starts_with(' ') {
            continue;
        }
        let base = slug(&heading_text(trimmed[level..].trim_end_matches('#')));
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor);
    }
    seen
}

/// What is wrong with one link of `file`, if anything.
fn check_link(file: &Path, target: &str) -> Option<String> {
    let (path, anchor) = target.split_once('#').unwrap_or((target, ""));
    let resolved = if path.is_empty() {
        file.to_path_buf()
    } else {
        file.parent().expect("a file has a folder").join(path)
    };
    if !resolved.exists() {
        return Some(format!("{target}: no such file ({})", resolved.display()));
    }
    let is_markdown = resolved.extension().is_some_and(|e| e == "md");
    if anchor.is_empty() || !is_markdown {
        return None;
    }
    let text = std::fs::read_to_string(&resolved).expect("read the linked file");
    (!anchors(&text).contains(anchor)).then(|| {
        format!(
            "{target}: no heading with anchor #{anchor} in {}",
            resolved.display()
        )
    })
}

/// Every broken relative link of the documentation under `root`, as
/// `FILE:LINE: target: what is wrong`.
fn broken_links(root: &Path) -> Vec<String> {
    let mut broken = Vec::new();
    for file in documentation_files(root) {
        let text = std::fs::read_to_string(&file).expect("read a documentation file");
        for (number, line) in prose_lines(&text) {
            for target in link_targets(&line) {
                if target.is_empty() || is_external(&target) {
                    continue;
                }
                if let Some(problem) = check_link(&file, &target) {
                    let shown = file.strip_prefix(root).unwrap_or(&file).display();
                    broken.push(format!("{shown}:{number}: {problem}"));
                }
            }
        }
    }
    broken
}

#[test]
fn every_relative_link_in_the_documentation_resolves() {
    let root = crate::util::repo();
    assert!(
        documentation_files(&root).len() > 1,
        "no documentation found under {}",
        root.display()
    );
    let broken = broken_links(&root);
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn a_link_to_a_missing_file_or_heading_is_reported() {
    let root = crate::util::scratch_dir("doc-links");
    std::fs::create_dir_all(root.join("docs/guide")).unwrap();
    std::fs::write(
        root.join("README.md"),
        "# Top\n\n[ok](docs/guide/page.md#a-heading-x) [gone](docs/missing.md)\n\
         `[code](not/checked.md)`\n```\n[fenced](not/checked.md)\n```\n",
    )
    .unwrap();
    std::fs::write(
        root.join("docs/guide/page.md"),
        "# Page\n\n## A heading: `x`\n\n[up](../../README.md#top) [no](#no-such-heading)\n\
         [web](https://example.invalid/x.md)\n",
    )
    .unwrap();
    let broken = broken_links(&root);
    assert_eq!(broken.len(), 2, "{broken:#?}");
    assert!(
        broken[0].starts_with("README.md:3: docs/missing.md: no such file"),
        "{broken:#?}"
    );
    assert!(
        broken[1].contains("page.md:5: #no-such-heading: no heading with anchor #no-such-heading"),
        "{broken:#?}"
    );
}

#[test]
fn repeated_headings_get_numbered_anchors_as_on_github() {
    let found = anchors("# Tests\n## Tests\n## Where the robot starts (`afford run`)\n");
    let expected: HashSet<String> = ["tests", "tests-1", "where-the-robot-starts-afford-run"]
        .into_iter()
        .map(String::from)
        .collect();
    assert_eq!(found, expected);
}
