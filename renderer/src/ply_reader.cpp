// The PLY reader; see ply_reader.h.
#include "ply_reader.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh_common.h"

namespace camhead::renderer::detail {
namespace {

using Path = std::filesystem::path;

struct PlyType {
  std::uint8_t size = 4;
  bool integer = false;
  bool is_signed = true;
};

bool parse_ply_type(std::string_view s, PlyType &t) {
  static constexpr std::pair<std::string_view, PlyType> names[] = {
      {"char", {1, true, true}},    {"int8", {1, true, true}},     {"uchar", {1, true, false}},
      {"uint8", {1, true, false}},  {"short", {2, true, true}},    {"int16", {2, true, true}},
      {"ushort", {2, true, false}}, {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"int32", {4, true, true}},   {"uint", {4, true, false}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},  {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}}};
  const auto *it = std::find_if(std::begin(names), std::end(names),
                                [&](const auto &entry) { return entry.first == s; });
  if (it != std::end(names))
    t = it->second;
  return it != std::end(names);
}

struct PlyProperty {
  std::string name;
  PlyType type;
  bool is_list = false;
  PlyType count_type;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { ascii, little, big };

// Reads one value at a time from the body; false at the end of the data or on
// a value that does not fit its declared type.
class PlyBody {
public:
  PlyBody(std::string_view data, PlyFormat format) : data_(data), format_(format) {}

  [[nodiscard]] bool at_end() const { return pos_ >= data_.size(); }

  bool read(PlyType t, double &out) {
    return format_ == PlyFormat::ascii ? read_ascii(t, out) : read_binary(t, out);
  }

private:
  bool read_ascii(PlyType t, double &out) {
    const auto space = [this](std::size_t i) { return std::isspace((unsigned char)data_[i]); };
    while (pos_ < data_.size() && space(pos_))
      ++pos_;
    const char *first = data_.data() + pos_;
    while (pos_ < data_.size() && !space(pos_))
      ++pos_;
    const char *last = data_.data() + pos_;
    first += first != last && *first == '+';
    if (!t.integer) {
      const auto r = std::from_chars(first, last, out);
      return first != last && r.ec == std::errc() && r.ptr == last;
    }
    std::int64_t v = 0;
    const auto r = std::from_chars(first, last, v);
    const int bits = t.size * 8 - (t.is_signed ? 1 : 0);
    const std::int64_t hi = (std::int64_t(1) << bits) - 1;
    out = double(v);
    return first != last && r.ec == std::errc() && r.ptr == last && v <= hi &&
           v >= (t.is_signed ? -hi - 1 : 0);
  }

  bool read_binary(PlyType t, double &out) {
    if (data_.size() - pos_ < t.size) {
      pos_ = data_.size();
      return false;
    }
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, t.size);
    pos_ += t.size;
    if ((format_ == PlyFormat::big) != (std::endian::native == std::endian::big))
      std::reverse(b, b + t.size);
    std::uint64_t u = 0; // b is little-endian now
    for (int k = t.size - 1; k >= 0; --k)
      u = u << 8 | b[k];
    const int shift = 64 - 8 * t.size; // sign extension through the top bit
    if (!t.integer)
      out = t.size == 4 ? double(load<float>(b)) : load<double>(b);
    else
      out = t.is_signed ? double(std::int64_t(u << shift) >> shift) : double(u);
    return true;
  }

