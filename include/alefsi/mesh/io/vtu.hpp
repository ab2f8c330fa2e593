#pragma once
/// \file mesh/io/vtu.hpp
/// VTK XML unstructured-grid (.vtu) and time-series collection (.pvd) writers, for ParaView.
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
/// Atomicity: every file (.vtu and .pvd) is written to a hidden temporary in the target's
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

/// One array of the appended block: its XML description and a function writing its bytes.
struct VtuArray {
  int section;  // 0 PointData, 1 CellData, 2 Points, 3 Cells
  const char* type;
  std::string name;
  int components;
  std::uint64_t bytes;
  std::function<void(AtomicFile&)> emit;
};

template <int D>
void write_vtu_to(AtomicFile& out, const Mesh<D>& mesh, std::span<const VtuField> fields, int order,
                  std::span<const Vec<D>> edge_midpoints) {
  const std::size_t nn = std::size_t(mesh.n_nodes()), ne = std::size_t(mesh.n_edges()),
                    nc = std::size_t(mesh.n_cells());
  const std::size_t np = order == 2 ? nn + ne : nn;
  const int npc = order == 2 ? D + 1 + simplex_edges<D> : D + 1;
  const std::uint8_t cell_type = D == 2 ? (order == 2 ? 22 : 5) : (order == 2 ? 24 : 10);

  std::vector<VtuArray> arrays;
  // --- point data
  for (const VtuField& f : fields) {
    if (f.location != FieldLocation::point) continue;
    const std::size_t c = std::size_t(f.components);
    const std::size_t cw = std::size_t(vtk_components<D>(f.components));
    const bool p2 = f.values.size() == c * (nn + ne);
    const std::span<const Real> v = f.values;
    arrays.push_back({0, "Float64", f.name, int(cw), 8 * cw * np, [=, &mesh](AtomicFile& o) {
                        auto tuples = [&](std::size_t first, std::size_t count) {
                          if (cw == c) return o.write(v.data() + first * c, count * c * sizeof(Real));
                          for (std::size_t i = first; i < first + count; ++i) {
                            for (std::size_t k = 0; k < c; ++k) o.put(v[i * c + k]);
                            for (std::size_t k = c; k < cw; ++k) o.put(Real(0));
                          }
                        };
                        tuples(0, nn);
                        if (order == 1) return;
                        if (p2) return tuples(nn, ne);
                        for (std::size_t e = 0; e < ne; ++e) {
                          const auto [a, b] = mesh.edge(Index(e));
                          for (std::size_t k = 0; k < c; ++k)
                            o.put(Real(0.5) * (v[std::size_t(a) * c + k] + v[std::size_t(b) * c + k]));
                          for (std::size_t k = c; k < cw; ++k) o.put(Real(0));
                        }
                      }});
  }
  // --- cell data
  arrays.push_back({1, "Int32", "region", 1, 4 * nc, [&mesh](AtomicFile& o) {
                      for (int t : mesh.cell_tags()) o.put(std::int32_t(t));
                    }});
  for (const VtuField& f : fields) {
    if (f.location != FieldLocation::cell) continue;
    const std::size_t c = std::size_t(f.components);
    const std::size_t cw = std::size_t(vtk_components<D>(f.components));
    const std::span<const Real> v = f.values;
    arrays.push_back({1, "Float64", f.name, int(cw), 8 * cw * nc, [=](AtomicFile& o) {
                        if (cw == c) return o.write(v.data(), v.size() * sizeof(Real));
                        for (std::size_t i = 0; i < nc; ++i) {
                          for (std::size_t k = 0; k < c; ++k) o.put(v[i * c + k]);
                          for (std::size_t k = c; k < cw; ++k) o.put(Real(0));
                        }
                      }});
  }
  // --- points
  arrays.push_back({2, "Float64", "Points", 3, 24 * np, [&, order](AtomicFile& o) {
                      auto point = [&](const Vec<D>& x) {
                        o.put(x[0]), o.put(x[1]), o.put(D == 3 ? x[D - 1] : Real(0));
                      };
                      for (const auto& x : mesh.coordinates()) point(x);
                      if (order == 1) return;
                      if (!edge_midpoints.empty()) {
                        for (const auto& x : edge_midpoints) point(x);
                      } else {
                        for (const auto& [a, b] : mesh.edges()) point(Real(0.5) * (mesh.node(a) + mesh.node(b)));
                      }
                    }});
  // --- cells
  arrays.push_back({3, "Int64", "connectivity", 1, 8 * nc * std::size_t(npc), [&, order](AtomicFile& o) {
                      for (Index c = 0; c < Index(nc); ++c) {
                        for (Index v : mesh.cell(c)) o.put(std::int64_t(v));
                        if (order == 2)
                          for (Index e : mesh.cell_edges(c)) o.put(std::int64_t(nn) + e);
                      }
                    }});
  arrays.push_back({3, "Int64", "offsets", 1, 8 * nc, [=](AtomicFile& o) {
                      for (std::size_t c = 1; c <= nc; ++c) o.put(std::int64_t(c) * npc);
                    }});
  arrays.push_back({3, "UInt8", "types", 1, nc, [=](AtomicFile& o) {
                      for (std::size_t c = 0; c < nc; ++c) o.put(cell_type);
                    }});

  // --- XML header
  static constexpr std::array<const char*, 4> sections{"PointData", "CellData", "Points", "Cells"};
  std::string xml;
  xml.reserve(4096);
  xml += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  xml += vtk_byte_order;
  xml += "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(np) +
         "\" NumberOfCells=\"" + std::to_string(nc) + "\">\n";
  std::uint64_t offset = 0;
  for (int s = 0; s < 4; ++s) {
    xml += std::string("      <") + sections[s] + ">\n";
    for (const VtuArray& a : arrays) {
      if (a.section != s) continue;
      xml += "        <DataArray type=\"" + std::string(a.type) + "\" Name=\"" + xml_escape(a.name) +
             "\" NumberOfComponents=\"" + std::to_string(a.components) + "\" format=\"appended\" offset=\"" +
             std::to_string(offset) + "\"/>\n";
      offset += sizeof(std::uint64_t) + a.bytes;
    }
    xml += std::string("      </") + sections[s] + ">\n";
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
  detail::write_vtu_to(out, mesh, fields, order, edge_midpoints);
  out.commit();
}

/// Overload for a braced list: `write_vtu(file, mesh, {{"p", 1, p}, {"u", 2, u}})`.
template <int D>
void write_vtu(const std::filesystem::path& file, const Mesh<D>& mesh, std::initializer_list<VtuField> fields,
               int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
  write_vtu(file, mesh, std::span<const VtuField>(fields.begin(), fields.size()), order, edge_midpoints);
}

/// A time series for ParaView: the collection file `run.pvd` and one `run/run_NNNNNN.vtu` per
/// step in the sibling folder named after the collection's stem (created by the constructor).
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
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec || !std::filesystem::is_directory(dir_))
      throw IoError("cannot create directory '" + dir_.string() + "' for the steps of '" + pvd_.string() +
                    "': " + (ec ? ec.message() : std::string("not a directory")));
  }

  /// Writes step `steps()` at `time` (see write_vtu for the other arguments) and rewrites the
  /// collection; returns the path of the new .vtu. On an exception the series is unchanged.
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::span<const VtuField> fields, int order = 1,
                              std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    ALEFSI_CHECK_ARG(std::isfinite(time), "time", "must be finite, got ", time);
    if (!steps_.empty())
      ALEFSI_CHECK_ARG(time > steps_.back().time, "time", "must exceed the previous step's time ",
                       detail::format_real(steps_.back().time), ", got ", detail::format_real(time));
    std::string name = std::to_string(steps_.size());
    if (name.size() < 6) name.insert(0, 6 - name.size(), '0');
    name = stem_ + "_" + name + ".vtu";
    const std::filesystem::path vtu = dir_ / name;
    write_vtu(vtu, mesh, fields, order, edge_midpoints);
    steps_.push_back({time, (std::filesystem::path(stem_) / name).generic_string()});
    try {
      write_collection();
    } catch (...) {
      steps_.pop_back();
      throw;
    }
    return vtu;
  }
  template <int D>
  std::filesystem::path write(Real time, const Mesh<D>& mesh, std::initializer_list<VtuField> fields,
                              int order = 1, std::span<const std::type_identity_t<Vec<D>>> edge_midpoints = {}) {
    return write(time, mesh, std::span<const VtuField>(fields.begin(), fields.size()), order, edge_midpoints);
  }

  const std::filesystem::path& pvd_file() const { return pvd_; }
  /// The folder holding the steps' .vtu files.
  const std::filesystem::path& directory() const { return dir_; }
  /// Number of steps written (and listed in the collection).
  std::size_t steps() const { return steps_.size(); }

 private:
  struct Step {
    Real time;
    std::string file;  // relative to the collection's folder, '/'-separated
  };

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
