#pragma once
/// \file fem/constraints.hpp
/// The constraint-aware map from field DOFs to the unknowns of the linear system.
///
/// Every field DOF f is an affine function of the unknowns:
///     field[f] = sum_k weight_k * unknown[index_k] + offset[f].
/// Three kinds of field DOF use this one mechanism:
///   - free:   one entry (its own unknown, weight 1), offset 0;
///   - fixed:  no entry, offset = the prescribed value (Dirichlet data, a pinned pressure);
///   - linked: entries on *extra* unknowns with given weights plus an offset — a velocity DOF
///             on rigid body K is u = H^K(x) Z^K + u_s^K(x): entries (Z^K_j, H_cj), offset u_s.
/// Unknowns are numbered: free field DOFs first, in field order, then the extra unknowns in the
/// order `add_unknowns` created them. Assembly scatters an element residual r and Jacobian J
/// as T^T r and T^T J T, where T is this map's matrix; the test functions of a body's rows
/// (eq. 11 of the paper) are exactly the columns of T for its unknowns.
///
/// The *structure* (which DOFs are fixed or linked, to which unknowns) is frozen by `finalize()`;
/// afterwards values (`set_fixed_value`, `set_link`) may change every step (moving walls, a
/// body's new position) without touching the sparsity pattern.
///
///     DofConstraints cons(space.n_field());
///     for (Index i : wall) cons.fix(space.velocity_field(i, 0), 0.0);
///     cons.finalize();
///     VecX field = cons.expand(unknowns);
#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

class DofConstraints {
 public:
  enum class Kind : unsigned char { free, fixed, linked };

  explicit DofConstraints(Index n_field) : kind_(n_field, Kind::free), value_(n_field, 0.0), link_of_(n_field, -1) {}

  Index n_field() const { return static_cast<Index>(kind_.size()); }

  /// Adds n extra unknowns (e.g. a rigid body's velocities); returns the index of the first
  /// among the extra unknowns (0-based within the extras; see `extra_unknown`).
  Index add_unknowns(int n) {
    require_open("add_unknowns");
    ALEFSI_CHECK_ARG(n > 0, "n", "must be positive, got ", n);
    const Index first = n_extra_;
    n_extra_ += n;
    return first;
  }

  /// Prescribes field[f] = value.
  void fix(Index f, Real value) {
    require_open("fix");
    check_field(f);
    kind_[f] = Kind::fixed;
    value_[f] = value;
  }

  /// field[f] = sum_k weights[k] * extra[extras[k]] + offset.
  void link(Index f, std::span<const Index> extras, std::span<const Real> weights, Real offset) {
    require_open("link");
    check_field(f);
    ALEFSI_CHECK_ARG(extras.size() == weights.size(), "weights", "needs one weight per extra unknown");
    for (Index e : extras) ALEFSI_CHECK_ARG(e >= 0 && e < n_extra_, "extras", "extra unknown ", e, " not created");
    kind_[f] = Kind::linked;
    value_[f] = offset;
    link_of_[f] = static_cast<Index>(links_.size());
    links_.push_back({std::vector<Index>(extras.begin(), extras.end()), std::vector<Real>(weights.begin(), weights.end())});
  }

  /// Freezes the structure and numbers the unknowns.
  void finalize() {
    require_open("finalize");
    const Index nf = n_field();
    start_.assign(nf + 1, 0);
    Index n_free = 0;
    for (Index f = 0; f < nf; ++f) {
      if (kind_[f] == Kind::free) ++n_free;
      start_[f + 1] = start_[f] + (kind_[f] == Kind::free ? 1 : kind_[f] == Kind::fixed ? 0 : Index(links_[link_of_[f]].extras.size()));
    }
    n_free_ = n_free;
    index_.resize(start_[nf]);
    weight_.resize(start_[nf]);
    Index u = 0;
    for (Index f = 0; f < nf; ++f) {
      if (kind_[f] == Kind::free) {
        index_[start_[f]] = u++;
        weight_[start_[f]] = 1.0;
      } else if (kind_[f] == Kind::linked) {
        const auto& l = links_[link_of_[f]];
        for (std::size_t k = 0; k < l.extras.size(); ++k) {
          index_[start_[f] + k] = n_free_ + l.extras[k];
          weight_[start_[f] + k] = l.weights[k];
        }
      }
    }
    links_.clear();
    links_.shrink_to_fit();
    finalized_ = true;
  }

