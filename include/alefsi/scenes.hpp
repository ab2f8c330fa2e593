#pragma once
/// \file scenes.hpp
/// Ready-made scenes (meshes, bodies, boundary data) shared by the examples, tests and
/// benchmarks: the paper's annulus and settling disks, the DFG cylinder, the oscillating cylinder
/// and an ellipse in simple shear (Jeffery's orbit).
#include "alefsi/scenes/annulus.hpp"
#include "alefsi/scenes/dfg.hpp"
#include "alefsi/scenes/jeffery.hpp"
#include "alefsi/scenes/oscillating_cylinder.hpp"
#include "alefsi/scenes/settling.hpp"
