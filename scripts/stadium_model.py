#!/usr/bin/env python3
"""The stands of "the teapot in a stadium" (scenes/stadium.toml; issue 15): the classic scene
that breaks uniform grids — a small detailed object in a very large, mostly empty scene
(Havran et al. 2000 and Szirmay-Kalos et al. 2002 discuss it as the grid's worst case).

  stadium_stands.obj  a closed oval ring of stands around the origin, 64 segments: the tiers
                      rise from the pitch's edge (radius 100 × 70, height 0) to the rim
                      (radius 150 × 110, height 40), with an outer wall down to the ground:
                      2·64 (tiers) + 2·64 (wall) = 256 triangles, 256 shared vertices.

Plain Python 3, deterministic. Run: python3 scripts/stadium_model.py (rewrites the file).
"""
import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "models", "stadium_stands.obj")
SEGMENTS = 64
# (x radius, z radius, height) of the three rings: pitch edge, rim, foot of the outer wall
RINGS = [(100.0, 70.0, 0.0), (150.0, 110.0, 40.0), (150.0, 110.0, 0.0)]


def main():
    lines = [
        "# stadium_stands.obj: written by scripts/stadium_model.py (see its header)",
        f"# {SEGMENTS} segments, {len(RINGS)} rings; {2 * SEGMENTS * (len(RINGS) - 1)} triangles",
    ]
    for rx, rz, y in RINGS:
        for i in range(SEGMENTS):
            a = 2.0 * math.pi * i / SEGMENTS
            lines.append(f"v {rx * math.cos(a):.6f} {y:.6f} {rz * math.sin(a):.6f}")
    for r in range(len(RINGS) - 1):
        for i in range(SEGMENTS):
            j = (i + 1) % SEGMENTS
            a, b = r * SEGMENTS + i + 1, r * SEGMENTS + j + 1
            c, d = a + SEGMENTS, b + SEGMENTS
            lines.append(f"f {a} {b} {d}")
            lines.append(f"f {a} {d} {c}")
    with open(OUT, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
