#pragma once
/// \file la.hpp
/// The la module: sparse assembly, fill-reducing orderings, the saddle-point blocks and the
/// direct linear-solver policies (SuiteSparse ones when alefsi was built with it) and their
/// factorisation reuse (`LinearSolve`).
/// Not included here: the iterative saddle-point solver `SaddlePointGmres` (la/krylov.hpp) and
/// its AMG (la/amg.hpp). They added about 3.5 s to every translation unit that includes them
/// (docs/performance.md, compile time), so a program includes them where it uses them.
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/coupling.hpp"
#include "alefsi/la/linear_solve.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
