//! The source's import graph, file by file: no file imports a file that imports it back (no
//! circle), and no file imports an item of a module that contains it (no arrow up).
//!
//! Both crates are walked from their roots (`src/lib.rs`, `src/app/main.rs`) through their
//! `mod` declarations. Every path a file names — `use` trees and paths in code starting with
//! `crate::`, `super::`, `self::`, `gpgpu_rt::`, a child module or a name the file imports — is
//! resolved to the deepest module it reaches, and that module's file is the arrow's head. When
//! the next segment is a name the module only imports (a `mod.rs` re-exporting a child's type),
//! the arrow follows the import to the file that defines it: a facade `mod.rs` is not where the
//! type lives. A `mod` declaration is no arrow: a module holding its children is not an import.
//!
//! Read with a small tokenizer (comments, strings and characters dropped), not a Rust parser:
//! it knows `use` trees, inline modules (`mod tests { … }`) and paths, which is what imports are.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// One module: its file, its child modules, the names it imports (name → the absolute path
/// they stand for), and the names it defines.
#[derive(Default)]
struct Module {
    file: PathBuf,
    children: BTreeMap<String, Vec<String>>,
    imports: HashMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
    defines: BTreeSet<String>,
}

/// The modules of both crates by absolute path (`["lib", "accel", "bvh"]`), and each file's
/// import paths (absolute) with the module each was written in.
#[derive(Default)]
struct Tree {
    modules: HashMap<Vec<String>, Module>,
    paths: Vec<(PathBuf, Vec<String>)>,
}

fn tokens(src: &str) -> Vec<String> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    while i < c.len() {
        let ch = c[i];
        if ch == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            loop {
                if at(i) == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if at(i) == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else if i >= c.len() {
                    break;
                } else {
                    i += 1;
                }
            }
        } else if ch == 'r' && (at(i + 1) == '"' || (at(i + 1) == '#' && at(i + 2) != '[')) {
            // a raw string: r"…", r#"…"#
            let mut j = i + 1;
            let mut hashes = 0;
            while at(j) == '#' {
                hashes += 1;
                j += 1;
            }
            if at(j) != '"' {
                out.push("r".into());
                i += 1;
                continue;
            }
            j += 1;
            while j < c.len() && !(c[j] == '"' && (0..hashes).all(|k| at(j + 1 + k) == '#')) {
                j += 1;
            }
            i = j + 1 + hashes;
        } else if ch == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if ch == '\'' {
            // a character literal, or a lifetime (dropped as well)
            if at(i + 1) == '\\' {
                i += 2;
                while i < c.len() && c[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(i + 2) == '\'' {
                i += 3;
            } else {
                i += 1;
            }
        } else if ch.is_alphanumeric() || ch == '_' {
            let s = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            out.push(c[s..i].iter().collect());
        } else if ch == ':' && at(i + 1) == ':' {
            out.push("::".into());
            i += 2;
        } else if ch.is_whitespace() {
            i += 1;
        } else {
            out.push(ch.to_string());
            i += 1;
        }
    }
    out
}

/// The paths of a `use` tree starting at `t[*i]`, each with the name it binds (its alias or
/// last segment; `*` for a glob), up to the closing `;`, `,` or `}`.
fn use_tree(t: &[String], i: &mut usize, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
    let mut path = prefix.to_vec();
    while *i < t.len() {
        let tok = t[*i].as_str();
        match tok {
            "::" => *i += 1,
            "{" => {
                *i += 1;
                while *i < t.len() && t[*i] != "}" {
                    use_tree(t, i, &path, out);
                    if t.get(*i).map(String::as_str) == Some(",") {
                        *i += 1;
                    }
                }
                *i += 1;
                return;
            }
            "*" => {
                *i += 1;
                out.push((path, "*".into()));
                return;
            }
            ";" | "," | "}" => {
                if let Some(last) = path.last().cloned() {
                    let name = if last == "self" {
                        path.pop();
                        path.last().cloned().unwrap_or_default()
                    } else {
                        last
                    };
                    out.push((path, name));
                }
                return;
            }
            "as" => {
                let alias = t[*i + 1].clone();
                *i += 2;
                if path.last().map(String::as_str) == Some("self") {
                    path.pop();
                }
                out.push((path, alias));
                return;
            }
            _ => {
                path.push(tok.to_string());
                *i += 1;
            }
        }
    }
}

