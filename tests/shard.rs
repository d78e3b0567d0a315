//! `bench --list`, `bench --shard K/N` and `bench merge` (sweeps as Slurm job arrays): a run in
//! two shards, merged, has the configurations and triangle-test counts of the unsharded run;
//! a missing, doubled or foreign shard is refused, not merged.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Command, Output};

mod common;

const BIN: &str = env!("CARGO_BIN_EXE_gpgpu-rt");

/// Three base-tracer configurations (thesis-5.1) and one whole protocol (klee-table2), tiny.
fn run_args() -> Vec<&'static str> {
    let protocols = ["thesis-5.1", "klee-table2"];
    [
        &protocols[..],
        &common::KLEE_TINY,
        &["--angles", "1", "--warmup", "0"],
    ]
    .concat()
}

fn bench(args: &[&str]) -> Output {
    common::run(&[&["bench"], args].concat())
}

fn run_into(out: &Path, extra: &[&str]) -> Output {
    let mut args = run_args();
    args.extend(extra);
    args.extend(["--quiet", "--out", out.to_str().unwrap()]);
    bench(&args)
}

fn ok(o: Output, what: &str) -> String {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{what} failed:\n{err}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn fails_with(o: Output, what: &str, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "{what} should fail");
    assert!(err.contains(needle), "{what}: {needle:?} not in:\n{err}");
}

/// The rows of a CSV (header included) with the columns `keep`, sorted: what must not depend on
/// how the run was split.
fn rows(path: &Path, keep: &[&str]) -> BTreeSet<Vec<String>> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let cols: Vec<usize> = keep
        .iter()
        .map(|k| {
            header
                .iter()
                .position(|h| h == k)
                .unwrap_or_else(|| panic!("no {k}"))
        })
        .collect();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            cols.iter().map(|&c| rec[c].to_string()).collect()
        })
        .collect()
}

/// Run scripts/slurm-bench.sh with `args`, then `rest`, with `GPGPU_RT` set to this build and
/// the environment `env`.
fn script(args: &[&str], rest: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm-bench.sh"))
        .args(args)
        .args(rest)
        .env("GPGPU_RT", BIN)
        .envs(env.iter().copied())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run scripts/slurm-bench.sh")
}

fn manifest(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("shard.json")).expect("shard.json");
    serde_json::from_str(&text).unwrap()
}

/// The ids of the units a shard measured.
fn measured(dir: &Path) -> BTreeSet<String> {
    let m = manifest(dir);
    let keys = |k: &str| {
        m[k].as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect::<Vec<_>>()
    };
    keys("configs")
        .into_iter()
        .chain(keys("sections"))
        .collect()
}

