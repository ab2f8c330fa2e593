#pragma once
/// \file scenes.hpp
/// Ready-made scenes (meshes, bodies, boundary data) shared by the examples, tests and
/// benchmarks: the paper's annulus and settling disks, an ellipse settling in a channel, the DFG
/// cylinder, the oscillating cylinder, an ellipse in simple shear (Jeffery's orbit), a sphere
/// settling in a spherical container and spheres settling in a box (3D).
#include "alefsi/scenes/annulus.hpp"
#include "alefsi/scenes/dfg.hpp"
#include "alefsi/scenes/jeffery.hpp"
#include "alefsi/scenes/oscillating_cylinder.hpp"
#include "alefsi/scenes/settling.hpp"
#include "alefsi/scenes/settling_sphere.hpp"
#include "alefsi/scenes/spheres_settling_in_box.hpp"
