#pragma once
/// \file mesh/io/gmsh.hpp
/// Reader for gmsh `.msh` files: MSH 4.1 (ASCII and binary) and MSH 2.2 (ASCII).
///
/// `read_gmsh<D>` turns the triangles (D = 2) or tetrahedra (D = 3) of a gmsh mesh into a
/// validated `Mesh<D>`:
///   - cells: element types 2 / 9 (triangle, triangle6) in 2D, 4 / 11 (tet, tet10) in 3D;
///     the physical tag of each cell becomes its cell tag (`Mesh::cell_tag`);
///   - boundary: elements of dimension D-1 (lines 1 / 8 in 2D, triangles 2 / 9 in 3D) become
///     tagged boundary facets carrying their physical tag (`Mesh::facet_tag`);
///   - points, and lines in 3D, are ignored; any other element type is an error.
/// Every cell and every (D-1)-element must belong to a physical group (in the .geo:
/// `Physical Surface` / `Physical Volume` for the cells, `Physical Curve` / `Physical Surface`
/// for the facets). Physical tags come from `$Entities` (or `$PartitionedEntities`) in MSH 4.1
/// and from the first element tag in MSH 2.2. `physical_names` maps the tags of the D- and
/// (D-1)-dimensional physical groups to their names from `$PhysicalNames`.
///   - An element in several groups (MSH 4.1: its entity lists several tags; MSH 2.2: the
///     element is written once per group) gets its first group as its tag; `cell_groups` and
///     `facet_groups` list every group's elements. A negative tag in `$Entities` is the group
///     |tag| (the entity with reversed orientation). A repeat with a tag the element already
///     has is an error.
///   - (D-1)-elements inside the domain (embedded curves / surfaces) are tagged interior facets.
///   - Partitioned MSH 4.1 files are read whole; `cell_partitions` gives each cell's partition.
///     Elements of ghost entities and of partition interfaces (entities whose parent model
///     entity is D-dimensional) are skipped.
///
/// Conventions:
///   - Nodes no cell uses as a vertex (gmsh writes geometry points, mid nodes, ...) are dropped;
///     the others are renumbered compactly in file order. Node tags may be sparse.
///   - Orientation: cells gmsh writes with negative orientation are reoriented by swapping
///     local vertices 1 and 2 (their mid nodes are permuted accordingly). Degenerate cells are
///     left to the Mesh constructor, which throws MeshError naming the cell. MeshError indices
///     count D-cells (for cells) and (D-1)-elements (for facets) in file order, from 0.
///   - Second-order files (triangle6 / tet10): gmsh's mid node k of a cell lies on the edge
///     (a_k, b_k) of its local vertices, with (0,1) (1,2) (2,0) for triangles and
///     (0,1) (1,2) (2,0) (3,0) (3,2) (3,1) for tetrahedra (gmsh MTetrahedron::edges_tetra; the
///     last two differ from our VTK order in simplex.hpp). `edge_midpoints[e]` holds the mid
///     node coordinates of mesh edge e; on curved boundaries gmsh puts them on the curve.
///   - In 2D every node must have z = 0 (up to 1e-12 relative): the mesh must lie in the plane.
///
/// Errors: a malformed file throws ParseError(file, line, message) with the 1-based line of the
/// offending line (inside a binary block: the line where that block starts; line 0 when the
/// file cannot be opened). An invalid mesh (degenerate cell, a tagged (D-1)-element that is
/// not a facet of the cells, ...) throws the Mesh constructor's MeshError (entity and index as it
/// gives them), its message led by the file and the line of the offending element.
///
///     auto g = alefsi::read_gmsh<2>("channel.msh");   // gmsh -2 channel.geo -format msh41
///     const alefsi::Mesh<2>& mesh = g.mesh;
///     for (auto& [tag, name] : g.physical_names) std::cout << tag << ' ' << name << '\n';
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/mesh/simplex.hpp"

namespace alefsi {

/// A mesh read from a gmsh file, with its physical names and second-order mid nodes.
template <int D>
struct GmshMesh {
  Mesh<D> mesh;
  /// Physical tag -> name from $PhysicalNames (groups of dimension D and D-1; may be empty).
  std::map<int, std::string> physical_names;
  /// For second-order files (triangle6 / tet10): coordinates of each mesh edge's mid node,
  /// indexed by mesh edge index (mesh.edge(e)); empty for first-order files.
  std::vector<Vec<D>> edge_midpoints;
  /// Physical group of dimension D -> its cells (sorted indices). A cell in several groups is
  /// in each; its `mesh.cell_tag` is the first (in MSH 4.1 the first its entity lists, in MSH
  /// 2.2 its first copy in the file).
  std::map<int, std::vector<Index>> cell_groups;
  /// Physical group of dimension D-1 -> its facets (sorted mesh facet indices), boundary or
  /// interior; `mesh.facet_tag` is the first group of a facet in several.
  std::map<int, std::vector<Index>> facet_groups;
  /// Partitioned MSH 4.1 files ($PartitionedEntities): the number of partitions and each
  /// cell's partition (1-based, as gmsh numbers them); 0 and empty otherwise.
  int n_partitions = 0;
  std::vector<int> cell_partitions;
};

namespace detail {

/// What gmsh element type `type` is: dimension, number of nodes, polynomial order, name.
struct GmshElementType {
  int dim;
  int nodes;
  int order;
  const char* name;
};

inline std::optional<GmshElementType> gmsh_element_type(int type) {
  switch (type) {
    case 1: return GmshElementType{1, 2, 1, "2-node line"};
    case 2: return GmshElementType{2, 3, 1, "3-node triangle"};
    case 3: return GmshElementType{2, 4, 1, "4-node quadrangle"};
    case 4: return GmshElementType{3, 4, 1, "4-node tetrahedron"};
    case 5: return GmshElementType{3, 8, 1, "8-node hexahedron"};
    case 6: return GmshElementType{3, 6, 1, "6-node prism"};
    case 7: return GmshElementType{3, 5, 1, "5-node pyramid"};
    case 8: return GmshElementType{1, 3, 2, "3-node second-order line"};
    case 9: return GmshElementType{2, 6, 2, "6-node second-order triangle"};
    case 10: return GmshElementType{2, 9, 2, "9-node second-order quadrangle"};
    case 11: return GmshElementType{3, 10, 2, "10-node second-order tetrahedron"};
    case 12: return GmshElementType{3, 27, 2, "27-node second-order hexahedron"};
    case 13: return GmshElementType{3, 18, 2, "18-node second-order prism"};
    case 14: return GmshElementType{3, 14, 2, "14-node second-order pyramid"};
    case 15: return GmshElementType{0, 1, 1, "1-node point"};
    case 16: return GmshElementType{2, 8, 2, "8-node second-order quadrangle"};
    case 17: return GmshElementType{3, 20, 2, "20-node second-order hexahedron"};
    case 18: return GmshElementType{3, 15, 2, "15-node second-order prism"};
    case 19: return GmshElementType{3, 13, 2, "13-node second-order pyramid"};
    case 20: return GmshElementType{2, 9, 3, "9-node third-order incomplete triangle"};
    case 21: return GmshElementType{2, 10, 3, "10-node third-order triangle"};
    case 22: return GmshElementType{2, 12, 4, "12-node fourth-order incomplete triangle"};
    case 23: return GmshElementType{2, 15, 4, "15-node fourth-order triangle"};
    case 24: return GmshElementType{2, 15, 5, "15-node fifth-order incomplete triangle"};
    case 25: return GmshElementType{2, 21, 5, "21-node fifth-order triangle"};
    case 26: return GmshElementType{1, 4, 3, "4-node third-order line"};
    case 27: return GmshElementType{1, 5, 4, "5-node fourth-order line"};
    case 28: return GmshElementType{1, 6, 5, "6-node fifth-order line"};
    case 29: return GmshElementType{3, 20, 3, "20-node third-order tetrahedron"};
    case 30: return GmshElementType{3, 35, 4, "35-node fourth-order tetrahedron"};
    case 31: return GmshElementType{3, 56, 5, "56-node fifth-order tetrahedron"};
    default: return std::nullopt;
  }
}

/// Local edges of gmsh's triangle6 / tet10 mid nodes (gmsh MTetrahedron::edges_tetra).
template <int D>
inline constexpr std::array<std::array<int, 2>, simplex_edges<D>> gmsh_mid_edges = [] {
  if constexpr (D == 2) return std::array<std::array<int, 2>, 3>{{{0, 1}, {1, 2}, {2, 0}}};
  else return std::array<std::array<int, 2>, 6>{{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}}};
}();

/// For gmsh mid node k, the local edge (SimplexTopology<D> order) it lies on, for a cell
/// kept as written (`swapped` false) or reoriented by swapping local vertices 1 and 2.
template <int D>
constexpr std::array<int, simplex_edges<D>> gmsh_mid_to_local(bool swapped) {
  std::array<int, simplex_edges<D>> out{};
  for (int k = 0; k < simplex_edges<D>; ++k) {
    auto pos = [&](int v) { return swapped && (v == 1 || v == 2) ? 3 - v : v; };
    const int a = pos(gmsh_mid_edges<D>[k][0]), b = pos(gmsh_mid_edges<D>[k][1]);
    out[k] = -1;
    for (int le = 0; le < simplex_edges<D>; ++le) {
      const auto& e = SimplexTopology<D>::edges[le];
      if ((e[0] == a && e[1] == b) || (e[0] == b && e[1] == a)) out[k] = le;
    }
  }
  return out;
}
static_assert(gmsh_mid_to_local<3>(false)[4] == 5 && gmsh_mid_to_local<3>(false)[5] == 4);
static_assert(gmsh_mid_to_local<2>(true)[0] == 2 && gmsh_mid_to_local<2>(true)[1] == 1);

inline std::uint32_t gmsh_bswap(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}
inline std::uint64_t gmsh_bswap(std::uint64_t v) {
  return (std::uint64_t(gmsh_bswap(std::uint32_t(v))) << 32) | gmsh_bswap(std::uint32_t(v >> 32));
}

/// Cursor over the whole file: line-structured ASCII records and raw binary data.
///
/// Line numbers are counted lazily (newlines between `synced_` and the read position), so
/// binary data advances without per-byte work and line numbers match what an editor shows.
/// In ASCII mode a "record" is one line: `begin_record` moves to the next non-blank line,
/// the `read_*` functions read fields of that line only, `end_record` checks that nothing is
/// left on it. In binary mode the same calls read raw little/big-endian values, and errors
/// report the line where the current block started (`begin_block`).
class GmshCursor {
 public:
  GmshCursor(std::string_view buf, const std::string& file)
      : begin_(buf.data()), p_(buf.data()), end_(buf.data() + buf.size()), synced_(p_), file_(file) {}

