//! `docs/listings.md` maps every listing, algorithm and figure of the sources to the lines that
//! implement it. This test keeps the map true as the code moves (GPU-free, instant): every
//! table row names at least one `` `path:first-last` `identifier` `` entry; the file must exist,
//! the range lie inside it, and the identifier occur within the range.

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

/// Every problem of one entry, as messages naming the map line.
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
    let range = &lines[e.first - 1..e.last];
    if !range.iter().any(|l| l.contains(&e.ident)) {
        return Some(format!("{at}: `{}` does not occur in these lines", e.ident));
    }
    None
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
    let items = |s: &str| map.lines().any(|l| l.starts_with(&format!("| {s} ")));
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
    wanted.extend(["Eq. 4.1", "Fig. 4.3"].map(String::from));
    // seed 004: the figures of the streaming tracer
    wanted.extend(["Fig. 1", "Fig. 2", "Fig. 3"].map(String::from));
    let missing: Vec<&String> = wanted.iter().filter(|w| !items(w)).collect();
    assert!(
        missing.is_empty(),
        "docs/listings.md has no row for {missing:?}"
    );
}

/// The checker itself: a wrong range, a missing file and an identifier outside its range are
/// all reported (a test that cannot fail is not a test).
#[test]
fn the_checker_catches_wrong_entries() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bad = "| X | y | `glsl/common/intersect.glsl:12-26` `intersectTriangle` |\n\
               | X | y | `glsl/common/intersect.glsl:1-9999` `intersectTriangle` |\n\
               | X | y | `glsl/nope.glsl:1-2` `main` |\n\
               | X | y | no entry here |\n";
    let (entries, rows_without) = map_entries(bad);
    assert_eq!(entries.len(), 3);
    assert_eq!(rows_without.len(), 1);
    for e in &entries {
        assert!(check(root, e).is_some(), "{e:?} passed");
    }
    let good = "| X | y | `glsl/common/intersect.glsl:1-30` `intersectTriangle` |";
    let (entries, _) = map_entries(good);
    assert!(check(root, &entries[0]).is_none());
}
