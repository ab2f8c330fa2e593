#pragma once
/// \file la.hpp
/// The la module: sparse assembly, fill-reducing orderings and linear-solver policies
/// (SuiteSparse ones when alefsi was built with it).
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
