#!/usr/bin/env bash
# scripts/gpu-check.sh — the first run on a machine with an NVIDIA GPU, bounded in time (480 s
# by default, every command bounded by what is left): the GL implementation and its profile,
# the tests of the designs' GPU paths, the driver parity against llvmpipe's record of the same
# commit, and the four sources' protocols at a scale that fits; all of it written to
# docs/results/<gpu>/ with a summary.md that says what ran, what passed and what was skipped.
#
#   scripts/gpu-bundle.sh                 here, first (cargo, Mesa): binary, tests, llvmpipe's
#                                         record into target/gpu-check/ — carry that folder
#   scripts/gpu-check.sh                  on the GPU machine (no cargo needed)
#   scripts/gpu-check.sh --dry-run        every step on the current driver (llvmpipe, or zink
#                                         with GPGPU_RT_DRIVER=zink), small, into a temporary
#                                         folder: checks the script without a GPU
#
# Options: --bin PATH (the gpgpu-rt binary; else target/gpu-check/gpgpu-rt, else
# target/release/gpgpu-rt where it is newer than the sources; built only where neither is and
# cargo is), --tests DIR (test executables; else target/gpu-check/tests), --reference DIR or
# .tar.gz (llvmpipe's parity record; else the bundle's, else recorded here where Mesa is),
# --any-commit (accept a record of another commit), --out DIR, --budget SECONDS.
set -uo pipefail
cd "$(dirname "$0")/.."

# the test files whose executables run on the device (scripts/gpu-bundle.sh reads this line)
gpu_tests=(accel bvh bvh_refit bvh_instances fused_passes grid linespace_build wagner stream)

budget=480
out=""
reference=""
dry_run=0
any_commit=""
bin=""
tests_dir=""
bundle=target/gpu-check
usage() { echo "gpu-check: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
    case "$1" in
        --out|--reference|--budget|--bin|--tests)
            [ $# -ge 2 ] && [ -n "$2" ] || usage "$1 needs a value (see --help)" ;;
    esac
    case "$1" in
        --dry-run) dry_run=1 ;;
        --out) out="$2"; shift ;;
        --reference) reference="$2"; shift ;;
        --any-commit) any_commit="--any-commit" ;;
        --budget) budget="$2"; shift ;;
        --bin) bin="$2"; shift ;;
        --tests) tests_dir="$2"; shift ;;
        -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
        *) usage "unknown option $1 (see --help)" ;;
    esac
    shift
done
# every argument checked before anything runs
case "$budget" in ''|*[!0-9]*) usage "--budget $budget is not a number of seconds" ;; esac
[ "$budget" -ge 20 ] || usage "--budget $budget: at least 20 seconds (the steps need some)"
if [ -n "$reference" ]; then
    case "$reference" in
        *.tar.gz) [ -f "$reference" ] || usage "--reference $reference: no such file" ;;
        *) [ -d "$reference" ] || usage "--reference $reference: no such folder (a parity record, or its .tar.gz)" ;;
    esac
fi
[ -z "$bin" ] || [ -x "$bin" ] || usage "--bin $bin: not an executable file"
[ -z "$tests_dir" ] || [ -d "$tests_dir" ] || usage "--tests $tests_dir: no such folder"
if [ -n "$out" ]; then
    [ ! -e "$out" ] || [ -d "$out" ] || usage "--out $out exists and is not a folder"
    probe="$out"; while [ ! -e "$probe" ]; do probe=$(dirname "$probe"); done
    [ -w "$probe" ] || usage "--out $out: $probe is not writable"
fi

start=$(date +%s)
left() { echo $(( budget - ($(date +%s) - start) )); }
say() { echo "[gpu-check $(( $(date +%s) - start ))s] $*" >&2; }
steps=()      # "| step | result | seconds |" rows of summary.md
failed=0

# step NAME MAX_SECONDS COMMAND...: run COMMAND for at most MAX_SECONDS and at most what is left
# of the budget (less a reserve for the summary); skipped, and said so, when no time is left —
# never `timeout 0`, which would mean no limit.
step() {
    local name="$1" max="$2"; shift 2
    local t; t=$(left); t=$(( t - 5 ))
    [ "$t" -gt "$max" ] && t=$max
    if [ "$t" -lt 5 ]; then
        say "skipped $name: the budget of ${budget}s is spent"
        steps+=("| $name | skipped: no time left | 0 |")
        failed=1
        return 1
    fi
    local s rc; s=$(date +%s)
    timeout -k 5 "$t" "$@"
    rc=$?
    local took=$(( $(date +%s) - s ))
    case $rc in
        0) steps+=("| $name | ok | $took |") ;;
        124|137) steps+=("| $name | stopped after ${t}s (its share of the budget) | $took |"); failed=1 ;;
        *) steps+=("| $name | failed (exit $rc) | $took |"); failed=1 ;;
    esac
    return $rc
}

