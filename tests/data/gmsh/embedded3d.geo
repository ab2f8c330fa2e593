// Unit box with the square [0.25,0.75]^2 x {0.5} embedded in it, as in gmsh's tutorial t15:
// the mesh conforms to the embedded surface, whose triangles are interior facets.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Rectangle(7) = {0.25, 0.25, 0.5, 0.5, 0.5};
Surface{7} In Volume{1};
MeshSize{:} = 0.3;
Physical Surface("walls", 1) = {1, 2, 3, 4, 5, 6};
Physical Surface("sensor", 7) = {7};
Physical Volume("fluid", 10) = {1};
