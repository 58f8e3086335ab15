//! The Markdown of the workspace holds together, and the user docs describe the tool as it is.
//!
//! - Every relative link of every Markdown file in the checkout (git's tracked and not-ignored
//!   files) names a file or folder git has, and its `#anchor`, if any, a heading of the target
//!   (GitHub's slug) or an `<a id>` there. Links are read as GitHub renders them, to the extent
//!   these docs use Markdown: inline links and images, reference definitions, `src` and `href`
//!   attributes; none inside fenced code blocks or code spans. Web and mail addresses are not
//!   fetched.
//! - The user docs (every Markdown file but the lab notes in `docs/notes/` and the generated
//!   results) cite no issue numbers and tell no history: what was tried, what did not pay, what
//!   was reverted. That belongs in `docs/notes/`. Generated blocks (the README's summary, the
//!   parameter tables) are their generators' business and are skipped.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeSet, HashMap};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_default()
}

/// Folders no Markdown of ours lives in: build outputs, fetched models, the fuzzer's own target.
const SKIPPED_FOLDERS: [&str; 5] = ["target", "out", ".git", "node_modules", "cache"];

/// The files git has in the checkout (tracked, or new and not ignored), relative to the root,
/// `/`-separated; `None` where git cannot tell (a packaged crate, no git installed).
fn git_files(root: &Path) -> Option<BTreeSet<String>> {
    let output = Command::new("git")
        .args(["ls-files", "-z", "--cached", "--others", "--exclude-standard"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|output| output.status.success())?;
    let listed = String::from_utf8(output.stdout).ok()?;
    // A tracked file deleted in the working tree is gone for a reader too.
    Some(listed.split('\0').filter(|path| !path.is_empty() && root.join(path).is_file()).map(str::to_owned).collect())
}

/// Every file under `folder`, for a checkout without git; relative to `root`, `/`-separated.
fn walked_files(root: &Path, folder: &Path, files: &mut BTreeSet<String>) {
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !SKIPPED_FOLDERS.contains(&name.as_str()) {
                walked_files(root, &path, files);
            }
        } else if let Ok(relative) = path.strip_prefix(root) {
            files.insert(relative.to_string_lossy().replace('\\', "/"));
        }
    }
}

/// The checkout's files as a reader of the repository sees them.
struct Checkout {
    root: PathBuf,
    files: BTreeSet<String>,
}

impl Checkout {
    fn read() -> Self {
        let root = workspace_root();
        let files = git_files(&root).unwrap_or_else(|| {
            let mut files = BTreeSet::new();
            walked_files(&root, &root, &mut files);
            files
        });
        Self { root, files }
    }

    fn markdown(&self) -> Vec<&str> {
        self.files.iter().map(String::as_str).filter(|path| path.ends_with(".md")).collect()
    }

