#pragma once
/// \file sim.hpp
/// The sim module: the ALE flow (AleFlow, the front) and its parts — configuration, flow state,
/// body system, discretisation, Newton driver, mesh velocity, contact and remesher seams —
/// checkpoints, and the run driver. docs/architecture.md shows how they fit.
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/body_system.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/sim/config.hpp"
#include "alefsi/sim/contact.hpp"
#include "alefsi/sim/collision_contact.hpp"
#include "alefsi/sim/discretisation.hpp"
#include "alefsi/sim/driver.hpp"
#include "alefsi/sim/flow_state.hpp"
#include "alefsi/sim/instantiate.hpp"
#include "alefsi/sim/kinematics.hpp"
#include "alefsi/sim/mesh_velocity.hpp"
#include "alefsi/sim/newton.hpp"
#include "alefsi/sim/remesher.hpp"
#include "alefsi/sim/remesher2d.hpp"
