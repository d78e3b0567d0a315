#!/usr/bin/env python3
"""CPU samples per kernel of a frame on llvmpipe, under `perf record -e cpu-clock`.

llvmpipe runs a dispatch on its worker threads as JIT code, one function per kernel; perf's
software clock samples them (no hardware counters needed, so it works in a VM) and counts
the process's own CPU time, which other load on the machine disturbs far less than the
GPU timers' wall time. Samples whose outermost JIT frame lies in one 4 KiB page belong to one
kernel; the kernels run one after the other, so the frame is a sequence of runs of samples,
printed in dispatch order for the last frames (page: samples). Which kernel a run is follows
from the pipeline's dispatch order (e.g. `--tracer bvh --refl-depth 0`: eye_ray_generation,
entry, intersect1, evaluate_hit, pixel_counts, intersect2, pixel_counts, shading).

    python3 tools/kernel_samples.py scenes/bunny.toml --tracer bvh --refl-depth 0 \\
        --width 512 --height 512 --frames 8 [--glsl-dir DIR]
    python3 tools/kernel_samples.py --bin OTHER/gpgpu-rt scenes/bunny.toml ...
"""
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HZ = 4000


def kernel_runs(data):
    """The JIT samples as runs (page, samples), in time order; runs under 3 samples (a
    kernel's tail on the other thread) are folded away."""
    out = subprocess.run(["perf", "script", "-i", data, "-F", "ip,dso"],
                         capture_output=True, text=True, check=True).stdout
    runs = []
    for block in out.split("\n\n"):
        jit = [line for line in block.strip().splitlines() if "perf-" in line or "JIT" in line]
        if not jit:
            continue
        page = int(jit[-1].split()[0], 16) >> 12
        if runs and runs[-1][0] == page:
            runs[-1][1] += 1
        else:
            runs.append([page, 1])
    merged = []
    for page, n in (r for r in runs if r[1] >= 3):
        if merged and merged[-1][0] == page:
            merged[-1][1] += n
        else:
            merged.append([page, n])
    return merged


def main():
    args = sys.argv[1:]
    if not args or args[0] in ("-h", "--help"):
        sys.exit(__doc__)
    binary = str(ROOT / "target/release/gpgpu-rt")
    if args[0] == "--bin":  # another build, e.g. the commit before a change, for pairs
        if len(args) < 3:
            sys.exit("--bin needs a binary and then the render arguments")
        binary, args = args[1], args[2:]
    if not Path(binary).is_file():
        sys.exit(f"{binary} not found: cargo build --release (or --bin)")
    with tempfile.TemporaryDirectory() as tmp:
        data = f"{tmp}/perf.data"
        subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-F", str(HZ), "-g",
                        "-o", data, binary, "render", *args, "-o", f"{tmp}/image.png"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        runs = kernel_runs(data)
    print(f"samples at {HZ} Hz per kernel run, in dispatch order (the last 24 runs):")
    for page, n in runs[-24:]:
        print(f"  {page & 0xffff:04x}: {n:4d} samples = {1e3 * n / HZ:6.1f} ms of CPU time")


if __name__ == "__main__":
    main()