  bool finalized() const { return finalized_; }
  Index n_unknowns() const { return n_free_ + n_extra_; }
  Index n_free() const { return n_free_; }
  /// Unknown index of extra unknown k.
  Index extra_unknown(Index k) const { return n_free_ + k; }
  Kind kind(Index f) const { return kind_[f]; }
  /// Offset of field DOF f (prescribed value, or the link's offset; 0 for free DOFs).
  Real offset(Index f) const { return value_[f]; }
  /// The entries of field DOF f: unknown indices and weights.
  std::span<const Index> indices(Index f) const { return {index_.data() + start_[f], std::size_t(start_[f + 1] - start_[f])}; }
  std::span<const Real> weights(Index f) const { return {weight_.data() + start_[f], std::size_t(start_[f + 1] - start_[f])}; }

  /// Changes the value of a fixed DOF (structure unchanged).
  void set_fixed_value(Index f, Real value) {
    ALEFSI_ASSERT(kind_[f] == Kind::fixed);
    value_[f] = value;
  }
  /// Changes the weights and offset of a linked DOF; its unknowns stay.
  void set_link(Index f, std::span<const Real> weights, Real offset) {
    ALEFSI_ASSERT(kind_[f] == Kind::linked && weights.size() == std::size_t(start_[f + 1] - start_[f]));
    std::copy(weights.begin(), weights.end(), weight_.begin() + start_[f]);
    value_[f] = offset;
  }

  /// field = T u + offset.
  VecX expand(const VecX& u) const {
    require_final();
    ALEFSI_CHECK_ARG(u.size() == n_unknowns(), "u", "has ", u.size(), " entries, expected ", n_unknowns());
    VecX field(n_field());
    for (Index f = 0; f < n_field(); ++f) {
      Real s = value_[f];
      for (Index k = start_[f]; k < start_[f + 1]; ++k) s += weight_[k] * u[index_[k]];
      field[f] = s;
    }
    return field;
  }
  /// T^T r: the residual of the unknowns from a residual on field DOFs.
  VecX reduce(const VecX& r_field) const {
    require_final();
    VecX r = VecX::Zero(n_unknowns());
    for (Index f = 0; f < n_field(); ++f)
      for (Index k = start_[f]; k < start_[f + 1]; ++k) r[index_[k]] += weight_[k] * r_field[f];
    return r;
  }
  /// Unknowns whose free entries take the given field values (extras are left 0): a starting
  /// guess that is exact for the free DOFs.
  VecX restrict_free(const VecX& field) const {
    require_final();
    VecX u = VecX::Zero(n_unknowns());
    for (Index f = 0; f < n_field(); ++f)
      if (kind_[f] == Kind::free) u[index_[start_[f]]] = field[f];
    return u;
  }

 private:
  struct Link {
    std::vector<Index> extras;
    std::vector<Real> weights;
  };
  void require_open(const char* what) const {
    if (finalized_) throw Error(std::string("DofConstraints::") + what + " after finalize()");
  }
  void require_final() const {
    if (!finalized_) throw Error("DofConstraints used before finalize()");
  }
  void check_field(Index f) const {
    ALEFSI_CHECK_ARG(f >= 0 && f < n_field(), "field_dof", f, " out of range [0, ", n_field(), ")");
    ALEFSI_CHECK_ARG(kind_[f] == Kind::free, "field_dof", f, " is already constrained");
  }

  std::vector<Kind> kind_;
  std::vector<Real> value_;
  std::vector<Index> link_of_;
  std::vector<Link> links_;
  Index n_extra_ = 0, n_free_ = 0;
  bool finalized_ = false;
  std::vector<Index> start_, index_;
  std::vector<Real> weight_;
};

}  // namespace alefsi
