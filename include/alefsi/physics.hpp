#pragma once
/// \file physics.hpp
/// The physics module: flow kernels.
#include "alefsi/physics/stokes.hpp"
