#pragma once
/// \file core/error.hpp
/// Typed exceptions with context, and the check macros.
///
/// Every error a user can provoke with bad input is one of these types, and its message
/// names the problem: the file and line for a mesh file, the cell for a bad cell, the
/// parameter for a bad value.
///
///     try { auto m = alefsi::read_gmsh<2>("box.msh"); }
///     catch (const alefsi::ParseError& e) { std::cerr << e.file() << ':' << e.line(); }
#include <cstddef>
#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "alefsi/core/types.hpp"

namespace alefsi {

/// Base of every exception alefsi throws.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A run-time parameter has a value outside its domain (names the parameter).
class InvalidArgument : public Error {
 public:
  InvalidArgument(std::string parameter, const std::string& what)
      : Error("invalid argument '" + parameter + "': " + what), parameter_(std::move(parameter)) {}
  const std::string& parameter() const noexcept { return parameter_; }

 private:
  std::string parameter_;
};

/// A mesh is not a valid conforming simplex mesh (names the offending entity).
class MeshError : public Error {
 public:
  enum class Entity { cell, node, facet, mesh };
  MeshError(Entity entity, Index index, const std::string& what)
      : Error(describe(entity, index) + what), entity_(entity), index_(index) {}
  Entity entity() const noexcept { return entity_; }
  /// Index of the offending cell / node / facet (-1 for a whole-mesh problem).
  Index index() const noexcept { return index_; }
  /// The same error with where it comes from in front ("mesh.msh:12: cell 5: ...").
  MeshError located(const std::string& where) const { return MeshError(entity_, index_, where + ": " + what(), Full{}); }

 private:
  struct Full {};
  MeshError(Entity entity, Index index, const std::string& message, Full)
      : Error(message), entity_(entity), index_(index) {}
  static std::string describe(Entity e, Index i) {
    switch (e) {
      case Entity::cell: return "cell " + std::to_string(i) + ": ";
      case Entity::node: return "node " + std::to_string(i) + ": ";
      case Entity::facet: return "facet " + std::to_string(i) + ": ";
      default: return "mesh: ";
    }
  }
  Entity entity_;
  Index index_;
};

/// A file could not be read or is malformed (names the file and the line).
class ParseError : public Error {
 public:
  ParseError(std::string file, std::size_t line, const std::string& what)
      : Error(file + ":" + std::to_string(line) + ": " + what), file_(std::move(file)), line_(line) {}
  const std::string& file() const noexcept { return file_; }
  /// 1-based line number (for binary sections: the line where the section started).
  std::size_t line() const noexcept { return line_; }

 private:
  std::string file_;
  std::size_t line_;
};

/// A file could not be written.
class IoError : public Error {
 public:
  using Error::Error;
};

/// A linear or nonlinear solver failed (singular matrix, no convergence).
class SolverError : public Error {
 public:
  using Error::Error;
};

namespace detail {
template <class... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}
/// Runs `act` on each process of a parallel run and then `all(ok)`, a collective call that
/// tells whether `act` succeeded on every process; when it failed somewhere, its exception is
/// rethrown where it was thrown and IoError(`elsewhere`) is thrown on the others, so that the
/// processes stop together instead of waiting for the one that threw.
template <class Act, class All>
void together(const Act& act, const All& all, const std::string& elsewhere) {
  std::exception_ptr failed;
  try {
    act();
  } catch (...) {
    failed = std::current_exception();
  }
  if (all(failed == nullptr)) return;
  if (failed) std::rethrow_exception(failed);
  throw IoError(elsewhere);
}
/// n in decimal with leading zeros up to `width` digits ("000042"), for file names.
inline std::string zero_padded(long n, std::size_t width) {
  std::string s = std::to_string(n);
  if (s.size() < width) s.insert(0, width - s.size(), '0');
  return s;
}
/// x in scientific notation with four significant digits ("1.234e-05"), for messages.
inline std::string sci(Real x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", x);
  return buf;
}
}  // namespace detail

}  // namespace alefsi

/// Always-on check of user input: throws `InvalidArgument(param, message)` when `cond` fails.
#define ALEFSI_CHECK_ARG(cond, param, ...)                                            \
  do {                                                                                \
    if (!(cond)) throw ::alefsi::InvalidArgument(param, ::alefsi::detail::concat(__VA_ARGS__)); \
  } while (false)

/// Debug-only assertion of an internal invariant (compiled out with NDEBUG).
#ifdef NDEBUG
#define ALEFSI_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define ALEFSI_ASSERT(cond) assert(cond)
#endif
