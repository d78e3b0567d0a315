#!/usr/bin/env python3
"""Klee 2016's Fig. 11 with our renders: exact against the line-space modes at 4, 25, 100 rays.

The thesis' Fig. 11 sets the exact soft shadow beside the Cascaded Line Space's at 4, 25 and
100 shadow rays a pixel and points at the line space's blocky penumbrae ("kantige Ränder").
This script renders the same comparison with `gpgpu-rt render --shadows MODE --light-samples
UxV` for `exact` and each mode (default `linespace`, `linespace-fast`, `variant2`) at 2x2, 5x5
and 10x10 samples, reads each render's `shadow.npy` AOV (the share of a pixel's shadow rays
that reach the light), and composes one PNG: a row per sample count; in it `exact`, then for
each mode its image and the map of |s - exact| (black 0, white 0.25 or more) labelled with its
mean over the pixels with a first hit (`triangle_id` >= 0), as results/linespace-shadows.md
gives it. It prints the errors (and each render's triangle tests and line-space lookups from
`--stats`) as a Markdown table. A render's time is left out: one frame's includes the
shaders' compilation.

    python3 tools/klee_fig11.py [--scene scenes/bunny_area.toml] [--size 128]
        [--samples 2x2,5x5,10x10] [--modes linespace,linespace-fast,variant2]
        [--bin target/release/gpgpu-rt] [--out docs/images/klee-fig11.png] [--work DIR]

Needs Python 3 with numpy; the PNGs are read and written by tools/pngio.py (no imaging library).
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pngio  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
ERROR_WHITE = 0.25  # |s - exact| drawn white from here on
LABEL = 16          # label strip height, pixels
GAP = 2             # pixels between cells


def render(binary, scene, mode, samples, size, folder):
    """Render one cell; returns (image, shadow values, stats, wall seconds)."""
    folder.mkdir(parents=True, exist_ok=True)
    png, stats = folder / "image.png", folder / "stats.json"
    cmd = [str(binary), "render", str(scene), "--shadows", mode, "--light-samples", samples,
           "--width", str(size), "--height", str(size), "-o", str(png),
           "--aov-dir", str(folder / "aov"), "--stats", str(stats), "--quiet"]
    start = time.monotonic()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if done.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr}")
    wall = time.monotonic() - start
    shadow = np.load(folder / "aov" / "shadow.npy").astype(np.float64)
    hit = np.load(folder / "aov" / "triangle_id.npy") >= 0
    return pngio.read_png(png), shadow, hit, json.loads(stats.read_text()), wall


def error_map(diff):
    """|s - exact| as grey: 0 black, ERROR_WHITE or more white."""
    grey = np.clip(diff / ERROR_WHITE, 0.0, 1.0) * 255.0
    return np.repeat(grey[:, :, None], 3, axis=2).astype(np.uint8)


def labelled(img, text):
    return np.vstack([pngio.label_strip(text, img.shape[1], LABEL), img])


def row_of(cells, height):
    parts = []
    for i, cell in enumerate(cells):
        if i:
            parts.append(np.full((height, GAP, 3), 255, dtype=np.uint8))
        parts.append(cell)
    return np.hstack(parts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="scenes/bunny_area.toml")
    ap.add_argument("--size", type=int, default=128, help="image side in pixels")
    ap.add_argument("--samples", default="2x2,5x5,10x10", help="light samples per row (the thesis: 4, 25, 100 rays)")
    ap.add_argument("--modes", default="linespace,linespace-fast,variant2",
                    help="--shadows modes compared with exact")
    ap.add_argument("--bin", default="target/release/gpgpu-rt")
    ap.add_argument("--out", default="docs/images/klee-fig11.png")
    ap.add_argument("--work", help="keep the renders here (default: a temporary folder)")
    args = ap.parse_args()

    binary = (ROOT / args.bin) if not Path(args.bin).is_absolute() else Path(args.bin)
    modes = [m for m in args.modes.split(",") if m]
    samples = [s for s in args.samples.split(",") if s]
    tmp = None if args.work else tempfile.TemporaryDirectory(prefix="klee_fig11_")
    work = Path(args.work) if args.work else Path(tmp.name)

    rows, table, walls = [], [], []
    for sample in samples:
        u, v = (int(x) for x in sample.lower().split("x"))
        rays = u * v
        exact_img, exact_s, hit, exact_stats, wall = render(binary, args.scene, "exact", sample, args.size,
                                                       work / sample / "exact")
        walls.append(("exact", sample, wall))
        cells = [labelled(exact_img, f"exact {rays} rays")]
        table.append((sample, rays, "exact", 0.0, 0.0, exact_stats))
        for mode in modes:
            img, s, _, stats, wall = render(binary, args.scene, mode, sample, args.size, work / sample / mode)
            walls.append((mode, sample, wall))
            diff = np.abs(s - exact_s)
            mean = float(diff[hit].mean())
            share = float((diff[hit] > 1e-6).mean())
            table.append((sample, rays, mode, mean, share, stats))
            cells.append(labelled(img, mode))
            cells.append(labelled(error_map(diff), f"err {mean:.4f}"))
        rows.append(row_of(cells, args.size + LABEL))

    width = rows[0].shape[1]
    picture = []
    for i, row in enumerate(rows):
        if i:
            picture.append(np.full((GAP, width, 3), 255, dtype=np.uint8))
        picture.append(row)
    out = ROOT / args.out if not Path(args.out).is_absolute() else Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    pngio.write_png(out, np.vstack(picture))

    print(f"{args.scene}, {args.size}x{args.size}, renderer {table[0][5].get('renderer', '?')}\n")
    print("| light samples (rays) | mode | mean \\|s − exact\\| (hit pixels) | hit pixels that differ | triangle tests | line-space lookups |")
    print("|---|---|---|---|---|---|")
    for sample, rays, mode, mean, share, stats in table:
        print(f"| {sample} ({rays}) | `{mode}` | {mean:.4f} | {100 * share:.1f} % | "
              f"{stats.get('triangle_tests_total', 0):,} | {stats.get('linespace_lookups', 0):,} |")
    total = sum(w for _, _, w in walls)
    print(f"\n{out.relative_to(ROOT) if out.is_relative_to(ROOT) else out}: "
          f"{len(walls)} renders, {total:.1f} s of render wall time "
          f"(slowest: {max(walls, key=lambda w: w[2])[0]} {max(walls, key=lambda w: w[2])[1]}, "
          f"{max(w for _, _, w in walls):.1f} s)")


if __name__ == "__main__":
    main()
