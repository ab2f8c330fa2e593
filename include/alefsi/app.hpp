#pragma once
/// \file app.hpp
/// Helpers for programs built on alefsi: the command-line options parser, the process's CPU
/// time and peak memory, a run's output options and closing report.
#include "alefsi/app/options.hpp"
#include "alefsi/app/resources.hpp"
#include "alefsi/app/run.hpp"