newer_than_sources() {
    [ -x "$1" ] && [ -z "$(find src glsl Cargo.toml Cargo.lock build.rs -newer "$1" -print -quit 2>/dev/null)" ]
}

# 1. the binary: given, bundled, or built and current; built only where none of them is
if [ -z "$bin" ]; then
    if [ -x "$bundle/gpgpu-rt" ]; then
        bin="$bundle/gpgpu-rt"
    elif newer_than_sources target/release/gpgpu-rt; then
        bin=target/release/gpgpu-rt
    elif command -v cargo >/dev/null 2>&1; then
        say "building (no current binary)"
        t=$(( $(left) / 2 )); [ "$t" -lt 1 ] && t=1
        timeout -k 5 "$t" cargo build --release --quiet || { say "the build failed or ran out of time"; exit 1; }
        bin=target/release/gpgpu-rt
    else
        say "no binary: run scripts/gpu-bundle.sh where cargo is and carry target/gpu-check, or pass --bin"
        exit 1
    fi
fi
[ -x "$bin" ] || { say "no executable at $bin"; exit 1; }
[ -z "$tests_dir" ] && [ -d "$bundle/tests" ] && tests_dir="$bundle/tests"
version=$(timeout 10 "$bin" --version 2>/dev/null) || { say "$bin --version failed"; exit 1; }

# 2. the device: an NVIDIA GPU unless --dry-run
if ! info_json=$(timeout 60 "$bin" info --json 2>/tmp/gpu-check-info.$$); then
    say "no GL context: $(cat /tmp/gpu-check-info.$$)"; rm -f /tmp/gpu-check-info.$$; exit 1
fi
rm -f /tmp/gpu-check-info.$$
renderer=$(printf '%s' "$info_json" | sed -n 's/.*"renderer": *"\([^"]*\)".*/\1/p' | head -1)
if [ "$dry_run" = 0 ] && ! printf '%s' "$renderer" | grep -qi nvidia; then
    say "the first EGL device is \"$renderer\", not an NVIDIA GPU (use --dry-run to check the script)"
    exit 1
fi
slug=$(printf '%s' "$renderer" | tr 'A-Z' 'a-z' | sed 's/[^a-z0-9]\+/-/g; s/^-//; s/-$//' | cut -c1-40)
if [ -z "$out" ]; then
    if [ "$dry_run" = 1 ]; then out=$(mktemp -d); else out="docs/results/$slug"; fi
fi
mkdir -p "$out"
exec 2> >(tee -a "$out/gpu-check.log" >&2)
say "device: $renderer; $version; writing $out"
printf '%s\n' "$info_json" > "$out/info.json"
timeout 60 "$bin" info > "$out/info.txt" 2>&1
printf '%s\n' "$version" > "$out/version.txt"
command -v nvidia-smi >/dev/null 2>&1 && timeout 20 nvidia-smi > "$out/nvidia-smi.txt" 2>&1

# 3. the tests of the designs' GPU paths, run by their executables (carried: no cargo here)
# the parity's image side: the bundle's record is made at 48 (scripts/gpu-bundle.sh); a dry run
# that records its own reference takes 32
if [ "$dry_run" = 1 ] && [ -z "$reference" ]; then size=32; else size=48; fi
# the executable of test file $1: in --tests (or the bundle), else the newest cargo built here
test_exe() {
    if [ -n "$tests_dir" ]; then echo "$tests_dir/$1"; return; fi
    ls -t "${CARGO_TARGET_DIR:-target}"/release/deps/"$1"-???????????????? 2>/dev/null | grep -v '\.d$' | head -1
}
if [ -n "$tests_dir" ] || [ -n "$(test_exe bvh)" ]; then
    mkdir -p "$out/tests"
    for t in "${gpu_tests[@]}"; do
        exe=$(test_exe "$t")
        [ -n "$exe" ] && [ -x "$exe" ] || { steps+=("| test $t | no executable | 0 |"); failed=1; continue; }
        say "tests/$t.rs"
        GPGPU_RT_TEST_ROOT="$PWD" step "test $t" 120 "$exe" --quiet --test-threads 2 > "$out/tests/$t.txt" 2>&1
    done
