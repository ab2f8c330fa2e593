#pragma once
/// \file mesh/io/vtu.hpp
/// VTK XML unstructured-grid (.vtu), parallel (.pvtu) and time-series collection (.pvd) writers,
/// for ParaView.
///
/// What is written (VTK >= 6 / ParaView readable; checked against VTK 9's reader):
///   * `<VTKFile type="UnstructuredGrid" version="1.0" header_type="UInt64">`, byte order of the
///     host (stated in `byte_order`, "LittleEndian" on every platform we build on), all arrays in
///     one raw binary `<AppendedData encoding="raw">` block (each array = UInt64 byte count + data).
///   * Points: Float64, always 3 components (z = 0 for a 2D mesh).
///     order 1: the mesh nodes, in node order.
///     order 2: the mesh nodes, then one point per mesh edge: point n_nodes() + e lies at the
///              midpoint of edge e, or at `edge_midpoints[e]` if given (curved P2 geometry).
///   * Cells: Int64 connectivity and offsets, UInt8 types. order 1: VTK_TRIANGLE (5) /
///     VTK_TETRA (10) with the cell's nodes; order 2: VTK_QUADRATIC_TRIANGLE (22) /
///     VTK_QUADRATIC_TETRA (24): the D+1 nodes, then n_nodes() + (the cell's edges in the local
///     order of mesh/simplex.hpp, which is VTK's mid-edge order). No permutation happens.
///   * Cell data: the mesh's cell tags as Int32 array "region" (always), then the user's cell
///     fields as Float64. Point data: the user's point fields as Float64. Fields keep their order.
///
/// Field layout (`VtuField::values`, component-interleaved: value[i * components + c]):
///   * point field: components * n_nodes values (P1) or components * (n_nodes + n_edges) values
///     (P2: the node values, then one value per edge in mesh edge order). A P1 field written with
///     order 2 is interpolated linearly to the mid-edge points (mean of the two end values); a P2
///     field written with order 1 is reduced to its node values.
///   * cell field: components * n_cells values.
///   * In 2D, a 2-component field (a vector) is written with 3 components (third = 0), so
///     ParaView can glyph and warp by it. Other component counts are written as given.
///   * Values are written bit for bit: NaN and infinities pass through (VTK accepts them).
///   * Units are whatever the caller uses; nothing is scaled.
///
/// Input checks, all done before anything touches the disk (`InvalidArgument` naming the
/// parameter or the field): order is 1 or 2; edge_midpoints is empty or has n_edges entries
/// (ignored for order 1); every field has a non-empty name unique among all fields and other
/// than "region" (reserved for the cell tags), components >= 1, and a value count matching its
/// location as above. Names may contain any character (XML-escaped in the file).
///
/// Pieces (MPI output, each process writing its cells): `write_vtu_piece` writes a subset of
/// the cells with the points they use (renumbered in the mesh's order, so a point on the border
/// of two pieces is in both), the same arrays as the whole file; `write_pvtu` writes the
/// `<VTKFile type="PUnstructuredGrid">` file naming the arrays and the pieces, which VTK's
/// parallel reader joins into one grid; `PvdWriter::write` with a `VtuPiece` runs a series of
/// them, with the processes agreeing after each file (a failure anywhere throws everywhere).
///
/// Atomicity: every file (.vtu, .pvtu and .pvd) is written to a hidden temporary in the target's
/// directory (".<name>.tmp-<random>", created exclusively), flushed and closed, then renamed over
/// the target. On any failure the temporary is removed and `IoError` (naming the target and the
/// reason) is thrown; the target is then untouched, old content or absent, never half-written.
/// (Protects against process crashes and I/O errors; there is no fsync, so not against power loss.)
///
///     std::vector<Real> p(mesh.n_nodes()), u(2 * mesh.n_nodes());    // P1 scalar, 2D vector
///     alefsi::write_vtu("flow.vtu", mesh, {{"pressure", 1, p}, {"velocity", 2, u}});
///     alefsi::PvdWriter series("out/run.pvd");  series.write(t, mesh, {{"pressure", 1, p}});
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// Where a field's values live: one tuple per point (node / mid-edge) or one per cell.
enum class FieldLocation { point, cell };

