#!/usr/bin/env python3
"""When the served page first showed the body coloured: reads the frames `browser_shot.py
--frames DIR` kept (DIR/frame-SECONDS.png, seconds since the page was asked for) and prints, per
frame, the share of the 3D view (the left half, below the top bar and above the timeline) in the
field's colours, then the first frame above 5 % — the criterion of `app/tests/web.rs`. Standard
library only (a PNG reader for the 8-bit RGB/RGBA frames Chromium writes).

    scripts/first_coloured_frame.py DIR"""

import os
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), f"{path}: {depth}-bit colour type {colour}"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, channels, rows


# The Rerun viewer's 3D view (rows 10-90 %, the left half); the app's own page (app/tests/page.rs)
# has its view right of the control panel, above the plots.
VIEWER_VIEW = ((0.10, 0.90), (0.0, 0.5))
APP_VIEW = ((0.08, 0.58), (0.36, 0.97))


def coloured_share(path, view=VIEWER_VIEW):
    width, height, channels, rows = read_png(path)
    (y0, y1), (x0, x1) = view
    total = coloured = 0
    for y in range(int(height * y0), int(height * y1), 2):
        row = rows[y]
        for x in range(int(width * x0), int(width * x1), 2):
            r, g, b = row[x * channels:x * channels + 3]
            hi, lo = max(r, g, b), min(r, g, b)
            total += 1
            coloured += hi > 40 and (hi - lo) / hi > 0.45
    return coloured / total


def main():
    folder = sys.argv[1]
    frames = sorted(f for f in os.listdir(folder) if f.startswith("frame-") and f.endswith(".png"))
    first = None
    for name in frames:
        t = float(name[len("frame-"):-len(".png")])
        share = coloured_share(os.path.join(folder, name))
        print(f"{t:8.3f} s  {100 * share:5.1f} % coloured")
        if first is None and share > 0.05:
            first = t
    print(f"first frame with the body coloured: {first:.3f} s" if first is not None else "never coloured")


if __name__ == "__main__":
    main()
