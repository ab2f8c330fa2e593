// Sphere squirmer in 3D (paper 6.1; examples/sphere_squirmer.cpp): a sphere of radius R at the
// origin in the cube [-H, H]^3 (OpenCASCADE), graded from h0 on the sphere by h = h0 + g d
// (d the distance to the sphere), capped at hmax. The equator x = 0 (where the slip jumps) is
// made of mesh edges in both variants.
//   octant = 1: only the octant x, y, z >= 0 is meshed; the example mirrors it into the eight
//               octants (a mesh symmetric about the three coordinate planes). Tags: walls 1
//               (x = H, y = H, z = H), symmetry planes 2, 3, 4 (x = 0, y = 0, z = 0; interior
//               after mirroring), sphere 5, fluid 10.
//   octant = 0: the whole cube, cut by the plane x = 0 so the equator is conforming; no
//               symmetry. Tags: walls 1, sphere 5, fluid 10.
// Run: gmsh -3 sphere_squirmer.geo -setnumber h0 0.04 -setnumber H 100 -format msh41 -o out.msh
SetFactory("OpenCASCADE");
DefineConstant[ R = 0.25, H = 100, h0 = 0.04, g = 0.5, hmax = 50, octant = 1 ];
If (octant)
  Box(1) = {0, 0, 0, H, H, H};
  Sphere(2) = {0, 0, 0, R};
  BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Else
  Box(1) = {-H, -H, -H, 2 * H, 2 * H, 2 * H};
  Sphere(2) = {0, 0, 0, R};
  BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
  Rectangle(10) = {-H, -H, 0, 2 * H, 2 * H};
  Rotate {{0, 1, 0}, {0, 0, 0}, Pi / 2} { Surface{10}; }
  BooleanFragments{ Volume{3}; Delete; }{ Surface{10}; Delete; }
EndIf
e = 1e-6 * R;
If (!octant)  // the part of the cutting plane inside the hole is no boundary: remove it
  disc() = Surface In BoundingBox{-e, -R - e, -R - e, e, R + e, R + e};
  Recursive Delete { Surface{disc()}; }
EndIf
ball() = Surface In BoundingBox{-R - e, -R - e, -R - e, R + e, R + e, R + e};
outer() = CombinedBoundary{ Volume{:}; };
outer() -= ball();
If (octant)
  sx() = Surface In BoundingBox{-e, -e, -e, e, H + e, H + e};
  sy() = Surface In BoundingBox{-e, -e, -e, H + e, e, H + e};
  sz() = Surface In BoundingBox{-e, -e, -e, H + e, H + e, e};
  outer() -= sx();
  outer() -= sy();
  outer() -= sz();
  Physical Surface("symmetry_x", 2) = sx();
  Physical Surface("symmetry_y", 3) = sy();
  Physical Surface("symmetry_z", 4) = sz();
EndIf
Physical Surface("walls", 1) = outer();
Physical Surface("sphere", 5) = ball();
Physical Volume("fluid", 10) = Volume{:};
Field[1] = Distance;
Field[1].SurfacesList = {ball()};
Field[2] = MathEval;
Field[2].F = Sprintf("Min(%g + %g * F1, %g)", h0, g, hmax);
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMax = hmax;
Mesh.Optimize = 1;