/// A named field to write; `values` is a view, it must outlive the write call.
struct VtuField {
  std::string name;
  int components = 1;
  std::span<const Real> values;
  FieldLocation location = FieldLocation::point;
};

namespace detail {

/// Escapes the five XML special characters for use in an attribute value.
inline std::string xml_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += ch;
    }
  }
  return out;
}

/// Shortest decimal text that reads back to the same double.
inline std::string format_real(Real x) {
  std::array<char, 32> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), x);
  return std::string(buf.data(), res.ptr);
}

inline constexpr const char* vtk_byte_order =
    std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big,
              "mixed-endian hosts are not supported by the VTK writer");

/// A file written to a temporary next to `target` and renamed over it by `commit()`.
/// Buffered binary output; any failure removes the temporary and throws IoError.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target) : target_(std::move(target)), buf_(std::size_t(1) << 20) {
    const std::string name = target_.filename().string();
    if (name.empty() || name == "." || name == "..") fail("the path does not name a file", 0);
    static std::atomic<std::uint64_t> counter{0};
    for (int attempt = 0; attempt < 64 && !f_; ++attempt) {
      std::uint64_t key = counter.fetch_add(1) * 0x9E3779B97F4A7C15ull;
      key ^= static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
      key ^= std::hash<std::thread::id>{}(std::this_thread::get_id()) << 1;
      std::array<char, 17> hex{};
      const auto res = std::to_chars(hex.data(), hex.data() + 16, key, 16);
      const std::filesystem::path tmp =
          target_.parent_path() / ("." + name + ".tmp-" + std::string(hex.data(), res.ptr));
      errno = 0;
      f_ = std::fopen(tmp.string().c_str(), "wbx");  // "x": exclusive creation, never clobbers
      if (f_) tmp_ = tmp;  // ours to remove from now on
      else if (errno != EEXIST) fail("cannot create temporary file '" + tmp.string() + "'", errno);
    }
    if (!f_) fail("cannot create a unique temporary file next to it", EEXIST);
    std::setvbuf(f_, nullptr, _IONBF, 0);  // we buffer ourselves
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() { discard(); }

  template <class T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (n_ + sizeof(T) > buf_.size()) flush_buffer();
    std::memcpy(buf_.data() + n_, &v, sizeof(T));
    n_ += sizeof(T);
  }
  void write(const void* data, std::size_t bytes) {
    if (n_ + bytes <= buf_.size()) {
      if (bytes) std::memcpy(buf_.data() + n_, data, bytes);
      n_ += bytes;
      return;
    }
    flush_buffer();
    raw_write(data, bytes);
  }
  void write(std::string_view s) { write(s.data(), s.size()); }
  /// Total bytes written so far.
  std::uint64_t position() const { return written_ + n_; }

  /// Flushes, closes and renames the temporary over the target.
  void commit() {
    flush_buffer();
    std::FILE* f = std::exchange(f_, nullptr);
    errno = 0;
    const bool flushed = std::fflush(f) == 0 && !std::ferror(f);
    const int flush_errno = errno;
    const bool closed = std::fclose(f) == 0;
    if (!flushed || !closed) fail("write error", flushed ? errno : flush_errno);
    std::error_code ec;
    std::filesystem::rename(tmp_, target_, ec);
    if (ec) fail("cannot rename the temporary file over it: " + ec.message(), 0);
    tmp_.clear();
  }

  const std::filesystem::path& target() const { return target_; }

 private:
  void flush_buffer() {
    raw_write(buf_.data(), n_);
    n_ = 0;
  }
  void raw_write(const void* data, std::size_t bytes) {
    if (bytes == 0) return;
    errno = 0;
    if (std::fwrite(data, 1, bytes, f_) != bytes) fail("write error", errno);
    written_ += bytes;
  }
  void discard() noexcept {
    if (f_) std::fclose(std::exchange(f_, nullptr));
    if (!tmp_.empty()) {
      std::error_code ec;
      std::filesystem::remove(tmp_, ec);
      tmp_.clear();
    }
  }
  [[noreturn]] void fail(const std::string& what, int err) {
    discard();
    std::string msg = "cannot write '" + target_.string() + "': " + what;
    if (err != 0) msg += ": " + std::generic_category().message(err);
    throw IoError(msg);
  }

  std::filesystem::path target_, tmp_;
  std::FILE* f_ = nullptr;
  std::vector<char> buf_;
  std::size_t n_ = 0;
  std::uint64_t written_ = 0;
};

