#!/usr/bin/env python3
"""Writes small hand-built seeds the shared data lacks: a GLB (from the glTF fixture with a data-URI
buffer), and tiny PNG (8- and 16-bit), TIFF and OpenEXR images, so the photo decoder's every
container is in the corpus from the start. Usage: seeds.py FIXTURES_DIR OUT_DIR (writes
OUT_DIR/gltf/*.glb and OUT_DIR/photo/*)."""
import base64
import json
import os
import struct
import sys
import zlib


def glb_from_gltf(path):
    doc = json.load(open(path))
    buffer = doc["buffers"][0]
    data = base64.b64decode(buffer.pop("uri").split(",", 1)[1])
    data += b"\0" * (-len(data) % 4)
    buffer["byteLength"] = len(data)
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    chunks += struct.pack("<II", len(data), 0x004E4942) + data
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def png(width, height, bit_depth, colour_type, row_bytes):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    raw = b"".join(b"\0" + row_bytes(y) for y in range(height))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def tiff_rgb8(width, height):
    pixels = bytes((x * 60 + y * 20) % 256 for y in range(height) for x in range(width * 3))
    entries = [
        (256, 3, 1, width), (257, 3, 1, height), (258, 3, 3, 0), (259, 3, 1, 1), (262, 3, 1, 2),
        (273, 4, 1, 0), (277, 3, 1, 3), (278, 3, 1, height), (279, 4, 1, len(pixels)),
    ]
    ifd_offset = 8
    ifd_size = 2 + 12 * len(entries) + 4
    bits_offset = ifd_offset + ifd_size
    strip_offset = bits_offset + 6
    out = b"II*\0" + struct.pack("<I", ifd_offset) + struct.pack("<H", len(entries))
    for tag, kind, count, value in entries:
        if tag == 258:
            value = bits_offset
        if tag == 273:
            value = strip_offset
        if kind == 3 and count == 1:
            out += struct.pack("<HHIHH", tag, kind, count, value, 0)
        else:
            out += struct.pack("<HHII", tag, kind, count, value)
    out += struct.pack("<I", 0) + struct.pack("<HHH", 8, 8, 8) + pixels
    return out


def exr_half_rgb(width, height):
    def attr(name, kind, body):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(body)) + body

    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = b"v/1\x01" + struct.pack("<i", 2)
    header += attr("channels", "chlist", channels)
    header += attr("compression", "compression", b"\0")
    header += attr("dataWindow", "box2i", box)
    header += attr("displayWindow", "box2i", box)
    header += attr("lineOrder", "lineOrder", b"\0")
    header += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    header += attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    header += b"\0"
    one = struct.pack("<e", 0.5) * width
    first = len(header) + 8 * height
    table, lines = b"", b""
    for y in range(height):
        table += struct.pack("<Q", first + len(lines))
        lines += struct.pack("<ii", y, 3 * len(one)) + one * 3
    return header + table + lines


def main():
    fixtures, out = sys.argv[1], sys.argv[2]
    os.makedirs(os.path.join(out, "gltf"), exist_ok=True)
    os.makedirs(os.path.join(out, "photo"), exist_ok=True)
    open(os.path.join(out, "gltf", "quad_nodes.glb"), "wb").write(
        glb_from_gltf(os.path.join(fixtures, "quad_nodes.gltf")))
    photo = os.path.join(out, "photo")
    open(os.path.join(photo, "rgb8.png"), "wb").write(
        png(4, 3, 8, 2, lambda y: bytes((x * 40 + y * 70) % 256 for x in range(12))))
    open(os.path.join(photo, "rgba16.png"), "wb").write(
        png(3, 2, 16, 6, lambda y: bytes((x * 13 + y) % 256 for x in range(24))))
    open(os.path.join(photo, "grey8.png"), "wb").write(png(5, 5, 8, 0, lambda y: bytes(range(y, y + 5))))
    open(os.path.join(photo, "rgb8.tif"), "wb").write(tiff_rgb8(4, 3))
    open(os.path.join(photo, "half_rgb.exr"), "wb").write(exr_half_rgb(3, 2))


if __name__ == "__main__":
    main()
