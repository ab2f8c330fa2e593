#pragma once
/// \file time.hpp
/// The time module: the ALE schemes as types (and their name -> type dispatch), the
/// step-size history, and the stepper that turns both into one step's coefficients.
#include "alefsi/time/history.hpp"
#include "alefsi/time/schemes.hpp"
#include "alefsi/time/stepper.hpp"
#include "alefsi/time/error_estimate.hpp"
#include "alefsi/time/step_controller.hpp"
#include "alefsi/time/step_sequence.hpp"
