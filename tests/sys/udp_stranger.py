#!/usr/bin/env python3
# A stranger on the board's network for tests/sys/test_board_stranger.sh: from its own UDP port
# on the same machine it sends the board CRC-valid frames that would take the arm from its host
# (HEARTBEAT with DISARM, as found in the issue, and END; a host HELLO), numbered far ahead of
# any host's, and counts the datagrams the board sends it. It sends SECONDS / 2 ms frames, one per
# 2 ms of its schedule, catching up at most 10 when the machine held it back: one sleep per frame
# sent 671 of 1,500 in 3 s on a loaded machine, and a larger burst could overflow the board's
# socket and lose frames the board must count. Frames are built here with struct and a table
# CRC-32C (docs/protocol.md), not with argil's code. With KEYFILE (a key file, docs/link.md)
# every other datagram is sealed with that key as docs/protocol.md "Authenticated UDP" says
# (hashlib's keyed BLAKE2b-128, a random nonce), the rest sent bare.
# Usage: udp_stranger.py PORT SECONDS [VERSION [KEYFILE]].
# Prints "sent N disarm D end E hello H sealed S received M".
import hashlib, os, socket, struct, sys, time

def crc_table():
    t = []
    for n in range(256):
        c = n
        for _ in range(8):
            c = (c >> 1) ^ (0x82F63B78 if c & 1 else 0)
        t.append(c)
    return t

CRC_TABLE = crc_table()

def crc32c(data):
    c = 0xFFFFFFFF
    for b in data:
        c = (c >> 8) ^ CRC_TABLE[(c ^ b) & 0xFF]
    return c ^ 0xFFFFFFFF

def frame(version, kind, seq, payload):
    h = struct.pack('<IBBHI', 0x4C475241, version, kind, len(payload), seq) + payload
    return h + struct.pack('<I', crc32c(h))

def read_key(path):
    for line in open(path):
        line = line.split('#')[0].strip()
        if line:
            return bytes.fromhex(line)
    raise SystemExit('no key in ' + path)

def seal(key, f):
    nonce = os.urandom(8)
    tag = hashlib.blake2b(b'ARGL-UDP' + b'\x01' + nonce + f, key=key, digest_size=16).digest()
    return f + nonce + tag

port, seconds = int(sys.argv[1]), float(sys.argv[2])
version = int(sys.argv[3]) if len(sys.argv) > 3 else 3
key = read_key(sys.argv[4]) if len(sys.argv) > 4 else None
sealed = 0
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(('127.0.0.1', 0))
s.setblocking(False)
board = ('127.0.0.1', port)
sent = disarm = end = hello = received = 0
seq = 0x40000000
PERIOD_S = 0.002
t_next = time.monotonic()
n_frames = int(seconds / PERIOD_S)

def drain():
    global received
    try:
        while True:
            s.recv(2048)
            received += 1
    except BlockingIOError:
        pass

while sent < n_frames:
    k = sent % 10
    if k == 9:
        f = frame(version, 1, seq, struct.pack('<BBHH16s', 2, 0, 16, 0, b'stranger'))
        hello += 1
    else:
        command = 3 if k == 8 else 2
        f = frame(version, 2, seq, struct.pack('<QIIB', int(time.monotonic() * 1e6), 0, 0, command))
        if command == 2:
            disarm += 1
        else:
            end += 1
    if key is not None and sent % 2 == 0:
        f = seal(key, f)
        sealed += 1
    s.sendto(f, board)
    sent += 1
    seq += 1
    t_next = max(t_next + PERIOD_S, time.monotonic() - 10 * PERIOD_S)
    ahead = t_next - time.monotonic()
    if ahead > 0:
        time.sleep(ahead)
    drain()
time.sleep(0.2)
drain()
print('sent %d disarm %d end %d hello %d sealed %d received %d' % (sent, disarm, end, hello, sealed, received))
