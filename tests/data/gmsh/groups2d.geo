// Unit square with a sensor line embedded in it (from (0.25,0.5) to (0.75,0.5)). Some entities
// are in two physical groups, as in gmsh's tutorial t14: the bottom curve is in `walls` and in
// `bottom`, the surface in `fluid` and in `all`. In MSH 4.1 gmsh lists both tags on the entity;
// in MSH 2.2 it writes each of its elements once per group.
lc = 0.25;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {1, 1, 0, lc};
Point(4) = {0, 1, 0, lc};
Point(5) = {0.25, 0.5, 0, lc};
Point(6) = {0.75, 0.5, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("walls", 1) = {1, 2, 3, 4};
Physical Curve("bottom", 2) = {1};
Physical Curve("sensor", 5) = {5};
Physical Surface("fluid", 10) = {1};
Physical Surface("all", 11) = {1};