  template <typename T> static T load(const unsigned char *b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

  std::string_view data_;
  PlyFormat format_;
  std::size_t pos_ = 0;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
};

PlyHeader parse_ply_header(const Path &path, const std::string &text) {
  PlyHeader header;
  bool have_format = false;
  std::size_t pos = 0;
  for (int line_no = 1;; ++line_no) {
    const std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos)
      fail(path, "header has no end_header line");
    std::string line = text.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    const auto bad = [&](const std::string &why) {
      fail(path, "header line " + std::to_string(line_no) + ": " + why);
    };
    std::istringstream words(line);
    std::vector<std::string> args((std::istream_iterator<std::string>(words)),
                                  std::istream_iterator<std::string>());
    const std::string key = args.empty() ? std::string() : args.front();
    if (!args.empty())
      args.erase(args.begin());
    if (line_no == 1 && line != "ply") {
      bad("not a PLY file");
    } else if (line_no == 1 || key.empty() || key == "comment" || key == "obj_info") {
      continue;
    } else if (key == "end_header") {
      break;
    } else if (key == "format") {
      const std::string f = args.size() == 2 ? args[0] : std::string();
      if (have_format || (f != "ascii" && f != "binary_little_endian" && f != "binary_big_endian"))
        bad("bad format line");
      header.format = f == "ascii"               ? PlyFormat::ascii
                      : f == "binary_big_endian" ? PlyFormat::big
                                                 : PlyFormat::little;
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      const std::string_view n = args.size() == 2 ? args[1] : std::string_view();
      const auto r = std::from_chars(n.data(), n.data() + n.size(), e.count);
      if (n.empty() || r.ec != std::errc() || r.ptr != n.data() + n.size())
        bad("bad element line");
      e.name = args[0];
      header.elements.push_back(std::move(e));
    } else if (key == "property") {
      PlyProperty p;
      p.is_list = !args.empty() && args[0] == "list";
      const bool ok = p.is_list ? args.size() == 4 && parse_ply_type(args[1], p.count_type) &&
                                      parse_ply_type(args[2], p.type) && p.count_type.integer
                                : args.size() == 2 && parse_ply_type(args[0], p.type);
      if (!ok || header.elements.empty())
        bad("bad property line");
      p.name = args.back();
      header.elements.back().properties.push_back(std::move(p));
    } else {
      bad("unknown keyword " + key);
    }
  }
  if (!have_format)
    fail(path, "header has no format line");
  header.body_offset = pos;
  return header;
}

// Where the vertex and face data sit among an element's properties.
struct PlyRoles {
  int axis[3] = {-1, -1, -1}; // x, y, z of a vertex
  int indices = -1;           // vertex_indices of a face
};

PlyRoles find_roles(const Path &path, const PlyElement &e) {
  const auto bad = [&](const std::string &why) { fail(path, "element " + e.name + ": " + why); };
  if (e.name == "vertex" && e.count > std::numeric_limits<std::uint32_t>::max())
    bad("too many vertices");
  PlyRoles roles;
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    const PlyProperty &p = e.properties[k];
    if (e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z")) {
      int &slot = roles.axis[p.name[0] - 'x'];
      if (slot >= 0 || p.is_list)
        bad("property " + p.name + " must be one scalar");
      slot = int(k);
    } else if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      if (roles.indices >= 0 || !p.is_list || !p.type.integer)
        bad("needs one integer list property vertex_indices");
      roles.indices = int(k);
    }
  }
  if (e.name == "vertex" && *std::min_element(roles.axis, roles.axis + 3) < 0)
    bad("needs properties x, y and z");
  if (e.name == "face" && roles.indices < 0)
    bad("needs a list property vertex_indices");
  return roles;
}

} // namespace

TriangleMesh parse_ply(const Path &path, const std::string &text) {
  const PlyHeader header = parse_ply_header(path, text);
  PlyBody body(std::string_view(text).substr(header.body_offset), header.format);
  // The whole layout is checked before any data is read.
  std::vector<PlyRoles> layout;
  int vertex_elements = 0, face_elements = 0;
  for (const PlyElement &e : header.elements) {
    vertex_elements += e.name == "vertex";
    face_elements += e.name == "face";
    if ((e.name == "vertex" && vertex_elements > 1) || (e.name == "face" && face_elements > 1))
      fail(path, "element " + e.name + ": appears twice");
    layout.push_back(find_roles(path, e));
  }
  if (vertex_elements == 0 || face_elements == 0)
    fail(path, "needs a vertex and a face element");
  TriangleMesh mesh;
  std::vector<std::uint32_t> corners;
  for (std::size_t ei = 0; ei < header.elements.size(); ++ei) {
    const PlyElement &e = header.elements[ei];
    const PlyRoles &roles = layout[ei];
    const auto bad = [&](const std::string &why) { fail(path, "element " + e.name + ": " + why); };
    if (e.name == "vertex")
      mesh.positions.reserve(std::size_t(std::min<std::uint64_t>(e.count, text.size())));
    // The loop below must consume bytes on every item, else a huge count of
    // an empty element would spin; such an element occupies no bytes at all.
    for (std::uint64_t item = 0; item < e.count && !e.properties.empty(); ++item) {
      const auto check = [&](bool ok) {
        if (!ok)
          bad((body.at_end() ? "truncated at item " : "bad value in item ") + std::to_string(item) +
              " of " + std::to_string(e.count));
      };
      double xyz[3] = {0.0, 0.0, 0.0};
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty &p = e.properties[k];
        double value = 0.0, count = 1.0;
        const bool collect = int(k) == roles.indices;
        if (p.is_list) {
          check(body.read(p.count_type, count) && count >= 0.0);
          corners.clear();
        }
        for (std::uint64_t c = 0; c < std::uint64_t(count); ++c) {
          check(body.read(p.type, value));
          if (collect) {
            check(value >= 0.0 && value <= double(std::numeric_limits<std::uint32_t>::max()));
            corners.push_back(std::uint32_t(value));
          }
        }
        for (int a = 0; a < 3; ++a)
          xyz[a] = int(k) == roles.axis[a] ? value : xyz[a];
        if (collect)
          add_polygon(mesh, corners);
      }
      // A double beyond the float range has no float value (UB to convert).
      const auto in_range = [](double v) {
        return std::abs(v) <= double(std::numeric_limits<float>::max());
      };
      if (e.name == "vertex") {
        check(in_range(xyz[0]) && in_range(xyz[1]) && in_range(xyz[2]));
        mesh.positions.emplace_back(float(xyz[0]), float(xyz[1]), float(xyz[2]));
      }
    }
  }
  return mesh;
}

} // namespace camhead::renderer::detail
