#pragma once
/// \file sim.hpp
/// The sim module: step loops.
#include "alefsi/sim/ale_flow.hpp"