/// Number of components a field is written with (2D vectors are padded to 3).
template <int D>
int vtk_components(int components) {
  return D == 2 && components == 2 ? 3 : components;
}

/// All input checks of write_vtu, before any file is opened.
template <int D>
void check_vtu_input(const Mesh<D>& mesh, std::span<const VtuField> fields, int order,
                     std::size_t n_edge_midpoints) {
  ALEFSI_CHECK_ARG(order == 1 || order == 2, "order", "must be 1 or 2, got ", order);
  const std::size_t nn = std::size_t(mesh.n_nodes()), ne = std::size_t(mesh.n_edges()),
                    nc = std::size_t(mesh.n_cells());
  ALEFSI_CHECK_ARG(n_edge_midpoints == 0 || n_edge_midpoints == ne, "edge_midpoints",
                   "must be empty or have one point per mesh edge (", ne, "), got ", n_edge_midpoints);
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const VtuField& f = fields[i];
    ALEFSI_CHECK_ARG(!f.name.empty(), concat("fields[", i, "]"), "has an empty name");
    const std::string param = "field '" + f.name + "'";
    ALEFSI_CHECK_ARG(f.name != "region", param, "the name 'region' is reserved for the cell tags");
    for (std::size_t j = 0; j < i; ++j)
      ALEFSI_CHECK_ARG(fields[j].name != f.name, param, "duplicate name (fields[", j, "] and fields[", i, "])");
    ALEFSI_CHECK_ARG(f.components >= 1, param, "components must be >= 1, got ", f.components);
    const std::size_t c = std::size_t(f.components), n = f.values.size();
    if (f.location == FieldLocation::cell) {
      ALEFSI_CHECK_ARG(n == c * nc, param, "cell field has ", n, " values, expected components * n_cells = ",
                       c * nc);
    } else {
      ALEFSI_CHECK_ARG(f.location == FieldLocation::point, param, "unknown FieldLocation");
      ALEFSI_CHECK_ARG(n == c * nn || n == c * (nn + ne), param, "point field has ", n,
                       " values, expected components * n_nodes = ", c * nn,
                       " (P1) or components * (n_nodes + n_edges) = ", c * (nn + ne), " (P2)");
    }
  }
}

/// The cells a file holds and the points they use: the whole mesh, or a piece (its cells in
/// increasing order; its points are the nodes and, for order 2, the edges of those cells, in
/// the mesh's point order: nodes, then n_nodes() + edge).
struct VtuSelection {
  bool whole = true;
  std::vector<Index> cells, points;  // a piece's; empty for the whole mesh
  std::vector<Index> local;          // a piece's: mesh point -> its point in the piece (-1: unused)

  template <int D>
  std::size_t n_points(const Mesh<D>& mesh, int order) const {
    return whole ? std::size_t(mesh.n_nodes() + (order == 2 ? mesh.n_edges() : 0)) : points.size();
  }
  template <int D>
  std::size_t n_cells(const Mesh<D>& mesh) const {
    return whole ? std::size_t(mesh.n_cells()) : cells.size();
  }
};

