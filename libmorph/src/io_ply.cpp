// PLY (Stanford polygon format): a text header declaring elements and their properties,
// then the data in ascii (one element per line), binary_little_endian or
// binary_big_endian. Vertices come from element "vertex" (properties x, y, z of any
// numeric type), faces from element "face" (list property "vertex_indices" or
// "vertex_index" with integer count and index types); every other element and property
// is skipped. A float-typed coordinate is read as that float, exactly.
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "io_detail.h"

namespace morph::io_detail {
namespace {

enum class Type { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct TypeName {
  std::string_view name;
  Type type;
};
constexpr std::array<TypeName, 16> kTypeNames = {{
    {"char", Type::int8},
    {"int8", Type::int8},
    {"uchar", Type::uint8},
    {"uint8", Type::uint8},
    {"short", Type::int16},
    {"int16", Type::int16},
    {"ushort", Type::uint16},
    {"uint16", Type::uint16},
    {"int", Type::int32},
    {"int32", Type::int32},
    {"uint", Type::uint32},
    {"uint32", Type::uint32},
    {"float", Type::float32},
    {"float32", Type::float32},
    {"double", Type::float64},
    {"float64", Type::float64},
}};

std::size_t size_of(Type type) {
  switch (type) {
    case Type::int8:
    case Type::uint8:
      return 1;
    case Type::int16:
    case Type::uint16:
      return 2;
    case Type::int32:
    case Type::uint32:
    case Type::float32:
      return 4;
    case Type::float64:
      return 8;
  }
  return 0;
}

bool is_integer(Type type) { return type != Type::float32 && type != Type::float64; }

// Scalar of `type` at `p`, as a double (exact for every PLY type).
double read_number(Type type, const char* p, std::endian order) {
  switch (type) {
    case Type::int8:
      return from_bytes<std::int8_t>(p, order);
    case Type::uint8:
      return from_bytes<std::uint8_t>(p, order);
    case Type::int16:
      return from_bytes<std::int16_t>(p, order);
    case Type::uint16:
      return from_bytes<std::uint16_t>(p, order);
    case Type::int32:
      return from_bytes<std::int32_t>(p, order);
    case Type::uint32:
      return from_bytes<std::uint32_t>(p, order);
    case Type::float32:
      return from_bytes<float>(p, order);
    case Type::float64:
      return from_bytes<double>(p, order);
  }
  return 0;
}

struct Property {
  std::string name;
  Type type = Type::float64;       // of the value, or of the items of a list
  std::optional<Type> count_type;  // set for a list
};

// What a property means to the reader.
enum class Role { skip, x, y, z, face_indices };

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::vector<Role> roles;
  std::size_t line = 0;  // of its header line
};

enum class Encoding { ascii, binary_little_endian, binary_big_endian };

struct Header {
  Encoding encoding = Encoding::ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // first byte after end_header
  std::size_t body_line = 0;    // ascii: line number of the first data line
};

std::optional<Type> type_named(std::string_view word) {
  for (const TypeName& t : kTypeNames) {
    if (t.name == word) return t.type;
  }
  return std::nullopt;
}

Header parse_header(std::string_view data, std::string_view name) {
  LineReader lines(data);
  std::string_view line;
  if (!lines.next(line) || line != "ply") {
    fail_at_line(name, 1, "missing PLY header: the file must start with the line 'ply'");
  }
  Header header;
  bool have_format = false;
  std::string_view token;
  for (;;) {
    if (!lines.next(line)) fail_at_line(name, lines.line(), "the header has no 'end_header' line");
    const std::size_t at = lines.line();
    Tokens tokens(line);
    if (!tokens.next(token)) continue;
    if (token == "end_header") break;
    if (token == "comment" || token == "obj_info") continue;
    const std::string_view keyword = token;
    std::vector<std::string_view> words;
    while (tokens.next(token)) words.push_back(token);
    if (keyword == "format") {
      if (words.size() != 2 || words[1] != "1.0") {
        fail_at_line(name, at,
                     "expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      }
      if (words[0] == "ascii") {
        header.encoding = Encoding::ascii;
      } else if (words[0] == "binary_little_endian") {
        header.encoding = Encoding::binary_little_endian;
      } else if (words[0] == "binary_big_endian") {
        header.encoding = Encoding::binary_big_endian;
      } else {
        fail_at_line(name, at, "unknown PLY format '" + std::string(words[0]) + "'");
      }
      have_format = true;
    } else if (keyword == "element") {
      if (words.size() != 2) fail_at_line(name, at, "expected 'element <name> <count>'");
      const std::int64_t count = parse_integer(words[1], name, at, "element count");
      if (count < 0) fail_at_line(name, at, "negative element count");
      for (const Element& e : header.elements) {
        if (e.name == words[0]) fail_at_line(name, at, "element '" + e.name + "' declared twice");
      }
      header.elements.push_back(
          {std::string(words[0]), static_cast<std::uint64_t>(count), {}, {}, at});
    } else if (keyword == "property") {
      if (header.elements.empty()) fail_at_line(name, at, "property before any element");
      Property property;
      std::string_view type_word;
      if (!words.empty() && words[0] == "list") {
        if (words.size() != 4) {
          fail_at_line(name, at, "expected 'property list <count type> <item type> <name>'");
        }
        property.count_type = type_named(words[1]);
        if (!property.count_type || !is_integer(*property.count_type)) {
          fail_at_line(name, at,
                       "list count type '" + std::string(words[1]) + "' is not an integer type");
        }
        type_word = words[2];
      } else {
        if (words.size() != 2) fail_at_line(name, at, "expected 'property <type> <name>'");
        type_word = words[0];
      }
      auto type = type_named(type_word);
      if (!type) fail_at_line(name, at, "unknown property type '" + std::string(type_word) + "'");
      property.type = *type;
      property.name = std::string(words.back());
      header.elements.back().properties.push_back(property);
      header.elements.back().roles.push_back(Role::skip);
    } else {
      fail_at_line(
          name, at,
          "unknown header line starting with '" + std::string(keyword.substr(0, 40)) + "'");
    }
  }
  if (!have_format) fail_in_file(name, "the header has no 'format' line");
  header.body_offset = data.size() - lines.remaining();
  header.body_line = lines.line() + 1;
  return header;
}

// Assigns roles: the coordinates of "vertex", the index list of "face".
void assign_roles(Header& header, std::string_view name) {
  for (Element& element : header.elements) {
    if (element.properties.empty() && element.count > 0) {
      fail_at_line(name, element.line, "element '" + element.name + "' has no properties");
    }
    if (element.name == "vertex") {
      const char* axes[3] = {"x", "y", "z"};
      for (int axis = 0; axis < 3; ++axis) {
        bool found = false;
        for (std::size_t p = 0; p < element.properties.size() && !found; ++p) {
          if (element.properties[p].name != axes[axis]) continue;
          if (element.properties[p].count_type) {
            fail_at_line(name, element.line,
                         std::string("vertex property ") + axes[axis] + " is a list");
          }
          element.roles[p] = static_cast<Role>(static_cast<int>(Role::x) + axis);
          found = true;
        }
        if (!found) {
          fail_at_line(name, element.line,
                       std::string("element vertex has no property ") + axes[axis]);
        }
      }
    } else if (element.name == "face") {
      bool found = false;
      for (std::size_t p = 0; p < element.properties.size() && !found; ++p) {
        const Property& property = element.properties[p];
        if (property.name != "vertex_indices" && property.name != "vertex_index") continue;
        if (!property.count_type || !is_integer(property.type)) {
          fail_at_line(name, element.line,
                       "face property " + property.name + " must be a list of integers");
        }
        element.roles[p] = Role::face_indices;
        found = true;
      }
      if (!found) {
        fail_at_line(name, element.line, "element face has no list property vertex_indices");
      }
    }
  }
}

// Smallest encoding of one instance: 2 bytes a value in ascii ("0 "), the fixed part
// of the binary record (lists may be empty).
std::uint64_t min_bytes(const Element& element, Encoding encoding) {
  std::uint64_t bytes = 0;
  for (const Property& property : element.properties) {
    if (encoding == Encoding::ascii) {
      bytes += 2;
    } else {
      bytes += size_of(property.count_type ? *property.count_type : property.type);
    }
  }
  return bytes;
}

void check_sizes(const Header& header, std::string_view name, const ReadLimits& limits,
                 std::uint64_t available) {
  std::uint64_t total = 0;
  for (const Element& element : header.elements) {
    std::uint64_t max_count = std::numeric_limits<std::uint64_t>::max();
    std::string what = "'" + element.name + "' elements";
    if (element.name == "vertex") {
      max_count = limits.max_vertices;
      what = "vertices";
    } else if (element.name == "face") {
      max_count = limits.max_faces;
      what = "faces";
    }
    const std::uint64_t bytes = min_bytes(element, header.encoding);
    check_count(name, what, element.count, max_count, bytes, available);
    total += element.count * bytes;
    if (total > available) {
      fail_limit(name, "the element counts in the header cannot fit in the " +
                           std::to_string(available) +
                           " bytes that follow (truncated file or wrong counts)");
    }
  }
}

// Reads the elements; one class for both encodings keeps the roles in one place.
class BodyReader {
 public:
  BodyReader(const Header& header, std::string_view body, std::string_view name,
             const ReadLimits& limits)
      : header_(header), body_(body), name_(name), limits_(limits) {
    for (const Element& e : header.elements) {
      if (e.name == "vertex") n_vertices_ = e.count;
    }
    if (header.encoding == Encoding::binary_big_endian) order_ = std::endian::big;
  }

  MeshData read() {
    for (const Element& e : header_.elements) {
      if (e.name == "vertex") mesh_.points.reserve(e.count);
      if (e.name == "face") {
        mesh_.face_end.reserve(e.count);
        mesh_.corners.reserve(3 * e.count);
        if (header_.encoding == Encoding::ascii) mesh_.face_line.reserve(e.count);
      }
    }
    if (header_.encoding == Encoding::ascii) {
      read_ascii();
    } else {
      read_binary();
    }
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const Element& element, std::uint64_t index, const std::string& what,
                         bool limit = false) {
    std::string message = std::string(name_) + ":";
    if (header_.encoding == Encoding::ascii) message += std::to_string(line_) + ":";
    message += " " + element.name + " " + std::to_string(index) + ": " + what;
    if (limit) throw limit_error(message);
    throw input_error(message);
  }

  void check_valence(const Element& element, std::uint64_t index, std::int64_t count) {
    if (count < 0) fail(element, index, "negative list count");
    if (static_cast<std::uint64_t>(count) > limits_.max_face_valence) {
      fail(element, index,
           "has " + std::to_string(count) + " vertices, more than the limit of " +
               std::to_string(limits_.max_face_valence),
           true);
    }
  }

  void add_index(const Element& element, std::uint64_t index, double value) {
    if (value < 0 || value >= static_cast<double>(n_vertices_)) {
      fail(element, index,
           "vertex index " + std::to_string(static_cast<std::int64_t>(value)) +
               " is out of range (the file has " + std::to_string(n_vertices_) + " vertices)");
    }
    mesh_.corners.push_back(static_cast<int>(value));
  }

  void read_ascii() {
    LineReader lines(body_, header_.body_line);
    std::string_view line;
    std::string_view token;
    for (const Element& element : header_.elements) {
      for (std::uint64_t i = 0; i < element.count; ++i) {
        do {
          if (!lines.next(line)) {
            fail(element, i,
                 "truncated: the header declares " + std::to_string(element.count) + " " +
                     element.name + " elements");
          }
          line_ = lines.line();
        } while (is_blank(line));
        Tokens tokens(line);
        double xyz[3] = {0, 0, 0};
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const Property& property = element.properties[p];
          const Role role = element.roles[p];
          auto next = [&]() {
            if (!tokens.next(token)) fail(element, i, "too few values for its properties");
            return token;
          };
          if (property.count_type) {
            const std::int64_t count = parse_integer(next(), name_, line_, "list count");
            if (role == Role::face_indices) check_valence(element, i, count);
            if (count < 0) fail(element, i, "negative list count");
            for (std::int64_t k = 0; k < count; ++k) {
              std::string_view item = next();
              if (role == Role::face_indices) {
                add_index(element, i,
                          static_cast<double>(parse_integer(item, name_, line_, "vertex index")));
              }
            }
            if (role == Role::face_indices) {
              mesh_.add_face_line(line_);
              mesh_.end_face();
            }
          } else if (role == Role::skip) {
            next();
          } else {
            std::string_view value = next();
            double& c = xyz[static_cast<int>(role) - static_cast<int>(Role::x)];
            if (property.type == Type::float32) {
              c = parse_float_coordinate(value, name_, line_);
            } else if (property.type == Type::float64) {
              c = parse_coordinate(value, name_, line_);
            } else {
              c = static_cast<double>(parse_integer(value, name_, line_, "coordinate"));
            }
          }
        }
        if (!tokens.empty()) fail(element, i, "more values than its properties");
        if (element.name == "vertex") mesh_.points.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
    }
    while (lines.next(line)) {
      if (!is_blank(line)) {
        fail_at_line(name_, lines.line(), "unexpected content after the last element");
      }
    }
  }

  // `bytes` more bytes of element `i`, or a truncation error.
  const char* take(const Element& element, std::uint64_t i, std::uint64_t bytes) {
    if (bytes > body_.size() - pos_) {
      fail(element, i,
           "the file ends inside this element (truncated, or the header counts are wrong)");
    }
    const char* p = body_.data() + pos_;
    pos_ += bytes;
    return p;
  }

  void read_binary() {
    for (const Element& element : header_.elements) {
      for (std::uint64_t i = 0; i < element.count; ++i) {
        double xyz[3] = {0, 0, 0};
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const Property& property = element.properties[p];
          const Role role = element.roles[p];
          const std::size_t item_size = size_of(property.type);
          if (property.count_type) {
            const double count_value = read_number(
                *property.count_type, take(element, i, size_of(*property.count_type)), order_);
            const auto count = static_cast<std::int64_t>(count_value);
            if (role == Role::face_indices) check_valence(element, i, count);
            if (count < 0) fail(element, i, "negative list count");
            const char* items = take(element, i, static_cast<std::uint64_t>(count) * item_size);
            if (role == Role::face_indices) {
              for (std::int64_t k = 0; k < count; ++k) {
                add_index(element, i, read_number(property.type, items + k * item_size, order_));
              }
              mesh_.end_face();
            }
          } else {
            const double value = read_number(property.type, take(element, i, item_size), order_);
            if (role == Role::skip) continue;
            if (!std::isfinite(value)) fail(element, i, "coordinate is not finite");
            xyz[static_cast<int>(role) - static_cast<int>(Role::x)] = value;
          }
        }
        if (element.name == "vertex") mesh_.points.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
    }
    if (pos_ != body_.size()) {
      fail_in_file(name_,
                   std::to_string(body_.size() - pos_) +
                       " bytes follow the last element: the file size does not match the header");
    }
  }

  const Header& header_;
  std::string_view body_;
  std::string_view name_;
  const ReadLimits& limits_;
  std::uint64_t n_vertices_ = 0;
  std::endian order_ = std::endian::little;
  std::size_t pos_ = 0;   // binary: next byte
  std::size_t line_ = 0;  // ascii: current line
  MeshData mesh_;
};

}  // namespace

Mesh read_ply(std::string_view data, std::string_view name, const ReadLimits& limits) {
  Header header = parse_header(data, name);
  assign_roles(header, name);
  const std::string_view body = data.substr(header.body_offset);
  // The last ascii line may lack its newline, hence the one spare byte.
  check_sizes(header, name, limits, body.size() + (header.encoding == Encoding::ascii ? 1 : 0));
  MeshData mesh = BodyReader(header, body, name, limits).read();
  return build_mesh(mesh, name, limits);
}

void write_ply(const WriteView& view, const Mesh& mesh, std::ostream& out, bool binary) {
  BlockWriter writer(out);
  std::string& text = writer.buffer();
  const bool wide_counts = view.max_valence > 255;
  text += "ply\nformat ";
  text += binary ? "binary_little_endian" : "ascii";
  text += " 1.0\ncomment written by libmorph\nelement vertex ";
  append_integer(text, view.vertices.size());
  text += "\nproperty double x\nproperty double y\nproperty double z\nelement face ";
  append_integer(text, view.faces.size());
  text += wide_counts ? "\nproperty list uint int vertex_indices\n"
                      : "\nproperty list uchar int vertex_indices\n";
  if (!view.colors.empty())
    text += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  text += "end_header\n";
  for (Mesh::VertexHandle v : view.vertices) {
    const Point& p = mesh.point(v);
    if (binary) {
      for (int i = 0; i < 3; ++i) append_le<double>(text, p[i]);
    } else {
      append_point(text, p);
      text += '\n';
    }
    writer.maybe_flush();
  }
  for (std::size_t f = 0; f < view.faces.size(); ++f) {
    const std::size_t valence = mesh.valence(view.faces[f]);
    if (binary) {
      if (wide_counts) {
        append_le<std::uint32_t>(text, static_cast<std::uint32_t>(valence));
      } else {
        append_le<std::uint8_t>(text, static_cast<std::uint8_t>(valence));
      }
    } else {
      append_integer(text, valence);
    }
    for (Mesh::VertexHandle v : mesh.fv_range(view.faces[f])) {
      if (binary) {
        append_le<std::int32_t>(text, view.index_of[v.idx()]);
      } else {
        text += ' ';
        append_integer(text, static_cast<std::uint64_t>(view.index_of[v.idx()]));
      }
    }
    if (!view.colors.empty()) {
      for (std::uint8_t channel : view.colors[f]) {
        if (binary) {
          append_le<std::uint8_t>(text, channel);
        } else {
          text += ' ';
          append_integer(text, channel);
        }
      }
    }
    if (!binary) text += '\n';
    writer.maybe_flush();
  }
  writer.finish();
}

}  // namespace morph::io_detail
