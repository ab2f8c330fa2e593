#pragma once
/// \file core.hpp
/// The core module: types, errors, Eigen includes.
#include "alefsi/core/eigen.hpp"
#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
