//! Embeds every file below `glsl/` into the binary (`gl::program::EMBEDDED`), keyed by its path
//! below `glsl/`, so a new kernel folder needs no table entry and the binary runs from any
//! folder. `--glsl-dir` reads the same paths from disk instead.

use std::path::{Path, PathBuf};

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// The commit the binary is built from (`git rev-parse --short=12 HEAD`), with `-dirty` where
/// tracked files differ from it; "unknown" without git or outside a checkout. `--version` and
/// every report name it, so that a committed result says which code made it.
fn commit(manifest: &Path) -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(manifest)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let Some(head) = git(&["rev-parse", "--short=12", "HEAD"]) else {
        return "unknown".to_string();
    };
    let dirty =
        git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    format!("{head}{}", if dirty { "-dirty" } else { "" })
}

fn main() {
    // the manifest folder of this build (read at run time: a build script compiled for one
    // checkout must not embed another checkout's kernels)
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    println!(
        "cargo:rustc-env=GPGPU_RT_COMMIT={}",
        commit(Path::new(&manifest))
    );
    // again after a commit, a checkout or a change of a tracked source (only paths that exist:
    // a missing one would run this script at every build)
    for p in [
        ".git/HEAD",
        ".git/index",
        "src",
        "Cargo.toml",
        "Cargo.lock",
        "build.rs",
    ] {
        let path = Path::new(&manifest).join(p);
        if path.exists() {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
    let root = Path::new(&manifest).join("glsl");
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    collect(&root, &mut files);
    let mut code = String::from("&[\n");
    for f in &files {
        println!("cargo:rerun-if-changed={}", f.display());
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        code.push_str(&format!(
            "    ({rel:?}, include_str!({:?})),\n",
            f.display().to_string()
        ));
    }
    code.push_str("]\n");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("embedded_glsl.rs");
    std::fs::write(out, code).expect("write embedded_glsl.rs");
}
