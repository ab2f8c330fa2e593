// Box [-1, 1]^3 with a spherical hole of radius 0.2 at the origin (OpenCASCADE), graded from
// h = 0.07 on the sphere to 0.45 at the walls. Walls tag 1 ("walls"), sphere tag 5, volume 10.
SetFactory("OpenCASCADE");
Box(1) = {-1, -1, -1, 2, 2, 2};
Sphere(2) = {0, 0, 0, 0.2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
e = 1e-3;
ball() = Surface In BoundingBox{-0.2 - e, -0.2 - e, -0.2 - e, 0.2 + e, 0.2 + e, 0.2 + e};
all() = Boundary{ Volume{3}; };
walls() = all();
walls() -= ball();
Physical Surface("walls", 1) = walls();
Physical Surface("sphere", 5) = ball();
Physical Volume("fluid", 10) = {3};
MeshSize{ PointsOf{ Volume{3}; } } = 0.45;
MeshSize{ PointsOf{ Surface{ball()}; } } = 0.07;
Field[1] = Distance;
Field[1].SurfacesList = {ball()};
Field[2] = MathEval;
Field[2].F = "0.07 + 0.5 * F1";
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMax = 0.45;