    fn text(&self, path: &str) -> String {
        std::fs::read_to_string(self.root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
    }

    /// A file, or a folder holding one.
    fn has(&self, path: &str) -> bool {
        let folder = format!("{}/", path.trim_end_matches('/'));
        path.is_empty() || self.files.contains(path) || self.files.range(folder.clone()..).next().is_some_and(|f| f.starts_with(&folder))
    }
}

/// For each line, whether it is part of a fenced code block (its fences included).
fn fenced_lines(text: &str) -> Vec<bool> {
    let mut open: Option<(char, usize)> = None;
    text.lines()
        .map(|line| {
            let trimmed = line.trim_start();
            let fence_char = trimmed.chars().next().filter(|c| *c == '`' || *c == '~');
            let run = fence_char.map_or(0, |c| trimmed.chars().take_while(|x| *x == c).count());
            match (open, fence_char) {
                (None, Some(c)) if run >= 3 => open = Some((c, run)),
                (Some((c, len)), Some(d)) if c == d && run >= len && trimmed[run * c.len_utf8()..].trim().is_empty() => {
                    open = None;
                    return true;
                }
                _ => {}
            }
            open.is_some()
        })
        .collect()
}

/// Replaces every character but newlines in `chars[from..to]` by a space.
fn blank(chars: &mut [char], from: usize, to: usize) {
    let to = to.min(chars.len());
    for c in &mut chars[from..to] {
        if *c != '\n' {
            *c = ' ';
        }
    }
}

/// The text with fenced code blocks and code spans blanked out, lines where they were.
fn prose(text: &str) -> Vec<char> {
    let fenced = fenced_lines(text);
    let mut chars: Vec<char> = text
        .lines()
        .zip(&fenced)
        .flat_map(|(line, fenced)| {
            let kept: Vec<char> = if *fenced { line.chars().map(|_| ' ').collect() } else { line.chars().collect() };
            kept.into_iter().chain(['\n'])
        })
        .collect();
    // A code span runs from a run of backticks to the next run of the same length within its
    // paragraph; an unmatched run is literal text.
    let run_at = |chars: &[char], i: usize| chars[i..].iter().take_while(|c| **c == '`').count();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            i += 1;
            continue;
        }
        let run = run_at(&chars, i);
        let mut j = i + run;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '`' {
                let other = run_at(&chars, j);
                if other == run {
                    close = Some(j);
                    break;
                }
                j += other;
            } else if chars[j] == '\n' && chars[j + 1..].iter().take_while(|c| **c != '\n').all(|c| c.is_whitespace()) {
                break; // a blank line ends the paragraph
            } else {
                j += 1;
            }
        }
        match close {
            Some(close) => {
                blank(&mut chars, i, close + run);
                i = close + run;
            }
            None => i += run,
        }
    }
    chars
}

fn line_of(chars: &[char], at: usize) -> usize {
    chars[..at].iter().filter(|c| **c == '\n').count() + 1
}

/// A link target at a line of its file.
struct Link {
    line: usize,
    target: String,
    /// Where `(target)` starts and ends in the prose, to blank it for the wording check.
    span: (usize, usize),
}

/// The destination of an inline link that starts at `chars[at]` (just after `](`), and where
/// the link's parentheses end.
fn destination(chars: &[char], at: usize) -> (String, usize) {
    let mut i = at;
    while i < chars.len() && chars[i].is_whitespace() {
        i += 1;
    }
    if chars.get(i) == Some(&'<') {
        let end = chars[i..].iter().position(|c| *c == '>' || *c == '\n').map_or(chars.len(), |p| i + p);
        let close = chars[end..].iter().position(|c| *c == ')').map_or(chars.len(), |p| end + p + 1);
        return (chars[i + 1..end].iter().collect(), close);
    }
    let start = i;
    let mut depth = 0usize;
    while i < chars.len() && !chars[i].is_whitespace() {
        match chars[i] {
            '(' => depth += 1,
            ')' if depth == 0 => break,
            ')' => depth -= 1,
            _ => {}
        }
        i += 1;
    }
    let target = chars[start..i].iter().collect();
    let close = chars[i..].iter().position(|c| *c == ')').map_or(chars.len(), |p| i + p + 1);
    (target, close)
}

/// Every link of a file's prose: `[text](target)`, `![alt](target)`, `[label]: target`,
/// `src="target"` and `href="target"`.
fn links(chars: &[char]) -> Vec<Link> {
    let mut found = Vec::new();
    for i in 0..chars.len().saturating_sub(1) {
        if chars[i] == ']' && chars[i + 1] == '(' {
            let (target, close) = destination(chars, i + 2);
            found.push(Link { line: line_of(chars, i), target, span: (i + 1, close) });
        }
        if chars[i] == ']' && chars.get(i + 1) == Some(&':') && chars[..i].iter().rev().take_while(|c| **c != '\n').last() == Some(&'[') {
            let (target, close) = destination(chars, i + 2);
            found.push(Link { line: line_of(chars, i), target, span: (i + 1, close) });
        }
        for attribute in ["src=\"", "href=\""] {
            let name: Vec<char> = attribute.chars().collect();
            if chars[i..].starts_with(&name) && i > 0 && chars[i - 1].is_whitespace() {
                let start = i + name.len();
                let end = chars[start..].iter().position(|c| *c == '"').map_or(chars.len(), |p| start + p);
                found.push(Link { line: line_of(chars, i), target: chars[start..end].iter().collect(), span: (start, end) });
            }
        }
    }
    found
}

