//! `docs/listings.md` maps every listing, algorithm and figure of the sources to the lines that
//! implement it. This test keeps the map true as the code moves (GPU-free, instant): every
//! table row names at least one `` `path:first-last` `identifier` `` entry; the file must exist,
//! the range lie inside it, begin on the line that defines the identifier (or opens the block
//! it names: a function, struct, declaration, loop) and end on the line where that construct
//! ends. A range that drifts with the code, stops short or runs into the next function fails.

use std::path::Path;

/// One code reference of the map: file, 1-based inclusive line range, identifier, and the
/// line of the map it is on.
#[derive(Debug)]
struct Entry {
    path: String,
    first: usize,
    last: usize,
    ident: String,
    map_line: usize,
}

/// The `` `path:a-b` `ident` `` entries of a line (in any order of appearance).
fn entries_of(line: &str, map_line: usize) -> Vec<Entry> {
    let mut out = Vec::new();
    // split at backticks: odd pieces are code spans
    let spans: Vec<&str> = line.split('`').skip(1).step_by(2).collect();
    for w in spans.windows(2) {
        let Some((path, range)) = w[0].rsplit_once(':') else {
            continue;
        };
        let Some((a, b)) = range.split_once('-') else {
            continue;
        };
        let (Ok(first), Ok(last)) = (a.parse::<usize>(), b.parse::<usize>()) else {
            continue;
        };
        if path.is_empty() || path.contains(' ') {
            continue;
        }
        out.push(Entry {
            path: path.to_string(),
            first,
            last,
            ident: w[1].to_string(),
            map_line,
        });
    }
    out
}

/// The file's lines without their comments and with their string and character literals
/// emptied (strings and `/* */` comments may span lines), so that braces in them are not
/// counted.
fn code_lines(lines: &[&str]) -> Vec<String> {
    let (mut in_string, mut in_comment) = (false, false);
    let mut out = Vec::with_capacity(lines.len());
    for line in lines {
        let mut code = String::new();
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            if in_comment {
                if c == '*' && chars.peek() == Some(&'/') {
                    chars.next();
                    in_comment = false;
                }
                continue;
            }
            if in_string {
                match c {
                    '\\' => {
                        chars.next();
                    }
                    '"' => {
                        in_string = false;
                        code.push('"');
                    }
                    _ => {}
                }
                continue;
            }
            match c {
                '/' if chars.peek() == Some(&'/') => break,
                '/' if chars.peek() == Some(&'*') => {
                    chars.next();
                    in_comment = true;
                }
                '"' => {
                    in_string = true;
                    code.push('"');
                }
                '\'' => {
                    // a char literal ('{', '\n'); a lifetime ('a) has no closing quote near
                    let rest: Vec<char> = chars.clone().take(3).collect();
                    match rest.iter().position(|&q| q == '\'').filter(|&i| i > 0) {
                        Some(close) => {
                            for _ in 0..=close {
                                chars.next();
                            }
                            code.push_str("' '");
                        }
                        None => code.push(c),
                    }
                }
                _ => code.push(c),
            }
        }
        out.push(code);
    }
    out
}

/// Whether `ident` occurs in `line` as a whole word.
fn has_word(line: &str, ident: &str) -> bool {
    let word = |c: char| c.is_alphanumeric() || c == '_';
    line.match_indices(ident).any(|(i, _)| {
        let before = line[..i].chars().next_back();
        let after = line[i + ident.len()..].chars().next();
        !before.is_some_and(word) && !after.is_some_and(word)
    })
}

/// The last line (0-based) of the construct that begins on line `first`: where the braces
/// opened from there close again, or, if none opens, where its statement ends (`;`, or a
/// line that ends the construct without braces).
fn construct_end(code: &[String], first: usize) -> Option<usize> {
    let (mut depth, mut opened) = (0i64, false);
    for (i, code) in code.iter().enumerate().skip(first) {
        for c in code.chars() {
            match c {
                '{' => {
                    depth += 1;
                    opened = true;
                }
                '}' => depth -= 1,
                _ => {}
            }
            if depth < 0 {
                return None;
            }
        }
        if opened && depth == 0 {
            return Some(i);
        }
        if !opened && code.trim_end().ends_with(';') {
            return Some(i);
        }
    }
    None
}

