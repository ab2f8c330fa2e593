#pragma once
/// \file sim/checkpoint.hpp
/// Binary checkpoint files: the exact state of a run, so that a restart continues bit for bit.
///
/// Format (host byte order, doubles bit for bit): the 8-byte magic "ALEFSICK", a uint32
/// version, then named sections, each a uint32 length + name followed by its payload of
/// scalars and length-prefixed (uint64) arrays. A reader checks the magic, the version and
/// every section name, and reports a truncated or foreign file as `IoError` naming the file,
/// the byte offset and what it was reading. Writing is atomic (temporary + rename, as the
/// VTU writer): a crash while writing leaves the previous checkpoint intact.
///
///     CheckpointWriter w("run/checkpoint.bin");  w.section("time");  w.put(t);  w.commit();
///     CheckpointReader r("run/checkpoint.bin");  r.section("time");  Real t = r.get<Real>();
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/io/vtu.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

inline constexpr char checkpoint_magic[9] = "ALEFSICK";
inline constexpr std::uint32_t checkpoint_version = 2;  // 2: the step-size history replaces the last dt

class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::filesystem::path file) : f_(std::move(file)) {
    f_.write(std::string_view(checkpoint_magic, 8));
    f_.put(checkpoint_version);
  }
  void section(std::string_view name) { put_string(name); }
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    f_.put(v);
  }
  void put_string(std::string_view s) {
    f_.put(std::uint32_t(s.size()));
    f_.write(s);
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    f_.put(std::uint64_t(v.size()));
    f_.write(v.data(), v.size() * sizeof(T));
  }
  void put_vector(const VecX& v) {
    f_.put(std::uint64_t(v.size()));
    f_.write(v.data(), std::size_t(v.size()) * sizeof(Real));
  }
  /// Renames the finished file over the target.
  void commit() { f_.commit(); }

 private:
  detail::AtomicFile f_;
};

class CheckpointReader {
 public:
  explicit CheckpointReader(std::filesystem::path file) : file_(std::move(file)) {
    std::ifstream in(file_, std::ios::binary);
    if (!in) throw IoError("checkpoint '" + file_.string() + "': cannot open");
    data_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (data_.size() < 8 || std::memcmp(data_.data(), checkpoint_magic, 8) != 0)
      throw IoError("checkpoint '" + file_.string() + "': not an alefsi checkpoint (bad magic)");
    pos_ = 8;
    const auto v = get<std::uint32_t>("version");
    if (v != checkpoint_version)
      throw IoError("checkpoint '" + file_.string() + "': version " + std::to_string(v) + ", this build reads " +
                    std::to_string(checkpoint_version));
  }
  const std::filesystem::path& file() const { return file_; }

  /// Reads a section header and checks its name.
  void section(std::string_view name) {
    const std::string got = get_string("section name");
    if (got != name)
      throw IoError("checkpoint '" + file_.string() + "': expected section '" + std::string(name) + "' at byte " +
                    std::to_string(pos_) + ", found '" + got + "'");
  }
  template <class T>
  T get(std::string_view what = "value") {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    take(&v, sizeof(T), what);
    return v;
  }
  std::string get_string(std::string_view what) {
    const auto n = get<std::uint32_t>(what);
    std::string s(n, '\0');
    take(s.data(), n, what);
    return s;
  }
  template <class T>
  std::vector<T> get_vector(std::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint64_t>(what);
    if (n > (data_.size() - pos_) / sizeof(T)) truncated(what);
    std::vector<T> v(n);
    take(v.data(), n * sizeof(T), what);
    return v;
  }
  VecX get_vecx(std::string_view what) {
    const auto v = get_vector<Real>(what);
    VecX out(Index(v.size()));
    std::copy(v.begin(), v.end(), out.data());
    return out;
  }
  /// Throws unless the whole file was read.
  void finish() const {
    if (pos_ != data_.size())
      throw IoError("checkpoint '" + file_.string() + "': " + std::to_string(data_.size() - pos_) +
                    " unexpected bytes after the last section");
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw IoError("checkpoint '" + file_.string() + "': " + why);
  }

 private:
  void take(void* out, std::size_t bytes, std::string_view what) {
    if (bytes > data_.size() - pos_) truncated(what);
    if (bytes) std::memcpy(out, data_.data() + pos_, bytes);
    pos_ += bytes;
  }
  [[noreturn]] void truncated(std::string_view what) const {
    throw IoError("checkpoint '" + file_.string() + "': truncated at byte " + std::to_string(pos_) + " while reading " +
                  std::string(what));
  }

  std::filesystem::path file_;
  std::vector<char> data_;
  std::size_t pos_ = 0;
};

/// Writes section "mesh": node coordinates, cells, cell tags, tagged boundary facets.
template <int D>
void write_mesh(CheckpointWriter& w, const Mesh<D>& m) {
  w.section("mesh");
  std::vector<Real> x(D * std::size_t(m.n_nodes()));
  for (Index i = 0; i < m.n_nodes(); ++i)
    for (int c = 0; c < D; ++c) x[D * std::size_t(i) + c] = m.node(i)[c];
  w.put_vector(x);
  w.put_vector(m.cells());
  w.put_vector(m.cell_tags());
  std::vector<typename Mesh<D>::Facet> facets;
  std::vector<int> tags;
  for (Index f : m.boundary_facets()) facets.push_back(m.facet(f)), tags.push_back(m.facet_tag(f));
  w.put_vector(facets);
  w.put_vector(tags);
}

/// Reads what write_mesh wrote; an invalid mesh is an IoError naming the file.
template <int D>
Mesh<D> read_mesh(CheckpointReader& r) {
  r.section("mesh");
  const auto x = r.get_vector<Real>("node coordinates");
  std::vector<Vec<D>> nodes(x.size() / D);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (int c = 0; c < D; ++c) nodes[i][c] = x[D * i + c];
  auto cells = r.get_vector<typename Mesh<D>::Cell>("cells");
  auto cell_tags = r.get_vector<int>("cell tags");
  const auto facets = r.get_vector<typename Mesh<D>::Facet>("boundary facets");
  const auto tags = r.get_vector<int>("boundary tags");
  try {
    return Mesh<D>(std::move(nodes), std::move(cells), facets, tags, std::move(cell_tags));
  } catch (const MeshError& e) {
    r.fail(std::string("invalid mesh: ") + e.what());
  }
}

}  // namespace alefsi
