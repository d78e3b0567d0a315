#!/usr/bin/env python3
"""Mutation testing of gpgpu-rt (issue 16): plant the mutants of scripts/mutants.toml one at a
time, run the tests, print the score and the survivors. Run through scripts/mutants.sh.

GLSL mutants: a fresh copy of glsl/ per mutant, mutated, and the prebuilt test binaries run
with GPGPU_RT_GLSL_DIR pointing at it (the kernels are read from there instead of the copies
built into the binaries; no recompilation). Rust mutants: a fresh copy of the tree per mutant
(the working tree without target/ and .git), mutated and built with `cargo test --release`
in a target directory of its own (seeded once from this tree's target/, so only the crate
itself is rebuilt).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def load_mutants(path):
    with open(path, "rb") as f:
        mutants = tomllib.load(f)["mutant"]
    ids = [m["id"] for m in mutants]
    dup = {i for i in ids if ids.count(i) > 1}
    if dup:
        sys.exit(f"{path}: duplicate ids {sorted(dup)}")
    return mutants


def check_mutant(m):
    """The mutant's original text occurs exactly once in its file (else the list is stale)."""
    text = (ROOT / m["file"]).read_text()
    n = text.count(m["from"])
    if n != 1:
        return f"{m['id']}: `from` occurs {n} times in {m['file']}"
    return None


def apply(tree, m):
    p = Path(tree) / m["file"]
    text = p.read_text()
    assert text.count(m["from"]) == 1, m["id"]
    p.write_text(text.replace(m["from"], m["to"]))


def run(cmd, env=None, cwd=None, timeout=None, log=None):
    """Run nice'd; returns (exit status, seconds). Timeout counts as a failure (124)."""
    t0 = time.time()
    try:
        r = subprocess.run(["nice", "-n", "10", *cmd], env=env, cwd=cwd, timeout=timeout,
                           stdout=log, stderr=subprocess.STDOUT)
        rc = r.returncode
    except subprocess.TimeoutExpired:
        rc = 124
    return rc, time.time() - t0


def test_binaries(log):
    """Build the unmutated tests; test name -> executable."""
    out = subprocess.run(
        ["nice", "-n", "10", "cargo", "test", "--release", "--no-run",
         "--message-format=json"], cwd=ROOT, stdout=subprocess.PIPE, stderr=log, text=True)
    if out.returncode != 0:
        sys.exit("the unmutated tree does not build (see the log)")
    exes = {}
    for line in out.stdout.splitlines():
        try:
            msg = json.loads(line)
        except json.JSONDecodeError:
            continue
        t = msg.get("target", {})
        if msg.get("reason") == "compiler-artifact" and msg.get("executable") \
                and "test" in t.get("kind", []):
            exes[t["name"]] = msg["executable"]
    return exes


def snapshot(exes, work):
    """Copies of the test executables, so that rebuilding the tree meanwhile changes nothing."""
    bin_dir = work / "bin"
    shutil.rmtree(bin_dir, ignore_errors=True)
    bin_dir.mkdir()
    for name, exe in exes.items():
        shutil.copy2(exe, bin_dir / name)
    return {name: str(bin_dir / name) for name in exes}


def split_spec(spec):
    """A test spec: "binary" (all its tests) or "binary:filter" (the tests whose name contains
    filter, as `cargo test --test binary -- filter` selects them)."""
    name, _, filt = spec.partition(":")
    return name, [filt] if filt else []


def run_glsl(m, tests, exes, work, timeout, log):
    glsl = work / "glsl"
    shutil.rmtree(glsl, ignore_errors=True)
    shutil.copytree(ROOT / "glsl", glsl)
    apply(work, m)
    env = dict(os.environ, GPGPU_RT_GLSL_DIR=str(glsl))
    for t in tests:
        print(f"--- {m['id']}: {t}", file=log, flush=True)
        name, filt = split_spec(t)
        rc, _ = run([exes[name], *filt, "--test-threads=1"], env=env, cwd=ROOT,
                    timeout=timeout, log=log)
        if rc != 0:
            return "killed", t
    return "survived", None


def fresh_tree(work):
    tree = work / "tree"
    shutil.rmtree(tree, ignore_errors=True)
    ignore = shutil.ignore_patterns("target", ".git")
    shutil.copytree(ROOT, tree, ignore=ignore, symlinks=True)
    target = work / "target"
    if not target.exists():
        shutil.copytree(ROOT / "target", target, symlinks=True)
    return tree, target


