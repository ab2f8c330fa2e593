#!/usr/bin/env python3
"""Writes square_v22.msh and the malformed files under bad/ (see README.md for the list).

Run from anywhere: python3 make_bad_files.py. Most files are small edits of the hand-written
square_v22.msh (below) or tiny_tri6_v41.msh; the binary ones derive from
channel2d_o1_msh41bin.msh, so rerun this script after regenerating that file.
"""
import os
import struct

G = os.path.dirname(os.path.abspath(__file__)) + '/'
B = G + 'bad/'
os.makedirs(B, exist_ok=True)
square = """$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "boundary"
2 5 "square"
$EndPhysicalNames
$Nodes
4
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
$EndNodes
$Elements
6
1 1 2 1 1 1 2
2 1 2 1 2 2 3
3 1 2 1 3 3 4
4 1 2 1 4 4 1
5 2 2 5 1 1 2 3
6 2 2 5 1 1 3 4
$EndElements
""".split('\n')[:-1]
assert len(square) == 24

def lines(mods=None, drop=(), insert=None, end=None):
    L = list(square)
    for ln, txt in (mods or {}).items(): L[ln - 1] = txt
    if insert:
        for ln, txt in sorted(insert.items(), reverse=True): L.insert(ln - 1, txt)
    L = [l for i, l in enumerate(L, 1) if i not in drop]
    if end is not None: L = L[:end]
    return L

def w(name, L, newline=True):
    with open(B + name, 'w') as f: f.write('\n'.join(L) + ('\n' if newline else ''))

with open(G + 'square_v22.msh', 'w') as f: f.write('\n'.join(square) + '\n')
w('truncated_elements_v22.msh', lines({23: '6 2 2 5 1 1 3'}, end=23), newline=False)
w('missing_endnodes_v22.msh', lines(drop=(15,)))
w('node_count_too_big_v22.msh', lines({10: '5'}))
w('node_count_too_small_v22.msh', lines({10: '3'}))
w('non_numeric_coordinate_v22.msh', lines({13: '3 1 1x 0'}))
w('undefined_node_v22.msh', lines({23: '6 2 2 5 1 1 3 99'}))
w('unknown_element_type_v22.msh', lines({22: '5 99 2 5 1 1 2 3'}))
w('quad_in_2d_v22.msh', lines({17: '5', 22: '5 3 2 5 1 1 2 3 4'}, drop=(23,)))
w('missing_physical_v22.msh', lines({18: '1 1 0 1 2', 19: '2 1 0 2 3', 20: '3 1 0 3 4', 21: '4 1 0 4 1',
                                     22: '5 2 0 1 2 3', 23: '6 2 0 1 3 4'}))
w('duplicate_node_tag_v22.msh', lines({14: '3 0 1 0'}))
w('nonplanar_v22.msh', lines({13: '3 1 1 0.1'}))
w('negative_count_v22.msh', lines({10: '-4'}))
w('missing_elements_v22.msh', lines(end=15))
w('unterminated_section_v22.msh', lines() + ['$Periodic', '1', '1 1 3', '0'])
# repeats with the same physical tag (a repeat with another tag is an element in two groups)
w('duplicate_triangle_v22.msh', lines({17: '7'}, insert={24: '7 2 2 5 1 1 2 3'}))
w('duplicate_boundary_v22.msh', lines({17: '7'}, insert={24: '7 1 2 1 1 1 2'}))
w('mixed_order_v22.msh', lines({23: '6 9 2 5 1 1 3 4 1 2 3'}))
w('extra_value_v22.msh', lines({12: '2 1 0 0 7'}))
w('short_element_line_v22.msh', lines({22: '5 2 2 5 1 1 2'}))
w('boundary_node_not_in_cell_v22.msh', lines({10: '5', 17: '7'}, insert={15: '5 2 2 0', 24: '7 1 2 1 1 3 5'}))
w('degenerate_cell_v22.msh', lines({14: '4 0.5 0.5 0'}))
w('not_a_facet_v22.msh', lines({17: '7'}, insert={24: '7 1 2 1 1 2 4'}))
w('tet_in_2d_v22.msh', lines({23: '6 4 2 5 1 1 2 3 4'}))
w('unsupported_version.msh', lines({2: '3.0 0 8'}))
open(B + 'empty.msh', 'w').close()
with open(B + 'not_msh.msh', 'w') as f: f.write('solid cube\nfacet normal 0 0 1\n')

# 4.1 files from the hand-written tri6 square
t = open(G + 'tiny_tri6_v41.msh').read().split('\n')[:-1]
def w41(name, L, newline=True):
    with open(B + name, 'w') as f: f.write('\n'.join(L) + ('\n' if newline else ''))
w41('truncated_nodes_v41.msh', t[:28] + ['0 0.'], newline=False)
T = list(t); T[9] = '1 1000000000000000000 1 9'; w41('huge_count_v41.msh', T)
# boundary block removed: triangles only
T = list(t); i = T.index('$Elements'); T[i + 1] = '1 2 1 2'; del T[i + 2:i + 7]; w41('missing_boundary_v41.msh', T)
T = list(t); T[10] = '2 2 0 9'; T[14] = '7'; T[19] = '3'; w41('duplicate_node_tag_v41.msh', T)

# sparse duplicate (sorted tag map)
s = open(G + 'tiny_sparse_v41.msh').read().replace('\n77\n', '\n1000000000\n')
open(B + 'duplicate_sparse_tag_v41.msh', 'w').write(s)

# binary headers
def binhead(version, ftype, dsize, marker):
    return (b'$MeshFormat\n' + f'{version} {ftype} {dsize}\n'.encode() + struct.pack('<i', marker) +
            b'\n$EndMeshFormat\n')
open(B + 'v22_binary.msh', 'wb').write(binhead('2.2', 1, 8, 1) + b'$Nodes\n')
open(B + 'data_size4_bin.msh', 'wb').write(binhead('4.1', 1, 4, 1) + b'$Nodes\n')
open(B + 'bad_endianness_bin.msh', 'wb').write(binhead('4.1', 1, 8, 2) + b'$Nodes\n')
d = open(G + 'channel2d_o1_msh41bin.msh', 'rb').read()
e = d.index(b'$Elements\n')
open(B + 'truncated_binary_v41.msh', 'wb').write(d[:d.index(b'$EndElements') - 100])
open(B + 'truncated_binary_header_v41.msh', 'wb').write(d[:e + 10 + 6])
# a binary node block whose count claims more nodes than the file holds
n = d.index(b'$Nodes\n') + 7
blk = n + 32
bad = bytearray(d); struct.pack_into('<Q', bad, blk + 12, 10**12)
open(B + 'bad_block_count_bin_v41.msh', 'wb').write(bytes(bad))
