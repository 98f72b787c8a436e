"""Minimal OpenEXR I/O: uncompressed scanlines of 32-bit float B, G, R.

The add-on hands Sunbeam the World's environment exactly as Blender sees it (any format
Blender reads, packed or generated images included) as such an EXR, and reads the tools' linear
frames (which are written in this form: uncompressed float B, G, R scanlines) back into the
render result. Blender's RenderResult.load_from_file wants multilayer channel names, and only
the standard library is available inside the add-on, so the few lines of the format (OpenEXR's
"Technical Introduction") are here.
"""

import os
import struct
from array import array


def _attr(name, kind, payload):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) + payload


def write_rgb(path, width, height, rows):
    """Write `rows` (top row first; each a (r, g, b) triple of float sequences of `width`)
    to `path` atomically (a temporary name, then a rename)."""
    channels = b"".join(name + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for name in (b"B", b"G", b"R"))
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2)
              + _attr("channels", "chlist", channels + b"\0")
              + _attr("compression", "compression", b"\0")
              + _attr("dataWindow", "box2i", window)
              + _attr("displayWindow", "box2i", window)
              + _attr("lineOrder", "lineOrder", b"\0")
              + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")
    line_bytes = 3 * 4 * width
    chunk = 8 + line_bytes
    first = len(header) + 8 * height
    offsets = struct.pack(f"<{height}Q", *(first + y * chunk for y in range(height)))
    pack_line = struct.Struct(f"<{width}f").pack
    tmp = path + ".part"
    with open(tmp, "wb") as f:
        f.write(header)
        f.write(offsets)
        for y, (r, g, b) in enumerate(rows):
            f.write(struct.pack("<ii", y, line_bytes))
            f.write(pack_line(*b) + pack_line(*g) + pack_line(*r))
    os.replace(tmp, path)


def _scanlines(path):
    """(width, height, lines) of an uncompressed float B, G, R scanline EXR: each line (top row
    first) a tuple of its B, G and R floats, channel after channel. Anything else raises
    ValueError naming the file."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        kind_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, kind_end + 1)
        start = kind_end + 5
        attrs[data[pos:name_end].decode()] = data[start:start + size]
        pos = start + size
    pos += 1
    channels, c = [], attrs["channels"]
    while c[0] != 0:
        end = c.index(b"\0")
        channels.append((c[:end].decode(), struct.unpack_from("<i", c, end + 1)[0]))
        c = c[end + 17:]
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"])
    if attrs["compression"][0] != 0 or channels != [("B", 2), ("G", 2), ("R", 2)]:
        raise ValueError(f"{path}: expected uncompressed float B, G, R channels")
    width, height = x1 - x0 + 1, y1 - y0 + 1
    unpack_line = struct.Struct(f"<{3 * width}f").unpack_from
    offsets = struct.unpack_from(f"<{height}Q", data, pos)
    return width, height, [unpack_line(data, offset + 8) for offset in offsets]


def read_rgb(path):
    """(width, height, pixels) of an uncompressed float B, G, R scanline EXR; pixels is a flat
    list of (r, g, b) tuples, top row first. Anything else raises ValueError naming the file."""
    width, height, lines = _scanlines(path)
    pixels = []
    for line in lines:
        b, g, r = line[:width], line[width:2 * width], line[2 * width:]
        pixels.extend(zip(r, g, b))
    return width, height, pixels


def read_rgba_bottom_up(path):
    """(width, height, data) of the same files for a GPU texture: data an array of 32-bit
    floats, R, G, B, A = 1 per pixel, bottom row first (OpenGL's order). Slice assignment keeps
    the interleaving in C: a viewport-sized frame takes a fraction of a second."""
    width, height, lines = _scanlines(path)
    data = array("f", [1.0]) * (4 * width * height)
    row = 4 * width
    for j, line in enumerate(reversed(lines)):
        for k, channel in enumerate((2, 1, 0)):  # R, G, B from the B, G, R channels
            data[j * row + k:(j + 1) * row:4] = array("f", line[channel * width:(channel + 1) * width])
    return width, height, data
