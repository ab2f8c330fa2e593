#pragma once
/// \file sim/checkpoint.hpp
/// Binary checkpoint files: the exact state of a run, so that a restart continues bit for bit,
/// and a file that is not exactly what was written is refused.
///
/// Format (version 7; host byte order, doubles bit for bit): the 8-byte magic "ALEFSICK", a
/// uint32 version, then named sections, each
///     uint32 name length | name | uint64 payload length | payload | uint32 CRC-32 of name + payload
/// with the payload a sequence of scalars and length-prefixed (uint64) arrays; the last section
/// is "end". The reader checks, when it opens the file, the magic, the version and every
/// section's length and checksum, then each section's name as it is read; it refuses, as
/// `IoError` naming the file, a truncated file (the section and the bytes missing), a
/// corrupted one (the section whose checksum fails, with its byte range), a foreign one, and a
/// length field larger than the file (no allocation is attempted). What
/// a section holds is the caller's: AleFlow writes its configuration (dimension, element pair,
/// scheme, equations, body model, bodies) and refuses a file written by another one, naming
/// what differs.
///
/// Writing is atomic (a temporary renamed over the target, as the VTU writer) and, with
/// `commit(keep_previous = true)`, the file it replaces is kept as `<name>.prev` (renamed
/// first): a crash at any point leaves a complete checkpoint, the new one or the previous.
///
///     CheckpointWriter w("run/checkpoint.bin");  w.section("time");  w.put(t);  w.commit();
///     CheckpointReader r("run/checkpoint.bin");  r.section("time");  Real t = r.get<Real>();
#include <array>
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
/// 2: the step-size history replaces the last dt; 3: section lengths and checksums, the
/// configuration section, the time counter; 4: four solution levels (the error estimate of
/// BDF3 reads n-3), the step-size controller's memory, the "solver" section (the matrices whose
/// analysis and factorisation a reused solve preconditions with); 5: the same for the
/// mesh-velocity (elasticity) solver, section "mesh-velocity solver"; 6: section "curved", the
/// curved boundaries' tags and their edge points' frame coefficients.
inline constexpr std::uint32_t checkpoint_version = 7;

namespace detail {
/// CRC-32 (IEEE 802.3, as zlib and PNG), updated with `n` bytes.
inline std::uint32_t crc32(std::uint32_t crc, const void* data, std::size_t n) {
  static constexpr auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ p[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}
}  // namespace detail

class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::filesystem::path file) : f_(std::move(file)) {
    f_.write(std::string_view(checkpoint_magic, 8));
    f_.put(checkpoint_version);
  }
  /// Starts a section (the previous one is written out with its checksum).
  void section(std::string_view name) {
    flush_section();
    name_ = name;
    open_ = true;
  }
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(&v, sizeof(T));
  }
  void put_string(std::string_view s) {
    put(std::uint32_t(s.size()));
    append(s.data(), s.size());
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(std::uint64_t(v.size()));
    append(v.data(), v.size() * sizeof(T));
  }
  void put_vector(const VecX& v) {
    put(std::uint64_t(v.size()));
    append(v.data(), std::size_t(v.size()) * sizeof(Real));
  }
  /// Writes the last section and the "end" section, and renames the finished file over the
  /// target; with `keep_previous`, an existing target is first renamed to `<target>.prev`.
  void commit(bool keep_previous = false) {
    section("end");
    flush_section();
    if (keep_previous) {
      const auto& target = f_.target();
      std::error_code ec;
      if (std::filesystem::exists(target, ec)) {
        std::filesystem::rename(target, previous_path(target), ec);
        if (ec) throw IoError("checkpoint '" + target.string() + "': cannot keep the previous one: " + ec.message());
      }
    }
    f_.commit();
  }
  /// Where `commit(true)` keeps the checkpoint it replaces.
  static std::filesystem::path previous_path(const std::filesystem::path& file) {
    return file.parent_path() / (file.filename().string() + ".prev");
  }

 private:
  void append(const void* data, std::size_t n) {
    if (!open_) throw Error("CheckpointWriter: data written before the first section");
    const auto* p = static_cast<const char*>(data);
    payload_.insert(payload_.end(), p, p + n);
  }
  void flush_section() {
    if (!open_) return;
    f_.put(std::uint32_t(name_.size()));
    f_.write(name_);
    f_.put(std::uint64_t(payload_.size()));
    f_.write(payload_.data(), payload_.size());
    std::uint32_t crc = detail::crc32(0, name_.data(), name_.size());
    crc = detail::crc32(crc, payload_.data(), payload_.size());
    f_.put(crc);
    payload_.clear();
    open_ = false;
  }

  detail::AtomicFile f_;
  std::string name_;
  std::vector<char> payload_;
  bool open_ = false;
};

class CheckpointReader {
 public:
  explicit CheckpointReader(const std::filesystem::path& file) : CheckpointReader(file, read_file(file)) {}
  /// A checkpoint held in memory (`bytes`, as a file would hold them); `name` names it in errors.
  CheckpointReader(std::filesystem::path name, std::vector<char> bytes) : file_(std::move(name)), data_(std::move(bytes)) {
    if (data_.size() < 8 || std::memcmp(data_.data(), checkpoint_magic, 8) != 0)
      throw IoError("checkpoint '" + file_.string() + "': not an alefsi checkpoint (bad magic)");
    pos_ = 8;
    end_ = data_.size();
    std::uint32_t v = 0;
    take(&v, sizeof v, "version");
    if (v != checkpoint_version)
      throw IoError("checkpoint '" + file_.string() + "': version " + std::to_string(v) + ", this build reads " +
                    std::to_string(checkpoint_version));
    end_ = next_ = pos_;
    verify();
  }
  const std::filesystem::path& file() const { return file_; }

