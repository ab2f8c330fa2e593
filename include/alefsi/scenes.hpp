#pragma once
/// \file scenes.hpp
/// Ready-made scenes (meshes, bodies, boundary data) shared by the examples, tests and
/// benchmarks: the paper's annulus and settling disks.
#include "alefsi/scenes/annulus.hpp"
#include "alefsi/scenes/dfg.hpp"
#include "alefsi/scenes/settling.hpp"
