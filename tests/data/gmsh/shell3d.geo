// Spherical shell a = 0.5 < |x| < b = 1 (OpenCASCADE); h = target edge length (-setnumber h ...).
// Inner sphere tag 1 ("inner"), outer sphere tag 2 ("outer"), volume 10.
SetFactory("OpenCASCADE");
DefineConstant[h = 0.25];
Sphere(1) = {0, 0, 0, 1.0};
Sphere(2) = {0, 0, 0, 0.5};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
e = 1e-3;
inner() = Surface In BoundingBox{-0.5 - e, -0.5 - e, -0.5 - e, 0.5 + e, 0.5 + e, 0.5 + e};
all() = Boundary{ Volume{3}; };
outer() = all();
outer() -= inner();
Physical Surface("inner", 1) = inner();
Physical Surface("outer", 2) = outer();
Physical Volume("fluid", 10) = {3};
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
Mesh.MeshSizeFromCurvature = 0;
