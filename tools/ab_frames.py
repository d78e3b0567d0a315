#!/usr/bin/env python3
"""A/B of two gpgpu-rt binaries on llvmpipe: the same renders, alternating per round, the GPU
time of the last of three frames (`gpu_ms_total` and chosen kernels from `--stats`). Prints a
Markdown table of the medians and the median per-round ratio B/A.

    python3 tools/ab_frames.py OLD_BINARY NEW_BINARY [--rounds 5] > report.md
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

CASES = [
    # (label, render arguments, kernels to report beside the total)
    ("bunny 512², bvh --four-kernels", ["scenes/bunny.toml", "--tracer", "bvh", "--four-kernels"], ["intersect1", "evaluate_hit", "intersect2"]),
    ("bunny 512², bvh (fused pass)", ["scenes/bunny.toml", "--tracer", "bvh"], ["fused_pass"]),
    ("dragon 512², bvh --four-kernels", ["scenes/dragon.toml", "--tracer", "bvh", "--four-kernels"], ["intersect1", "evaluate_hit", "intersect2"]),
    ("teapot1 256², grid exact", ["scenes/teapot1.toml", "--tracer", "grid", "--width", "256", "--height", "256"], ["grid_count", "grid_fill", "intersect1"]),
    ("bunny_area 256², linespace 5×5", ["scenes/bunny_area.toml", "--shadows", "linespace", "--light-samples", "5x5", "--width", "256", "--height", "256"], ["shadow_linespace"]),
]


def run(binary, args, tmp):
    stats = os.path.join(tmp, "s.json")
    cmd = [binary, "render", *args, "--frames", "3", "--stats", stats, "-o", os.path.join(tmp, "x.png")]
    if "--width" not in args:
        cmd += ["--width", "512", "--height", "512"]
    subprocess.run(cmd, check=True, capture_output=True)
    with open(stats) as f:
        return json.load(f)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("--rounds", type=int, default=5)
    o = p.parse_args()
    results = {c[0]: {"a": [], "b": []} for c in CASES}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(o.rounds):
            order = [("a", o.a), ("b", o.b)] if r % 2 == 0 else [("b", o.b), ("a", o.a)]
            for label, args, kernels in CASES:
                for side, binary in order:
                    s = run(binary, args, tmp)
                    row = {"total": s["gpu_ms_total"]}
                    row.update({k: s["gpu_ms"].get(k, float("nan")) for k in kernels})
                    results[label][side].append(row)
            print(f"round {r + 1} done", file=sys.stderr)
    print("| case | measure | A ms (median) | B ms (median) | B/A: median of rounds (range) |")
    print("|---|---|---:|---:|---:|")
    for label, _, kernels in CASES:
        a, b = results[label]["a"], results[label]["b"]
        for k in ["total", *kernels]:
            ratios = [y[k] / x[k] for x, y in zip(a, b) if x[k] > 0]
            ma = statistics.median(x[k] for x in a)
            mb = statistics.median(y[k] for y in b)
            rng = f"{min(ratios):.3f}–{max(ratios):.3f}" if ratios else "-"
            med = f"{statistics.median(ratios):.3f}" if ratios else "-"
            print(f"| {label} | {k} | {ma:.1f} | {mb:.1f} | {med} ({rng}) |")


if __name__ == "__main__":
    main()
