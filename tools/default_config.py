#!/usr/bin/env python3
"""Which configuration of the SAH BVH `render` and `view` take by default, measured: the whole
frame of each candidate on Mesa llvmpipe and on zink, in one run.

For each driver and scene this renders at 512² (the scene's own reflection depth): the default
(`--tracer bvh` and nothing else), the fused pass named (`--fused-passes`), the thesis' four
kernels (`--four-kernels`); on the dragon also a turning frame (`--rotate objects --turn 1`):
the default, one tree (refitted), a tree per object under instances (two levels), and the four
kernels over one tree.
Each render draws FRAMES frames and reports its last (`--stats`: `wall_ms`, the frame from the start of
its draw to `glFinish`, the scene's transform and the accelerator's update included, and
`gpu_ms_total`); the configurations alternate within a
round, every other round in reverse order, ROUNDS rounds, and the report gives the median and range of each, and each one's ratio to
the default in the same round.

    python3 tools/default_config.py [--rounds N] [--drivers llvmpipe,zink]
        [--out docs/results/default-config.md]
"""
import argparse
import datetime
import json
import statistics
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target/release/gpgpu-rt"
FRAMES = 5
TURN = ["--rotate", "objects", "--turn", "1"]
STILL = [
    ("default", []),
    ("--fused-passes", ["--fused-passes"]),
    ("--four-kernels", ["--four-kernels"]),
]
TURNING = [
    ("turning, default", TURN),
    ("turning, --bvh-levels one", TURN + ["--bvh-levels", "one"]),
    ("turning, --bvh-levels two", TURN + ["--bvh-levels", "two"]),
    ("turning, --four-kernels --bvh-levels one", TURN + ["--four-kernels", "--bvh-levels", "one"]),
]
CASES = [("scenes/bunny.toml", STILL), ("scenes/dragon.toml", STILL + TURNING)]


def frame(driver, scene, options):
    """The last frame's wall and GPU milliseconds, its configuration and its renderer."""
    with tempfile.TemporaryDirectory() as d:
        stats = Path(d) / "s.json"
        cmd = [str(BIN), "render", scene, "--tracer", "bvh", "--width", "512", "--height", "512",
               "--frames", str(FRAMES), "--driver", driver, "--quiet", "--stats", str(stats),
               "-o", str(Path(d) / "x.png"), *options]
        subprocess.run(cmd, check=True, cwd=ROOT, capture_output=True)
        s = json.loads(stats.read_text())
    config = f"{s['bvh_passes']}, {s['bvh_levels']} level(s)"
    return s["wall_ms"], s["gpu_ms_total"], config, s["renderer"]


def spread(values):
    return f"{statistics.median(values):.0f} ({min(values):.0f}–{max(values):.0f})"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--drivers", default="llvmpipe,zink")
    p.add_argument("--out", default="docs/results/default-config.md")
    a = p.parse_args()
    lines = [
        "# The SAH BVH's default configuration, measured",
        "",
        f"`python3 tools/default_config.py --rounds {a.rounds} --drivers {a.drivers}`, "
        f"{datetime.date.today()}, on this machine's CPU (Mesa's software drivers share it: "
        "ratios, not absolute times, carry over). 512², each scene's reflection depth, "
        f"the last of {FRAMES} frames of each render, the configurations in turn (every other round "
        "in reverse); wall: the frame from the start of its draw "
        "to `glFinish` (the transform and the BVH's update included). Ratio: to the default "
        "in the same round.",
    ]
    for driver in a.drivers.split(","):
        for scene, configs in CASES:
            rows = {name: [] for name, _ in configs}
            renderer, ran = "", {}
            for r in range(a.rounds):
                # every other round in reverse, so that no configuration always runs first
                for name, options in (configs if r % 2 == 0 else configs[::-1]):
                    wall, gpu, config, renderer = frame(driver, scene, options)
                    rows[name].append((wall, gpu))
                    ran[name] = config
            lines += ["", f"## {Path(scene).stem}, {renderer}", "",
                      "| configuration | ran as | wall ms | GPU ms | wall / default |",
                      "|---|---|---:|---:|---:|"]
            base = [w for w, _ in rows["default"]]
            for name, _ in configs:
                walls = [w for w, _ in rows[name]]
                gpus = [g for _, g in rows[name]]
                ratios = [w / b for w, b in zip(walls, base)]
                lines.append(f"| {name} | {ran[name]} | {spread(walls)} | {spread(gpus)} | "
                             f"{statistics.median(ratios):.2f} "
                             f"({min(ratios):.2f}–{max(ratios):.2f}) |")
    out = ROOT / a.out
    out.write_text("\n".join(lines) + "\n")
    print(out.read_text())


if __name__ == "__main__":
    main()
