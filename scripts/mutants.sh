#!/usr/bin/env bash
# Mutation testing (issue 16): plants each mutant of scripts/mutants.toml in a fresh copy of
# the kernels or of the tree, runs the tests listed for it (--full: every test binary), and
# prints the score and the survivors. Run by hand before an issue is resolved, not in CI.
#
#   scripts/mutants.sh                 # all mutants, listed tests only
#   scripts/mutants.sh --full          # all mutants, the whole suite each
#   scripts/mutants.sh --kind glsl     # only the GLSL mutants (no recompilation: fast)
#   scripts/mutants.sh --only id1,id2  # some mutants
#   scripts/mutants.sh --check         # only check that every `from` text is still there
#
# Work files, the log and results.tsv go to $MUTANTS_DIR (default /tmp/gpgpu-rt-mutants).
# Everything runs under `nice`, one mutant at a time.
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/mutants.py "$@"