/// GitHub's anchor for a heading: its rendered text lowercased, spaces turned into `-`, every
/// character but letters, digits, `-` and `_` dropped (backticks, dots, parentheses...).
fn slug(heading: &str) -> String {
    // Rendered text: a link shows its text, not its target; tags show nothing.
    let chars: Vec<char> = heading.chars().collect();
    let mut rendered = String::new();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] == ']' && chars.get(i + 1) == Some(&'(') {
            i = destination(&chars, i + 2).1;
        } else if chars[i] == '<' && chars[i + 1..].contains(&'>') {
            i += chars[i..].iter().position(|c| *c == '>').map_or(1, |p| p + 1);
        } else {
            rendered.push(chars[i]);
            i += 1;
        }
    }
    rendered
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

/// The anchors a Markdown file offers: its headings' slugs (a repeated one numbered `-1`, `-2`,
/// as GitHub does) and the `id`/`name` of its `<a>` tags.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    for (line, fenced) in text.lines().zip(fenced_lines(text)) {
        if fenced {
            continue;
        }
        let trimmed = line.trim_start_matches(' ');
        let level = trimmed.chars().take_while(|c| *c == '#').count();
        if (1..=6).contains(&level) && trimmed[level..].starts_with([' ', '\t']) {
            // An ATX heading may close with a run of `#`s.
            let mut heading = trimmed[level..].trim();
            let without_closing = heading.trim_end_matches('#');
            if without_closing.is_empty() || without_closing.ends_with([' ', '\t']) {
                heading = without_closing.trim_end();
            }
            let base = slug(heading);
            let count = seen.entry(base.clone()).or_insert(0);
            found.insert(if *count == 0 { base.clone() } else { format!("{base}-{count}") });
            *count += 1;
        }
        for tag in line.split("<a ").skip(1) {
            let tag = tag.split('>').next().unwrap_or_default();
            for attribute in ["id=\"", "name=\""] {
                if let Some((_, rest)) = tag.split_once(attribute) {
                    found.insert(rest.split('"').next().unwrap_or_default().to_owned());
                }
            }
        }
    }
    found
}