/// Make `path`, written in module `at`, absolute: `crate`, `super`, `self` and `gpgpu_rt`
/// resolved; a path starting elsewhere (a child, an extern crate, a local name) is kept
/// relative, marked by a leading `"?"`.
fn absolute(path: &[String], at: &[String]) -> Vec<String> {
    let mut segs = path.iter().peekable();
    let mut base: Vec<String> = match segs.peek().map(|s| s.as_str()) {
        Some("crate") => {
            segs.next();
            vec![at[0].clone()]
        }
        Some("gpgpu_rt") => {
            segs.next();
            vec!["lib".into()]
        }
        Some("self") | Some("super") => at.to_vec(),
        _ => {
            return std::iter::once("?".to_string())
                .chain(path.iter().cloned())
                .collect()
        }
    };
    while let Some(s) = segs.peek() {
        match s.as_str() {
            "self" => {}
            "super" => {
                base.pop();
            }
            _ => break,
        }
        segs.next();
    }
    base.extend(segs.cloned());
    base
}

fn child_file(dir: &Path, name: &str) -> Option<PathBuf> {
    let flat = dir.join(format!("{name}.rs"));
    let nested = dir.join(name).join("mod.rs");
    [flat, nested].into_iter().find(|p| p.is_file())
}

/// Read the module `module` in `file` and, through its `mod` declarations, its descendants.
fn read(tree: &mut Tree, file: &Path, module: Vec<String>) {
    let src = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let t = tokens(&src);
    let stem = file.file_stem().unwrap().to_str().unwrap();
    let dir = match stem {
        "mod" | "lib" | "main" => file.parent().unwrap().to_path_buf(),
        _ => file.with_extension(""),
    };
    // the inline modules open at this point, and the brace depth each one closes at
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0;
    let mut files = Vec::new();
    let mut i = 0;
    tree.modules.entry(module.clone()).or_default().file = file.to_path_buf();
    while i < t.len() {
        let here: Vec<String> = module
            .iter()
            .cloned()
            .chain(inline.iter().map(|m| m.0.clone()))
            .collect();
        let tok = t[i].as_str();
        let next = t.get(i + 1).map(String::as_str).unwrap_or("");
        match tok {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if inline.last().map(|m| m.1) == Some(depth) {
                    inline.pop();
                }
            }
            "mod" if next.chars().all(|c| c.is_alphanumeric() || c == '_') => {
                let name = next.to_string();
                if t.get(i + 2).map(String::as_str) == Some("{") {
                    inline.push((name.clone(), depth));
                    depth += 1;
                    i += 3;
                    let m = tree.modules.entry(here.clone()).or_default();
                    m.children
                        .insert(name.clone(), [here.clone(), vec![name]].concat());
                    tree.modules
                        .entry([here, vec![t[i - 2].clone()]].concat())
                        .or_default()
                        .file = file.to_path_buf();
                    continue;
                }
                if inline.is_empty() {
                    let f = child_file(&dir, &name)
                        .unwrap_or_else(|| panic!("{}: mod {name}: no file", file.display()));
                    let m = tree.modules.entry(module.clone()).or_default();
                    m.children
                        .insert(name.clone(), [module.clone(), vec![name.clone()]].concat());
                    m.defines.insert(name.clone());
                    files.push((f, [module.clone(), vec![name]].concat()));
                }
            }
            "use" => {
                let mut j = i + 1;
                if t.get(j).map(String::as_str) == Some("::") {
                    j += 1;
                }
                let mut uses = Vec::new();
                use_tree(&t, &mut j, &[], &mut uses);
                for (path, name) in uses {
                    let abs = absolute(&path, &here);
                    let m = tree.modules.entry(here.clone()).or_default();
                    if name == "*" {
                        m.globs.push(abs.clone());
                    } else {
                        m.imports.insert(name, abs.clone());
                    }
                    tree.paths.push((file.to_path_buf(), abs));
                }
                i = j;
                continue;
            }
            "fn" | "struct" | "enum" | "trait" | "type" | "const" | "static" | "union"
                if inline.is_empty() && next.chars().all(|c| c.is_alphanumeric() || c == '_') =>
            {
                tree.modules
                    .entry(module.clone())
                    .or_default()
                    .defines
                    .insert(next.into());
            }
            "macro_rules" if inline.is_empty() => {
                if let Some(name) = t.get(i + 2) {
                    tree.modules
                        .entry(module.clone())
                        .or_default()
                        .defines
                        .insert(name.clone());
                }
            }
            _ if next == "::" && t.get(i.wrapping_sub(1)).map(String::as_str) != Some("::") => {
                // a path in code: its segments up to the first non-identifier
                let mut path = vec![tok.to_string()];
                let mut j = i + 1;
                while t.get(j).map(String::as_str) == Some("::")
                    && t.get(j + 1)
                        .is_some_and(|s| s.chars().all(|c| c.is_alphanumeric() || c == '_'))
                {
                    path.push(t[j + 1].clone());
                    j += 2;
                }
                tree.paths
                    .push((file.to_path_buf(), absolute(&path, &here)));
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    for (f, m) in files {
        read(tree, &f, m);
    }
}

impl Tree {
    /// The file `path` (absolute, or `"?"`-relative to module `at`) leads to: the deepest
    /// module it names, or, where the next segment is a name that module imports, the file
    /// that import leads to. `None` for a path outside the crates (std, an extern crate, a
    /// local variable).
    fn resolve(
        &self,
        path: &[String],
        at: &[String],
        seen: &mut BTreeSet<Vec<String>>,
    ) -> Option<PathBuf> {
        if !seen.insert(path.to_vec()) {
            return None;
        }
        let path: Vec<String> = if path[0] == "?" {
            // relative: a child of `at`, or a name `at` imports
            let m = self.modules.get(at)?;
            if let Some(child) = m.children.get(&path[1]) {
                [child.clone(), path[2..].to_vec()].concat()
            } else if let Some(target) = m.imports.get(&path[1]) {
                if target[0] == "?" && !m.children.contains_key(&target[1]) {
                    return None; // an extern crate's item
                }
                let full = [target.clone(), path[2..].to_vec()].concat();
                return self.resolve(&full, at, seen);
            } else {
                return None;
            }
        } else {
            path.to_vec()
        };
        if !self.modules.contains_key(&path[..1]) {
            return None;
        }
        let mut depth = 1;
        while depth < path.len() && self.modules.contains_key(&path[..depth + 1]) {
            depth += 1;
        }
        let m = &self.modules[&path[..depth]];
        if let Some(name) = path.get(depth) {
            if !m.defines.contains(name) {
                if let Some(target) = m.imports.get(name) {
                    let full = [target.clone(), path[depth + 1..].to_vec()].concat();
                    if let Some(f) = self.resolve(&full, &path[..depth], seen) {
                        return Some(f);
                    }
                }
                for g in &m.globs {
                    let full = [g.clone(), path[depth..].to_vec()].concat();
                    if let Some(f) = self.resolve(&full, &path[..depth], seen) {
                        if f != m.file {
                            return Some(f);
                        }
                    }
                }
            }
        }
        Some(m.file.clone())
    }

    /// The module a file holds (its outermost).
    fn module_of(&self, file: &Path) -> Vec<String> {
        self.modules
            .iter()
            .filter(|(_, m)| m.file == file)
            .map(|(k, _)| k.clone())
            .min_by_key(Vec::len)
            .unwrap()
    }
}

/// The file graph of both crates: file → the files it imports.
fn graph() -> (BTreeMap<PathBuf, BTreeSet<PathBuf>>, Tree) {
    let mut tree = Tree::default();
    read(&mut tree, Path::new("src/lib.rs"), vec!["lib".into()]);
    read(&mut tree, Path::new("src/app/main.rs"), vec!["bin".into()]);
    let mut g: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for m in tree.modules.values() {
        g.entry(m.file.clone()).or_default();
    }
    for (file, path) in &tree.paths {
        // the module the path was written in: a relative path is resolved against the
        // file's own module (inline modules read their file's names)
        let at = tree.module_of(file);
        if let Some(to) = tree.resolve(path, &at, &mut BTreeSet::new()) {
            if &to != file {
                g.get_mut(file).unwrap().insert(to);
            }
        }
    }
    (g, tree)
}

/// The strongly connected components of more than one file (Tarjan's algorithm).
fn circles(g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct S<'a> {
        g: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: HashMap<&'a PathBuf, usize>,
        low: HashMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut S<'a>, v: &'a PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on.insert(v);
        for w in &s.g[v] {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut c = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on.remove(w);
                c.push(w.clone());
                if w == v {
                    break;
                }
            }
            if c.len() > 1 {
                c.sort();
                s.out.push(c);
            }
        }
    }
    let mut s = S {
        g,
        index: HashMap::new(),
        low: HashMap::new(),
        stack: vec![],
        on: BTreeSet::new(),
        out: vec![],
    };
    for v in g.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The arrows from a file to a module that contains it (a child reading its parent's items).
fn arrows_up(g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>, tree: &Tree) -> Vec<(PathBuf, PathBuf)> {
    let mut up = Vec::new();
    for (from, tos) in g {
        let inner = tree.module_of(from);
        for to in tos {
            let outer = tree.module_of(to);
            if outer.len() < inner.len() && inner.starts_with(&outer) {
                up.push((from.clone(), to.clone()));
            }
        }
    }
    up
}

/// A path, and the files of a circle, as the failure message shows them.
fn show(c: &[PathBuf], g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> String {
    let mut s = String::new();
    for f in c {
        let inside: Vec<String> = g[f]
            .iter()
            .filter(|t| c.contains(t))
            .map(|t| t.display().to_string())
            .collect();
        s += &format!("    {} -> {}\n", f.display(), inside.join(", "));
    }
    s
}

/// The circles tolerated, each as its files (sorted), with why it is still here: none is left;
/// a new one must not join the list without a reason a reader accepts.
const KNOWN_CIRCLES: &[(&[&str], &str)] = &[];

/// The modules whose children read items their `mod.rs` (or `lib.rs`) defines: an arrow up,
/// tolerated. Only the crate root: `errln!`/`outln!` are `#[macro_export]`ed, so their path is
/// `crate::errln!` wherever they are defined (`output::console`).
const KNOWN_UP: &[&str] = &["src/lib.rs"];

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let (g, _) = graph();
    let found = circles(&g);
    let known: Vec<Vec<PathBuf>> = KNOWN_CIRCLES
        .iter()
        .map(|(files, _)| files.iter().map(PathBuf::from).collect())
        .collect();
    let mut msg = String::new();
    for c in found.iter().filter(|c| !known.contains(c)) {
        msg += &format!(
            "  a circle of {} files (each with its imports inside the circle):\n",
            c.len()
        );
        msg += &show(c, &g);
    }
    for (k, (files, _)) in known.iter().zip(KNOWN_CIRCLES) {
        if !found.contains(k) {
            msg +=
                &format!("  a known circle is gone or changed, update KNOWN_CIRCLES: {files:?}\n");
        }
    }
    println!(
        "{} file circles, {} of them known",
        found.len(),
        known.len()
    );
    assert!(msg.is_empty(), "import circles:\n{msg}");
}

#[test]
fn no_file_imports_from_a_module_that_contains_it() {
    let (g, tree) = graph();
    let up = arrows_up(&g, &tree);
    let new: Vec<String> = up
        .iter()
        .filter(|(_, to)| !KNOWN_UP.iter().any(|k| to == Path::new(k)))
        .map(|(a, b)| format!("  {} -> {}", a.display(), b.display()))
        .collect();
    let bench = up
        .iter()
        .filter(|(a, _)| a.starts_with("src/app/bench"))
        .count();
    assert_eq!(bench, 0, "the bench has arrows up: {up:?}");
    assert!(
        new.is_empty(),
        "{} arrows up:\n{}",
        new.len(),
        new.join("\n")
    );
}

/// The graph is read, not assumed: a known arrow is found, and a planted circle is one.
#[test]
fn the_reader_finds_arrows_and_circles() {
    let (mut g, tree) = graph();
    let main = PathBuf::from("src/app/main.rs");
    let bench = PathBuf::from("src/app/bench/mod.rs");
    assert!(
        g[&main].contains(&bench),
        "main.rs -> bench/mod.rs not found: {:?}",
        g[&main]
    );
    let n = g.len();
    assert!(n > 100, "only {n} files read");
    // planted: bench/mod.rs imported back by main.rs's import
    g.get_mut(&bench).unwrap().insert(main.clone());
    let found = circles(&g);
    assert!(
        found
            .iter()
            .any(|c| c.contains(&main) && c.contains(&bench)),
        "{found:?}"
    );
    assert!(arrows_up(&g, &tree).contains(&(bench, main)));
}
