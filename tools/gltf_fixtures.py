#!/usr/bin/env python3
"""glTF files made by tools this project did not write, for tests/gltf.rs.

    tools/gltf_fixtures.py OUT MODELS

writes into OUT:
- torus_knot.glb: MODELS/torus_knot.obj converted by trimesh (PyPI);
- authored.gltf: a scene authored with pygltflib (PyPI): MODELS/cow.obj's triangles (read by
  trimesh, without processing) in a data-URI buffer under a node hierarchy — a parent with a
  translation and a rotation, a child with a scale — a textured floor quad in an external
  .bin with an external PNG, a perspective camera given as a matrix, and a KHR_lights_punctual
  point light;
- authored.toml, authored_cow.obj, floor.obj, floor.mtl, floor.png: the same scene as a TOML
  scene over OBJ files, which gpgpu-rt must render with the same first hits, shadows and colours.

(Cesium's obj2gltf and Khronos' validator are npm packages: tests/gltf.rs runs them itself.)
Exit status 2 when trimesh, pygltflib or NumPy is missing.
"""
import base64
import math
import os
import sys

try:
    import numpy as np
    import pygltflib as g
    import trimesh
except ImportError as e:
    print(f"gltf_fixtures: {e} (pip install trimesh pygltflib numpy)", file=sys.stderr)
    sys.exit(2)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pngio import write_png  # noqa: E402  (beside this script)

# the scene both files describe
PARENT_T = [0.2, 0.0, -0.3]
PARENT_YAW = 30.0  # degrees about +y
COW_SIZE = 2.0  # the child's scale makes the cow this long
EYE, TARGET, UP, FOV = [0.5, 2.0, 3.6], [0.1, 0.4, 0.0], [0.0, 1.0, 0.0], 45.0
LIGHT = [1.5, 3.0, 2.0]
FLOOR = 1.5  # half the floor's side
# 2×2 texels, row 0 at the top of the image
TEXELS = [[(220, 40, 40), (40, 200, 60)], [(40, 60, 220), (230, 210, 40)]]


