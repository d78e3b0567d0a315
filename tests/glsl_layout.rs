//! GPU-free, instant: the shape of the kernels' GLSL that the accelerators' variants rely on.
//! An accelerator's variants are kernels of its own, not switches in shared code:
//! - no conditional directive in `glsl/common/` names an accelerator's switch — each names a
//!   #define the pipeline sets for every kernel (`pipeline::mueller2015::kernel_defines`), or is
//!   the default of a hook (`#ifndef X` / `#define X`, which the including kernel may define
//!   first) or an include guard; a switch one accelerator sets lives in its own folder, or the
//!   common file takes a hook its kernel defines (as `closestHit` and `occluded`);
//! - the SAH BVH's fused pass (its entry files, `bvh/fused*.comp`, picked in
//!   `src/accel/bvh/fused.rs`, and the includes that only they use) has at most
//!   [`FUSED_CONDITIONALS`] conditional directives: its variants are entry files over one body.
//!
//! Planted violations in the checkers' own tests below show that each rule can fail.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The most `#if`/`#ifdef`/`#ifndef`/`#elif` directives the fused pass' own files may hold (16
/// in one file before its variants became entry files: a third of that).
const FUSED_CONDITIONALS: usize = 5;

/// Switches that only the accelerators' kernels are compiled with, or that the pipeline sets
/// on behalf of one accelerator (the SAH BVH's two levels, its image-buffer reads); with every
/// string literal of `src/accel/` and every `BVH_*` name they must not steer `glsl/common/`.
const ACCELERATOR_SWITCHES: &[&str] = &[
    "BVH_INSTANCES",
    "SCENE_IMAGES",
    "PIXEL_RECORDS",
    "HIT_LIST",
    "PASS_EYE_RAYS",
    "COUNTER_CLOUD_JUMPS",
    "FUSED_MISS",
    "BVH_BLOCK_LISTS",
    "RECORD_STORE_64",
    "PREFETCH_RAYS",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Every shader file under `glsl/`, by its path relative to `glsl/`.
fn shader_files() -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let glsl = root().join("glsl");
    for dir in std::fs::read_dir(&glsl).unwrap() {
        let dir = dir.unwrap().path();
        if !dir.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            let rel = f
                .strip_prefix(&glsl)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            out.insert(rel, std::fs::read_to_string(&f).unwrap());
        }
    }
    out
}

/// The conditional directives of a text: (line, directive, its identifiers).
fn conditionals(text: &str) -> Vec<(usize, String, Vec<String>)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let Some(rest) = t.strip_prefix('#') else {
            continue;
        };
        let rest = rest.trim_start();
        let Some(kw) = ["ifdef", "ifndef", "elif", "if"]
            .into_iter()
            .find(|k| rest.starts_with(k))
        else {
            continue;
        };
        let expr = rest[kw.len()..].split("//").next().unwrap_or("");
        let names = expr
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .filter(|w| {
                w.chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                    && *w != "defined"
            })
            .map(String::from)
            .collect();
        out.push((i + 1, kw.to_string(), names));
    }
    out
}

/// The names `kernel_defines` sets for every kernel of the pipeline: its `.set("NAME", …)` calls
/// and the counter slots `COUNTER_<NAME>` of `COUNTERS`.
fn pipeline_defines(source: &str) -> BTreeSet<String> {
    let body = source
        .split("pub fn kernel_defines(")
        .nth(1)
        .expect("pipeline::mueller2015::kernel_defines");
    let body = &body[..body.find("\n}\n").expect("end of kernel_defines")];
    let mut out: BTreeSet<String> = body
        .split(".set(")
        .skip(1)
        .filter_map(|s| s.trim_start().strip_prefix('"')?.split('"').next())
        .map(String::from)
        .collect();
    let counters = source
        .split("pub const COUNTERS: &[&str] = &[")
        .nth(1)
        .expect("COUNTERS");
    for name in counters[..counters.find("];").unwrap()]
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with('"'))
        .filter_map(|l| l.split('"').nth(1))
    {
        out.insert(format!("COUNTER_{}", name.to_uppercase()));
    }
    out
}

/// The upper-case string literals of the accelerators' Rust sources (the #defines they set).
fn accelerator_literals(sources: &[String]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for s in sources {
        for lit in s.split('"').skip(1).step_by(2) {
            if lit.len() > 1
                && lit
                    .chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
                && lit.starts_with(|c: char| c.is_ascii_uppercase())
            {
                out.insert(lit.to_string());
            }
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(std::fs::read_to_string(&p).unwrap());
        }
    }
}

