#pragma once
/// \file mesh/adapt.hpp
/// Mesh adaptation of moved 2D meshes (split / collapse / flip / smooth, boundary nodes
/// kept on their curves) and transfer of P1 / P2 fields to the adapted mesh.
///
///     auto m2 = alefsi::adapt(moved, curves, opt, &report);
///     alefsi::FieldTransfer2D T(moved, m2, 2);
///     auto u2 = T.apply(u, 2);
#include "alefsi/mesh/adapt/adapt2d.hpp"
#include "alefsi/mesh/adapt/locate.hpp"
#include "alefsi/mesh/adapt/transfer.hpp"