  [[noreturn]] void fail(std::size_t line, const std::string& what) const { throw ParseError(file_, line, what); }
  [[noreturn]] void fail(const std::string& what) const { fail(rec_line_, what); }

  const std::string& file() const { return file_; }
  bool binary() const { return binary_; }
  bool swapped() const { return swap_; }
  void set_binary(bool b, bool swap) {
    binary_ = b;
    swap_ = swap;
  }
  void set_section(std::string name) { section_ = std::move(name); }
  std::size_t record_line() const { return rec_line_; }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

  /// Line number of the read position.
  std::size_t line() {
    line_ += static_cast<std::size_t>(std::count(synced_, p_, '\n'));
    synced_ = p_;
    return line_;
  }
  /// Line number of the last line of the file.
  std::size_t last_line() {
    std::size_t n = line() + static_cast<std::size_t>(std::count(p_, end_, '\n'));
    if (end_ != begin_ && end_[-1] == '\n' && n > 1) --n;
    return n;
  }

  [[noreturn]] void fail_truncated(const std::string& while_reading) {
    fail(last_line(), "unexpected end of file in the $" + section_ + " section while reading " + while_reading +
                          " (truncated file?)");
  }

  // --- section markers -------------------------------------------------------------------
  /// Next whitespace-separated token (any mode's text part); empty at end of file.
  std::string_view next_token() {
    skip_blank();
    rec_line_ = line();
    const char* s = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {s, static_cast<std::size_t>(p_ - s)};
  }
  /// After a section marker whose data is binary: consume the rest of the marker line.
  void end_marker_line() {
    skip_inline();
    if (p_ < end_ && *p_ == '\n') ++p_;
    else if (p_ == end_) fail_truncated("the section data");
    else fail(line(), "unexpected text after $" + section_);
  }
  /// Reads `$End<section>`; names the likely cause if something else is there.
  void expect_end() {
    const std::string want = "$End" + section_;
    const std::string_view t = next_token();
    if (t == want) return;
    if (t.empty()) fail(last_line(), "missing " + want + ": unexpected end of file (truncated file?)");
    if (t.front() == '$') fail("missing " + want + " before '" + shorten(t) + "'");
    fail("expected " + want + ", found '" + shorten(t) +
         "': the section holds more data than its header announces (count mismatch)");
  }
  /// Skips an unknown section up to its `$End<name>` line.
  void skip_section(const std::string& name, std::size_t start_line) {
    const std::string want = "\n$End" + name;
    std::string_view rest(p_, remaining());
    for (std::size_t at = rest.find(want); at != std::string_view::npos; at = rest.find(want, at + 1)) {
      const std::size_t after = at + want.size();
      if (after == rest.size() || is_space(rest[after])) {
        p_ += after;
        return;
      }
    }
    fail(start_line, "missing $End" + name + " for the $" + name + " section starting here (truncated file?)");
  }

  // --- records -------------------------------------------------------------------------
  void begin_record() {
    if (binary_) return;
    skip_blank();
    if (p_ == end_) fail_truncated("the next entry");
    rec_line_ = line();
  }
  void begin_block() {
    if (binary_) rec_line_ = line();
    else begin_record();
  }
  void end_record(const char* what) {
    if (binary_) return;
    skip_inline();
    if (p_ < end_ && *p_ != '\n') {
      const char* s = p_;
      while (p_ < end_ && !is_space(*p_)) ++p_;
      fail("unexpected extra value '" + shorten({s, static_cast<std::size_t>(p_ - s)}) + "' at the end of the " +
           what + " line");
    }
  }
  /// The rest of the current line (ASCII), trimmed.
  std::string_view rest_of_line() {
    skip_inline();
    const char* s = p_;
    while (p_ < end_ && *p_ != '\n') ++p_;
    const char* e = p_;
    while (e > s && is_space(e[-1])) --e;
    return {s, static_cast<std::size_t>(e - s)};
  }