/// `a/b/../c` as `a/c`; `None` for a path that leaves the checkout.
fn normalised(path: &Path) -> Option<String> {
    let mut parts: Vec<String> = Vec::new();
    for component in path.components() {
        match component {
            Component::Normal(part) => parts.push(part.to_string_lossy().into_owned()),
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::CurDir => {}
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(parts.join("/"))
}

/// `%20` and the like, as a browser reads them in a link.
fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = text.get(i + 1..i + 3).and_then(|hex| u8::from_str_radix(hex, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(byte)) => {
                decoded.push(byte);
                i += 3;
            }
            (byte, _) => {
                decoded.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&decoded).into_owned()
}

fn is_external(target: &str) -> bool {
    let lower = target.to_ascii_lowercase();
    ["http://", "https://", "mailto:"].iter().any(|scheme| lower.starts_with(scheme))
}

#[test]
fn every_relative_link_and_anchor_in_the_markdown_resolves() {
    let checkout = Checkout::read();
    let markdown = checkout.markdown();
    assert!(markdown.len() > 20, "found the Markdown files: {markdown:?}");
    let mut anchors_of: HashMap<String, BTreeSet<String>> = HashMap::new();
    let mut broken = Vec::new();
    let (mut links_checked, mut anchors_checked) = (0, 0);
    for &file in &markdown {
        let text = checkout.text(file);
        let folder = Path::new(file).parent().unwrap_or(Path::new(""));
        for link in links(&prose(&text)) {
            if link.target.is_empty() || is_external(&link.target) {
                continue;
            }
            links_checked += 1;
            let (path, anchor) = link.target.split_once('#').map_or((link.target.as_str(), None), |(p, a)| (p, Some(a)));
            let path = percent_decoded(path);
            let resolved = if path.is_empty() {
                Some(file.to_owned())
            } else if let Some(from_root) = path.strip_prefix('/') {
                normalised(Path::new(from_root))
            } else {
                normalised(&folder.join(&path))
            };
            let Some(resolved) = resolved.clone().filter(|resolved| checkout.has(resolved)) else {
                let resolved = resolved.unwrap_or_else(|| "a path outside the checkout".to_owned());
                broken.push(format!("{file}:{}: `{}`: {resolved} is not in the checkout", link.line, link.target));
                continue;
            };
            let Some(anchor) = anchor.filter(|anchor| !anchor.is_empty()) else { continue };
            anchors_checked += 1;
            if !resolved.ends_with(".md") {
                broken.push(format!("{file}:{}: `{}`: an anchor into a file that is not Markdown", link.line, link.target));
                continue;
            }
            let offered = anchors_of.entry(resolved.clone()).or_insert_with(|| anchors(&checkout.text(&resolved)));
            if !offered.contains(&percent_decoded(anchor)) {
                broken.push(format!("{file}:{}: `{}`: {resolved} has no heading or <a id> `#{anchor}`", link.line, link.target));
            }
        }
    }
    // Not vacuous: the docs hold about 350 relative links, 160 of them with an anchor.
    assert!(links_checked > 300, "only {links_checked} relative links found");
    assert!(anchors_checked > 120, "only {anchors_checked} of them with an anchor");
    assert!(broken.is_empty(), "{} broken links:\n{}", broken.len(), broken.join("\n"));
}

/// Files a generator writes (each says so in its first line) and the lab notes, where history
/// and issue numbers belong.
fn is_user_doc(path: &str, text: &str) -> bool {
    !path.starts_with("docs/notes/") && !path.starts_with("docs/results/") && !text.starts_with("<!-- Generated")
}

/// Generated blocks inside a hand-written file, by their opening and closing markers.
const GENERATED_BLOCKS: [(&str, &str); 2] = [("<!-- summary -->", "<!-- /summary -->"), ("<!-- parameters -->", "<!-- /parameters -->")];

/// What a user doc must not say, found in one line (lowercased): a description of the finding.
fn history_in(line: &str) -> Vec<String> {
    let chars: Vec<char> = line.chars().collect();
    let mut found = Vec::new();
    let word_at = |at: usize, word: &str| {
        let len = word.chars().count();
        chars[at..].starts_with(&word.chars().collect::<Vec<_>>())
            && (at == 0 || !chars[at - 1].is_alphanumeric())
            && chars.get(at + len).is_none_or(|c| !c.is_alphanumeric())
    };
    for at in 0..chars.len() {
        // `issue 40`, `issue #40`, `issues #39`.
        if chars[at..].starts_with(&['i', 's', 's', 'u', 'e']) && (at == 0 || !chars[at - 1].is_alphanumeric()) {
            let mut i = at + 5;
            if chars.get(i) == Some(&'s') {
                i += 1;
            }
            while chars.get(i).is_some_and(|c| *c == ' ') {
                i += 1;
            }
            if chars.get(i) == Some(&'#') {
                i += 1;
            }
            if chars.get(i).is_some_and(char::is_ascii_digit) {
                found.push("an issue number".to_owned());
            }
        }
        // `#47`, `(#41)`: a bare issue reference.
        if chars[at] == '#'
            && chars.get(at + 1).is_some_and(char::is_ascii_digit)
            && (at == 0 || chars[at - 1].is_whitespace() || chars[at - 1] == '(')
        {
            found.push("an issue reference".to_owned());
        }
        for phrase in ["when last timed", "did not pay", "tried", "reverted"] {
            if word_at(at, phrase) {
                found.push(format!("history: \"{phrase}\""));
            }
        }
    }
    found
}

#[test]
fn the_user_docs_cite_no_issues_and_tell_no_history() {
    let checkout = Checkout::read();
    let mut user_docs = Vec::new();
    let mut findings = Vec::new();
    for file in checkout.markdown() {
        let text = checkout.text(file);
        if !is_user_doc(file, &text) {
            continue;
        }
        user_docs.push(file);
        let mut chars = prose(&text);
        for link in links(&chars) {
            blank(&mut chars, link.span.0, link.span.1);
        }
        let prose: String = chars.iter().collect();
        let mut generated = false;
        for ((number, line), source) in prose.lines().enumerate().zip(text.lines()) {
            if GENERATED_BLOCKS.iter().any(|(open, _)| line.trim() == *open) {
                generated = true;
            } else if GENERATED_BLOCKS.iter().any(|(_, close)| line.trim() == *close) {
                generated = false;
            } else if !generated {
                for finding in history_in(&line.to_lowercase()) {
                    findings.push(format!("{file}:{}: {finding}: {}", number + 1, source.trim()));
                }
            }
        }
    }
    // Not vacuous: the README, docs/*.md and every technique README are user docs.
    for expected in ["README.md", "docs/cli.md", "docs/architecture.md", "ssm-techniques/pcss/README.md", "ssm-scene/README.md"] {
        assert!(user_docs.contains(&expected), "{expected} is not among the user docs: {user_docs:?}");
    }
    assert!(user_docs.len() >= 15, "user docs: {user_docs:?}");
    assert!(
        findings.is_empty(),
        "user docs describe the tool as it is (history and issue numbers go to docs/notes/):\n{}",
        findings.join("\n")
    );
}

#[test]
fn the_slug_is_githubs_for_the_headings_we_write() {
    assert_eq!(slug("Counted work (`--count-work`)"), "counted-work---count-work");
    assert_eq!(slug("`sweep` and `merge`"), "sweep-and-merge");
    assert_eq!(slug("2026-12-05: Fig. 12, time against triangles"), "2026-12-05-fig-12-time-against-triangles");
    assert_eq!(
        slug("Contact shadows ([results.md#contact-shadows](results.md#contact-shadows))"),
        "contact-shadows-resultsmdcontact-shadows"
    );
    assert_eq!(slug("Edge rows: why `clamp` is the default (2026-12-05)"), "edge-rows-why-clamp-is-the-default-2026-12-05");
    assert_eq!(slug("wedges_work"), "wedges_work");
    let offered = anchors("# A\n\n```\n# not a heading\n```\n## A\n<a id=\"here\"></a>\n### B ##\n");
    assert_eq!(offered, ["a", "a-1", "b", "here"].into_iter().map(str::to_owned).collect());
}

#[test]
fn code_is_not_prose() {
    let chars = prose("a `[x](nowhere)` b\n```\n[y](nowhere)\n```\n``[z](`q`)`` [w](here#h) ![i](pic.png)\n");
    let targets: Vec<String> = links(&chars).into_iter().map(|link| link.target).collect();
    assert_eq!(targets, ["here#h", "pic.png"]);
    assert_eq!(
        history_in("as tried in issue #40 (#41), see #47; retried"),
        ["history: \"tried\"", "an issue number", "an issue reference", "an issue reference", "an issue reference"]
    );
    assert!(history_in("pvsm.md#interiors, section 4.2, retried over regions").is_empty());
}
