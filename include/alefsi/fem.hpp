#pragma once
/// \file fem.hpp
/// The fem module: quadrature, Lagrange elements, element pairs, DOF maps, constraints, norms.
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/fem/lagrange.hpp"
#include "alefsi/fem/norms.hpp"
#include "alefsi/fem/quadrature.hpp"