  /// A 32-bit int field (binary: 4 bytes).
  int read_int(const char* what) {
    if (binary_) return static_cast<int>(raw<std::uint32_t>(what));
    const std::int64_t v = ascii_integer(what);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      fail(std::string(what) + " " + std::to_string(v) + " is out of range");
    return static_cast<int>(v);
  }
  /// A non-negative size_t field (binary: 8 bytes).
  std::int64_t read_size(const char* what) {
    if (binary_) {
      const std::uint64_t v = raw<std::uint64_t>(what);
      if (v > std::uint64_t(std::numeric_limits<std::int64_t>::max()))
        fail(std::string("bad ") + what + " " + std::to_string(v) + " (out of range)");
      return static_cast<std::int64_t>(v);
    }
    const std::int64_t v = ascii_integer(what);
    if (v < 0) fail(std::string("negative ") + what + " " + std::to_string(v));
    return v;
  }
  /// A count whose items need at least `ascii_bytes` / `binary_bytes` bytes each: rejects
  /// counts the rest of the file cannot hold before anything is allocated for them.
  std::int64_t read_count(const char* what, std::size_t ascii_bytes, std::size_t binary_bytes) {
    const std::int64_t n = read_size(what);
    const std::size_t per = binary_ ? binary_bytes : ascii_bytes;
    if (std::uint64_t(n) > remaining() / per)
      fail("bad " + std::string(what) + " " + std::to_string(n) +
           ": the rest of the file cannot hold that many (truncated file or corrupt count)");
    return n;
  }
  double read_real(const char* what) {
    double v;
    if (binary_) {
      const std::uint64_t bits = raw<std::uint64_t>(what);
      std::memcpy(&v, &bits, sizeof v);
    } else {
      const char* s = field_start(what);
      if (*s == '+') ++s;
      const auto r = std::from_chars(s, end_, v);
      if (r.ec == std::errc::result_out_of_range) fail_token(what, "out of range");
      if (r.ec != std::errc() || (r.ptr < end_ && !is_space(*r.ptr))) fail_token(what, "non-numeric");
      p_ = r.ptr;
    }
    if (!std::isfinite(v)) fail(std::string("non-finite ") + what);
    return v;
  }
  /// A string field (ASCII): the token up to the next white space.
  std::string_view read_word(const char* what) {
    const char* s = field_start(what);
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {s, static_cast<std::size_t>(p_ - s)};
  }
  /// ASCII: the raw 4-byte int right after the current line break (binary $MeshFormat).
  std::uint32_t raw_after_newline(const char* what) {
    if (p_ == end_) fail_truncated(what);
    if (*p_ != '\n') fail(std::string("expected a line break before the ") + what);
    ++p_;
    return raw<std::uint32_t>(what);
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
  void skip_blank() {
    while (p_ < end_ && is_space(*p_)) ++p_;
  }
  void skip_inline() {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r')) ++p_;
  }
  /// "a what" / "an what".
  static std::string a(const char* what) {
    return (std::strchr("aeiou", what[0]) && what[0] ? "an " : "a ") + std::string(what);
  }
  static std::string shorten(std::string_view t) {
    return t.size() > 40 ? std::string(t.substr(0, 40)) + "..." : std::string(t);
  }
  /// Start of the next field on the current line (ASCII).
  const char* field_start(const char* what) {
    skip_inline();
    if (p_ == end_) fail_truncated(what);
    if (*p_ == '\n') fail(std::string("the line ends before the ") + what);
    return p_;
  }
  [[noreturn]] void fail_token(const char* what, const char* kind) {
    const char* s = p_;
    const char* e = s;
    while (e < end_ && !is_space(*e)) ++e;
    const std::string_view t(s, static_cast<std::size_t>(e - s));
    if (t.front() == '$')
      fail("found '" + shorten(t) + "' where " + a(what) +
           " was expected: the section ends before the count in its header is reached (count mismatch)");
    fail(std::string(kind) + " token '" + shorten(t) + "' where " + a(what) + " was expected");
  }
  std::int64_t ascii_integer(const char* what) {
    const char* s = field_start(what);
    if (*s == '+') ++s;
    std::int64_t v = 0;
    const auto r = std::from_chars(s, end_, v);
    if (r.ec == std::errc::result_out_of_range) fail_token(what, "out-of-range");
    if (r.ec != std::errc() || (r.ptr < end_ && !is_space(*r.ptr))) fail_token(what, "non-numeric");
    p_ = r.ptr;
    return v;
  }
  template <class U>
  U raw(const char* what) {
    if (remaining() < sizeof(U))
      fail("truncated file: the binary data of the $" + section_ + " section ends inside " + a(what));
    U v;
    std::memcpy(&v, p_, sizeof(U));
    p_ += sizeof(U);
    return swap_ ? gmsh_bswap(v) : v;
  }

  const char* begin_;
  const char* p_;
  const char* end_;
  const char* synced_;
  std::size_t line_ = 1;
  std::size_t rec_line_ = 1;
  bool binary_ = false;
  bool swap_ = false;
  std::string section_ = "MeshFormat";
  std::string file_;
};

/// The parser: reads the sections into flat arrays, then builds the Mesh.
template <int D>
class GmshReader {
 public:
  GmshReader(std::string_view buf, const std::string& file) : cur_(buf, file) {}

  GmshMesh<D> read() {
    parse_sections();
    return build();
  }

 private:
  static constexpr int nv = D + 1;
  static constexpr int ne = simplex_edges<D>;
  static constexpr const char* cell_word = D == 2 ? "triangle" : "tetrahedron";
  static constexpr const char* cell_words = D == 2 ? "triangles" : "tetrahedra";
  static constexpr const char* facet_word = D == 2 ? "line" : "triangle";
  static constexpr const char* cell_group = D == 2 ? "Physical Surface" : "Physical Volume";
  static constexpr const char* facet_group = D == 2 ? "Physical Curve" : "Physical Surface";

  struct Entity {
    std::vector<int> phys;  // physical tags in file order (the first is the element's tag)
    int partition = 0;      // partitioned entity: its first partition (0: not partitioned)
    int parent_dim = -1;    // partitioned entity: dimension of the model entity it comes from
  };
  enum class Kind { cell, facet, ignore };

  // --- sections --------------------------------------------------------------------------
  void parse_sections() {
    std::string_view m = cur_.next_token();
    if (m != "$MeshFormat")
      cur_.fail(cur_.record_line(), m.empty() ? "empty file: not a gmsh .msh file"
                                              : "not a gmsh .msh file: it must start with $MeshFormat");
    parse_mesh_format();
    for (;;) {
      m = cur_.next_token();
      if (m.empty()) break;
      const std::size_t line = cur_.record_line();
      if (m.front() != '$' || m.size() < 2)
        cur_.fail(line, "unexpected '" + std::string(m.substr(0, 40)) + "' outside of any $Section");
      const std::string name(m.substr(1));
      if (name.rfind("End", 0) == 0) cur_.fail(line, "'" + std::string(m) + "' without a matching opening marker");
      cur_.set_section(name);
      if (name == "MeshFormat") cur_.fail(line, "duplicate $MeshFormat section");
      if (name == "PhysicalNames") {
        parse_physical_names();
      } else if (name == "Entities" && v41_) {
        once(have_entities_, name, line);
        parse_entities();
      } else if (name == "PartitionedEntities" && v41_) {
        once(have_partitions_, name, line);
        if (have_nodes_ || have_elements_) cur_.fail(line, "$PartitionedEntities must come before $Nodes and $Elements");
        parse_partitioned_entities();
      } else if (name == "Nodes") {
        once(have_nodes_, name, line);
        if (v41_) parse_nodes41();
        else parse_nodes22();
      } else if (name == "Elements") {
        once(have_elements_, name, line);
        elements_line_ = line;
        if (v41_) parse_elements41();
        else parse_elements22();
      } else {
        cur_.skip_section(name, line);
      }
    }
    cur_.set_section("Nodes");
    if (!have_nodes_) cur_.fail(cur_.last_line(), "missing $Nodes section");
    if (!have_elements_) cur_.fail(cur_.last_line(), "missing $Elements section");
  }

