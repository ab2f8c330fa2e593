#pragma once
/// \file core/grid.hpp
/// Iteration over a box of integer grid coordinates, as uniform bucket grids need it
/// (mesh/adapt/locate.hpp, physics/collision.hpp).
///
///     std::array<int, 3> lo{0, 0, 0}, hi{1, 2, 0};
///     alefsi::for_each_in_box(lo, hi, [](const auto& i) { /* 6 calls */ });
#include <cstddef>
#include <tuple>

namespace alefsi {

/// Calls f(i) for every coordinate tuple i with lo[d] <= i[d] <= hi[d] (inclusive; a
/// std::array-like `Key`), first coordinate fastest. Requires lo <= hi in every coordinate.
template <class Key, class F>
void for_each_in_box(const Key& lo, const Key& hi, F&& f) {
  constexpr std::size_t D = std::tuple_size<Key>::value;
  Key i = lo;
  while (true) {
    f(i);
    std::size_t d = 0;
    while (d < D && i[d] == hi[d]) i[d] = lo[d], ++d;
    if (d == D) return;
    ++i[d];
  }
}

}  // namespace alefsi
