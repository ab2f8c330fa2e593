#pragma once
/// \file sim.hpp
/// The sim module: the ALE flow with its step loop, checkpoints, and the run driver.
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/sim/driver.hpp"