/// Every problem of one entry, as messages naming the map line: the range must begin on the
/// line that defines (or opens the block named by) the identifier, and end on the line where
/// that construct ends — so a range that drifts, or stops short, or runs on into the next
/// function, fails.
fn check(root: &Path, e: &Entry) -> Option<String> {
    let at = format!(
        "docs/listings.md:{}: `{}:{}-{}`",
        e.map_line, e.path, e.first, e.last
    );
    let text = match std::fs::read_to_string(root.join(&e.path)) {
        Ok(t) => t,
        Err(err) => return Some(format!("{at}: cannot read {}: {err}", e.path)),
    };
    let lines: Vec<&str> = text.lines().collect();
    if e.first == 0 || e.first > e.last || e.last > lines.len() {
        return Some(format!(
            "{at}: not a range inside the file's {} lines",
            lines.len()
        ));
    }
    let code = code_lines(&lines);
    if !has_word(&code[e.first - 1], &e.ident) {
        let found = code
            .iter()
            .position(|l| has_word(l, &e.ident))
            .map_or("nowhere in the file".to_string(), |i| {
                format!("first on line {}", i + 1)
            });
        return Some(format!(
            "{at}: line {} does not define `{}` ({found})",
            e.first, e.ident
        ));
    }
    match construct_end(&code, e.first - 1) {
        Some(end) if end + 1 == e.last => None,
        Some(end) => Some(format!(
            "{at}: the construct of `{}` ends on line {}, not {}",
            e.ident,
            end + 1,
            e.last
        )),
        None => Some(format!("{at}: the construct of `{}` does not end", e.ident)),
    }
}

fn map_entries(map: &str) -> (Vec<Entry>, Vec<String>) {
    let mut entries = Vec::new();
    let mut rows_without = Vec::new();
    for (i, line) in map.lines().enumerate() {
        let row = line.trim_start();
        // table rows other than the header and the separator
        if !row.starts_with('|') || row.starts_with("|---") || row.starts_with("| Item") {
            continue;
        }
        let found = entries_of(row, i + 1);
        if found.is_empty() {
            rows_without.push(format!(
                "docs/listings.md:{}: a row without a code entry",
                i + 1
            ));
        }
        entries.extend(found);
    }
    (entries, rows_without)
}

#[test]
fn every_entry_of_the_listing_map_points_at_its_identifier() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let map = std::fs::read_to_string(root.join("docs/listings.md")).expect("docs/listings.md");
    let (entries, mut problems) = map_entries(&map);
    assert!(entries.len() >= 40, "only {} entries parsed", entries.len());
    problems.extend(entries.iter().filter_map(|e| check(root, e)));
    assert!(
        problems.is_empty(),
        "the listing map is out of date:\n{}",
        problems.join("\n")
    );
}

