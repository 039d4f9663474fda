# A scripted board on UDP for `argil connect --device udp:127.0.0.1:PORT` (tests/sys/
# test_paint_colour.sh): answers every host HELLO with a board HELLO; once the host sends anything
# else (its tool, windows), it sends 1 kHz TELEMETRY (ACTIVE, board tool carve, button 1 held)
# whose stylus holds 0.3 s, then draws y = cy - 9 .. cy + 9 mm in 1.2 s, 2 mm inside the +x side
# of connect's clay (centre cx cy cz mm, radius 30 mm; its side, as the top of the B-spline clay
# sinks a few mm within seconds in connect), and holds; a HEARTBEAT every 5 ms. Frames as
# docs/protocol.md. Usage: fake_paint_board.py PORT CX CY CZ SECONDS (exit 1 if no host came).
import socket
import struct
import sys
import time

port = int(sys.argv[1])
cx, cy, cz, seconds = (float(v) for v in sys.argv[2:6])
TABLE = []
for i in range(256):
    c = i
    for _ in range(8):
        c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
    TABLE.append(c)


def crc32c(b):
    c = 0xFFFFFFFF
    for x in b:
        c = TABLE[(c ^ x) & 0xFF] ^ (c >> 8)
    return c ^ 0xFFFFFFFF


seq = 0


def frame(kind, payload):
    global seq
    seq += 1
    h = struct.pack("<IBBHI", 0x4C475241, 3, kind, len(payload), seq) + payload
    return h + struct.pack('<I', crc32c(h))


HELLO, WINDOW = 1, 5
window = 0
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(('127.0.0.1', port))
s.setblocking(False)
host = None
t_start = None
deadline = time.monotonic() + 10.0
tick = 0
while True:
    now = time.monotonic()
    try:
        while True:
            data, addr = s.recvfrom(2048)
            host = addr
            if len(data) >= 16 and data[5] == WINDOW:
                window = struct.unpack_from('<I', data, 12)[0]  # reported back as in use
            if len(data) >= 6 and data[5] == HELLO:
                s.sendto(frame(HELLO, struct.pack('<BBHH16s', 1, 3, 32, 1000, b'fakeboard')), host)
            elif t_start is None:
                t_start = now  # the host saw our HELLO: the stroke starts
    except BlockingIOError:
        pass
    if t_start is None:
        if now > deadline:
            sys.exit('fake_paint_board: no host within 10 s')
        time.sleep(0.001)
        continue
    t = now - t_start
    if t > seconds:
        break
    u = min(max((t - 0.3) / 1.2, 0.0), 1.0)
    pos = ((cx + 28.0) * 1e-3, (cy - 9.0 + 18.0 * u) * 1e-3, cz * 1e-3)
    tick += 1
    tm = struct.pack('<QIBBBB3f3f3fIII', int(t * 1e6), tick, 3, 3, 1, 3, *pos,
                     0.0, 0.0, 0.0, 0.0, 0.0, 0.0, window, 0, 0)
    s.sendto(frame(3, tm), host)
    if tick % 5 == 0:
        s.sendto(frame(2, struct.pack('<QIIB', int(t * 1e6), window, 0, 0)), host)
    time.sleep(0.001)
