#pragma once
/// \file la/partition.hpp
/// Assembly in parts, for runs under MPI (la/petsc.hpp): the cells cut into P parts along a
/// space-filling curve, and the seam through which a linear solver tells the flow that each
/// process assembles only the matrix of its part (the solver then solves with the sum of the
/// parts).
///
/// The cut: the cells are sorted by the Morton (Z-order) key of their centroids, quantised on the
/// mesh's bounding box (21 bits per axis in 3D, 31 in 2D; x the most significant), and split
/// into P runs of consecutive cells whose sizes differ by at most one. The result depends only
/// on the mesh, so every process computes the same partition without communication. A Morton
/// run is compact: its boundary grows like a part's surface, not its volume (a structured cube
/// cut in two parts is cut on its mid-plane x = 1/2).
///
/// A solver may partition the cells better (la/petsc.hpp: PT-Scotch on the cells' dual graph,
/// through PETSc's MatPartitioning); the Morton cut is what a flow uses otherwise.
///
///     const std::vector<int> part = partition_cells(mesh, 4);
///     const std::vector<Index> mine = cells_of_part(part, rank);
#include <algorithm>
#include <array>
#include <concepts>
#include <cstdint>
#include <numeric>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

namespace detail {
/// The Morton key of a point quantised to `bits` bits per axis (q[0] the most significant).
template <int D>
std::uint64_t morton_key(const std::array<std::uint64_t, D>& q, int bits) {
  std::uint64_t key = 0;
  for (int b = bits - 1; b >= 0; --b)
    for (int k = 0; k < D; ++k) key = (key << 1) | ((q[std::size_t(k)] >> b) & 1u);
  return key;
}
}  // namespace detail

/// The part (0 .. parts - 1) of each cell of `mesh`: runs of the Morton order of the cells'
/// centroids, as equal as the cell count allows (file comment).
template <int D>
std::vector<int> partition_cells(const Mesh<D>& mesh, int parts) {
  ALEFSI_CHECK_ARG(parts >= 1, "parts", "must be at least 1, got ", parts);
  const Index nc = mesh.n_cells();
  std::vector<int> part(std::size_t(nc), 0);
  if (parts == 1 || nc == 0) return part;
  Vec<D> lo = mesh.node(0), hi = mesh.node(0);
  for (const auto& x : mesh.coordinates()) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  constexpr int bits = D == 3 ? 21 : 31;
  const Real top = Real((std::uint64_t(1) << bits) - 1);
  std::vector<std::uint64_t> key(static_cast<std::size_t>(nc));
  for (Index c = 0; c < nc; ++c) {
    const Vec<D> y = mesh.centroid(c);
    std::array<std::uint64_t, D> q{};
    for (int k = 0; k < D; ++k) {
      const Real w = hi[k] > lo[k] ? (y[k] - lo[k]) / (hi[k] - lo[k]) : 0.0;
      q[std::size_t(k)] = std::uint64_t(std::clamp(w, Real(0), Real(1)) * top);
    }
    key[std::size_t(c)] = detail::morton_key<D>(q, bits);
  }
  std::vector<Index> order(static_cast<std::size_t>(nc));
  std::iota(order.begin(), order.end(), Index(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](Index a, Index b) { return key[std::size_t(a)] < key[std::size_t(b)]; });
  for (Index i = 0; i < nc; ++i)  // run p holds the places [p nc / P, (p + 1) nc / P)
    part[std::size_t(order[std::size_t(i)])] = int((std::int64_t(i) * parts) / nc);
  return part;
}

/// The cells of part `p`, ascending.
inline std::vector<Index> cells_of_part(const std::vector<int>& part, int p) {
  std::vector<Index> cells;
  for (std::size_t c = 0; c < part.size(); ++c)
    if (part[c] == p) cells.push_back(Index(c));
  return cells;
}

/// A cell kernel seen through a part's numbering: cell i of the part is the mesh's cell
/// cells[i] (for an Assembler built with AssembledCells::part, la/assembler.hpp).
template <class Kernel>
struct PartKernel {
  const Kernel* kernel;
  const std::vector<Index>* cells;
  template <class U, class A, class R>
  void cell(Index i, const U& u, A& a, R& r) const {
    kernel->cell((*cells)[std::size_t(i)], u, a, r);
  }
};

/// A linear solver that can take each process's part of a matrix (la/petsc.hpp under MPI): after
/// `set_summed(true)` the matrix each process passes to analyze/factorize is the sum over its
/// own cells, and the solver solves with the sum of the parts; the right-hand side stays whole
/// (the same on every process). `parts()` processes, this one `part()`; `sum(v)` and `min(w)`
/// reduce a vector over them (every process gets the result).
template <class S>
concept SummedPartsSolver =
    LinearSolver<S> && requires(S& s, const S& cs, VecX& v, std::vector<int>& w) {
      { cs.parts() } -> std::convertible_to<int>;
      { cs.part() } -> std::convertible_to<int>;
      s.set_summed(true);
      cs.sum(v);
      cs.min(w);
    };

}  // namespace alefsi
