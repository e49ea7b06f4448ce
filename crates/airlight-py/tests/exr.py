"""A tiny OpenEXR reader for the tests: scanline images, uncompressed or ZIP
(what ``airlight render -o x.exr`` writes), HALF or FLOAT channels.

It shares no code with Airlight, so that a render compared through it is
checked against the bytes the CLI wrote, not against the library's reader.
"""

import struct
import zlib

import numpy as np

_TYPES = {1: np.float16, 2: np.float32, 0: np.uint32}
_LINES = {0: 1, 2: 1, 3: 16}  # NONE, ZIPS, ZIP: scanlines per chunk


def _cstr(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode(), end + 1


def _unzip(raw, size):
    if len(raw) == size:  # stored as is when compression did not pay
        return raw
    t = np.frombuffer(zlib.decompress(raw), dtype=np.uint8).astype(np.int64)
    # Undo the predictor: each byte after the first is stored as its
    # difference from the previous one, plus 128.
    t = ((np.cumsum(t - 128) + 128) % 256).astype(np.uint8)
    # Then the interleaving: even bytes first, odd bytes after.
    out = np.empty_like(t)
    half = (len(t) + 1) // 2
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def read_exr(path):
    """The R, G, B channels as a float32 array (height, width, 3)."""
    planes = read_channels(path)
    return np.stack([planes["R"], planes["G"], planes["B"]], axis=-1)


def read_channels(path):
    """Every channel, by name (``R``, ``albedo.R``, ``Z``...), as float32 arrays (height, width)."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"\x76\x2f\x31\x01", "not an EXR file"
    pos, header = 8, {}
    while data[pos] != 0:
        name, pos = _cstr(data, pos)
        kind, pos = _cstr(data, pos)
        (size,) = struct.unpack_from("<i", data, pos)
        header[name] = (kind, data[pos + 4 : pos + 4 + size])
        pos += 4 + size
    pos += 1
    channels, raw = [], header["channels"][1]
    p = 0
    while raw[p] != 0:
        name, p = _cstr(raw, p)
        (ptype,) = struct.unpack_from("<i", raw, p)
        channels.append((name, _TYPES[ptype]))
        p += 16
    compression = header["compression"][1][0]
    assert compression in _LINES, f"compression {compression} not supported"
    x0, y0, x1, y1 = struct.unpack("<4i", header["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = _LINES[compression]
    chunks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    planes = {name: np.zeros((h, w), dtype=np.float32) for name, _ in channels}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        n = min(lines, y1 - y + 1)
        expected = n * w * sum(np.dtype(t).itemsize for _, t in channels)
        block = _unzip(data[off + 8 : off + 8 + size], expected) if compression else data[off + 8 : off + 8 + size]
        q = 0
        for row in range(n):
            for name, t in channels:
                step = w * np.dtype(t).itemsize
                planes[name][y - y0 + row] = np.frombuffer(block[q : q + step], dtype=t)
                q += step
    return planes
