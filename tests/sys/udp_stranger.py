#!/usr/bin/env python3
# A stranger on the board's network for tests/sys/test_board_stranger.sh: from its own UDP port
# on the same machine it sends the board CRC-valid frames that would take the arm from its host
# (HEARTBEAT with DISARM, as found in the issue, and END; a host HELLO), numbered far ahead of
# any host's, every 2 ms, and counts the datagrams the board sends it. Frames are built here
# with struct and a bitwise CRC-32C (docs/protocol.md), not with argil's code. With KEYFILE (a
# key file, docs/link.md) every other datagram is sealed with that key as docs/protocol.md
# "Authenticated UDP" says (hashlib's keyed BLAKE2b-128, a random nonce), the rest sent bare.
# Usage: udp_stranger.py PORT SECONDS [VERSION [KEYFILE]].
# Prints "sent N disarm D end E hello H sealed S received M".
import hashlib, os, socket, struct, sys, time

def crc32c(data):
    c = 0xFFFFFFFF
    for b in data:
        c ^= b
        for _ in range(8):
            c = (c >> 1) ^ (0x82F63B78 if c & 1 else 0)
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
t_end = time.monotonic() + seconds

def drain():
    global received
    try:
        while True:
            s.recv(2048)
            received += 1
    except BlockingIOError:
        pass

while time.monotonic() < t_end:
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
    time.sleep(0.002)
    drain()
time.sleep(0.2)
drain()
print('sent %d disarm %d end %d hello %d sealed %d received %d' % (sent, disarm, end, hello, sealed, received))
