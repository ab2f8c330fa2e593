#pragma once
/// \file scenes.hpp
/// Ready-made scenes (meshes, bodies, boundary data) shared by the examples, tests and
/// benchmarks: the paper's annulus and settling disks, the DFG cylinder and the oscillating cylinder.
#include "alefsi/scenes/annulus.hpp"
#include "alefsi/scenes/dfg.hpp"
#include "alefsi/scenes/oscillating_cylinder.hpp"
#include "alefsi/scenes/settling.hpp"