/// The conditionals of the common files that name anything but a pipeline-wide define, a
/// hook's default or an include guard — or that name an accelerator's switch at all.
fn common_violations(
    common: &BTreeMap<String, String>,
    pipeline: &BTreeSet<String>,
    accel: &BTreeSet<String>,
) -> Vec<String> {
    let mut out = Vec::new();
    for (file, text) in common {
        let lines: Vec<&str> = text.lines().collect();
        for (line, kw, names) in conditionals(text) {
            for n in names {
                let accelerator = ACCELERATOR_SWITCHES.contains(&n.as_str())
                    || n.starts_with("BVH_")
                    || accel.contains(&n);
                // `#ifndef X` then `#define X …`: a hook's default, or an include guard
                let default = kw == "ifndef"
                    && lines.get(line).is_some_and(|next| {
                        next.trim_start()
                            .strip_prefix("#define")
                            .and_then(|r| r.split_whitespace().next())
                            == Some(n.as_str())
                    });
                if accelerator || !(default || pipeline.contains(&n)) {
                    out.push(format!("glsl/common/{file}:{line}: #{kw} {n}"));
                }
            }
        }
    }
    out
}

/// `#include "…"` targets of a file, relative to `glsl/`.
fn includes(file: &str, text: &str) -> Vec<String> {
    let dir = file.rsplit_once('/').map_or("", |(d, _)| d);
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("#include"))
        .filter_map(|r| r.split('"').nth(1))
        .map(|target| {
            let mut parts: Vec<&str> = dir.split('/').filter(|p| !p.is_empty()).collect();
            for p in target.split('/') {
                match p {
                    ".." => {
                        parts.pop();
                    }
                    "." => {}
                    p => parts.push(p),
                }
            }
            parts.join("/")
        })
        .collect()
}

/// Everything a file includes, directly or not, itself included.
fn closure(file: &str, files: &BTreeMap<String, String>) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![file.to_string()];
    while let Some(f) = todo.pop() {
        if !seen.insert(f.clone()) {
            continue;
        }
        if let Some(text) = files.get(&f) {
            todo.extend(includes(&f, text));
        }
    }
    seen
}

/// The fused pass' conditionals: those of its entry files and of every file that no other
/// kernel includes (a file shared with other kernels — the records, the lights, the hit's
/// evaluation — is a facility of its own). Returns (count, where each is).
fn fused_conditionals(
    entries: &[String],
    files: &BTreeMap<String, String>,
) -> (usize, Vec<String>) {
    let kernels: Vec<&String> = files
        .keys()
        .filter(|f| !f.ends_with(".glsl") && !entries.contains(f))
        .collect();
    let shared: BTreeSet<String> = kernels.iter().flat_map(|k| closure(k, files)).collect();
    let own: BTreeSet<String> = entries
        .iter()
        .flat_map(|e| closure(e, files))
        .filter(|f| !shared.contains(f))
        .collect();
    let mut found = Vec::new();
    for f in &own {
        for (line, kw, names) in conditionals(&files[f]) {
            found.push(format!("glsl/{f}:{line}: #{kw} {}", names.join(" ")));
        }
    }
    (found.len(), found)
}

/// The fused pass' entry files, as `src/accel/bvh/fused.rs` picks them.
fn fused_entries(bvh_rs: &str) -> Vec<String> {
    let mut out: Vec<String> = bvh_rs
        .split('"')
        .skip(1)
        .step_by(2)
        .filter(|s| s.starts_with("bvh/fused") && s.ends_with(".comp"))
        .map(String::from)
        .collect();
    out.sort();
    out.dedup();
    out
}

