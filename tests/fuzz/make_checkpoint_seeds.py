#!/usr/bin/env python3
"""Seeds for fuzz_checkpoint from a real checkpoint (format version 5).

usage: make_checkpoint_seeds.py CHECKPOINT OUTDIR
Writes OUTDIR/raw_<name> (mode byte 0, then the file) and OUTDIR/framed_<name> (mode byte 1,
then the section payloads joined by b"SECT", as the harness frames them), and
OUTDIR/raw_huge_length (the file with the first section's length field set to 2^60).
The tree's seeds came from `examples/dkt --h-body 0.12 --h-far 0.6 --t-end 0.003
--checkpoint-every 1 --vtu-every 0 --no-reuse --output OUT` (OUT/checkpoint.bin; without reuse
the solver sections, which the harness does not read, are empty and the seeds stay small).
"""
import os
import struct
import sys


def sections(data):
    assert data[:8] == b"ALEFSICK", "not an alefsi checkpoint"
    p = 12
    while p < len(data):
        (n,) = struct.unpack_from("<I", data, p)
        name = data[p + 4 : p + 4 + n]
        (length,) = struct.unpack_from("<Q", data, p + 4 + n)
        start = p + 12 + n
        yield name.decode(), start - 8, data[start : start + length]
        p = start + length + 4


def main():
    src, out = sys.argv[1], sys.argv[2]
    data = open(src, "rb").read()
    name = os.path.basename(src)
    os.makedirs(out, exist_ok=True)
    open(os.path.join(out, "raw_" + name), "wb").write(b"\x00" + data)
    payloads = [pl for nm, _, pl in sections(data) if nm != "end"]
    open(os.path.join(out, "framed_" + name), "wb").write(b"\x01" + b"SECT".join(payloads))
    first = next(sections(data))
    huge = bytearray(data)
    struct.pack_into("<Q", huge, first[1], 1 << 60)
    open(os.path.join(out, "raw_huge_length"), "wb").write(b"\x00" + bytes(huge))


if __name__ == "__main__":
    main()
