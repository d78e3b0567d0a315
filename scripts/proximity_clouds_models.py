#!/usr/bin/env python3
"""The streaming tracer's procedural test models (Fig. 4 and Fig. 5), written once as OBJ files
into scenes/models/ (plain Python 3, no packages):

  knight_standin.obj  634 triangles: a stand-in for the paper's Knight (not available) — a
                      lathe-turned chess-piece base (25 segments × 9 profile rings, capped:
                      2·25·9 = 450) and a horse-head silhouette of 47 points extruded 0.3 deep
                      (2·47 sides + 2·45 caps = 184); with the scene's 2-triangle floor, 636.
  torus_knot.obj      1012 triangles: a (2,3) torus knot (trefoil), a tube of 46 segments along
                      the knot × 11 around it (2·46·11).
  closed_box.obj      12 triangles: the closed box around it (8 shared corners, faces wound
                      to face inwards); 1012 + 12 = 1024.

Every vertex is written once and shared by index, so the closed meshes have no cracks
(tests/proximity_clouds_scenes.rs checks the counts, the closed box, the knot inside it).
Run: python3 scripts/proximity_clouds_models.py  (rewrites the three files; deterministic)
"""
import math
import os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "models")


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(a):
    n = math.sqrt(dot(a, a))
    return [a[0] / n, a[1] / n, a[2] / n]


def signed_volume(verts, tris):
    return sum(dot(verts[a], cross(verts[b], verts[c])) for a, b, c in tris) / 6.0


def orient(verts, tris, outward=True):
    """Flip every triangle if the closed mesh's signed volume has the wrong sign."""
    if (signed_volume(verts, tris) > 0) != outward:
        tris = [(a, c, b) for a, b, c in tris]
    return tris


def write_obj(name, header, verts, tris):
    with open(os.path.join(OUT, name), "w") as f:
        for line in header:
            f.write(f"# {line}\n")
        f.write(f"# {len(verts)} vertices, {len(tris)} triangles\n")
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % tuple(v))
        for a, b, c in tris:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")


# --- the knight stand-in -------------------------------------------------------------------

BASE_PROFILE = [  # (radius, height) from the bottom up: a chess piece's turned base
    (0.50, 0.00), (0.50, 0.07), (0.43, 0.11), (0.41, 0.17), (0.46, 0.21),
    (0.35, 0.27), (0.30, 0.35), (0.34, 0.39), (0.36, 0.43),
]
BASE_SEGMENTS = 25

HEAD_CONTROL = [  # a horse head's silhouette in (x, y), counter-clockwise, x forward
    (-0.30, 0.38), (0.05, 0.36), (0.30, 0.40), (0.24, 0.62), (0.28, 0.82), (0.46, 0.90),
    (0.62, 0.97), (0.63, 1.08), (0.48, 1.18), (0.28, 1.30), (0.16, 1.52), (0.06, 1.40),
    (-0.08, 1.34), (-0.22, 1.20), (-0.30, 0.98), (-0.34, 0.72),
]
HEAD_POINTS = 47
HEAD_DEPTH = 0.30


def lathe(profile, segments):
    verts, tris = [], []
    rings = []
    for r, y in profile:
        ring = []
        for i in range(segments):
            a = 2 * math.pi * i / segments
            ring.append(len(verts))
            verts.append([r * math.cos(a), y, -r * math.sin(a)])
        rings.append(ring)
    bottom, top = len(verts), len(verts) + 1
    verts.append([0.0, profile[0][1], 0.0])
    verts.append([0.0, profile[-1][1], 0.0])
    for i in range(segments):
        j = (i + 1) % segments
        tris.append((bottom, rings[0][j], rings[0][i]))
        for k in range(len(rings) - 1):
            lo, hi = rings[k], rings[k + 1]
            tris.append((lo[i], lo[j], hi[j]))
            tris.append((lo[i], hi[j], hi[i]))
        tris.append((top, rings[-1][i], rings[-1][j]))
    return verts, orient(verts, tris)


def catmull_rom_closed(points, per_segment):
    out = []
    n = len(points)
    for i in range(n):
        p0, p1, p2, p3 = (points[(i + k) % n] for k in (-1, 0, 1, 2))
        for s in range(per_segment):
            t = s / per_segment
            t2, t3 = t * t, t * t * t
            out.append(tuple(
                0.5 * (2 * p1[c] + (-p0[c] + p2[c]) * t + (2 * p0[c] - 5 * p1[c] + 4 * p2[c] - p3[c]) * t2
                       + (-p0[c] + 3 * p1[c] - 3 * p2[c] + p3[c]) * t3)
                for c in range(2)))
    return out


def resample_closed(points, count):
    """`count` points evenly spaced by arc length along the closed polyline."""
    seg = [math.dist(points[i], points[(i + 1) % len(points)]) for i in range(len(points))]
    total = sum(seg)
    out, i, acc = [], 0, 0.0
    for k in range(count):
        target = total * k / count
        while acc + seg[i] < target:
            acc += seg[i]
            i += 1
        t = (target - acc) / seg[i]
        a, b = points[i], points[(i + 1) % len(points)]
        out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
    return out


