//! The README is the front door: at most 250 lines, and every relative link in it and in the pages
//! under `docs/` names a file that exists (anchors into the README name one of its headings).

use std::path::{Path, PathBuf};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ sits in the repository").to_path_buf()
}

/// The targets of the Markdown links `[text](target)` and images `![alt](target)` outside code
/// blocks and code spans.
fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop code spans, whose brackets are not links.
        let mut plain = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k % 2 == 0 {
                plain.push_str(part);
            }
        }
        let mut rest = plain.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            out.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    out
}

/// GitHub's anchor of a heading: lower case, spaces to `-`, punctuation dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn check_links(file: &Path, problems: &mut Vec<String>) {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let dir = file.parent().expect("a file has a folder");
    for target in link_targets(&text) {
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (path, fragment) = match target.split_once('#') {
            Some((p, f)) => (p, Some(f)),
            None => (target.as_str(), None),
        };
        let resolved = if path.is_empty() { file.to_path_buf() } else { dir.join(path) };
        if !resolved.exists() {
            problems.push(format!("{}: link `{target}`: no such file", file.display()));
            continue;
        }
        if let Some(fragment) = fragment
            && resolved.extension().is_some_and(|e| e == "md")
        {
            let page = std::fs::read_to_string(&resolved).unwrap_or_default();
            let found =
                page.lines().filter(|l| l.starts_with('#')).any(|l| anchor(l.trim_start_matches('#')) == fragment);
            if !found {
                problems.push(format!("{}: link `{target}`: no such heading", file.display()));
            }
        }
    }
}

#[test]
fn the_readme_is_a_front_door_of_at_most_250_lines() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines; the limit is 250 (move reference material to docs/)");
    // The two commands come first.
    let first_block: Vec<&str> =
        readme.lines().skip_while(|l| !l.starts_with("```sh")).skip(1).take_while(|l| !l.starts_with("```")).collect();
    assert!(first_block.iter().any(|l| l.starts_with("cargo run -- demo")), "{first_block:?}");
    assert!(first_block.iter().any(|l| l.starts_with("cargo test --workspace")), "{first_block:?}");
}

#[test]
fn every_link_of_the_readme_and_the_docs_exists() {
    let root = repo_root();
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    assert!(docs.len() >= 10, "docs/ has {} pages", docs.len());
    files.extend(docs);
    let mut problems = Vec::new();
    for f in &files {
        check_links(f, &mut problems);
    }
    assert!(problems.is_empty(), "broken links:\n{}", problems.join("\n"));
    // Every docs page the README links to is one of those checked.
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let linked_pages =
        link_targets(&readme).into_iter().filter(|t| t.starts_with("docs/") && t.ends_with(".md")).count();
    assert!(linked_pages >= 10, "the README links {linked_pages} docs pages");
}

#[test]
fn the_link_finder_sees_links_and_skips_code() {
    let text = "see [a](docs/a.md) and `[b](no.md)`\n```\n[c](no.md)\n```\n![img](x.png)";
    assert_eq!(link_targets(text), vec!["docs/a.md".to_string(), "x.png".to_string()]);
    assert_eq!(anchor("Test your own ground segmenter"), "test-your-own-ground-segmenter");
    assert_eq!(anchor("Forests and McDaniel et al. (seed 002)"), "forests-and-mcdaniel-et-al-seed-002");
}
