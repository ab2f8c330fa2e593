#pragma once
/// \file alefsi.hpp
/// Everything: include this in applications and examples (tests include narrow headers).
#include "alefsi/app.hpp"
#include "alefsi/core.hpp"
#include "alefsi/fem.hpp"
#include "alefsi/la.hpp"
#include "alefsi/mesh.hpp"
#include "alefsi/physics.hpp"
#include "alefsi/scenes.hpp"
#include "alefsi/sim.hpp"
#include "alefsi/time.hpp"