def run_rust(m, tests, full, work, timeout, log):
    tree, target = fresh_tree(work)
    apply(tree, m)
    env = dict(os.environ, CARGO_TARGET_DIR=str(target))
    env.pop("GPGPU_RT_GLSL_DIR", None)
    names = sorted({split_spec(t)[0] for t in tests})
    selection = [] if full else [a for t in names for a in ("--test", t)]
    print(f"--- {m['id']}: build", file=log, flush=True)
    rc, _ = run(["cargo", "test", "--release", "--no-run", *selection], env=env, cwd=tree,
                log=log)
    if rc != 0:
        return "unviable", "build"
    runs = [([], [], "all")] if full else [(["--test", split_spec(t)[0]], split_spec(t)[1], t)
                                           for t in tests]
    for select, filt, t in runs:
        print(f"--- {m['id']}: {t}", file=log, flush=True)
        rc, _ = run(["cargo", "test", "--release", *select, "--", *filt, "--test-threads=1"],
                    env=env, cwd=tree, timeout=timeout, log=log)
        if rc != 0:
            return "killed", t
    return "survived", None


def baseline(mutants, exes, full, timeout, log):
    """The unmutated kernels pass every binary the GLSL mutants use."""
    specs = sorted(exes) if full else sorted({t for m in mutants for t in m["tests"]})
    env = dict(os.environ)
    env.pop("GPGPU_RT_GLSL_DIR", None)
    for t in specs:
        name, filt = split_spec(t)
        if name not in exes:
            sys.exit(f"unknown test binary {name}")
        rc, secs = run([exes[name], *filt, "--test-threads=1"], env=env, cwd=ROOT,
                       timeout=timeout, log=log)
        print(f"baseline {t}: {'ok' if rc == 0 else 'FAILS'} ({secs:.0f} s)", flush=True)
        if rc != 0:
            sys.exit(f"baseline: tests/{t}.rs fails without a mutant; fix that first")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", default=str(ROOT / "scripts/mutants.toml"))
    ap.add_argument("--only", help="comma-separated mutant ids")
    ap.add_argument("--kind", choices=["glsl", "rust", "all"], default="all")
    ap.add_argument("--full", action="store_true",
                    help="run every test binary per mutant, not only those listed for it")
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--check", action="store_true", help="only check the list")
    ap.add_argument("--work", default=os.environ.get("MUTANTS_DIR", "/tmp/gpgpu-rt-mutants"))
    ap.add_argument("--timeout", type=int, default=900, help="seconds per test run")
    a = ap.parse_args()

    mutants = load_mutants(a.list)
    errors = [e for e in map(check_mutant, mutants) if e]
    if errors:
        sys.exit("\n".join(errors))
    if a.only:
        keep = set(a.only.split(","))
        mutants = [m for m in mutants if m["id"] in keep]
    if a.kind != "all":
        mutants = [m for m in mutants if m["file"].startswith("glsl/") == (a.kind == "glsl")]
    glsl_n = sum(m["file"].startswith("glsl/") for m in mutants)
    print(f"{len(mutants)} mutants ({glsl_n} GLSL, {len(mutants) - glsl_n} Rust) from {a.list}")
    if a.check:
        return

    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    log = open(work / "log.txt", "w")
    print(f"log: {work / 'log.txt'}; "
          + ("every test binary per mutant (--full)" if a.full
             else "per mutant only the test binaries listed for it (--full: all)"), flush=True)
    exes = snapshot(test_binaries(log), work)
    if not a.no_baseline and glsl_n:
        baseline([m for m in mutants if m["file"].startswith("glsl/")], exes, a.full,
                 a.timeout, log)

    results = []
    for m in mutants:
        tests = sorted(exes) if a.full else m["tests"]
        t0 = time.time()
        if m["file"].startswith("glsl/"):
            fate, by = run_glsl(m, tests, exes, work, a.timeout, log)
        else:
            fate, by = run_rust(m, tests, a.full, work, a.timeout, log)
        secs = time.time() - t0
        results.append((m, fate, by))
        print(f"{fate.upper():9} {m['id']:28} {secs:5.0f} s  {m['what']}"
              + (f"  [caught by {by}]" if fate == "killed" else ""), flush=True)

    report(results, work)


def report(results, work):
    killed = sum(f == "killed" for _, f, _ in results)
    survived = [m for m, f, _ in results if f == "survived"]
    unviable = [m for m, f, _ in results if f == "unviable"]
    scored = killed + len(survived)
    score = 100.0 * killed / scored if scored else 0.0
    print(f"\nscore: {killed}/{scored} killed = {score:.1f} %"
          + (f" ({len(unviable)} unviable: {', '.join(m['id'] for m in unviable)})"
             if unviable else ""))
    if survived:
        print("survivors:")
        for m in survived:
            print(f"  {m['id']}: {m['file']}: {m['what']}")
    with open(work / "results.tsv", "w") as f:
        for m, fate, by in results:
            f.write(f"{m['id']}\t{fate}\t{by or ''}\t{m['file']}\n")


if __name__ == "__main__":
    main()
