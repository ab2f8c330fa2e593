#pragma once
/// \file la.hpp
/// The la module: sparse assembly and linear-solver policies.
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"