template <int D>
VtuSelection select_cells(const Mesh<D>& mesh, std::span<const Index> cells, int order) {
  const Index nn = mesh.n_nodes(), np = order == 2 ? nn + mesh.n_edges() : nn;
  for (std::size_t i = 0; i < cells.size(); ++i)
    ALEFSI_CHECK_ARG(cells[i] >= 0 && cells[i] < mesh.n_cells() && (i == 0 || cells[i] > cells[i - 1]), "cells",
                     "must be increasing cell indices of the mesh (", mesh.n_cells(), " cells); cells[", i, "] = ",
                     cells[i], i > 0 ? concat(" after ", cells[i - 1]) : std::string());
  VtuSelection s;
  s.whole = false;
  s.cells.assign(cells.begin(), cells.end());
  std::vector<char> used(std::size_t(np), 0);
  for (Index c : cells) {
    for (Index v : mesh.cell(c)) used[std::size_t(v)] = 1;
    if (order == 2)
      for (Index e : mesh.cell_edges(c)) used[std::size_t(nn + e)] = 1;
  }
  s.local.assign(std::size_t(np), -1);
  for (Index g = 0; g < np; ++g)
    if (used[std::size_t(g)]) s.local[std::size_t(g)] = Index(s.points.size()), s.points.push_back(g);
  return s;
}

/// One array of a file: its XML description and a function writing its bytes.
struct VtuArray {
  int section;  // 0 PointData, 1 CellData, 2 Points, 3 Cells
  const char* type;
  std::string name;
  int components;
  std::uint64_t bytes;
  std::function<void(AtomicFile&)> emit;
};

inline constexpr std::array<const char*, 4> vtu_sections{"PointData", "CellData", "Points", "Cells"};