  /// Reads the next section's header, checks its name, its length and its checksum, and makes
  /// its payload the one the get functions read. The previous section must have been read to
  /// its end.
  void section(std::string_view name) {
    if (pos_ != end_)
      fail("section '" + section_ + "' has " + std::to_string(end_ - pos_) + " unread bytes");
    pos_ = next_;
    end_ = data_.size();
    const std::size_t start = pos_;
    std::uint32_t n = 0;
    take(&n, sizeof n, "section name length");
    if (n > 256 || n > end_ - pos_) fail("bad section header at byte " + std::to_string(start));
    const std::string got(data_.data() + pos_, n);
    pos_ += n;
    std::uint64_t len = 0;
    take(&len, sizeof len, "length of section '" + got + "'");
    if (len > end_ - pos_ || end_ - pos_ - len < sizeof(std::uint32_t))
      throw IoError("checkpoint '" + file_.string() + "': truncated in section '" + got + "' (it claims " +
                    std::to_string(len) + " bytes, " + std::to_string(end_ - pos_) + " are left)");
    const std::size_t payload = pos_;
    std::uint32_t stored = 0;
    std::memcpy(&stored, data_.data() + payload + len, sizeof stored);
    std::uint32_t crc = detail::crc32(0, got.data(), got.size());
    crc = detail::crc32(crc, data_.data() + payload, std::size_t(len));
    if (crc != stored)
      fail("section '" + got + "' (bytes " + std::to_string(start) + " to " + std::to_string(payload + len + 4) +
           ") fails its checksum: the file is corrupted");
    if (got != name)
      fail("expected section '" + std::string(name) + "' at byte " + std::to_string(start) + ", found '" + got + "'");
    section_ = got;
    pos_ = payload;
    end_ = payload + std::size_t(len);
    next_ = end_ + sizeof(std::uint32_t);
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
    if (n > end_ - pos_) truncated(what);
    std::string s(n, '\0');
    take(s.data(), n, what);
    return s;
  }
  template <class T>
  std::vector<T> get_vector(std::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint64_t>(what);
    if (n > (end_ - pos_) / sizeof(T)) truncated(what);
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
  /// Reads the "end" section; throws unless the whole file was read.
  void finish() {
    section("end");
    if (next_ != data_.size())
      fail(std::to_string(data_.size() - next_) + " unexpected bytes after the last section");
  }
  [[noreturn]] void fail(const std::string& why) const { throw IoError("checkpoint '" + file_.string() + "': " + why); }

 private:
  static std::vector<char> read_file(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw IoError("checkpoint '" + file.string() + "': cannot open");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  // Every section's length and checksum, up to "end" and the end of the file: a file that is
  // not exactly what was written is refused before anything is read from it.
  void verify() const {
    std::size_t p = pos_;
    const std::size_t n = data_.size();
    for (;;) {
      const std::size_t start = p;
      std::uint32_t len_name = 0;
      std::uint64_t len = 0;
      if (n - p < sizeof len_name) fail("truncated at byte " + std::to_string(p) + " (a section header expected)");
      std::memcpy(&len_name, data_.data() + p, sizeof len_name);
      p += sizeof len_name;
      if (len_name > 256 || n - p < len_name + sizeof len)
        fail("truncated or corrupted at byte " + std::to_string(start) + " (a section header expected)");
      const std::string name(data_.data() + p, len_name);
      p += len_name;
      std::memcpy(&len, data_.data() + p, sizeof len);
      p += sizeof len;
      if (len > n - p || n - p - len < sizeof(std::uint32_t))
        fail("truncated in section '" + name + "' (it claims " + std::to_string(len) + " bytes, " + std::to_string(n - p) +
             " are left)");
      std::uint32_t stored = 0;
      std::memcpy(&stored, data_.data() + p + len, sizeof stored);
      std::uint32_t crc = detail::crc32(0, name.data(), name.size());
      crc = detail::crc32(crc, data_.data() + p, std::size_t(len));
      if (crc != stored)
        fail("section '" + name + "' (bytes " + std::to_string(start) + " to " + std::to_string(p + len + 4) +
             ") fails its checksum: the file is corrupted");
      p += std::size_t(len) + sizeof stored;
      if (name == "end") break;
    }
    if (p != n) fail(std::to_string(n - p) + " unexpected bytes after the last section");
  }
  void take(void* out, std::size_t bytes, std::string_view what) {
    if (bytes > end_ - pos_) truncated(what);
    if (bytes) std::memcpy(out, data_.data() + pos_, bytes);
    pos_ += bytes;
  }
  [[noreturn]] void truncated(std::string_view what) const {
    throw IoError("checkpoint '" + file_.string() + "': truncated at byte " + std::to_string(pos_) + " while reading " +
                  std::string(what) + (section_.empty() ? std::string() : " (section '" + section_ + "')"));
  }

  std::filesystem::path file_;
  std::vector<char> data_;
  std::size_t pos_ = 0, end_ = 0, next_ = 0;
  std::string section_;
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
  for (Index f : m.tagged_interior_facets()) facets.push_back(m.facet(f)), tags.push_back(m.facet_tag(f));
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