#[test]
fn two_shards_merged_equal_the_unsharded_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = |n: &str| tmp.path().join(n);

    // --list: one line per unit, index and a unique id
    let listed = ok(bench(&[&run_args()[..], &["--list"]].concat()), "--list");
    let ids: Vec<String> = listed
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let f: Vec<&str> = l.split('\t').collect();
            assert_eq!(f[0], (i + 1).to_string(), "{l}");
            f[1].to_string()
        })
        .collect();
    assert_eq!(
        ids.len(),
        10,
        "three teapot configurations with base and with the SAH BVH's two structures, and \
         klee-table2:\n{listed}"
    );
    assert_eq!(ids.iter().collect::<BTreeSet<_>>().len(), 10, "unique ids");
    assert!(ids.contains(&"klee-table2".to_string()));
    assert!(!dir("listed").exists(), "--list writes nothing");

    ok(run_into(&dir("whole"), &[]), "the unsharded run");
    // the shards and the merge as the Slurm jobs of scripts/slurm-bench.sh run them
    let root = dir("slurm");
    for k in ["1", "2"] {
        let task = script(
            &["--task", "2", root.to_str().unwrap()],
            &run_args(),
            &[("SLURM_ARRAY_TASK_ID", k)],
        );
        ok(task, "an array task of slurm-bench.sh");
    }
    let (s1, s2) = (root.join("shard-1"), root.join("shard-2"));
    ok(
        script(&["--merge", "2", root.to_str().unwrap()], &[], &[]),
        "slurm-bench.sh's merge job",
    );
    let merged = root.join("merged");

    // the shards took every unit once, by index mod 2, and wrote no report
    let (m1, m2) = (measured(&s1), measured(&s2));
    let want1: BTreeSet<String> = ids.iter().step_by(2).cloned().collect();
    assert_eq!(m1, want1, "shard 1/2 measures units 1, 3, …");
    assert!(m1.is_disjoint(&m2));
    assert_eq!(m1.len() + m2.len(), ids.len());
    assert!(!s1.join("report.md").exists());

    let merge = |dirs: &[&Path], out: &Path| {
        let mut a: Vec<&str> = vec!["merge"];
        a.extend(dirs.iter().map(|d| d.to_str().unwrap()));
        a.extend(["--out", out.to_str().unwrap()]);
        bench(&a)
    };
    ok(
        merge(&[&s2, &s1], &dir("merged2")),
        "a merge given the shards in another order",
    );
    // the same settings spelled another way (protocols in another order, `--opt=value`, not
    // quiet) are the same run: the merge compares what is measured, not the text
    let mut respelled: Vec<String> = ["klee-table2", "thesis-5.1"].map(String::from).to_vec();
    respelled.extend(common::KLEE_TINY.map(String::from));
    respelled.extend(["--angles=1", "--warmup=0", "--shard=2/2", "--out"].map(String::from));
    respelled.push(dir("respelled").display().to_string());
    let respelled: Vec<&str> = respelled.iter().map(String::as_str).collect();
    ok(bench(&respelled), "shard 2/2 spelled another way");
    ok(
        merge(&[&s1, &dir("respelled")], &dir("merged3")),
        "a merge of shards whose command lines differ only in spelling",
    );

    // the same configurations with the same counts as the unsharded run
    let keep = [
        "scene",
        "tracer",
        "width",
        "height",
        "triangles",
        "triangle_tests",
    ];
    for csv in ["thesis-5.1.csv", "thesis-5.1_summary.csv"] {
        let keep: &[&str] = if csv.contains("summary") {
            &[
                "scene",
                "tracer",
                "width",
                "triangles",
                "triangle_tests_median",
            ]
        } else {
            &keep
        };
        assert_eq!(
            rows(&merged.join(csv), keep),
            rows(&dir("whole").join(csv), keep),
            "{csv}"
        );
    }
    let klee = [
        "scene",
        "variant",
        "device",
        "rays",
        "triangle_tests",
        "linespace_lookups",
    ];
    assert_eq!(
        rows(&merged.join("klee-table2.csv"), &klee),
        rows(&dir("whole").join("klee-table2.csv"), &klee)
    );
    let report = std::fs::read_to_string(merged.join("report.md")).expect("merged report.md");
    for needle in [
        "Merged from 2 shards",
        "| 1/2 |",
        "| 2/2 |",
        "## thesis-5.1",
        "## klee-table2",
    ] {
        assert!(
            report.contains(needle),
            "{needle:?} not in the merged report"
        );
    }
    for f in ["frames/thesis-5.1/teapot1_base.png", "thesis-5.1_fps.png"] {
        let whole = dir("whole").join(f);
        if whole.exists() {
            assert!(merged.join(f).exists(), "{f} missing from the merge");
        }
    }

    // a missing, a doubled and a foreign shard are refused
    fails_with(merge(&[&s1], &dir("m2")), "a missing shard", "2/2 missing");
    fails_with(
        merge(&[&s1, &s2, &s1], &dir("m3")),
        "a doubled shard",
        "given twice",
    );
    fails_with(
        merge(&[&s1, &s2], &s1),
        "merging into a shard",
        "one of the shards",
    );
    ok(
        bench(&[
            "thesis-5.1",
            "--width",
            "8",
            "--angles",
            "1",
            "--warmup",
            "0",
            "--shard",
            "2/2",
            "--out",
            dir("other").to_str().unwrap(),
        ]),
        "a shard of another run",
    );
    fails_with(
        merge(&[&s1, &dir("other")], &dir("m4")),
        "a foreign shard",
        "different runs",
    );
    fails_with(
        merge(&[&dir("whole")], &dir("m5")),
        "an unsharded folder",
        "shard.json",
    );
}

/// slurm-bench.sh submits an array of N shard tasks and a merge that depends on all of them
/// (`sbatch` replaced by a stand-in that records its arguments).
#[test]
fn slurm_bench_submits_an_array_and_a_dependent_merge() {
    let tmp = tempfile::tempdir().unwrap();
    let log = tmp.path().join("sbatch.log");
    let fake = tmp.path().join("sbatch");
    std::fs::write(
        &fake,
        format!("#!/bin/sh\necho \"$*\" >> {}\necho 4242\n", log.display()),
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let out = tmp.path().join("sweep");
    let path = format!(
        "{}:{}",
        tmp.path().display(),
        std::env::var("PATH").unwrap()
    );
    let o = script(
        &["3", out.to_str().unwrap()],
        &["thesis-5.1", "--width", "16"],
        &[("PATH", &path)],
    );
    ok(o, "slurm-bench.sh");
    let calls = std::fs::read_to_string(&log).unwrap();
    let lines: Vec<&str> = calls.lines().collect();
    assert_eq!(lines.len(), 2, "{calls}");
    let o = out.display();
    assert!(lines[0].contains("--array=1-3"), "{calls}");
    assert!(
        lines[0].ends_with(&format!("--task 3 {o} thesis-5.1 --width 16")),
        "{calls}"
    );
    assert!(lines[1].contains("--dependency=afterok:4242"), "{calls}");
    assert!(lines[1].ends_with(&format!("--merge 3 {o}")), "{calls}");
    // a protocol the binary refuses fails before anything is submitted
    std::fs::remove_file(&log).unwrap();
    let o = script(
        &["3", out.to_str().unwrap()],
        &["no-such-protocol"],
        &[("PATH", &path)],
    );
    assert!(!o.status.success());
    assert!(!log.exists(), "nothing submitted");
}
