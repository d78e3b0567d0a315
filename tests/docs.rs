//! The documentation against the tree it describes (GPU-free apart from `render --help`, which
//! opens no GL context): every relative link of the README and `docs/` resolves to a file or
//! folder that exists; every test file is described in `docs/testing.md`, every shipped scene in
//! `docs/scenes.md`, and every long option of `gpgpu-rt render` appears in the synopsis of
//! `docs/commands.md`. A page that moves, a test or scene added without its row, or an option
//! added without its place in the synopsis fails here. Anchors (`#…`) are not checked: GitHub
//! and other renderers spell them differently.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The text outside code: fenced blocks dropped, inline code spans replaced by `code` (a link
/// whose text is a code span stays a link; a `[x](y)` inside code is no link).
fn prose(md: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in md.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            out.push('\n');
            continue;
        }
        if fenced {
            out.push('\n');
            continue;
        }
        // split at backticks: the odd pieces are code spans (a line's spans are balanced in
        // these pages; an unbalanced backtick makes the rest of the line code, which only
        // hides links, never invents one)
        for (i, piece) in line.split('`').enumerate() {
            out.push_str(if i % 2 == 0 { piece } else { "code" });
        }
        out.push('\n');
    }
    out
}

/// The targets of the inline links and images of `md`, `[text](target)` and
/// `![alt](target)`, with the 1-based line each is on; a title (`(target "title")`) dropped.
fn link_targets(md: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose(md).lines().enumerate() {
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            // the target ends at the parenthesis that closes the link
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
            let target = after[..end].split_whitespace().next().unwrap_or("");
            out.push((n + 1, target.trim_matches(['<', '>']).to_string()));
            rest = &after[end..];
        }
    }
    out
}

/// A target that names a file of this tree: not a URL, not an anchor of the same page.
fn relative(target: &str) -> Option<&str> {
    let external = target.contains("://") || target.starts_with("mailto:");
    let path = target.split(['#', '?']).next().unwrap_or("");
    (!external && !path.is_empty()).then_some(path)
}

/// The README and every page under `docs/`.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().collect();
        entries.sort_by_key(|e| e.path());
        for e in entries {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    let mut out = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut out);
    out
}

/// The links of `md` (a page in `dir`) whose file does not exist, as "line: target".
fn broken_links(md: &str, dir: &Path) -> Vec<String> {
    link_targets(md)
        .into_iter()
        .filter_map(|(line, target)| {
            let path = relative(&target)?;
            let path = path.replace("%20", " ");
            (!dir.join(&path).exists()).then(|| format!("{line}: {target}"))
        })
        .collect()
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let md = std::fs::read_to_string(&page).unwrap();
        checked += link_targets(&md).len();
        let rel = page.strip_prefix(root()).unwrap().display().to_string();
        for b in broken_links(&md, page.parent().unwrap()) {
            broken.push(format!("{rel}:{b}"));
        }
    }
    // the README and the design pages link dozens of files: a parser that found none is broken
    assert!(checked > 200, "only {checked} links found");
    assert!(
        broken.is_empty(),
        "links to files that do not exist:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_link_checker_finds_what_is_broken() {
    let dir = root().join("docs");
    let md = "A [page](testing.md), [an anchor](#here), [a heading of a page](scenes.md#scenes),\n\
              ![an image](images/teapot1.png), [a URL](https://example.org/x.md),\n\
              [`code` as text](../README.md) and [a folder](results/).\n\
              [gone](nowhere.md) and [also gone](design/nothing.md#x \"title\")\n\
              `[not a link](in-code.md)`\n\
              ```\n[nor](in-a-block.md)\n```\n";
    assert_eq!(
        broken_links(md, &dir),
        ["4: nowhere.md", "4: design/nothing.md#x"],
        "{:?}",
        link_targets(md)
    );
}

/// The `` `…` `` spans of `text`.
fn code_spans(text: &str) -> Vec<&str> {
    text.split('`').skip(1).step_by(2).collect()
}

/// The files of the folder `dir` ending in `ext` whose name (after `prefix`) is no code span
/// of the page `page`, sorted.
fn not_named(dir: &str, ext: &str, page: &str, prefix: &str) -> Vec<String> {
    let text = std::fs::read_to_string(root().join(page)).unwrap();
    let named = code_spans(&text);
    let mut missing: Vec<String> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(ext) && !named.contains(&format!("{prefix}{n}").as_str()))
        .collect();
    missing.sort();
    missing
}

#[test]
fn every_test_file_is_described_in_testing_md() {
    let missing = not_named("tests", ".rs", "docs/testing.md", "tests/");
    assert!(
        missing.is_empty(),
        "test files without a row in docs/testing.md: {missing:?}"
    );
}

#[test]
fn every_scene_is_described_in_scenes_md() {
    let missing = not_named("scenes", ".toml", "docs/scenes.md", "");
    assert!(
        missing.is_empty(),
        "scenes not in docs/scenes.md: {missing:?}"
    );
}

/// The long options (`--name`) of a help text, in order, without `--help`.
fn long_options(help: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for line in help.lines() {
        let line = line.trim_start();
        // an option's own line: `--name <VALUE>`, or `-o, --output <OUTPUT>`
        let line = line.strip_prefix("-o, ").unwrap_or(line);
        let Some(name) = line.strip_prefix("--") else {
            continue;
        };
        let name: String = name
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect();
        if name != "help" && !out.contains(&name) {
            out.push(name);
        }
    }
    out
}

#[test]
fn every_render_option_is_in_the_commands_synopsis() {
    let out = Command::new(env!("CARGO_BIN_EXE_gpgpu-rt"))
        .args(["render", "--help"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let options = long_options(&String::from_utf8(out.stdout).unwrap());
    assert!(
        options.len() > 20 && options.iter().any(|o| o == "tracer"),
        "render --help parsed into {options:?}"
    );
    let commands = std::fs::read_to_string(root().join("docs/commands.md")).unwrap();
    // the synopsis: the first fenced block, the one that shows `gpgpu-rt render`
    let synopsis = commands
        .split("```")
        .nth(1)
        .filter(|b| b.contains("gpgpu-rt render SCENE"))
        .expect("docs/commands.md opens with the synopsis of gpgpu-rt render");
    // from `gpgpu-rt render` to the next command's line
    let render = &synopsis[synopsis.find("gpgpu-rt render").unwrap()..];
    let render = render.split("\ngpgpu-rt ").next().unwrap();
    let words: Vec<&str> = render
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .collect();
    let missing: Vec<&String> = options
        .iter()
        .filter(|o| !words.contains(&format!("--{o}").as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "render options missing from the synopsis in docs/commands.md: {missing:?}"
    );
}