  void once(bool& seen, const std::string& name, std::size_t line) {
    if (seen) cur_.fail(line, "duplicate $" + name + " section");
    seen = true;
  }

  void parse_mesh_format() {
    cur_.set_section("MeshFormat");
    cur_.begin_record();
    const std::string_view version = cur_.read_word("version number");
    const int file_type = cur_.read_int("file type");
    const int data_size = cur_.read_int("data size");
    cur_.end_record("$MeshFormat");
    double v = 0;
    const auto r = std::from_chars(version.data(), version.data() + version.size(), v);
    if (r.ec != std::errc() || r.ptr != version.data() + version.size())
      cur_.fail("non-numeric version number '" + std::string(version.substr(0, 40)) + "'");
    if (file_type != 0 && file_type != 1)
      cur_.fail("bad file type " + std::to_string(file_type) + " (0 = ASCII, 1 = binary)");
    const bool binary = file_type == 1;
    const bool v41 = v == 4.1, v22 = v == 2.2;
    if (!(v41 || (v22 && !binary)))
      cur_.fail("unsupported MSH format version " + std::string(version) + (binary ? " binary" : " ASCII") +
                "; alefsi reads MSH 4.1 (ASCII or binary) and MSH 2.2 (ASCII): re-export with "
                "gmsh -format msh41 (or -format msh22 without -bin)");
    v41_ = v41;
    if (binary) {
      if (data_size != 8)
        cur_.fail("unsupported data size " + std::to_string(data_size) +
                  " in a binary file: alefsi reads binary files whose size_t is 8 bytes");
      const std::uint32_t one = cur_.raw_after_newline("endianness check int");
      if (one == 1u) cur_.set_binary(true, false);
      else if (one == gmsh_bswap(std::uint32_t{1})) cur_.set_binary(true, true);
      else
        cur_.fail("bad endianness check int " + std::to_string(one) +
                  " after the binary $MeshFormat line (expected 1)");
    }
    cur_.expect_end();
  }

  /// Text section inside a possibly binary file: $PhysicalNames is always ASCII.
  void parse_physical_names() {
    const bool bin = cur_.binary(), swap = cur_.swapped();
    cur_.set_binary(false, false);
    cur_.begin_record();
    const std::int64_t n = cur_.read_count("number of physical names", 8, 8);
    cur_.end_record("$PhysicalNames count");
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.begin_record();
      const int dim = cur_.read_int("physical dimension");
      const int tag = cur_.read_int("physical tag");
      std::string_view name = cur_.rest_of_line();
      if (name.size() < 2 || name.front() != '"' || name.back() != '"')
        cur_.fail("physical name must be a quoted string, found '" + std::string(name.substr(0, 40)) + "'");
      name = name.substr(1, name.size() - 2);
      if (dim < 0 || dim > 3) cur_.fail("bad physical dimension " + std::to_string(dim));
      if (dim == D || dim == D - 1) {
        auto [it, fresh] = names_.emplace(tag, std::string(name));
        if (!fresh && it->second != name)
          cur_.fail("physical tag " + std::to_string(tag) + " names both '" + it->second + "' and '" +
                    std::string(name) + "' (groups of dimension " + std::to_string(D) + " and " +
                    std::to_string(D - 1) + " share the tag); alefsi keys names by tag, give them distinct tags");
      }
    }
    cur_.expect_end();
    cur_.set_binary(bin, swap);
  }

  void parse_entities() {
    if (cur_.binary()) cur_.end_marker_line();
    cur_.begin_block();
    // a point needs >= 5 tokens (36 bytes in binary), a curve/surface/volume >= 9 (68 bytes)
    const auto count = read_entity_counts({10, 36}, {18, 68});
    cur_.end_record("$Entities count");
    for (int d = 0; d < 4; ++d) {
      for (std::int64_t i = 0; i < count[d]; ++i) {
        cur_.begin_record();
        const int tag = cur_.read_int("entity tag");
        Entity e;
        read_entity_tail(d, e);
        add_entity(d, tag, std::move(e));
      }
    }
    cur_.expect_end();
  }

  /// The numbers of points, curves, surfaces and volumes of an ($Partitioned)Entities header;
  /// a point's record needs at least `point_bytes` bytes, any other's `other_bytes` (ASCII,
  /// binary), which bounds each count by what the rest of the file can hold.
  std::array<std::int64_t, 4> read_entity_counts(std::array<std::size_t, 2> point_bytes,
                                                 std::array<std::size_t, 2> other_bytes) {
    static constexpr const char* what[] = {"number of points", "number of curves", "number of surfaces",
                                           "number of volumes"};
    std::array<std::int64_t, 4> count{};
    for (int d = 0; d < 4; ++d) {
      const auto& bytes = d == 0 ? point_bytes : other_bytes;
      count[std::size_t(d)] = cur_.read_count(what[d], bytes[0], bytes[1]);
    }
    return count;
  }

  /// What ends an entity record of dimension d: the point's coordinates or the bounding box,
  /// the physical tags and the bounding entities.
  void read_entity_tail(int d, Entity& e) {
    for (int k = 0; k < (d == 0 ? 3 : 6); ++k) cur_.read_real(d == 0 ? "point coordinate" : "bounding box coordinate");
    const std::int64_t np = cur_.read_count("number of physical tags", 2, 4);
    e.phys.resize(std::size_t(np));
    // a negative tag is the group |tag| holding the entity with reversed orientation (gmsh t14)
    for (auto& p : e.phys) {
      p = cur_.read_int("physical tag");
      if (p == std::numeric_limits<int>::min()) cur_.fail("physical tag " + std::to_string(p) + " is out of range");
      p = std::abs(p);
    }
    if (d > 0) {
      const std::int64_t nb = cur_.read_count("number of bounding entities", 2, 4);
      for (std::int64_t k = 0; k < nb; ++k) cur_.read_int("bounding entity tag");
    }
    cur_.end_record("entity");
  }

  void add_entity(int d, int tag, Entity e) {
    if (!entities_[std::size_t(d)].emplace(tag, std::move(e)).second)
      cur_.fail("duplicate entity tag " + std::to_string(tag) + " of dimension " + std::to_string(d));
  }

