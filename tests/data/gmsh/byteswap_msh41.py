#!/usr/bin/env python3
"""Rewrite a little-endian MSH 4.1 binary file as big-endian (for the reader's byte-swap test).

Usage: python3 byteswap_msh41.py in.msh out.msh
Handles $MeshFormat, $Entities, $Nodes and $Elements; other sections are copied unchanged
(they must be text, e.g. $PhysicalNames).
"""
import struct
import sys

NODES_PER_TYPE = {1: 2, 2: 3, 4: 4, 8: 3, 9: 6, 11: 10, 15: 1}


class Swapper:
    def __init__(self, data):
        self.d, self.p, self.out = data, 0, bytearray()

    def take(self, fmt, n=1):
        size = struct.calcsize("<" + fmt) * n
        vals = struct.unpack_from("<" + fmt * n, self.d, self.p)
        self.out += struct.pack(">" + fmt * n, *vals)
        self.p += size
        return vals

    def text_line(self):
        e = self.d.index(b"\n", self.p) + 1
        line = self.d[self.p:e]
        self.out += line
        self.p = e
        return line.strip()

    def run(self):
        while self.p < len(self.d):
            marker = self.text_line().decode()
            if marker == "$MeshFormat":
                self.text_line()
                self.take("i")
                self.text_line()  # the newline after the int
            elif marker == "$Entities":
                counts = self.take("Q", 4)
                for dim, n in enumerate(counts):
                    for _ in range(n):
                        self.take("i")
                        self.take("d", 3 if dim == 0 else 6)
                        (nphys,) = self.take("Q")
                        self.take("i", nphys)
                        if dim > 0:
                            (nb,) = self.take("Q")
                            self.take("i", nb)
                self.text_line()
            elif marker == "$Nodes":
                nblocks = self.take("Q", 4)[0]
                for _ in range(nblocks):
                    dim, _, parametric = self.take("i", 3)
                    (n,) = self.take("Q")
                    self.take("Q", n)
                    self.take("d", n * (3 + (dim if parametric else 0)))
                self.text_line()
            elif marker == "$Elements":
                nblocks = self.take("Q", 4)[0]
                for _ in range(nblocks):
                    _, _, etype = self.take("i", 3)
                    (n,) = self.take("Q")
                    self.take("Q", n * (1 + NODES_PER_TYPE[etype]))
                self.text_line()
        return bytes(self.out)


if __name__ == "__main__":
    with open(sys.argv[1], "rb") as f:
        data = f.read()
    with open(sys.argv[2], "wb") as f:
        f.write(Swapper(data).run())
