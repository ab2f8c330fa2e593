#pragma once
/// \file app/resources.hpp
/// What a program reports of its own cost: the process's CPU time and its peak resident memory
/// (POSIX getrusage; Linux gives ru_maxrss in kB).
///
///     const Real cpu0 = alefsi::app::cpu_seconds();
///     ...
///     std::cout << alefsi::app::cpu_seconds() - cpu0 << " s CPU, peak " << alefsi::app::peak_mb() << " MB\n";
/// (In namespace alefsi::app, so that programs with helpers of these names and `using namespace
/// alefsi` keep theirs.)
#include <sys/resource.h>

#include <ctime>

#include "alefsi/core/types.hpp"

namespace alefsi::app {

/// CPU time of the process so far (std::clock), seconds.
inline Real cpu_seconds() { return Real(std::clock()) / CLOCKS_PER_SEC; }

/// Peak resident memory of the process so far, MB.
inline Real peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return Real(u.ru_maxrss) / 1024;
}

}  // namespace alefsi::app