else
    say "no test executables (scripts/gpu-bundle.sh makes them): the tests are skipped"
    steps+=("| tests | skipped: no test executables (--tests or scripts/gpu-bundle.sh) | 0 |")
    failed=1
fi

# 4. parity against llvmpipe's record of the same commit
if [ -z "$reference" ] && [ -f "$bundle/parity-llvmpipe.tar.gz" ] && [ "$dry_run" = 0 ]; then
    reference="$bundle/parity-llvmpipe.tar.gz"
fi
unpacked=0
case "$reference" in
    *.tar.gz)
        mkdir -p "$out/parity-llvmpipe"
        tar -C "$out" -xzf "$reference" || { say "cannot unpack $reference"; exit 1; }
        reference="$out/parity-llvmpipe"; unpacked=1 ;;
esac
if [ -z "$reference" ]; then
    reference="$out/parity-llvmpipe"
    say "recording llvmpipe's parity results"
    GPGPU_RT_DRIVER=llvmpipe step "parity record on llvmpipe" 240 "$bin" parity --size "$size" --out "$reference" 2>>"$out/gpu-check.log" \
        || { say "no llvmpipe record: run scripts/gpu-bundle.sh where Mesa is and carry target/gpu-check"; reference=""; }
fi
if [ -n "$reference" ]; then
    say "parity: this device against $reference"
    # a GPU may round a few grazing rays onto the other side of an edge (docs/drivers.md)
    tolerance=0.002
    [ "$dry_run" = 1 ] && tolerance=0
    step "parity against llvmpipe" 240 "$bin" parity --size "$size" --tolerance "$tolerance" \
        --out "$out/parity" --against "$reference" $any_commit \
        > /dev/null 2>>"$out/gpu-check.log" \
        || { [ -f "$out/parity/report.md" ] && say "parity: see $out/parity/report.md" \
             || say "parity: no report (see $out/gpu-check.log)"; }
    # the bundle's record unpacked here is the bundle's to keep; one recorded here stays
    [ "$unpacked" = 1 ] && rm -rf "$out/parity-llvmpipe"
    # the barrier bits (gl::sync): every bit before every access against the bits each access
    # needs, on this device — no run on llvmpipe or lavapipe can show a missing bit
    if [ -d "$out/parity" ]; then
        say "parity: every barrier bit against the minimal ones"
        GPGPU_RT_BARRIERS=all step "parity, every barrier bit against the minimal ones" 240 \
            "$bin" parity --size "$size" --out "$out/parity-all-barriers" --against "$out/parity" \
            > /dev/null 2>>"$out/gpu-check.log" \
            || { [ -f "$out/parity-all-barriers/report.md" ] && say "barriers: see $out/parity-all-barriers/report.md" \
                 || say "barriers: no report (see $out/gpu-check.log)"; }
    fi
fi

# 5. the four sources' protocols, each bounded by an equal share of what is left
if [ "$dry_run" = 1 ]; then
    protocols=(thesis-5.3 wagner-a2)
    extra=(--scale quick --width 16 --height 16 --angles 1)
else
    protocols=(thesis-5.1 thesis-5.3 wagner-a2 proximity-clouds-table1)
    extra=(--scale full --angles 4 --warmup 1)
fi
n=${#protocols[@]}
for p in "${protocols[@]}"; do
    share=$(( ($(left) - 10) / n ))
    n=$(( n - 1 ))
    say "bench $p (at most ${share}s)"
    step "bench $p" "$share" "$bin" bench "$p" "${extra[@]}" --out "$out/$p" > "$out/bench-$p.txt" 2>&1
done

# 6. what a reader needs to judge the run
{
    echo "# First run on $renderer"
    echo
    echo "$version, written by scripts/gpu-check.sh in $(( $(date +%s) - start )) s of a ${budget}-second budget."
    echo "The GL implementation, its limits and the profile it runs under: [info.txt](info.txt) ([info.json](info.json))."
    echo
    echo "| step | result | seconds |"
    echo "|---|---|---|"
    printf '%s\n' "${steps[@]}"
    echo
    echo "Test output: \`tests/<file>.txt\`; the parity: [parity/report.md](parity/report.md); each protocol's"
    echo "report: \`<protocol>/report.md\` (frame times: \`wall_ms\`, to after glFinish, beside \`gpu_ms\`, the"
    echo "sum of the timed kernels); the log: [gpu-check.log](gpu-check.log)."
} > "$out/summary.md"
say "done in $(( $(date +%s) - start ))s; results in $out (summary.md)"
exit $failed
