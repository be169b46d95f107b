//! The repository's Markdown pages, which `bench` rewrites in part (docs/BENCHMARKS.md's
//! generated sections, the DETAILS.md pages): every relative link and image leads to a file that
//! is there, or into out/ (ignored by git) on a page that names that folder, as it does in the
//! command that fills it. And docs/ stays small enough to be read rather than scrolled past: a
//! run that wrote its per-map images there again would fail here (issue 61).

use std::path::{Component, Path, PathBuf};

/// Issue 61's bound on docs/: the pages, their reports and the screenshots the README shows.
const DOCS_MAX_FILES: usize = 40;
const DOCS_MAX_BYTES: u64 = 3 * 1024 * 1024;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("eval/ lies in the repository")
        .to_path_buf()
}

/// Folders that hold no page of the project's: build output, git, other projects' code.
fn skipped_folder(name: &str) -> bool {
    name.starts_with('.')
        || ["target", "out", "third_party", "node_modules", "site"].contains(&name)
}

fn files_below(dir: &Path, skip: &dyn Fn(&str) -> bool, found: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !skip(&name) {
                files_below(&path, skip, found);
            }
        } else {
            found.push(path);
        }
    }
}

/// The link targets of `text` (`[text](target)` and `![alt](target "title")`), outside fenced
/// code blocks.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(start) = rest.find("](") {
            rest = &rest[start + 2..];
            let end = rest.find(')').unwrap_or(rest.len());
            let target = rest[..end].split_whitespace().next().unwrap_or("");
            targets.push(target.to_string());
            rest = &rest[end..];
        }
    }
    targets
}

/// `%20` and the like, as a browser reads a link.
fn percent_decoded(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(b)) => {
                out.push(b);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `path` with `..` and `.` resolved lexically (the target may not exist).
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

/// What is wrong with each relative link of the page `page` (text `text`) in `root`.
fn broken_links(root: &Path, page: &Path, text: &str) -> Vec<String> {
    let folder = page.parent().unwrap_or(root);
    let mut broken = Vec::new();
    for target in link_targets(text) {
        let plain = target.split('#').next().unwrap_or("");
        let external = plain.contains("://") || plain.starts_with("mailto:");
        if plain.is_empty() || external {
            continue;
        }
        let resolved = lexical(&folder.join(percent_decoded(plain)));
        if resolved.exists() {
            continue;
        }
        // Into out/: made by a command, which the page must give with the folder it fills.
        if let Ok(below_out) = resolved.strip_prefix(root.join("out")) {
            let made_in = Path::new("out").join(below_out.parent().unwrap_or(Path::new("")));
            let folder_named = made_in.to_string_lossy().replace('\\', "/");
            if text.contains(&format!("`{folder_named}/`")) {
                continue;
            }
            broken.push(format!(
                "{target}: lies in out/ but the page never names `{folder_named}/`, the folder its command fills"
            ));
            continue;
        }
        broken.push(format!("{target}: no such file"));
    }
    broken
}

#[test]
fn every_relative_link_of_every_page_resolves() {
    let root = repository();
    let mut files = Vec::new();
    files_below(&root, &skipped_folder, &mut files);
    let pages: Vec<PathBuf> = files
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    assert!(
        pages.iter().any(|p| p.ends_with("docs/BENCHMARKS.md")),
        "the walk found no docs/BENCHMARKS.md under {}",
        root.display()
    );
    let mut broken = Vec::new();
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        for why in broken_links(&root, page, &text) {
            let name = page.strip_prefix(&root).unwrap_or(page);
            broken.push(format!("{}: {why}", name.display()));
        }
    }
    assert!(
        broken.is_empty(),
        "{} broken links:\n{}",
        broken.len(),
        broken.join("\n")
    );
}

#[test]
fn a_broken_link_and_an_unexplained_out_link_are_found() {
    let root = repository();
    let page = root.join("docs/BENCHMARKS.md");
    let text = "[ok](history/) [gone](bench/no-such-plot.png) ![made](../out/bench/a.png)\n\
                ```\n[in code](not-checked.png)\n```\n";
    let broken = broken_links(&root, &page, text);
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(broken[0].contains("no such file") && broken[1].contains("never names"));
    let explained = format!("{text}\nDrawn into `out/bench/` by `strandlight bench`.\n");
    assert_eq!(broken_links(&root, &page, &explained).len(), 1);
}

#[test]
fn docs_holds_pages_and_data_not_per_map_images() {
    let mut files = Vec::new();
    files_below(&repository().join("docs"), &|_| false, &mut files);
    let bytes: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
        .sum();
    assert!(
        files.len() <= DOCS_MAX_FILES && bytes <= DOCS_MAX_BYTES,
        "docs/ holds {} files, {:.1} MB (at most {DOCS_MAX_FILES} and {} MB): per-map images and \
         per-run reports belong in out/ (`bench` draws its plots there)",
        files.len(),
        bytes as f64 / 1e6,
        DOCS_MAX_BYTES / (1024 * 1024)
    );
}