/// The arrays of a file of `mesh`'s selected cells, in the order they are written. Their
/// writers refer to `mesh`, `sel`, the fields' values and `edge_midpoints`, which must outlive them.
template <int D>
std::vector<VtuArray> vtu_arrays(const Mesh<D>& mesh, std::span<const VtuField> fields, int order,
                                 std::span<const Vec<D>> edge_midpoints, const VtuSelection& sel) {
  const std::size_t nn = std::size_t(mesh.n_nodes()), ne = std::size_t(mesh.n_edges());
  const std::size_t np = sel.n_points(mesh, order), nc = sel.n_cells(mesh);
  const int npc = order == 2 ? D + 1 + simplex_edges<D> : D + 1;
  const std::uint8_t cell_type = D == 2 ? (order == 2 ? 22 : 5) : (order == 2 ? 24 : 10);
  // the mesh point of point i and the mesh cell of cell k in the file
  auto point = [&sel](std::size_t i) { return sel.whole ? i : std::size_t(sel.points[i]); };
  auto cell = [&sel](std::size_t k) { return sel.whole ? Index(k) : sel.cells[k]; };

  std::vector<VtuArray> arrays;
  // --- point data
  for (const VtuField& f : fields) {
    if (f.location != FieldLocation::point) continue;
    const std::size_t c = std::size_t(f.components);
    const std::size_t cw = std::size_t(vtk_components<D>(f.components));
    const bool p2 = f.values.size() == c * (nn + ne);
    const std::span<const Real> v = f.values;
    arrays.push_back({0, "Float64", f.name, int(cw), 8 * cw * np, [=, &mesh, &sel](AtomicFile& o) {
                        // the whole mesh's tuples lie in order in v, unless padded or interpolated
                        std::size_t i = 0;
                        if (sel.whole && cw == c) {
                          i = order == 1 || p2 ? np : nn;  // a P1 field at order 2: its mid-edge values below
                          o.write(v.data(), i * c * sizeof(Real));
                        }
                        for (; i < np; ++i) {
                          const std::size_t g = point(i);
                          if (g < nn || p2) {
                            for (std::size_t k = 0; k < c; ++k) o.put(v[g * c + k]);
                          } else {  // a P1 field at a mid-edge point: the mean of the edge's ends
                            const auto [a, b] = mesh.edge(Index(g - nn));
                            for (std::size_t k = 0; k < c; ++k)
                              o.put(Real(0.5) * (v[std::size_t(a) * c + k] + v[std::size_t(b) * c + k]));
                          }
                          for (std::size_t k = c; k < cw; ++k) o.put(Real(0));
                        }
                      }});
  }
  // --- cell data
  arrays.push_back({1, "Int32", "region", 1, 4 * nc, [=, &mesh](AtomicFile& o) {
                      for (std::size_t k = 0; k < nc; ++k) o.put(std::int32_t(mesh.cell_tags()[std::size_t(cell(k))]));
                    }});
  for (const VtuField& f : fields) {
    if (f.location != FieldLocation::cell) continue;
    const std::size_t c = std::size_t(f.components);
    const std::size_t cw = std::size_t(vtk_components<D>(f.components));
    const std::span<const Real> v = f.values;
    arrays.push_back({1, "Float64", f.name, int(cw), 8 * cw * nc, [=, &sel](AtomicFile& o) {
                        if (sel.whole && cw == c) return o.write(v.data(), v.size() * sizeof(Real));
                        for (std::size_t k = 0; k < nc; ++k) {
                          const std::size_t g = std::size_t(cell(k));
                          for (std::size_t j = 0; j < c; ++j) o.put(v[g * c + j]);
                          for (std::size_t j = c; j < cw; ++j) o.put(Real(0));
                        }
                      }});
  }
  // --- points
  arrays.push_back({2, "Float64", "Points", 3, 24 * np, [=, &mesh](AtomicFile& o) {
                      auto put = [&](const Vec<D>& x) { o.put(x[0]), o.put(x[1]), o.put(D == 3 ? x[D - 1] : Real(0)); };
                      for (std::size_t i = 0; i < np; ++i) {
                        const std::size_t g = point(i);
                        if (g < nn) put(mesh.node(Index(g)));
                        else if (!edge_midpoints.empty()) put(edge_midpoints[g - nn]);
                        else put(Real(0.5) * (mesh.node(mesh.edge(Index(g - nn))[0]) + mesh.node(mesh.edge(Index(g - nn))[1])));
                      }
                    }});
  // --- cells
  arrays.push_back({3, "Int64", "connectivity", 1, 8 * nc * std::size_t(npc), [=, &mesh, &sel](AtomicFile& o) {
                      auto id = [&](std::size_t g) { return std::int64_t(sel.whole ? Index(g) : sel.local[g]); };
                      for (std::size_t k = 0; k < nc; ++k) {
                        const Index c = cell(k);
                        for (Index v : mesh.cell(c)) o.put(id(std::size_t(v)));
                        if (order == 2)
                          for (Index e : mesh.cell_edges(c)) o.put(id(nn + std::size_t(e)));
                      }
                    }});
  arrays.push_back({3, "Int64", "offsets", 1, 8 * nc, [=](AtomicFile& o) {
                      for (std::size_t k = 1; k <= nc; ++k) o.put(std::int64_t(k) * npc);
                    }});
  arrays.push_back({3, "UInt8", "types", 1, nc, [=](AtomicFile& o) {
                      for (std::size_t k = 0; k < nc; ++k) o.put(cell_type);
                    }});
  return arrays;
}