def look_at_matrix(eye, target, up):
    """The camera node's world matrix (column-major, as glTF stores it): the camera looks down
    its −z at `target` with `up` as +y."""
    eye, target, up = (np.array(v, dtype=np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.identity(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    return [float(x) for x in m.T.flatten()]


def main(out, models):
    knot = trimesh.load(f"{models}/torus_knot.obj", process=False, force="mesh")
    knot.export(f"{out}/torus_knot.glb")

    cow = trimesh.load(f"{models}/cow.obj", process=False, force="mesh")
    pos = np.asarray(cow.vertices, dtype=np.float32)
    nrm = np.asarray(cow.vertex_normals, dtype=np.float32)
    idx = np.asarray(cow.faces, dtype=np.uint32).flatten()
    scale = COW_SIZE / float(np.max(pos.max(axis=0) - pos.min(axis=0)))
    # the same triangles and normals as an OBJ for the TOML scene (f32 values written exactly)
    with open(f"{out}/authored_cow.obj", "w") as f:
        f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in pos.astype(np.float64).tolist())
        f.writelines(f"vn {x!r} {y!r} {z!r}\n" for x, y, z in nrm.astype(np.float64).tolist())
        f.writelines(f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}\n" for a, b, c in cow.faces.tolist())

    floor_pos = np.array([[-FLOOR, 0, -FLOOR], [FLOOR, 0, -FLOOR], [FLOOR, 0, FLOOR], [-FLOOR, 0, FLOOR]], dtype=np.float32)
    floor_nrm = np.array([[0, 1, 0]] * 4, dtype=np.float32)
    # glTF's texture coordinates run down the image, OBJ's up: the same texel at each corner
    floor_uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float32)
    floor_idx = np.array([0, 2, 1, 0, 3, 2], dtype=np.uint32)
    write_png(f"{out}/floor.png", np.array(TEXELS, dtype=np.uint8))
    with open(f"{out}/floor.mtl", "w") as f:
        f.write("newmtl floor\nKd 1 1 1\nmap_Kd floor.png\n")
    with open(f"{out}/floor.obj", "w") as f:
        f.write("mtllib floor.mtl\nusemtl floor\n")
        f.writelines(f"v {x} {y} {z}\n" for x, y, z in floor_pos.tolist())
        f.writelines(f"vt {u} {1 - v}\n" for u, v in floor_uv.tolist())
        f.write("vn 0 1 0\n")
        for a, b, c in floor_idx.reshape(-1, 3).tolist():
            f.write(f"f {a + 1}/{a + 1}/1 {b + 1}/{b + 1}/1 {c + 1}/{c + 1}/1\n")

    cow_bytes = pos.tobytes() + nrm.tobytes() + idx.tobytes()
    floor_bytes = floor_pos.tobytes() + floor_nrm.tobytes() + floor_uv.tobytes() + floor_idx.tobytes()
    with open(f"{out}/floor.bin", "wb") as f:
        f.write(floor_bytes)
    views = [
        g.BufferView(buffer=0, byteOffset=0, byteLength=pos.nbytes, target=g.ARRAY_BUFFER),
        g.BufferView(buffer=0, byteOffset=pos.nbytes, byteLength=nrm.nbytes, target=g.ARRAY_BUFFER),
        g.BufferView(buffer=0, byteOffset=pos.nbytes + nrm.nbytes, byteLength=idx.nbytes, target=g.ELEMENT_ARRAY_BUFFER),
    ]
    off = 0
    for arr, target in ((floor_pos, g.ARRAY_BUFFER), (floor_nrm, g.ARRAY_BUFFER), (floor_uv, g.ARRAY_BUFFER), (floor_idx, g.ELEMENT_ARRAY_BUFFER)):
        views.append(g.BufferView(buffer=1, byteOffset=off, byteLength=arr.nbytes, target=target))
        off += arr.nbytes
    acc = [
        g.Accessor(bufferView=0, componentType=g.FLOAT, count=len(pos), type=g.VEC3,
                   min=pos.min(axis=0).tolist(), max=pos.max(axis=0).tolist()),
        g.Accessor(bufferView=1, componentType=g.FLOAT, count=len(nrm), type=g.VEC3),
        g.Accessor(bufferView=2, componentType=g.UNSIGNED_INT, count=len(idx), type=g.SCALAR),
        g.Accessor(bufferView=3, componentType=g.FLOAT, count=4, type=g.VEC3,
                   min=floor_pos.min(axis=0).tolist(), max=floor_pos.max(axis=0).tolist()),
        g.Accessor(bufferView=4, componentType=g.FLOAT, count=4, type=g.VEC3),
        g.Accessor(bufferView=5, componentType=g.FLOAT, count=4, type=g.VEC2),
        g.Accessor(bufferView=6, componentType=g.UNSIGNED_INT, count=6, type=g.SCALAR),
    ]
    half = math.radians(PARENT_YAW) / 2
    gltf = g.GLTF2(
        asset=g.Asset(version="2.0", generator="gpgpu-rt tools/gltf_fixtures.py (pygltflib)"),
        scene=0,
        scenes=[g.Scene(nodes=[0, 2, 3, 4])],
        nodes=[
            g.Node(name="parent", translation=PARENT_T, rotation=[0.0, math.sin(half), 0.0, math.cos(half)], children=[1]),
            g.Node(name="cow", scale=[scale] * 3, mesh=0),
            g.Node(name="floor", mesh=1),
            g.Node(name="camera", camera=0, matrix=look_at_matrix(EYE, TARGET, UP)),
            g.Node(name="light", translation=LIGHT, extensions={"KHR_lights_punctual": {"light": 0}}),
        ],
        meshes=[
            g.Mesh(name="cow", primitives=[g.Primitive(attributes=g.Attributes(POSITION=0, NORMAL=1), indices=2, material=0)]),
            g.Mesh(name="floor", primitives=[g.Primitive(attributes=g.Attributes(POSITION=3, NORMAL=4, TEXCOORD_0=5), indices=6, material=1)]),
        ],
        materials=[
            g.Material(name="cow", pbrMetallicRoughness=g.PbrMetallicRoughness(baseColorFactor=[0.85, 0.8, 0.7, 1.0], metallicFactor=0.0, roughnessFactor=1.0)),
            g.Material(name="floor", pbrMetallicRoughness=g.PbrMetallicRoughness(baseColorTexture=g.TextureInfo(index=0), metallicFactor=0.0, roughnessFactor=1.0)),
        ],
        textures=[g.Texture(source=0, sampler=0)],
        samplers=[g.Sampler(magFilter=g.LINEAR, minFilter=g.LINEAR)],
        images=[g.Image(uri="floor.png")],
        cameras=[g.Camera(type="perspective", perspective=g.Perspective(yfov=math.radians(FOV), znear=0.05, aspectRatio=1.0))],
        extensionsUsed=["KHR_lights_punctual"],
        extensions={"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 10.0}]}},
        accessors=acc,
        bufferViews=views,
        buffers=[
            g.Buffer(byteLength=len(cow_bytes), uri="data:application/octet-stream;base64," + base64.b64encode(cow_bytes).decode()),
            g.Buffer(byteLength=len(floor_bytes), uri="floor.bin"),
        ],
    )
    gltf.save_json(f"{out}/authored.gltf")

    # the glTF materials' terms (src/scene/gltf.rs, material_terms): metallic 0, roughness 1
    terms = "reflection = 0.0\nspecular = 0.0\nshininess = 1.0\n"
    with open(f"{out}/authored.toml", "w") as f:
        f.write(f"""[camera]
position = {EYE}
look_at = {TARGET}
up = {UP}
fov_y = {FOV}

[[light]]
position = {LIGHT}
color = [1.0, 1.0, 1.0]

[[object]]
type = "obj"
path = "authored_cow.obj"
translate = {PARENT_T}
rotate = [0.0, {PARENT_YAW}, 0.0]
scale = {scale!r}
color = [0.85, 0.8, 0.7]
{terms}
[[object]]
type = "obj"
path = "floor.obj"
{terms}""")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
