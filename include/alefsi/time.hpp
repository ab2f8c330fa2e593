#pragma once
/// \file time.hpp
/// The time module: the ALE schemes as types.
#include "alefsi/time/schemes.hpp"
