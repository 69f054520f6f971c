#!/usr/bin/python3
"""Rebuilds the fixtures of this folder from the original DJI JPEGs (see PROVENANCE.md).

usage: make_fixture.py ORIGINAL_DIR OUT_DIR NAME...

For each NAME: the original's SOI and its APP1 segments (EXIF, then XMP) are copied byte for
byte; the APP2 "MPF" segment (it indexes the 1920 x 1080 preview DJI appends after the main
image, which is cut) and the main image (tables, scan, EOI, the appended preview) are replaced
by the main image downscaled by 6.25 (4000 x 2250 -> 640 x 360 px, Pillow LANCZOS, JPEG quality
75), taken from Pillow's encoding from its first DQT marker on (Pillow's SOI and JFIF APP0 are
dropped). The script checks that every kept byte equals the original's.
"""
import io
import struct
import sys

from PIL import Image

SCALE = 6.25


def segments(data):
    """(marker, start, end) of each segment from SOI up to (not including) SOS."""
    assert data[:2] == b"\xff\xd8", "not a JPEG"
    i, out = 2, []
    while True:
        assert data[i] == 0xFF
        marker = data[i + 1]
        if marker == 0xDA:
            return out
        length = struct.unpack(">H", data[i + 2:i + 4])[0]
        out.append((marker, i, i + 2 + length))
        i += 2 + length


def fixture(original):
    data = open(original, "rb").read()
    kept = b"\xff\xd8"
    for marker, start, end in segments(data):
        if marker == 0xE1:  # APP1: EXIF or XMP, kept as they are
            kept += data[start:end]
    image = Image.open(io.BytesIO(data))
    w, h = image.size
    small = image.resize((round(w / SCALE), round(h / SCALE)), Image.LANCZOS)
    buf = io.BytesIO()
    small.save(buf, "JPEG", quality=75)
    encoded = buf.getvalue()
    body = encoded[encoded.index(b"\xff\xdb"):]
    out = kept + body
    # Check: the APP1 segments of the result are the original's, byte for byte.
    mine = [out[s:e] for m, s, e in segments(out) if m == 0xE1]
    theirs = [data[s:e] for m, s, e in segments(data) if m == 0xE1]
    assert mine == theirs and len(theirs) == 2
    assert Image.open(io.BytesIO(out)).size == small.size
    return out


if __name__ == "__main__":
    src, dst = sys.argv[1], sys.argv[2]
    for name in sys.argv[3:]:
        open(f"{dst}/{name}", "wb").write(fixture(f"{src}/{name}"))
