#pragma once
/// \file app.hpp
/// Helpers for programs built on alefsi: the command-line options parser.
#include "alefsi/app/options.hpp"