  /// $PartitionedEntities (MSH 4.1, written by gmsh's partitioner): the entities the element
  /// blocks of a partitioned file refer to, each with its partitions and physical tags; the
  /// ghost entities, whose elements copy those of neighbouring partitions.
  void parse_partitioned_entities() {
    if (cur_.binary()) cur_.end_marker_line();
    cur_.begin_block();
    cur_.begin_record();
    const std::int64_t np = cur_.read_size("number of partitions");
    if (np < 1 || np > std::numeric_limits<int>::max())
      cur_.fail("number of partitions " + std::to_string(np) + " is not in [1, 2^31)");
    n_partitions_ = int(np);
    cur_.end_record("number of partitions");
    cur_.begin_record();
    const std::int64_t ng = cur_.read_count("number of ghost entities", 4, 8);
    cur_.end_record("number of ghost entities");
    for (std::int64_t i = 0; i < ng; ++i) {
      cur_.begin_record();
      ghosts_.insert(cur_.read_int("ghost entity tag"));
      cur_.read_int("ghost entity partition");
      cur_.end_record("ghost entity");
    }
    cur_.begin_record();
    const auto count = read_entity_counts({16, 52}, {24, 84});
    cur_.end_record("$PartitionedEntities count");
    for (int d = 0; d < 4; ++d) {
      for (std::int64_t i = 0; i < count[d]; ++i) {
        cur_.begin_record();
        const int tag = cur_.read_int("entity tag");
        Entity e;
        e.parent_dim = cur_.read_int("parent dimension");
        cur_.read_int("parent tag");
        const std::int64_t nparts = cur_.read_count("number of partitions of the entity", 2, 4);
        for (std::int64_t k = 0; k < nparts; ++k) {
          const int part = cur_.read_int("partition tag");
          if (part < 1 || part > n_partitions_)
            cur_.fail("partition tag " + std::to_string(part) + " is not in [1, " + std::to_string(n_partitions_) + "]");
          if (k == 0) e.partition = part;
        }
        read_entity_tail(d, e);
        add_entity(d, tag, std::move(e));
      }
    }
    cur_.expect_end();
  }

  std::int64_t read_node_tag() {
    const std::int64_t tag = cur_.read_size("node tag");
    if (tag == 0) cur_.fail("bad node tag 0 (node tags must be positive)");
    return tag;
  }

  /// Stores a node; `tag_line` is where its tag is (for duplicate-tag errors).
  void add_node(std::int64_t tag, double x, double y, double z, std::size_t tag_line) {
    if constexpr (D == 2) {
      if (std::abs(z) > 1e-12 * std::max({1.0, std::abs(x), std::abs(y)}))
        cur_.fail("node " + std::to_string(tag) + " has z = " + std::to_string(z) +
                  ": a 2D mesh is not planar (all z must be 0)");
      nx_.emplace_back(x, y);
    } else {
      nx_.emplace_back(x, y, z);
    }
    ntag_.push_back(tag);
    nline_.push_back(tag_line);
  }

  void parse_nodes22() {
    cur_.begin_record();
    const std::size_t header = cur_.record_line();
    const std::int64_t n = cur_.read_count("number of nodes", 8, 8);
    cur_.end_record("$Nodes count");
    reserve_nodes(n, header);
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.begin_record();
      const std::int64_t tag = read_node_tag();
      const double x = cur_.read_real("x coordinate"), y = cur_.read_real("y coordinate"),
                   z = cur_.read_real("z coordinate");
      cur_.end_record("node");
      add_node(tag, x, y, z, cur_.record_line());
    }
    cur_.expect_end();
  }

  void parse_nodes41() {
    if (cur_.binary()) cur_.end_marker_line();
    cur_.begin_block();
    const std::size_t header = cur_.record_line();
    const std::int64_t blocks = cur_.read_count("number of node blocks", 8, 20);
    const std::int64_t total = cur_.read_count("number of nodes", 8, 32);
    cur_.read_size("minimum node tag");
    cur_.read_size("maximum node tag");
    cur_.end_record("$Nodes header");
    reserve_nodes(total, header);
    std::int64_t seen = 0;
    std::vector<std::int64_t> tags;
    std::vector<std::size_t> tag_lines;
    for (std::int64_t b = 0; b < blocks; ++b) {
      cur_.begin_block();
      const int dim = cur_.read_int("entity dimension");
      cur_.read_int("entity tag");
      const int parametric = cur_.read_int("parametric flag");
      const std::int64_t n = cur_.read_count("number of nodes in the block", 8, 32);
      cur_.end_record("node block header");
      if (dim < 0 || dim > 3) cur_.fail("bad entity dimension " + std::to_string(dim) + " in a node block");
      if (parametric != 0 && parametric != 1) cur_.fail("bad parametric flag " + std::to_string(parametric));
      if (n > total - seen)
        cur_.fail("the node blocks hold more nodes than the " + std::to_string(total) + " announced on line " +
                  std::to_string(header) + " (count mismatch)");
      seen += n;
      tags.resize(static_cast<std::size_t>(n));
      tag_lines.resize(static_cast<std::size_t>(n));
      for (std::size_t i = 0; i < tags.size(); ++i) {
        cur_.begin_record();
        tags[i] = read_node_tag();
        cur_.end_record("node tag");
        tag_lines[i] = cur_.record_line();
      }
      const int extra = parametric ? dim : 0;
      for (std::int64_t i = 0; i < n; ++i) {
        cur_.begin_record();
        const double x = cur_.read_real("x coordinate"), y = cur_.read_real("y coordinate"),
                     z = cur_.read_real("z coordinate");
        for (int k = 0; k < extra; ++k) cur_.read_real("parametric coordinate");
        cur_.end_record("node coordinates");
        add_node(tags[std::size_t(i)], x, y, z, tag_lines[std::size_t(i)]);
      }
    }
    if (seen != total)
      cur_.fail(header, "the $Nodes header announces " + std::to_string(total) + " nodes but its blocks hold " +
                            std::to_string(seen) + " (count mismatch)");
    cur_.expect_end();
  }

  void reserve_nodes(std::int64_t n, std::size_t line) {
    if (n > std::numeric_limits<Index>::max()) cur_.fail(line, "too many nodes (" + std::to_string(n) + ")");
    ntag_.reserve(ntag_.size() + std::size_t(n));
    nx_.reserve(nx_.size() + std::size_t(n));
    nline_.reserve(nline_.size() + std::size_t(n));
  }

  /// What to do with elements of gmsh type `type` in a D-dimensional mesh; throws for types
  /// alefsi does not read.
  Kind classify(int type) {
    if ((D == 2 && (type == 2 || type == 9)) || (D == 3 && (type == 4 || type == 11))) return Kind::cell;
    if ((D == 2 && (type == 1 || type == 8)) || (D == 3 && (type == 2 || type == 9))) return Kind::facet;
    const auto t = gmsh_element_type(type);
    if (!t) cur_.fail("unknown element type " + std::to_string(type));
    if (t->dim < D - 1) return Kind::ignore;
    if (t->dim > D)
      cur_.fail("element type " + std::to_string(type) + " (" + t->name + ") is " + std::to_string(t->dim) +
                "-dimensional: this is not a " + std::to_string(D) + "D mesh (use read_gmsh<" +
                std::to_string(t->dim) + ">)");
    cur_.fail("unsupported element type " + std::to_string(type) + " (" + t->name + ") in a " + std::to_string(D) +
              "D mesh: alefsi reads " + (D == 2 ? "triangles (types 2, 9) and lines (types 1, 8)"
                                                 : "tetrahedra (types 4, 11) and triangles (types 2, 9)"));
  }

