#pragma once
/// \file core/eigen_sparse.hpp
/// Eigen's sparse module, included with its warnings kept out of user code.
#include "alefsi/core/eigen.hpp"
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
