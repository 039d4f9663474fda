"""Reads the 8-bit RGB PNGs argil writes (host/render/png_write.c) with Python's standard
library only, for the shell tests that judge screenshots and plots (tests/sys/test_*.sh)."""
import struct
import zlib


def load(path, header_only=False):
    """(width, height, rows): rows[y][x] is an (r, g, b) tuple; rows is None if header_only."""
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
    pos, idat, w, h = 8, b'', 0, 0
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            assert depth == 8 and ctype == 2, 'not 8-bit RGB'
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    if header_only:
        return w, h, None
    raw = zlib.decompress(idat)
    stride, prev, rows = w * 3, bytearray(w * 3), []
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
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
        rows.append([tuple(line[i:i + 3]) for i in range(0, stride, 3)])
        prev = line
    return w, h, rows


def wire(p):
    """The second iso-surface's wire colour (magenta)."""
    return p[0] > p[1] + 60 and p[2] > p[1] + 60
