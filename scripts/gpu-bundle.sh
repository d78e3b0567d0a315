#!/usr/bin/env bash
# scripts/gpu-bundle.sh — here, where cargo and Mesa are: everything scripts/gpu-check.sh needs
# on a GPU machine that has neither, in one folder to carry there (target/gpu-check/):
#   gpgpu-rt              the release binary (its --version names the commit)
#   tests/                the test executables of the designs' GPU paths (BVH, refit, fused
#                         passes, instances, hit list, grids, line-space build, the twins)
#   parity-llvmpipe.tar.gz  llvmpipe's parity record by the same binary (gpu-check compares the
#                         GPU with it, and refuses a record of another commit)
# Stripped and packed to stay within what the device tool carries (64 MiB).
#
#   scripts/gpu-bundle.sh
set -euo pipefail
cd "$(dirname "$0")/.."

# the parity's image side: the one scripts/gpu-check.sh renders at on a GPU
size=48
case "${1:-}" in
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    "") ;;
    *) echo "gpu-bundle: unknown option $1 (see --help)" >&2; exit 2 ;;
esac

# the test files gpu-check runs on the device (scripts/gpu-check.sh reads the same list)
tests=$(sed -n 's/^gpu_tests=(\(.*\))$/\1/p' scripts/gpu-check.sh)
[ -n "$tests" ] || { echo "gpu-bundle: no gpu_tests=(...) line in scripts/gpu-check.sh" >&2; exit 1; }

bundle=target/gpu-check
rm -rf "$bundle"
mkdir -p "$bundle/tests"
cargo build --release --quiet
# the test executables as cargo names them (deps/<file>-<hash>), the newest of each
cargo test --release --no-run --quiet $(printf -- '--test %s ' $tests)
for t in $tests; do
    exe=$(ls -t target/release/deps/"$t"-???????????????? 2>/dev/null | grep -v '\.d$' | head -1 || true)
    [ -n "$exe" ] || { echo "gpu-bundle: no executable of tests/$t.rs" >&2; exit 1; }
    cp "$exe" "$bundle/tests/$t"
    strip "$bundle/tests/$t"
done
cp target/release/gpgpu-rt "$bundle/gpgpu-rt"
strip "$bundle/gpgpu-rt"
"$bundle/gpgpu-rt" --version > "$bundle/VERSION"
GPGPU_RT_DRIVER=llvmpipe "$bundle/gpgpu-rt" parity --size "$size" --out "$bundle/parity-llvmpipe" 2>"$bundle/parity-llvmpipe.log" \
    || { echo "gpu-bundle: llvmpipe's parity record failed (see $bundle/parity-llvmpipe.log)" >&2; exit 1; }
tar -C "$bundle" -czf "$bundle/parity-llvmpipe.tar.gz" parity-llvmpipe
rm -rf "$bundle/parity-llvmpipe"
du -sh "$bundle"
echo "carry $bundle (scripts/gpu-check.sh finds it there): $(cat "$bundle/VERSION")"
