#!/usr/bin/env python3
"""Two of the papers' pictures, rendered with gpgpu-rt and composed side by side.

    python3 tools/paper_figures.py stream [--size 160] [--out docs/images/stream-figs4-7.png]
    python3 tools/paper_figures.py grid-holes [--size 192] [--out docs/images/thesis-grid-holes.png]

`stream`: the streaming tracer's test scenes as its Figs. 4–7 show them — the Knight stand-in
(Fig. 4), the torus knot in its closed box (Fig. 5), the 1764-triangle bunny (Fig. 6), the
Stanford bunny (Fig. 7) — each rendered by `--tracer stream` at the paper's grid, and the
sparse room (not in the paper) beside them.

`grid-holes`: Müller 2015's uniform grid (`--grid-variant thesis`) loses hits when its
fixed-size voxel lists (`--voxel-array-length`, Listing 17: 512) are too short for the
triangles a voxel holds; the ids that do not fit are dropped. The bunny at 24³, the exact
grid beside the thesis grid with lists of 512, 64 and 16 ids. Each panel's label gives the
share of pixels whose first hit (the `triangle_id` AOV) differs from the exact grid's
("wrong"); the table printed gives `dropped_triangle_refs` from `--stats` as well.

Each prints a Markdown table of what it rendered. Needs Python 3 with numpy; the PNGs are
read and written by tools/pngio.py (no imaging library).
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
LABEL = 16
GAP = 2

# (label, scene, options): the streaming tracer's figures at the paper's grids (docs/scenes.md)
STREAM = [
    ("Fig. 4 knight", "scenes/knight.toml", ["--grid", "14x16x14"]),
    ("Fig. 5 torus knot", "scenes/torus_knot.toml", ["--grid", "16"]),
    ("Fig. 6 bunny 1764", "scenes/bunny_low.toml", ["--grid", "20"]),
    ("Fig. 7 bunny 69451", "scenes/bunny.toml", ["--grid", "128"]),
    ("sparse room", "scenes/sparse_room.toml", []),
]

HOLES_SCENE, HOLES_GRID = "scenes/bunny.toml", "24"
HOLES = [("exact grid", ["--grid-variant", "exact"])] + [
    (f"thesis L={n}", ["--grid-variant", "thesis", "--voxel-array-length", str(n)]) for n in (512, 64, 16)
]


def render(binary, scene, options, size, folder):
    """One render into folder: (image, AOV folder, stats, wall seconds)."""
    folder.mkdir(parents=True, exist_ok=True)
    cmd = [str(binary), "render", scene, *options, "--width", str(size), "--height", str(size),
           "-o", str(folder / "image.png"), "--aov-dir", str(folder / "aov"),
           "--stats", str(folder / "stats.json"), "--quiet"]
    start = time.monotonic()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if done.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr}")
    wall = time.monotonic() - start
    stats = json.loads((folder / "stats.json").read_text())
    return pngio.read_png(folder / "image.png"), folder / "aov", stats, wall, cmd


def compose(cells):
    """Labelled cells of one height, side by side with white gaps."""
    parts = []
    for i, (img, text) in enumerate(cells):
        if i:
            parts.append(np.full((img.shape[0] + LABEL, GAP, 3), 255, dtype=np.uint8))
        parts.append(np.vstack([pngio.label_strip(text, img.shape[1], LABEL), img]))
    return np.hstack(parts)


def shown(cmd):
    """The render command as a reader would type it (the temporary paths left out)."""
    keep, skip = [], False
    for word in cmd[1:]:
        if skip:
            skip = False
            continue
        if word in ("-o", "--aov-dir", "--stats"):
            skip = True
            continue
        if word != "--quiet":
            keep.append(word)
    return "gpgpu-rt " + " ".join(keep)


def stream(args, binary, work):
    cells, walls = [], []
    print("| figure | command | triangles | grid cells | triangle tests |")
    print("|---|---|---|---|---|")
    for i, (label, scene, options) in enumerate(STREAM):
        img, _, stats, wall, cmd = render(binary, scene, ["--tracer", "stream", *options],
                                          args.size, work / f"stream{i}")
        cells.append((img, label))
        walls.append(wall)
        grid = "×".join(str(g) for g in stats["grid_dims"]) if "grid_dims" in stats else "?"
        print(f"| {label} | `{shown(cmd)}` | {stats.get('triangles', '?'):,} | {grid} | "
              f"{stats.get('triangle_tests_total', 0):,} |")
    return compose(cells), walls


def grid_holes(args, binary, work):
    cells, walls, exact_ids = [], [], None
    print("| grid | command | dropped_triangle_refs | first hits unlike the exact grid's |")
    print("|---|---|---|---|")
    for i, (label, options) in enumerate(HOLES):
        img, aov, stats, wall, cmd = render(binary, HOLES_SCENE,
                                            ["--tracer", "grid", "--grid", HOLES_GRID, *options],
                                            args.size, work / f"holes{i}")
        ids = np.load(aov / "triangle_id.npy")
        if exact_ids is None:
            exact_ids = ids
        wrong = float((ids != exact_ids).mean())
        walls.append(wall)
        text = label if i == 0 else f"{label} {100 * wrong:.1f}% wrong"
        cells.append((img, text))
        print(f"| {label} | `{shown(cmd)}` | {stats.get('dropped_triangle_refs', 0):,} | "
              f"{100 * wrong:.1f} % of pixels |")
    return compose(cells), walls


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("figure", choices=["stream", "grid-holes"])
    ap.add_argument("--size", type=int, help="image side in pixels (stream: 160, grid-holes: 192)")
    ap.add_argument("--bin", default="target/release/gpgpu-rt")
    ap.add_argument("--out", help="the PNG (default: docs/images/stream-figs4-7.png or thesis-grid-holes.png)")
    ap.add_argument("--work", help="keep the renders here (default: a temporary folder)")
    args = ap.parse_args()
    binary = Path(args.bin) if Path(args.bin).is_absolute() else ROOT / args.bin
    tmp = None if args.work else tempfile.TemporaryDirectory(prefix="paper_figures_")
    work = Path(args.work) if args.work else Path(tmp.name)
    if args.figure == "stream":
        args.size = args.size or 160
        picture, walls = stream(args, binary, work)
        out = args.out or "docs/images/stream-figs4-7.png"
    else:
        args.size = args.size or 192
        picture, walls = grid_holes(args, binary, work)
        out = args.out or "docs/images/thesis-grid-holes.png"
    out = Path(out) if Path(out).is_absolute() else ROOT / out
    out.parent.mkdir(parents=True, exist_ok=True)
    pngio.write_png(out, picture)
    shown_out = out.relative_to(ROOT) if out.is_relative_to(ROOT) else out
    print(f"\n{shown_out}: {len(walls)} renders at {args.size}x{args.size}, {sum(walls):.1f} s of render wall time")


if __name__ == "__main__":
    main()