template <int D>
void write_vtu_to(AtomicFile& out, const Mesh<D>& mesh, std::span<const VtuField> fields, int order,
                  std::span<const Vec<D>> edge_midpoints, const VtuSelection& sel) {
  const std::vector<VtuArray> arrays = vtu_arrays(mesh, fields, order, edge_midpoints, sel);
  const std::size_t np = sel.n_points(mesh, order), nc = sel.n_cells(mesh);

  // --- XML header
  std::string xml;
  xml.reserve(4096);
  xml += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  xml += vtk_byte_order;
  xml += "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(np) +
         "\" NumberOfCells=\"" + std::to_string(nc) + "\">\n";
  std::uint64_t offset = 0;
  for (int s = 0; s < 4; ++s) {
    xml += std::string("      <") + vtu_sections[s] + ">\n";
    for (const VtuArray& a : arrays) {
      if (a.section != s) continue;
      xml += "        <DataArray type=\"" + std::string(a.type) + "\" Name=\"" + xml_escape(a.name) +
             "\" NumberOfComponents=\"" + std::to_string(a.components) + "\" format=\"appended\" offset=\"" +
             std::to_string(offset) + "\"/>\n";
      offset += sizeof(std::uint64_t) + a.bytes;
    }
    xml += std::string("      </") + vtu_sections[s] + ">\n";
  }
  xml += "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
  out.write(xml);

  // --- appended data, in the same order as the header
  for (int s = 0; s < 4; ++s)
    for (const VtuArray& a : arrays) {
      if (a.section != s) continue;
      out.put(std::uint64_t(a.bytes));
      [[maybe_unused]] const std::uint64_t start = out.position();
      a.emit(out);
      ALEFSI_ASSERT(out.position() - start == a.bytes);
    }
  out.write("\n  </AppendedData>\n</VTKFile>\n");
}

}  // namespace detail

/// Writes `mesh` and `fields` to the .vtu file `file` (atomically; see the file comment).
/// Throws InvalidArgument for bad input (before writing) and IoError if the file cannot be written.
template <int D>
void write_vtu(const std::filesystem::path& file, const Mesh<D>& mesh, std::span<const VtuField> fields,
               int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
  detail::check_vtu_input(mesh, fields, order, edge_midpoints.size());
  detail::AtomicFile out(file);
  detail::write_vtu_to(out, mesh, fields, order, edge_midpoints, detail::VtuSelection{});
  out.commit();
}

/// Overload for a braced list: `write_vtu(file, mesh, {{"p", 1, p}, {"u", 2, u}})`.
template <int D>
void write_vtu(const std::filesystem::path& file, const Mesh<D>& mesh, std::initializer_list<VtuField> fields,
               int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
  write_vtu(file, mesh, std::span<const VtuField>(fields.begin(), fields.size()), order, edge_midpoints);
}

/// A piece of a partitioned output: the cells `cells` of `mesh` (increasing indices) and the
/// points they use, written as write_vtu writes the whole mesh (the same arrays; fields hold
/// the whole mesh's values, and the piece takes those of its points and cells). The points
/// keep the mesh's order among themselves, so a point on the border of two pieces appears in
/// both. An empty `cells` writes an empty piece. Checks and atomicity as write_vtu.
template <int D>
void write_vtu_piece(const std::filesystem::path& file, const Mesh<D>& mesh, std::span<const Index> cells,
                     std::span<const VtuField> fields, int order = 1,
                     std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
  detail::check_vtu_input(mesh, fields, order, edge_midpoints.size());
  const detail::VtuSelection sel = detail::select_cells(mesh, cells, order);
  detail::AtomicFile out(file);
  detail::write_vtu_to(out, mesh, fields, order, edge_midpoints, sel);
  out.commit();
}

/// The parallel file (.pvtu) that shows the pieces `sources` (paths relative to the folder of
/// `file`, each written by write_vtu_piece with these `fields` and `order`) as one grid:
/// `<VTKFile type="PUnstructuredGrid">` naming every array with its type and components, then
/// one `<Piece Source=...>` per source, in order. The pieces are not opened. Atomic as write_vtu.
template <int D>
void write_pvtu(const std::filesystem::path& file, const Mesh<D>& mesh, std::span<const VtuField> fields,
                std::span<const std::string> sources, int order = 1) {
  detail::check_vtu_input(mesh, fields, order, 0);
  ALEFSI_CHECK_ARG(!sources.empty(), "sources", "a parallel file needs at least one piece");
  for (std::size_t i = 0; i < sources.size(); ++i)
    ALEFSI_CHECK_ARG(!sources[i].empty(), detail::concat("sources[", i, "]"), "is empty");
  detail::VtuSelection none;
  none.whole = false;  // (descriptions only: no bytes are written)
  const std::vector<detail::VtuArray> arrays = detail::vtu_arrays(mesh, fields, order, {}, none);
  std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"";
  xml += detail::vtk_byte_order;
  xml += "\" header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n";
  for (int s = 0; s < 3; ++s) {  // the cells' arrays are not declared in a parallel file
    xml += std::string("    <P") + detail::vtu_sections[s] + ">\n";
    for (const detail::VtuArray& a : arrays) {
      if (a.section != s) continue;
      xml += "      <PDataArray type=\"" + std::string(a.type) + "\"" +
             (s == 2 ? std::string() : " Name=\"" + detail::xml_escape(a.name) + "\"") +
             " NumberOfComponents=\"" + std::to_string(a.components) + "\"/>\n";
    }
    xml += std::string("    </P") + detail::vtu_sections[s] + ">\n";
  }
  for (const std::string& src : sources) xml += "    <Piece Source=\"" + detail::xml_escape(src) + "\"/>\n";
  xml += "  </PUnstructuredGrid>\n</VTKFile>\n";
  detail::AtomicFile out(file);
  out.write(xml);
  out.commit();
}