/// The links `](../path#Lnn)` of the map: the file exists and has line nn, and that line is a
/// comment (they point at the comment that explains a deviation).
#[test]
fn every_line_link_of_the_map_points_at_a_comment() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let map = std::fs::read_to_string(root.join("docs/listings.md")).expect("docs/listings.md");
    let mut problems = Vec::new();
    let mut links = 0;
    for (i, line) in map.lines().enumerate() {
        for piece in line.split("](../").skip(1) {
            let target = &piece[..piece.find(')').unwrap_or(piece.len())];
            let Some((path, anchor)) = target.split_once("#L") else {
                continue;
            };
            links += 1;
            let at = format!("docs/listings.md:{}: {target}", i + 1);
            let Ok(text) = std::fs::read_to_string(root.join(path)) else {
                problems.push(format!("{at}: no such file"));
                continue;
            };
            let n: usize = anchor.parse().unwrap_or(0);
            match text.lines().nth(n.wrapping_sub(1)) {
                Some(l) if l.trim_start().starts_with("//") => {}
                Some(l) => problems.push(format!("{at}: not a comment: {l:?}")),
                None => problems.push(format!("{at}: no line {n}")),
            }
        }
    }
    assert!(links >= 15, "only {links} line links");
    assert!(
        problems.is_empty(),
        "stale links in the listing map:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_map_covers_every_listing_the_issue_names() {
    let map =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/listings.md"))
            .expect("docs/listings.md");
    let items = |s: &str| {
        map.lines()
            .any(|l| l.starts_with(&format!("| {s} ")) || l.starts_with(&format!("| {s},")))
    };
    let mut wanted: Vec<String> = (11..=22).map(|n| format!("Listing {n}")).collect();
    wanted.extend(
        [
            "Algorithm 1",
            "Algorithm 2",
            "Algorithm 3",
            "Fig. 8",
            "Fig. 13",
        ]
        .map(String::from),
    );
    wanted.extend(
        [
            "Listing 1",
            "Listing 2",
            "Listing 3",
            "Algorithm 4",
            "Fig. 7",
            "Fig. 9",
        ]
        .map(String::from),
    );
    wanted.extend((1..=5).map(|n| format!("Listing 4.{n}")));
    wanted.extend(["Eq. 4.1", "Fig. 4.3", "Fig. 4.4", "ch. 3.3.2"].map(String::from));
    // the streaming tracer: the figures of the streaming tracer
    wanted.extend(["Fig. 1", "Fig. 2", "Fig. 3"].map(String::from));
    let missing: Vec<&String> = wanted.iter().filter(|w| !items(w)).collect();
    assert!(
        missing.is_empty(),
        "docs/listings.md has no row for {missing:?}"
    );
}

/// The checker itself: a wrong range, a missing file, an identifier outside its range, and the
/// ways a range drifts — starting at the comment above the definition, stopping a line short,
/// running on into the next function, starting inside the construct — are all reported (a
/// test that cannot fail is not a test).
#[test]
fn the_checker_catches_wrong_entries() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bad = "| X | y | `glsl/common/intersect.glsl:12-26` `intersectTriangle` |\n\
               | X | y | `glsl/common/intersect.glsl:1-9999` `intersectTriangle` |\n\
               | X | y | `glsl/nope.glsl:1-2` `main` |\n\
               | X | y | `glsl/common/intersect.glsl:6-34` `intersectTriangle` |\n\
               | X | y | `glsl/common/intersect.glsl:28-33` `intersectTriangle` |\n\
               | X | y | `glsl/common/intersect.glsl:28-35` `intersectTriangle` |\n\
               | X | y | `glsl/common/intersect.glsl:9-34` `intersectEdges` |\n\
               | X | y | `glsl/common/intersect.glsl:31-34` `edge1` |\n\
               | X | y | no entry here |\n";
    let (entries, rows_without) = map_entries(bad);
    assert_eq!(entries.len(), 8);
    assert_eq!(rows_without.len(), 1);
    for e in &entries {
        assert!(check(root, e).is_some(), "{e:?} passed");
    }
    let good = "| X | y | `glsl/common/intersect.glsl:28-34` `intersectTriangle`<br>\
                `glsl/common/intersect.glsl:9-26` `intersectEdges` |";
    let (entries, _) = map_entries(good);
    assert_eq!(entries.len(), 2);
    for e in &entries {
        assert_eq!(check(root, e), None);
    }
}

/// Braces in comments, strings (also across lines) and char literals do not count; a
/// construct without braces ends at its `;`.
#[test]
fn construct_ends_skip_comments_and_strings() {
    let text = [
        "fn f() {",           // 0
        "    let s = \"{ \\", // 1: a string with a brace, continued
        "        }}\"; // }", // 2
        "    let c = '{';",   // 3
        "    /* { */",        // 4
        "}",                  // 5
        "const X: u32 =",     // 6
        "    2;",             // 7
    ];
    let code = code_lines(&text);
    assert_eq!(construct_end(&code, 0), Some(5));
    assert_eq!(construct_end(&code, 6), Some(7));
    assert!(has_word("int getVoxelID(ivec3 v)", "getVoxelID"));
    assert!(!has_word("int getVoxelIDs(ivec3 v)", "getVoxelID"));
}
