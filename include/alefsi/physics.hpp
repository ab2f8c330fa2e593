#pragma once
/// \file physics.hpp
/// The physics module: Stokes and ALE Navier-Stokes kernels, their stabilisation policies,
/// mesh motion.
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/mass_properties.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/physics/stabilisation.hpp"
#include "alefsi/physics/stokes.hpp"