  /// Stores one element (node tags in `nodes`) of a kept kind.
  void add_element(Kind kind, int type, const std::int64_t* nodes, int phys, std::size_t line) {
    if (kind == Kind::cell) {
      if (cell_type_ == 0) {
        cell_type_ = type;
        cell_type_line_ = line;
      } else if (type != cell_type_) {
        cur_.fail(line, "mixes first- and second-order cells: type " + std::to_string(type) + " here, type " +
                            std::to_string(cell_type_) + " on line " + std::to_string(cell_type_line_));
      }
      cell_nodes_.insert(cell_nodes_.end(), nodes, nodes + gmsh_element_type(type)->nodes);
      cell_phys_.push_back(phys);
      cell_line_.push_back(line);
    } else {
      facet_nodes_.insert(facet_nodes_.end(), nodes, nodes + D);
      facet_phys_.push_back(phys);
      facet_line_.push_back(line);
    }
  }

  void parse_elements22() {
    cur_.begin_record();
    const std::int64_t n = cur_.read_count("number of elements", 8, 8);
    cur_.end_record("$Elements count");
    std::array<std::int64_t, 64> nodes{};
    for (std::int64_t i = 0; i < n; ++i) {
      cur_.begin_record();
      cur_.read_size("element tag");
      const int type = cur_.read_int("element type");
      const std::int64_t ntags = cur_.read_count("number of element tags", 2, 2);
      int phys = 0;
      for (std::int64_t k = 0; k < ntags; ++k) {
        const int t = cur_.read_int("element tag");
        if (k == 0) phys = t;
      }
      const Kind kind = classify(type);
      const int nn = gmsh_element_type(type)->nodes;
      for (int k = 0; k < nn; ++k) nodes[std::size_t(k)] = cur_.read_size("node tag");
      cur_.end_record("element");
      if (kind != Kind::ignore) add_element(kind, type, nodes.data(), phys, cur_.record_line());
    }
    cur_.expect_end();
  }

  void parse_elements41() {
    if (cur_.binary()) cur_.end_marker_line();
    cur_.begin_block();
    const std::size_t header = cur_.record_line();
    const std::int64_t blocks = cur_.read_count("number of element blocks", 8, 20);
    const std::int64_t total = cur_.read_count("number of elements", 4, 16);
    cur_.read_size("minimum element tag");
    cur_.read_size("maximum element tag");
    cur_.end_record("$Elements header");
    std::int64_t seen = 0;
    std::array<std::int64_t, 64> nodes{};
    for (std::int64_t b = 0; b < blocks; ++b) {
      cur_.begin_block();
      const int dim = cur_.read_int("entity dimension");
      const int entity = cur_.read_int("entity tag");
      const int type = cur_.read_int("element type");
      Kind kind = classify(type);
      const int nn = gmsh_element_type(type)->nodes;
      const std::int64_t n = cur_.read_count("number of elements in the block", std::size_t(2 * (nn + 1)),
                                             std::size_t(8 * (nn + 1)));
      cur_.end_record("element block header");
      const std::size_t block_line = cur_.record_line();
      if (dim != gmsh_element_type(type)->dim)
        cur_.fail("element block of dimension " + std::to_string(dim) + " holds element type " + std::to_string(type) +
                  " of dimension " + std::to_string(gmsh_element_type(type)->dim));
      if (n > total - seen)
        cur_.fail("the element blocks hold more elements than the " + std::to_string(total) + " announced on line " +
                  std::to_string(header) + " (count mismatch)");
      seen += n;
      const Entity* e = kind == Kind::ignore ? nullptr : find_entity(dim, entity, block_line);
      // a partitioned file's ghost cells copy cells of other partitions, and the facets of its
      // partition interfaces (entities that come from a D-dimensional model entity) are interior
      // facets of the model that no physical group asked for
      if (e && ((kind == Kind::cell && ghosts_.count(entity)) || (kind == Kind::facet && e->parent_dim == D)))
        kind = Kind::ignore, e = nullptr;
      for (std::int64_t i = 0; i < n; ++i) {
        cur_.begin_record();
        cur_.read_size("element tag");
        for (int k = 0; k < nn; ++k) nodes[std::size_t(k)] = cur_.read_size("node tag");
        cur_.end_record("element");
        if (kind == Kind::ignore) continue;
        add_element(kind, type, nodes.data(), e && !e->phys.empty() ? e->phys[0] : 0, cur_.record_line());
        if (!e) continue;
        auto& extra = kind == Kind::cell ? cell_extra_ : facet_extra_;
        const std::size_t index = (kind == Kind::cell ? cell_line_ : facet_line_).size() - 1;
        for (std::size_t k = 1; k < e->phys.size(); ++k) extra.emplace_back(index, e->phys[k]);
        if (kind == Kind::cell && have_partitions_) cell_part_.push_back(e->partition);
      }
    }
    if (seen != total)
      cur_.fail(header, "the $Elements header announces " + std::to_string(total) + " elements but its blocks hold " +
                            std::to_string(seen) + " (count mismatch)");
    cur_.expect_end();
  }

  /// The entity (dim, tag) of an element block (MSH 4.1); nullptr for a file without $Entities.
  const Entity* find_entity(int dim, int entity, std::size_t block_line) {
    if (!have_entities_ && !have_partitions_) return nullptr;
    const auto it = entities_[std::size_t(dim)].find(entity);
    if (it == entities_[std::size_t(dim)].end())
      cur_.fail(block_line, "element block refers to entity " + std::to_string(entity) + " of dimension " +
                                std::to_string(dim) + ", which " +
                                (have_partitions_ ? "neither $Entities nor $PartitionedEntities lists"
                                                  : "$Entities does not list"));
    return &it->second;
  }

  // --- building the mesh -----------------------------------------------------------------
  /// File node index of every node tag (dense table or sorted list); reports duplicates.
  class NodeMap {
   public:
    void build(const std::vector<std::int64_t>& tags, const std::vector<std::size_t>& lines, GmshCursor& cur) {
      const std::size_t n = tags.size();
      const std::int64_t max_tag = n ? *std::max_element(tags.begin(), tags.end()) : 0;
      if (std::uint64_t(max_tag) <= 4 * std::uint64_t(n) + 1024) {
        dense_.assign(std::size_t(max_tag) + 1, -1);
        for (std::size_t i = 0; i < n; ++i) {
          Index& slot = dense_[std::size_t(tags[i])];
          if (slot >= 0) duplicate(tags[i], lines[std::size_t(slot)], lines[i], cur);
          slot = static_cast<Index>(i);
        }
      } else {
        sorted_.resize(n);
        for (std::size_t i = 0; i < n; ++i) sorted_[i] = {tags[i], static_cast<Index>(i)};
        std::sort(sorted_.begin(), sorted_.end());
        // report the earliest (in file order) repeated definition, with the tag's first one
        std::size_t again = n, first = n;
        for (std::size_t k = 1, run = 0; k < n; ++k) {
          if (sorted_[k].first != sorted_[k - 1].first) run = k;
          else if (std::size_t(sorted_[k].second) < again)
            again = std::size_t(sorted_[k].second), first = std::size_t(sorted_[run].second);
        }
        if (again < n) duplicate(tags[again], lines[first], lines[again], cur);
      }
    }
    Index operator()(std::int64_t tag) const {
      if (!sorted_.empty() || dense_.empty()) {
        const auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair<std::int64_t, Index>{tag, -1});
        return it != sorted_.end() && it->first == tag ? it->second : -1;
      }
      return tag >= 0 && std::uint64_t(tag) < dense_.size() ? dense_[std::size_t(tag)] : -1;
    }