/// This process's share of a partitioned output (PvdWriter::write with a piece): its cells
/// (increasing), its part among `parts`, and `all`, a collective call that returns whether its
/// argument is true on every process (under MPI: an allreduce of AND).
struct VtuPiece {
  std::span<const Index> cells;
  int part = 0, parts = 1;
  std::function<bool(bool)> all;
};

/// A time series for ParaView: the collection file `run.pvd` and one `run/run_NNNNNN.vtu` per
/// step in the sibling folder named after the collection's stem (created by the constructor);
/// in pieces (write with a VtuPiece), `run/run_NNNNNN.pvtu` and its pieces
/// `run/run_NNNNNN_pPPPP.vtu` instead.
/// After every step the collection is rewritten atomically, so it always lists exactly the
/// completed steps (a crashed run leaves a readable series). Times must increase strictly.
/// Starting a series replaces an existing collection of that name at the first step; stale
/// .vtu files of an earlier, longer run stay in the folder but are not listed.
class PvdWriter {
 public:
  explicit PvdWriter(std::filesystem::path pvd_file) : pvd_(std::move(pvd_file)) {
    stem_ = pvd_.stem().string();
    ALEFSI_CHECK_ARG(!pvd_.filename().empty() && !stem_.empty() && stem_ != "." && stem_ != "..",
                     "pvd_file", "'", pvd_.string(), "' does not name a file");
    dir_ = pvd_.parent_path() / stem_;
    std::error_code ec;  // (processes of a parallel run may create it at the same time)
    std::filesystem::create_directories(dir_, ec);
    if (!std::filesystem::is_directory(dir_))
      throw IoError("cannot create directory '" + dir_.string() + "' for the steps of '" + pvd_.string() +
                    "': " + (ec ? ec.message() : std::string("not a directory")));
  }

