#!/usr/bin/env python3
"""Read gpgpu-rt's OpenEXR outputs with the reference implementation's Python bindings
(PyPI `openexr`) and compare them with the NumPy AOVs and the PNG of the same frame.

    tools/exr_check.py AOVS.exr NPY_DIR [COLOR.exr RGB_OUT.npy]

Exit status 0 when every channel equals its npy array exactly (triangle_id as the npy's i32
bits), 1 with the differences named, 2 when OpenEXR or NumPy is missing. With COLOR.exr, its
RGB channels as OpenEXR reads them are written to RGB_OUT.npy (f32 [H,W,3]) for the caller to
compare with the PNG.
"""
import sys

try:
    import numpy as np
    import OpenEXR
except ImportError as e:
    print(f"exr_check: {e} (pip install openexr numpy)", file=sys.stderr)
    sys.exit(2)


def main(argv):
    exr, npy_dir = argv[1], argv[2]
    channels = OpenEXR.File(exr).channels()
    problems = []
    expected = {"hit_t": ("hit_t", None), "triangle_id": ("triangle_id", None), "shadow": ("shadow", None)}
    for name in ("normal", "ray_origin", "ray_direction"):
        for k, axis in enumerate("XYZ"):
            expected[f"{name}.{axis}"] = (name, k)
    for channel, (file, k) in expected.items():
        try:
            want = np.load(f"{npy_dir}/{file}.npy")
        except FileNotFoundError:
            if channel in channels:
                problems.append(f"{channel}: in the EXR, but no {file}.npy")
            continue
        if k is not None:
            want = want[:, :, k]
        if channel not in channels:
            problems.append(f"{channel}: missing from the EXR")
            continue
        got = channels[channel].pixels
        if channel == "triangle_id":
            if got.dtype != np.uint32:
                problems.append(f"triangle_id: {got.dtype}, not uint32")
            got = got.view(np.int32)
        if got.shape != want.shape or got.dtype != want.dtype:
            problems.append(f"{channel}: {got.dtype}{got.shape}, npy {want.dtype}{want.shape}")
        elif not np.array_equal(got, want, equal_nan=True):
            n = int(np.sum(got != want))
            problems.append(f"{channel}: {n} values differ from {file}.npy")
    extra = set(channels) - set(expected)
    if extra:
        problems.append(f"channels no npy file has: {sorted(extra)}")
    if len(argv) > 4:
        rgb = OpenEXR.File(argv[3]).channels()["RGB"].pixels
        np.save(argv[4], rgb.astype(np.float32))
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
