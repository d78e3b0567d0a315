#!/usr/bin/env python3
"""A turning frame against a still one, per BVH structure, by CPU samples on llvmpipe.

Issue 34 item 4 asks for a frame of the dragon turning every frame (`--rotate objects`) at no
more than 1.3x a still frame. This runs `tools/kernel_samples.py` (CPU samples per JIT kernel,
which the machine's other load disturbs far less than the GPU timers) on each scene for:
the still frame with one tree; the turning frame with one tree (refitted on the GPU every
frame); the turning and the still frame with a tree per object under instances
(`--bvh-instances`) — each with the four kernels (`--four-kernels`) and with the fused pass. A frame's cost is
the sum of its kernels' samples; each run renders FRAMES frames and keeps the median of its last
three; the configurations alternate within a round, and the ratios are taken within a round.
The frames are told apart by their count of kernel runs: a turning frame of one tree that
rebuilt on the CPU instead of refitting (no refit kernels; the shipped scenes' turns stay
below REBUILD_GROWTH) would shift them.

    python3 tools/turning_frames.py [--rounds N] [--out docs/results/turning_frames.md]
        [SCENE.toml ...]   (default: scenes/dragon.toml scenes/bunny.toml)
"""
import argparse
import datetime
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FRAMES = 5
TURN = ["--rotate", "objects", "--turn", "1"]
# name, options, kernel runs a frame (in dispatch order: the refit's transform and two passes
# where one tree turns; eye rays, entry, intersect1, evaluate_hit, counts, intersect2, counts,
# shading for the four kernels; entry, fused pass, counts for the fused pass)
CONFIGS = [
    ("still, one tree", [], 0),
    ("turning, one tree (refit)", TURN, 3),
    ("turning, instances", TURN + ["--bvh-instances"], 0),
    ("still, instances", ["--bvh-instances"], 0),
]
PASSES = [("four kernels", ["--four-kernels"], 8), ("fused", [], 3)]


def frame_samples(scene, options, runs_per_frame):
    """The median over the last three frames of a frame's samples (all its kernels)."""
    cmd = [sys.executable, str(ROOT / "tools/kernel_samples.py"), str(scene), "--tracer", "bvh",
           "--refl-depth", "0", "--width", "512", "--height", "512", "--frames", str(FRAMES),
           *options]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=ROOT).stdout
    runs = [int(m.group(1)) for m in re.finditer(r":\s+(\d+) samples", out)]
    frames = [sum(runs[len(runs) - (i + 1) * runs_per_frame:len(runs) - i * runs_per_frame])
              for i in range(3)]
    return statistics.median(frames)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*", default=["scenes/dragon.toml", "scenes/bunny.toml"])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--out", default="docs/results/turning_frames.md")
    a = p.parse_args()
    results = {}  # (scene, passes, config) -> [samples per round]
    for r in range(a.rounds):
        for scene in a.scenes:
            for pname, popts, pruns in PASSES:
                for cname, copts, cruns in CONFIGS:
                    s = frame_samples(scene, popts + copts, pruns + cruns)
                    results.setdefault((scene, pname, cname), []).append(s)
                    print(f"round {r + 1}: {scene}, {pname}, {cname}: {s}", flush=True)
    lines = [
        "# A turning frame against a still one (issue 34 item 4)",
        "",
        f"Written by `python3 tools/turning_frames.py --rounds {a.rounds} "
        f"{' '.join(a.scenes)}` on {datetime.date.today()} (llvmpipe, this machine's cores; "
        "see the tool's docstring). CPU samples at 4000 Hz of one frame's kernels (512², no "
        f"reflections, one light, the median of frames {FRAMES - 2}–{FRAMES}), per round; a turning frame "
        "turns every object by 1° (`--rotate objects --turn 1`). Ratios against the still "
        "frame with one tree, the design's default, taken within each round.",
        "",
    ]
    for scene in a.scenes:
        for pname, _, _ in PASSES:
            lines += [f"## {Path(scene).stem}, {pname}", "",
                      "| frame | samples per round | / still, one tree (per round) | median ratio |",
                      "|---|---|---|---|"]
            still = results[(scene, pname, CONFIGS[0][0])]
            for cname, _, _ in CONFIGS:
                s = results[(scene, pname, cname)]
                ratios = [x / y for x, y in zip(s, still)]
                lines.append(f"| {cname} | {', '.join(f'{x:.0f}' for x in s)} | "
                             f"{', '.join(f'{x:.2f}' for x in ratios)} | "
                             f"{statistics.median(ratios):.2f} |")
            lines.append("")
    Path(a.out).write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
