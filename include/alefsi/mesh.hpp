#pragma once
/// \file mesh.hpp
/// The mesh module: simplex meshes, generators and file I/O.
#include "alefsi/mesh/adapt.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/mesh/io/vtu.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/mesh/simplex.hpp"