#[test]
fn no_accelerator_switch_in_common_glsl() {
    let files = shader_files();
    let common: BTreeMap<String, String> = files
        .iter()
        .filter_map(|(f, t)| {
            f.strip_prefix("common/")
                .map(|n| (n.to_string(), t.clone()))
        })
        .collect();
    assert!(
        common.len() >= 10,
        "glsl/common/ has {} files",
        common.len()
    );
    // kernel_defines in the pipeline's module, its counters in options.rs
    let pipeline = [
        "src/pipeline/mueller2015/mod.rs",
        "src/pipeline/mueller2015/options.rs",
    ];
    let pipeline = pipeline_defines(&pipeline.map(read).concat());
    assert!(pipeline.contains("SHADOW_BITS") && pipeline.contains("COUNTER_RAYS"));
    let mut sources = Vec::new();
    rust_files(&root().join("src/accel"), &mut sources);
    let accel = accelerator_literals(&sources);
    assert!(accel.contains("PASS_EYE_RAYS") && accel.contains("FIRST_LIGHT_PACKED"));
    let bad = common_violations(&common, &pipeline, &accel);
    assert!(
        bad.is_empty(),
        "switches in glsl/common/ that are not the pipeline's (move them to the accelerator's \
         folder, or give the common file a hook its kernel defines):\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_fused_pass_variants_are_entry_files() {
    let files = shader_files();
    let entries = fused_entries(&read("src/accel/bvh/fused.rs"));
    assert!(
        entries.len() >= 2 && entries.iter().all(|e| files.contains_key(e)),
        "fused entry files {entries:?}"
    );
    let (n, found) = fused_conditionals(&entries, &files);
    assert!(
        n <= FUSED_CONDITIONALS,
        "{n} conditional directives in the fused pass' own files (at most {FUSED_CONDITIONALS}):\n{}",
        found.join("\n")
    );
}

/// The checkers fail on planted violations.
#[test]
fn the_checkers_find_planted_violations() {
    let pipeline: BTreeSet<String> = ["SHADOW_BITS", "STORE_AOVS"].map(String::from).into();
    let accel: BTreeSet<String> = ["FIRST_LIGHT_PACKED", "STORE_AOVS"]
        .map(String::from)
        .into();
    let common = |text: &str| BTreeMap::from([("x.glsl".to_string(), text.to_string())]);
    let bad = |text: &str| common_violations(&common(text), &pipeline, &accel);
    // fine: pipeline-wide, a hook's default, an include guard
    assert!(bad("#if SHADOW_BITS\n#endif\n").is_empty());
    assert!(bad("#ifndef COUNTS_RAY\n#define COUNTS_RAY true\n#endif\n").is_empty());
    assert!(bad("#ifndef X_GLSL\n#define X_GLSL\n#endif\n").is_empty());
    // planted: an accelerator's switch by list, by prefix, set in src/accel/, unknown
    assert_eq!(bad("#if BVH_INSTANCES\n#endif\n").len(), 1);
    assert_eq!(bad("#ifdef PIXEL_RECORDS\n#endif\n").len(), 1);
    assert_eq!(
        bad("#if defined(SHADOW_BITS) && defined(HIT_LIST)\n#endif\n").len(),
        1
    );
    assert_eq!(bad("  #  if BVH_ANYTHING // a comment\n#endif\n").len(), 1);
    assert_eq!(
        bad("#if FIRST_LIGHT_PACKED\n#elif SOMETHING_ELSE\n#endif\n").len(),
        2
    );
    // a name the pipeline sets but an accelerator sets too is the accelerator's
    assert_eq!(bad("#if STORE_AOVS\n#endif\n").len(), 1);
    // an #ifndef that defines something else is no hook's default
    assert_eq!(bad("#ifndef HOOK\n#define OTHER 1\n#endif\n").len(), 1);

    // the fused pass: entry files and the includes no other kernel uses count
    let cond = |n: usize| "#if A\n#endif\n".repeat(n);
    let files = |own: usize, shared: usize, entry: usize| {
        BTreeMap::from([
            (
                "bvh/fused_a.comp".to_string(),
                format!(
                    "#include \"body.glsl\"\n#include \"shared.glsl\"\n{}",
                    cond(entry)
                ),
            ),
            (
                "bvh/fused_b.comp".to_string(),
                "#include \"body.glsl\"\n".to_string(),
            ),
            ("bvh/body.glsl".to_string(), cond(own)),
            ("bvh/shared.glsl".to_string(), cond(shared)),
            (
                "bvh/other.comp".to_string(),
                "#include \"../bvh/shared.glsl\"\n".to_string(),
            ),
        ])
    };
    let entries = ["bvh/fused_a.comp", "bvh/fused_b.comp"].map(String::from);
    assert_eq!(fused_conditionals(&entries, &files(3, 9, 1)).0, 4);
    // planted: the body over the limit, a conditional moved into an include of its own
    assert!(fused_conditionals(&entries, &files(6, 0, 0)).0 > FUSED_CONDITIONALS);
    assert!(fused_conditionals(&entries, &files(3, 0, 3)).0 > FUSED_CONDITIONALS);
    let bvh_rs = "kernel(\"bvh/fused_pass.comp\", \"fused_pass\"), \"bvh/fused.glsl\"";
    assert_eq!(fused_entries(bvh_rs), ["bvh/fused_pass.comp"]);
}