def area2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def ear_clip(poly):
    """Triangulate a simple counter-clockwise polygon: len(poly) − 2 triangles."""
    idx = list(range(len(poly)))
    tris = []
    while len(idx) > 3:
        for k in range(len(idx)):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            if area2(poly[a], poly[b], poly[c]) <= 1e-9:
                continue
            if any(area2(poly[a], poly[b], poly[p]) >= 0 and area2(poly[b], poly[c], poly[p]) >= 0
                   and area2(poly[c], poly[a], poly[p]) >= 0 for p in idx if p not in (a, b, c)):
                continue
            tris.append((a, b, c))
            idx.pop(k)
            break
        else:
            raise SystemExit("ear clipping found no ear: the silhouette is not simple")
    tris.append(tuple(idx))
    return tris


def extrude(poly, depth):
    n = len(poly)
    verts = [[x, y, depth / 2] for x, y in poly] + [[x, y, -depth / 2] for x, y in poly]
    tris = []
    for a, b, c in ear_clip(poly):
        tris.append((a, b, c))
        tris.append((n + a, n + c, n + b))
    for i in range(n):
        j = (i + 1) % n
        tris.append((n + i, n + j, j))
        tris.append((n + i, j, i))
    return verts, orient(verts, tris)


def knight():
    bv, bt = lathe(BASE_PROFILE, BASE_SEGMENTS)
    poly = resample_closed(catmull_rom_closed(HEAD_CONTROL, 40), HEAD_POINTS)
    assert sum(area2((0, 0), poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly))) > 0
    hv, ht = extrude(poly, HEAD_DEPTH)
    off = len(bv)
    verts = bv + hv
    tris = bt + [(a + off, b + off, c + off) for a, b, c in ht]
    assert len(tris) == 634, len(tris)
    write_obj("knight_standin.obj", [
        "Streaming tracer, Fig. 4: a stand-in for the paper's Knight model (not available), written by",
        "scripts/proximity_clouds_models.py: a lathe-turned chess-piece base (25 segments x 9 rings, capped,",
        "450 triangles) and a horse-head silhouette of 47 points extruded 0.3 deep (184 triangles);",
        "scenes/knight.toml adds a 2-triangle floor: 636 triangles as the paper's Knight scene.",
    ], verts, tris)


# --- the torus knot in its box -------------------------------------------------------------

KNOT_P, KNOT_Q = 2, 3
KNOT_ALONG, KNOT_AROUND = 46, 11
KNOT_TUBE = 0.45


def knot_point(phi):
    r = math.cos(KNOT_Q * phi) + 2.0
    return [r * math.cos(KNOT_P * phi), r * math.sin(KNOT_P * phi), -math.sin(KNOT_Q * phi)]


def torus_knot():
    verts, tris = [], []
    for i in range(KNOT_ALONG):
        phi = 2 * math.pi * i / KNOT_ALONG
        c = knot_point(phi)
        t = norm(sub(knot_point(phi + 1e-4), knot_point(phi - 1e-4)))
        n = norm(cross(t, [0.0, 0.0, 1.0]))  # the tangent is never along z: |d(x,y)/dφ| ≥ 2
        b = cross(n, t)
        for j in range(KNOT_AROUND):
            a = 2 * math.pi * j / KNOT_AROUND
            verts.append([c[k] + KNOT_TUBE * (math.cos(a) * n[k] + math.sin(a) * b[k]) for k in range(3)])
    for i in range(KNOT_ALONG):
        for j in range(KNOT_AROUND):
            i2, j2 = (i + 1) % KNOT_ALONG, (j + 1) % KNOT_AROUND
            v = lambda ii, jj: ii * KNOT_AROUND + jj  # noqa: E731
            tris.append((v(i, j), v(i2, j), v(i2, j2)))
            tris.append((v(i, j), v(i2, j2), v(i, j2)))
    tris = orient(verts, tris)
    assert len(tris) == 1012
    write_obj("torus_knot.obj", [
        "Streaming tracer, Fig. 5: a (2,3) torus knot (trefoil), written by scripts/proximity_clouds_models.py:",
        "the curve r = 2 + cos(3t), (r cos 2t, r sin 2t, -sin 3t), a tube of radius 0.45,",
        "46 segments along the knot x 11 around it = 1012 triangles; closed_box.obj adds 12.",
    ], verts, tris)


BOX_MIN = [-4.0, -4.0, -3.0]
BOX_MAX = [4.0, 4.0, 9.0]


def closed_box():
    verts = [[(BOX_MIN, BOX_MAX)[(k >> a) & 1][a] for a in range(3)] for k in range(8)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    centre = [(lo + hi) / 2 for lo, hi in zip(BOX_MIN, BOX_MAX)]

    def facing_out(t):
        a, b, c = (verts[k] for k in t)
        return dot(cross(sub(b, a), sub(c, a)), sub(a, centre)) > 0

    tris = [(a, c, b) if facing_out((a, b, c)) else (a, b, c) for a, b, c in tris]
    write_obj("closed_box.obj", [
        "Streaming tracer, Fig. 5: the closed box around the torus knot, written by",
        "scripts/proximity_clouds_models.py: 8 shared corners, 12 triangles wound to face inwards;",
        "the camera and the light are inside it (all shadow rays originate inside the box).",
    ], verts, tris)


if __name__ == "__main__":
    knight()
    torus_knot()
    closed_box()