  /// Writes step `steps()` at `time` (see write_vtu for the other arguments) and rewrites the
  /// collection; returns the path of the new .vtu. On an exception the series is unchanged.
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::span<const VtuField> fields, int order = 1,
                              std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    check_time(time);
    const std::string name = step_name() + ".vtu";
    const std::filesystem::path vtu = dir_ / name;
    write_vtu(vtu, mesh, fields, order, edge_midpoints);
    list(time, name, [&] { write_collection(); });
    return vtu;
  }
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::initializer_list<VtuField> fields,
                              int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    return write(time, mesh, std::span<const VtuField>(fields.begin(), fields.size()), order, edge_midpoints);
  }

  /// One step of a run whose processes each hold a part of the cells (MPI): every process calls
  /// it with the same arguments except `piece`. Each writes its cells to
  /// `<stem>/<stem>_NNNNNN_pPPPP.vtu` (write_vtu_piece); once every piece is written, part 0
  /// writes `<stem>/<stem>_NNNNNN.pvtu` (write_pvtu) and lists it in the collection. A failure on
  /// any process throws on every process (IoError on those that did not fail) and leaves the
  /// series as it was; the pieces of a step that failed may remain, unlisted. Returns the .pvtu.
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::span<const VtuField> fields, const VtuPiece& piece,
                              int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    ALEFSI_CHECK_ARG(piece.parts >= 1 && piece.part >= 0 && piece.part < piece.parts, "piece",
                     "part ", piece.part, " of ", piece.parts, " parts");
    ALEFSI_CHECK_ARG(piece.all != nullptr, "piece.all", "the collective test is empty");
    check_time(time);
    const std::string step = step_name();
    auto source = [&](int k) { return step + "_p" + detail::zero_padded(k, 4) + ".vtu"; };
    // every process reaches each agreement, whatever failed before it
    const std::string elsewhere = "step " + std::to_string(steps_.size()) + " of '" + pvd_.string() + "': ";
    detail::together(
        [&] { write_vtu_piece(dir_ / source(piece.part), mesh, piece.cells, fields, order, edge_midpoints); },
        piece.all, elsewhere + "another process could not write its piece");
    const std::filesystem::path pvtu = dir_ / (step + ".pvtu");
    list(time, step + ".pvtu", [&] {
      detail::together(
          [&] {
            if (piece.part != 0) return;
            std::vector<std::string> sources;
            for (int k = 0; k < piece.parts; ++k) {
              sources.push_back(source(k));
              if (!std::filesystem::is_regular_file(dir_ / sources.back()))  // another folder, or one not shared
                throw IoError(elsewhere + "the piece of part " + std::to_string(k) + " is not in '" + dir_.string() +
                              "': every process needs the same output folder, visible to part 0");
            }
            write_pvtu(pvtu, mesh, fields, sources, order);
            write_collection();
          },
          piece.all, elsewhere + "part 0 could not write the step's parallel file or the collection");
    });
    return pvtu;
  }
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::initializer_list<VtuField> fields,
                              const VtuPiece& piece, int order = 1,
                              std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    return write(time, mesh, std::span<const VtuField>(fields.begin(), fields.size()), piece, order, edge_midpoints);
  }

  const std::filesystem::path& pvd_file() const { return pvd_; }
  /// The folder holding the steps' files (.vtu; in pieces .pvtu and the pieces).
  const std::filesystem::path& directory() const { return dir_; }
  /// Number of steps written (and listed in the collection).
  std::size_t steps() const { return steps_.size(); }

 private:
  struct Step {
    Real time;
    std::string file;  // relative to the collection's folder, '/'-separated
  };

  void check_time(Real time) const {
    ALEFSI_CHECK_ARG(std::isfinite(time), "time", "must be finite, got ", time);
    if (!steps_.empty())
      ALEFSI_CHECK_ARG(time > steps_.back().time, "time", "must exceed the previous step's time ",
                       detail::format_real(steps_.back().time), ", got ", detail::format_real(time));
  }
  /// Lists step `file` (in the steps' folder) at `time` and runs `write`, which writes the
  /// collection; if it throws, the step is not listed.
  template <class Write>
  void list(Real time, const std::string& file, const Write& write) {
    steps_.push_back({time, (std::filesystem::path(stem_) / file).generic_string()});
    try {
      write();
    } catch (...) {
      steps_.pop_back();
      throw;
    }
  }
  /// "<stem>_NNNNNN" for the next step.
  std::string step_name() const { return stem_ + "_" + detail::zero_padded(long(steps_.size()), 6); }

  void write_collection() const {
    std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"";
    xml += detail::vtk_byte_order;
    xml += "\">\n  <Collection>\n";
    for (const Step& s : steps_)
      xml += "    <DataSet timestep=\"" + detail::format_real(s.time) + "\" group=\"\" part=\"0\" file=\"" +
             detail::xml_escape(s.file) + "\"/>\n";
    xml += "  </Collection>\n</VTKFile>\n";
    detail::AtomicFile out(pvd_);
    out.write(xml);
    out.commit();
  }

  std::filesystem::path pvd_, dir_;
  std::string stem_;
  std::vector<Step> steps_;
};

}  // namespace alefsi
