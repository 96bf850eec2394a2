//! Every relative link of the README and of `docs/*.md` resolves inside the repository: the
//! file (or directory) it names exists, and its `#anchor`, if any, is a heading of the target
//! page (as GitHub derives anchors from headings).
//!
//! Links are the inline `[text](target)` and reference `[label]: target` forms outside code
//! blocks and code spans; web links (`http:`, `https:`, `mailto:`) are not followed.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the tests package lives in the repository root")
        .to_path_buf()
}

/// The pages checked: the README and every page of `docs/`.
fn pages() -> Vec<PathBuf> {
    let root = root();
    let mut pages = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/ is readable")
        .map(|e| e.expect("docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// The lines of `text` outside fenced code blocks, with code spans blanked.
fn prose_lines(text: &str) -> Vec<String> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            out.push(String::new());
            continue;
        }
        if fenced {
            out.push(String::new());
            continue;
        }
        // Code spans: drop what lies between backtick runs.
        let mut kept = String::new();
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                kept.push(c);
            }
        }
        out.push(kept);
    }
    out
}

/// The link targets of `text`, with their line numbers (1-based).
fn links(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (i, line) in prose_lines(text).iter().enumerate() {
        // Reference definitions: `[label]: target`.
        let trimmed = line.trim_start();
        if trimmed.starts_with('[') {
            if let Some(end) = trimmed.find("]:") {
                let target = trimmed[end + 2..].split_whitespace().next().unwrap_or("");
                if !target.is_empty() {
                    found.push((i + 1, target.to_string()));
                }
                continue;
            }
        }
        // Inline links: `](target)` or `](target "title")`, parentheses nested once allowed.
        let mut rest = line.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let mut depth = 0usize;
            let mut end = None;
            for (j, c) in after.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => {
                        end = Some(j);
                        break;
                    }
                    ')' => depth -= 1,
                    _ => {}
                }
            }
            let Some(end) = end else { break };
            let inner = after[..end].trim();
            let target = match inner.strip_prefix('<') {
                Some(bracketed) => bracketed.split('>').next().unwrap_or(""),
                None => inner.split_whitespace().next().unwrap_or(""),
            };
            found.push((i + 1, target.to_string()));
            rest = &after[end..];
        }
    }
    found
}

/// GitHub's anchor for a heading: lower case, punctuation other than `-` and `_` dropped,
/// spaces made hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            '-' | '_' => Some(c),
            c if c.is_alphanumeric() => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a page: one per heading, a repeated one numbered `-1`, `-2`, … as GitHub
/// does.
fn anchors(text: &str) -> Vec<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        if fenced || !trimmed.starts_with('#') {
            continue;
        }
        let title = trimmed.trim_start_matches('#');
        if !title.starts_with(' ') {
            continue;
        }
        // Markup that GitHub drops from the anchor: code spans' backticks, emphasis, links.
        let plain: String = title.chars().filter(|c| !matches!(c, '`' | '*')).collect();
        let base = slug(&plain);
        let n = seen.entry(base.clone()).or_insert(0);
        out.push(if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        });
        *n += 1;
    }
    out
}

/// What is wrong with `target` written in `page`, if anything.
fn check(page: &Path, target: &str) -> Option<String> {
    if target.contains("://") || target.starts_with("mailto:") {
        return None;
    }
    let (path, anchor) = match target.split_once('#') {
        Some((p, a)) => (p, Some(a)),
        None => (target, None),
    };
    let file = if path.is_empty() {
        page.to_path_buf()
    } else {
        page.parent().expect("a page is in a directory").join(path)
    };
    let root = root();
    let Ok(resolved) = file.canonicalize() else {
        return Some(format!("{} does not exist", file.display()));
    };
    if !resolved.starts_with(root.canonicalize().expect("the root exists")) {
        return Some(format!("{} is outside the repository", resolved.display()));
    }
    let anchor = anchor?;
    if resolved.extension().is_none_or(|e| e != "md") {
        return Some(format!(
            "anchor #{anchor} on {}, which is not a markdown page",
            resolved.display()
        ));
    }
    let text = std::fs::read_to_string(&resolved).expect("a linked page is readable");
    if anchors(&text).iter().any(|a| a == anchor) {
        None
    } else {
        Some(format!(
            "{} has no heading with the anchor #{anchor}",
            resolved.display()
        ))
    }
}

#[test]
fn relative_links_of_the_readme_and_docs_resolve() {
    let mut broken = Vec::new();
    let mut count = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).expect("a page is readable");
        for (line, target) in links(&text) {
            count += 1;
            if let Some(why) = check(&page, &target) {
                broken.push(format!("{}:{line}: ({target}) {why}", page.display()));
            }
        }
    }
    assert!(count > 0, "no links found: the parser is broken");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_link_checker_finds_links_and_anchors() {
    let text = "# Top `code`\n\nSee [a](docs/a.md#two-words), [b](<b c.md> \"t\") and `[no](x)`.\n\
                ```\n[no](y)\n```\n[ref]: r.md#top-code\n## Two words\n## Two words\n";
    let found: Vec<String> = links(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(found, ["docs/a.md#two-words", "b c.md", "r.md#top-code"]);
    assert_eq!(anchors(text), ["top-code", "two-words", "two-words-1"]);
    assert_eq!(
        slug("The `kind` key: what (and why)?"),
        "the-kind-key-what-and-why"
    );
    // A missing file and a missing anchor are reported; a web link is not followed.
    let page = root().join("README.md");
    assert!(check(&page, "docs/no-such-page.md").is_some());
    assert!(check(&page, "#no-such-heading").is_some());
    assert!(check(&page, "https://example.org/x.md").is_none());
    assert!(check(&page, "docs/architecture.md").is_none());
}