   private:
    [[noreturn]] static void duplicate(std::int64_t tag, std::size_t first, std::size_t again, GmshCursor& cur) {
      cur.fail(again,
               "duplicate node tag " + std::to_string(tag) + " (first defined on line " + std::to_string(first) + ")");
    }
    std::vector<Index> dense_;
    std::vector<std::pair<std::int64_t, Index>> sorted_;
  };

  /// Elements whose sorted vertices repeat an earlier one's. MSH 2.2 writes an element once
  /// per physical group it belongs to: a repeat with another physical tag is merged into its
  /// first copy (its tag joins `extra`); a repeat with a tag the element already has is an
  /// error (the first such in file order is reported). Returns, per element, its first copy.
  template <int K>
  std::vector<std::size_t> find_repeats(const std::vector<std::array<Index, K>>& items, const std::vector<int>& phys,
                                        const std::vector<std::size_t>& lines, const std::string& word,
                                        std::vector<std::pair<std::size_t, int>>& extra) {
    std::vector<std::array<Index, K>> keys(items);
    for (auto& k : keys) std::sort(k.begin(), k.end());
    std::vector<std::size_t> order(items.size()), first(items.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::iota(first.begin(), first.end(), std::size_t(0));
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return keys[a] != keys[b] ? keys[a] < keys[b] : a < b; });
    std::size_t again = items.size(), again_first = 0;
    std::vector<int> run_tags;
    for (std::size_t k = 0, run = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      if (k == 0 || keys[i] != keys[order[k - 1]]) {
        run = k;
        run_tags.assign(1, phys[i]);
        continue;
      }
      first[i] = order[run];
      if (std::find(run_tags.begin(), run_tags.end(), phys[i]) != run_tags.end()) {
        if (i < again) again = i, again_first = order[run];
      } else {
        run_tags.push_back(phys[i]);
        extra.emplace_back(order[run], phys[i]);
      }
    }
    if (again < items.size())
      cur_.fail(lines[again], "this " + word + " repeats the one on line " + std::to_string(lines[again_first]) +
                                  " with the same physical tag " + std::to_string(phys[again]));
    return first;
  }

  /// Keeps the entries of `v` (`per` consecutive ones per element; none: nothing to do)
  /// whose element is its own first copy.
  template <class T>
  static void keep_firsts(std::vector<T>& v, const std::vector<std::size_t>& first, std::size_t per = 1) {
    if (v.empty()) return;
    std::size_t n = 0;
    for (std::size_t i = 0; i < first.size(); ++i)
      if (first[i] == i) {
        for (std::size_t k = 0; k < per; ++k) v[per * n + k] = v[per * i + k];
        ++n;
      }
    v.resize(per * n);
  }

  /// New index of each kept element (its first copy's rank among the kept ones).
  static std::vector<std::size_t> kept_index(const std::vector<std::size_t>& first) {
    std::vector<std::size_t> out(first.size());
    std::size_t n = 0;
    for (std::size_t i = 0; i < first.size(); ++i) out[i] = first[i] == i ? n++ : out[first[i]];
    return out;
  }

  GmshMesh<D> build() {
    cur_.set_section("Elements");
    if (cell_line_.empty())
      cur_.fail(elements_line_, std::string("no ") + std::to_string(D) + "-dimensional cells (" + cell_words +
                                    ") in $Elements: not a " + std::to_string(D) +
                                    "D mesh, or the domain has no physical group (mesh it with gmsh -" +
                                    std::to_string(D) + ")");
    NodeMap map;
    map.build(ntag_, nline_, cur_);

    // resolve node tags
    const int cn = gmsh_element_type(cell_type_)->nodes;
    const bool order2 = cn > nv;
    std::size_t nc = cell_line_.size();
    const std::size_t nf = facet_line_.size();
    if (std::max(nc, nf) > std::size_t(std::numeric_limits<Index>::max()))
      cur_.fail(elements_line_, "too many elements (" + std::to_string(std::max(nc, nf)) + ")");
    std::vector<Index> cell_idx(cell_nodes_.size());
    for (std::size_t i = 0; i < cell_nodes_.size(); ++i) {
      cell_idx[i] = map(cell_nodes_[i]);
      if (cell_idx[i] < 0) undefined_node(cell_nodes_[i], cell_line_[i / std::size_t(cn)]);
    }
    std::vector<Index> facet_idx(facet_nodes_.size());
    for (std::size_t i = 0; i < facet_nodes_.size(); ++i) {
      facet_idx[i] = map(facet_nodes_[i]);
      if (facet_idx[i] < 0) undefined_node(facet_nodes_[i], facet_line_[i / std::size_t(D)]);
    }

    // physical groups
    const auto untagged = std::find(cell_phys_.begin(), cell_phys_.end(), 0);
    if (std::all_of(cell_phys_.begin(), cell_phys_.end(), [](int p) { return p == 0; }))
      cur_.fail(cell_line_.front(), std::string("missing physical groups: no ") + cell_word +
                                        " belongs to a physical group; add '" + cell_group +
                                        "(\"domain\") = {...};' for the domain and '" + facet_group +
                                        "(...)' for the boundary to the .geo");
    if (untagged != cell_phys_.end())
      cur_.fail(cell_line_[std::size_t(untagged - cell_phys_.begin())],
                std::string("missing physical group: this ") + cell_word + " belongs to none; every " + cell_word +
                    " must be in a " + cell_group + " of the .geo");
    if (nf == 0)
      cur_.fail(elements_line_, std::string("missing physical groups on the boundary: the file has no boundary ") +
                                    facet_word + "s; add '" + facet_group +
                                    "(\"wall\") = {...};' for the boundary to the .geo");
    const auto untagged_f = std::find(facet_phys_.begin(), facet_phys_.end(), 0);
    if (untagged_f != facet_phys_.end())
      cur_.fail(facet_line_[std::size_t(untagged_f - facet_phys_.begin())],
                std::string("missing physical group: this boundary ") + facet_word + " belongs to none; every " +
                    facet_word + " must be in a " + facet_group + " of the .geo");

    // keep the nodes cells use as vertices, in file order
    std::vector<Index> new_id(ntag_.size(), -1);
    for (std::size_t c = 0; c < nc; ++c)
      for (int k = 0; k < nv; ++k) new_id[std::size_t(cell_idx[c * std::size_t(cn) + std::size_t(k)])] = 0;
    std::vector<Vec<D>> x;
    for (std::size_t i = 0; i < new_id.size(); ++i)
      if (new_id[i] == 0) {
        new_id[i] = static_cast<Index>(x.size());
        x.push_back(nx_[i]);
      }

    // cells, reoriented where gmsh wrote them negatively
    std::vector<typename Mesh<D>::Cell> cells(nc);
    std::vector<char> swapped(nc, 0);
    for (std::size_t c = 0; c < nc; ++c) {
      auto& cell = cells[c];
      for (int k = 0; k < nv; ++k)
        cell[std::size_t(k)] = new_id[std::size_t(cell_idx[c * std::size_t(cn) + std::size_t(k)])];
      Mat<D> J;
      for (int k = 0; k < D; ++k) J.col(k) = x[std::size_t(cell[std::size_t(k + 1)])] - x[std::size_t(cell[0])];
      if (J.determinant() < 0) {
        std::swap(cell[1], cell[2]);
        swapped[c] = 1;
      }
    }
    std::vector<typename Mesh<D>::Facet> facets(nf);
    for (std::size_t f = 0; f < nf; ++f)
      for (int k = 0; k < D; ++k) {
        const Index v = new_id[std::size_t(facet_idx[f * D + std::size_t(k)])];
        if (v < 0)
          cur_.fail(facet_line_[f], std::string("boundary ") + facet_word + " uses node " +
                                        std::to_string(facet_nodes_[f * D + std::size_t(k)]) +
                                        ", which is not a vertex of any " + cell_word);
        facets[f][std::size_t(k)] = v;
      }

    // repeated elements (MSH 2.2 writes an element once per physical group) join their first copy
    const auto ffirst = find_repeats<D>(facets, facet_phys_, facet_line_, facet_word, facet_extra_);
    const auto cfirst = find_repeats<nv>(cells, cell_phys_, cell_line_, cell_word, cell_extra_);
    {
      const auto fnew = kept_index(ffirst), cnew = kept_index(cfirst);
      for (auto& [f, tag] : facet_extra_) f = fnew[f];
      for (auto& [c, tag] : cell_extra_) c = cnew[c];
    }
    keep_firsts(facets, ffirst), keep_firsts(facet_phys_, ffirst), keep_firsts(facet_line_, ffirst);
    keep_firsts(cells, cfirst), keep_firsts(swapped, cfirst), keep_firsts(cell_line_, cfirst);
    keep_firsts(cell_phys_, cfirst), keep_firsts(cell_part_, cfirst), keep_firsts(cell_idx, cfirst, std::size_t(cn));
    nc = cells.size();

    GmshMesh<D> out;
    try {
      out.mesh = Mesh<D>(std::move(x), cells, facets, facet_phys_, cell_phys_);
    } catch (const MeshError& e) {
      // the same error, located: the file and the line of the offending element
      const std::vector<std::size_t>* lines = e.entity() == MeshError::Entity::cell    ? &cell_line_
                                              : e.entity() == MeshError::Entity::facet ? &facet_line_
                                                                                       : nullptr;
      const bool known = lines && e.index() >= 0 && std::size_t(e.index()) < lines->size();
      throw e.located(cur_.file() + (known ? ":" + std::to_string((*lines)[std::size_t(e.index())]) : std::string()));
    }
    out.physical_names = std::move(names_);
    for (std::size_t c = 0; c < nc; ++c) out.cell_groups[cell_phys_[c]].push_back(Index(c));
    for (const auto& [c, tag] : cell_extra_) out.cell_groups[tag].push_back(Index(c));
    const std::vector<Index> mesh_facet = facet_indices(out.mesh, facets);
    for (std::size_t f = 0; f < facets.size(); ++f) out.facet_groups[facet_phys_[f]].push_back(mesh_facet[f]);
    for (const auto& [f, tag] : facet_extra_) out.facet_groups[tag].push_back(mesh_facet[f]);
    for (auto* groups : {&out.cell_groups, &out.facet_groups})
      for (auto& [tag, items] : *groups) {
        std::sort(items.begin(), items.end());
        items.erase(std::unique(items.begin(), items.end()), items.end());
      }
    out.n_partitions = n_partitions_;
    out.cell_partitions = std::move(cell_part_);

    if (order2) {
      const Mesh<D>& mesh = out.mesh;
      std::vector<Index> mid(std::size_t(mesh.n_edges()), -1);
      out.edge_midpoints.assign(std::size_t(mesh.n_edges()), Vec<D>::Zero());
      constexpr auto as_written = gmsh_mid_to_local<D>(false), reoriented = gmsh_mid_to_local<D>(true);
      for (std::size_t c = 0; c < nc; ++c) {
        const auto& local = swapped[c] ? reoriented : as_written;
        for (int k = 0; k < ne; ++k) {
          const Index node = cell_idx[c * std::size_t(cn) + std::size_t(nv + k)];
          const Index e = mesh.cell_edges(Index(c))[std::size_t(local[std::size_t(k)])];
          Index& m = mid[std::size_t(e)];
          if (m >= 0 && m != node)
            cur_.fail(cell_line_[c], std::string("second-order ") + cell_word + " has mid node " +
                                         std::to_string(ntag_[std::size_t(node)]) + " on an edge whose mid node is " +
                                         std::to_string(ntag_[std::size_t(m)]) + " in another cell (non-conforming)");
          m = node;
          out.edge_midpoints[std::size_t(e)] = nx_[std::size_t(node)];
        }
      }
    }
    return out;
  }

  /// The mesh facet index of each facet (vertex triple or pair, any order) of `facets`.
  static std::vector<Index> facet_indices(const Mesh<D>& mesh, const std::vector<typename Mesh<D>::Facet>& facets) {
    std::vector<std::vector<Index>> by_node(std::size_t(mesh.n_nodes()));
    for (Index f = 0; f < mesh.n_facets(); ++f) by_node[std::size_t(mesh.facet(f)[0])].push_back(f);
    std::vector<Index> out(facets.size(), -1);
    for (std::size_t i = 0; i < facets.size(); ++i) {
      auto k = facets[i];
      std::sort(k.begin(), k.end());
      for (Index f : by_node[std::size_t(k[0])])
        if (mesh.facet(f) == k) out[i] = f;
    }
    return out;
  }

  [[noreturn]] void undefined_node(std::int64_t tag, std::size_t line) {
    cur_.fail(line, "element references node tag " + std::to_string(tag) + ", which $Nodes does not define");
  }

  GmshCursor cur_;
  bool v41_ = false;
  bool have_entities_ = false, have_partitions_ = false, have_nodes_ = false, have_elements_ = false;
  int n_partitions_ = 0;
  std::set<int> ghosts_;  // ghost entities (of dimension D) of a partitioned file
  std::size_t elements_line_ = 0;
  std::map<int, std::string> names_;
  std::array<std::unordered_map<int, Entity>, 4> entities_;
  // nodes in file order
  std::vector<std::int64_t> ntag_;
  std::vector<Vec<D>> nx_;
  std::vector<std::size_t> nline_;
  // kept elements: D-cells (all nodes) and (D-1)-facets (vertices only)
  int cell_type_ = 0;
  std::size_t cell_type_line_ = 0;
  std::vector<std::int64_t> cell_nodes_;
  std::vector<int> cell_phys_;
  std::vector<std::size_t> cell_line_;
  std::vector<int> cell_part_;  // partitioned files: each cell's partition
  std::vector<std::int64_t> facet_nodes_;
  std::vector<int> facet_phys_;
  std::vector<std::size_t> facet_line_;
  // (element, tag) for an element's physical tags beyond its first
  std::vector<std::pair<std::size_t, int>> cell_extra_, facet_extra_;
};

}  // namespace detail

/// Reads a gmsh mesh from a stream; `name_for_errors` names it in ParseError messages.
template <int D>
GmshMesh<D> read_gmsh(std::istream& in, const std::string& name_for_errors) {
  std::string buf;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) buf.append(chunk, std::size_t(in.gcount()));
  if (in.bad()) throw ParseError(name_for_errors, 0, "read error");
  return detail::GmshReader<D>(buf, name_for_errors).read();
}

/// Reads a gmsh `.msh` file (MSH 4.1 ASCII / binary or MSH 2.2 ASCII).
template <int D>
GmshMesh<D> read_gmsh(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "cannot open file for reading");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0 || !in) return read_gmsh<D>(in, path);
  std::string buf(static_cast<std::size_t>(size), '\0');
  if (!in.read(buf.data(), size)) throw ParseError(path, 0, "read error");
  return detail::GmshReader<D>(buf, path).read();
}

}  // namespace alefsi
