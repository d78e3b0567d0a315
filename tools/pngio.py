"""PNG in and out with numpy and zlib only, and a small bitmap font for labels.

The figure scripts (`tools/klee_fig11.py`, `tools/tile_png.py`) compose the images that
`gpgpu-rt render` writes into one picture. No imaging library is needed: the reader handles
the 8-bit greyscale, RGB and RGBA PNGs without interlacing that `render` writes (every filter
type), the writer writes 8-bit RGB with the Up filter.
"""
import struct
import zlib

import numpy as np

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}  # PNG colour type -> samples per pixel


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png(path):
    """An 8-bit PNG as a uint8 array [H, W, 3] (grey expanded, alpha dropped), row 0 at the top."""
    data = open(path, "rb").read()
    if data[:8] != PNG_SIGNATURE:
        raise ValueError(f"{path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in CHANNELS or interlace:
        raise ValueError(f"{path}: only 8-bit, non-interlaced grey/RGB/RGBA PNGs are read here")
    bpp = CHANNELS[colour]
    stride = width * bpp
    raw = zlib.decompress(b"".join(idat))
    out = np.zeros((height, stride), dtype=np.uint8)
    prior = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        row_start = y * (stride + 1)
        kind = raw[row_start]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=row_start + 1).astype(np.int32)
        if kind == 0:
            cur = line
        elif kind == 2:
            cur = (line + prior) & 0xFF
        else:
            # Sub, Average and Paeth depend on the pixel to the left: byte by byte
            cur = line.copy()
            for i in range(stride):
                left = cur[i - bpp] if i >= bpp else 0
                up = prior[i]
                if kind == 1:
                    pred = left
                elif kind == 3:
                    pred = (left + up) >> 1
                elif kind == 4:
                    pred = _paeth(left, up, prior[i - bpp] if i >= bpp else 0)
                else:
                    raise ValueError(f"{path}: filter type {kind}")
                cur[i] = (cur[i] + pred) & 0xFF
        out[y] = cur
        prior = cur
    img = out.reshape(height, width, bpp)
    if bpp <= 2:
        img = np.repeat(img[:, :, :1], 3, axis=2)
    return np.ascontiguousarray(img[:, :, :3])


def write_png(path, img):
    """Write a uint8 array [H, W, 3] as an RGB PNG (the Up filter, zlib level 9)."""
    img = np.ascontiguousarray(img, dtype=np.uint8)
    height, width, _ = img.shape
    rows = img.reshape(height, width * 3).astype(np.int16)
    up = np.vstack([rows[:1], (rows[1:] - rows[:-1]) & 0xFF]).astype(np.uint8)
    filters = np.full((height, 1), 2, dtype=np.uint8)
    filters[0] = 0  # the first row has no prior row: unfiltered
    raw = np.hstack([filters, up]).tobytes()

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(PNG_SIGNATURE + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9))
                + chunk(b"IEND", b""))


# A 3×5 font (capitals; lower case is drawn as capitals), enough for the figures' labels:
# each glyph is its five rows of three pixels, "#" set.
FONT_ROWS = {
    "A": ".#. #.# ### #.# #.#", "B": "##. #.# ##. #.# ##.", "C": ".## #.. #.. #.. .##",
    "D": "##. #.# #.# #.# ##.", "E": "### #.. ##. #.. ###", "F": "### #.. ##. #.. #..",
    "G": ".## #.. #.# #.# .##", "H": "#.# #.# ### #.# #.#", "I": "### .#. .#. .#. ###",
    "J": "..# ..# ..# #.# .#.", "K": "#.# #.# ##. #.# #.#", "L": "#.. #.. #.. #.. ###",
    "M": "#.# ### ### #.# #.#", "N": "##. #.# #.# #.# #.#", "O": ".#. #.# #.# #.# .#.",
    "P": "##. #.# ##. #.. #..", "Q": ".#. #.# #.# ##. .##", "R": "##. #.# ##. #.# #.#",
    "S": ".## #.. .#. ..# ##.", "T": "### .#. .#. .#. .#.", "U": "#.# #.# #.# #.# ###",
    "V": "#.# #.# #.# #.# .#.", "W": "#.# #.# ### ### #.#", "X": "#.# #.# .#. #.# #.#",
    "Y": "#.# #.# .#. .#. .#.", "Z": "### ..# .#. #.. ###",
    "0": "### #.# #.# #.# ###", "1": ".#. ##. .#. .#. ###", "2": "##. ..# .#. #.. ###",
    "3": "##. ..# .#. ..# ##.", "4": "#.# #.# ### ..# ..#", "5": "### #.. ##. ..# ##.",
    "6": ".## #.. ### #.# ###", "7": "### ..# .#. .#. .#.", "8": "### #.# ### #.# ###",
    "9": "### #.# ### ..# ##.", ".": "... ... ... ... .#.", "-": "... ... ### ... ...",
    "=": "... ### ... ### ...", ":": "... .#. ... .#. ...", "/": "..# ..# .#. #.. #..",
    "(": "..# .#. .#. .#. ..#", ")": "#.. .#. .#. .#. #..", "|": ".#. .#. .#. .#. .#.",
    "<": "..# .#. #.. .#. ..#", ">": "#.. .#. ..# .#. #..", "'": ".#. .#. ... ... ...",
    "^": ".#. #.# ... ... ...", "%": "#.# ..# .#. #.. #.#", " ": "... ... ... ... ...",
}


def _glyph(c):
    rows = FONT_ROWS.get(c.upper(), FONT_ROWS["-"]).split()
    return np.array([[ch == "#" for ch in row] for row in rows], dtype=bool)


def text_width(text, scale=2):
    return len(text) * 4 * scale - scale if text else 0


def draw_text(img, text, x, y, colour=(255, 255, 255), scale=2):
    """Draw `text` into img (uint8 [H, W, 3]) with its top-left corner at (x, y)."""
    for i, c in enumerate(text):
        mask = np.kron(_glyph(c), np.ones((scale, scale), dtype=bool))
        x0 = x + i * 4 * scale
        h, w = mask.shape
        region = img[y:y + h, x0:x0 + w]
        region[mask[:region.shape[0], :region.shape[1]]] = colour


def label_strip(text, width, height=16, background=(24, 24, 32), colour=(235, 235, 235)):
    """A strip `height` pixels high with `text` centred in it (cut to fit)."""
    strip = np.zeros((height, width, 3), dtype=np.uint8)
    strip[:] = background
    while text and text_width(text) > width - 4:
        text = text[:-1]
    draw_text(strip, text, max(2, (width - text_width(text)) // 2), (height - 10) // 2, colour)
    return strip
