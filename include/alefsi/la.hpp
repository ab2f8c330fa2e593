#pragma once
/// \file la.hpp
/// The la module: sparse assembly, fill-reducing orderings and linear-solver policies: direct
/// (SuiteSparse ones when alefsi was built with it), and the iterative saddle-point solver with
/// its smoothed-aggregation AMG.
#include "alefsi/la/amg.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/krylov.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
