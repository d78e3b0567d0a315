#!/usr/bin/env bash
# scripts/gpu-check.sh — one command for a machine with an NVIDIA GPU, at most eight minutes:
# build (where cargo is), list the EGL devices, run the driver-parity check on the GPU against
# llvmpipe's results, and run the four sources' bench protocols at a scale that fits; all of it
# written to docs/results/<gpu>/ (the GPU's name from GL_RENDERER), with the log.
#
#   scripts/gpu-check.sh                        on the GPU machine
#   scripts/gpu-check.sh --reference DIR        llvmpipe's parity results recorded elsewhere
#                                               (where the GPU machine has no Mesa):
#   scripts/gpu-check.sh --record-reference DIR here, before: `parity --out DIR` on llvmpipe
#   scripts/gpu-check.sh --dry-run              every step on the current driver (llvmpipe or
#                                               zink, GPGPU_RT_DRIVER), tiny, into a temporary
#                                               folder: checks the script without a GPU
#
# Options: --out DIR (instead of docs/results/<gpu>), --budget SECONDS (480), --bin PATH (the
# gpgpu-rt binary; default target/release/gpgpu-rt, built first where cargo is).
set -uo pipefail
cd "$(dirname "$0")/.."

budget=480
out=""
reference=""
record_reference=""
dry_run=0
bin="target/release/gpgpu-rt"
while [ $# -gt 0 ]; do
    case "$1" in
        --dry-run) dry_run=1 ;;
        --out) out="$2"; shift ;;
        --reference) reference="$2"; shift ;;
        --record-reference) record_reference="$2"; shift ;;
        --budget) budget="$2"; shift ;;
        --bin) bin="$2"; shift ;;
        -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
        *) echo "gpu-check: unknown option $1 (see --help)" >&2; exit 2 ;;
    esac
    shift
done

start=$(date +%s)
left() { echo $(( budget - ($(date +%s) - start) )); }
say() { echo "[gpu-check $(( $(date +%s) - start ))s] $*" >&2; }

# 1. the binary: built here where cargo is, else the one carried along
if command -v cargo >/dev/null 2>&1 && [ "$bin" = "target/release/gpgpu-rt" ]; then
    say "building"
    timeout "$(left)" cargo build --release --quiet || { say "build failed"; exit 1; }
fi
[ -x "$bin" ] || { say "no binary at $bin: build it (cargo build --release) or pass --bin"; exit 1; }

size=48
if [ -n "$record_reference" ]; then
    say "recording llvmpipe's parity results into $record_reference"
    GPGPU_RT_DRIVER=llvmpipe "$bin" parity --size "$size" --out "$record_reference"
    exit $?
fi

# 2. the device: an NVIDIA GPU unless --dry-run
if ! info_json=$("$bin" info --json 2>/dev/null); then
    say "no GL context:"; "$bin" info --json; exit 1
fi
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
say "device: $renderer; writing $out"
printf '%s\n' "$info_json" > "$out/info.json"
say "EGL devices: $(printf '%s' "$info_json" | tr -d '\n' | sed -n 's/.*"egl_devices": *\[\([^]]*\)\].*/\1/p')"

# 3. parity against llvmpipe: recorded here where Mesa is installed, else --reference
failed=0
if [ -z "$reference" ]; then
    reference="$out/parity-llvmpipe"
    say "recording llvmpipe's parity results"
    if ! GPGPU_RT_DRIVER=llvmpipe timeout "$(left)" "$bin" parity --size "$size" --out "$reference" 2>>"$out/gpu-check.log"; then
        say "llvmpipe is not available here: run --record-reference on a machine with Mesa and pass --reference"
        reference=""
        failed=1
    fi
fi
if [ -n "$reference" ]; then
    say "parity: this device against $reference"
    tolerance=0.002
    [ "$dry_run" = 1 ] && tolerance=0
    timeout "$(left)" "$bin" parity --size "$size" --tolerance "$tolerance" --out "$out/parity" --against "$reference" \
        || { say "parity: the drivers differ (see $out/parity/report.md)"; failed=1; }
fi

# 4. the four sources' protocols at a scale that fits what is left
if [ "$dry_run" = 1 ]; then
    protocols=(thesis-5.3 wagner-a2)
    extra=(--width 16 --height 16 --angles 1)
else
    protocols=(thesis-5.1 thesis-5.3 klee-fig13 wagner-a2 proximity-clouds-table1)
    extra=()
fi
n=${#protocols[@]}
for p in "${protocols[@]}"; do
    share=$(( $(left) / n ))
    n=$(( n - 1 ))
    if [ "$share" -lt 20 ]; then say "no time left for $p"; failed=1; continue; fi
    say "bench $p (at most ${share}s)"
    timeout "$share" "$bin" bench "$p" --scale quick "${extra[@]}" --out "$out/$p" \
        || { say "bench $p failed or ran out of time"; failed=1; }
done
say "done in $(( $(date +%s) - start ))s; results in $out"
exit $failed
