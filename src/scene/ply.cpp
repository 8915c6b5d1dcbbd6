// The PLY reader (ply.h). The header becomes a list of elements with typed properties; the data is
// checked against it as a whole before anything is allocated; then every entry is read through
// one of two cursors with the same interface: Binary (every read bounds-checked, located by byte
// offset) and Ascii (whitespace-separated numbers parsed whole, located by line and column).
#include "scene/ply.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "io/input_file.h"

namespace pathex {
namespace {

// --- types ---

enum class Type : std::uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeName {
  const char* name;
  Type type;
};
constexpr TypeName kTypeNames[] = {
    {"char", Type::kInt8},     {"int8", Type::kInt8},       {"uchar", Type::kUint8},   {"uint8", Type::kUint8},
    {"short", Type::kInt16},   {"int16", Type::kInt16},     {"ushort", Type::kUint16}, {"uint16", Type::kUint16},
    {"int", Type::kInt32},     {"int32", Type::kInt32},     {"uint", Type::kUint32},   {"uint32", Type::kUint32},
    {"float", Type::kFloat32}, {"float32", Type::kFloat32}, {"double", Type::kFloat64}, {"float64", Type::kFloat64}};

std::size_t size_of(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8: return 1;
    case Type::kInt16:
    case Type::kUint16: return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32: return 4;
    case Type::kFloat64: return 8;
  }
  return 1;
}
bool is_integer(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }
const char* name_of(Type t) {
  for (const TypeName& n : kTypeNames)
    if (n.type == t) return n.name;
  return "?";
}
// "an int", "a float": the type with its article, for messages.
std::string a(Type t) { return std::string(name_of(t)[0] == 'i' ? "an " : "a ") + name_of(t); }
std::optional<Type> type_named(std::string_view s) {
  for (const TypeName& n : kTypeNames)
    if (s == n.name) return n.type;
  return std::nullopt;
}
// The values of an integer type.
std::pair<std::int64_t, std::int64_t> range_of(Type t) {
  switch (t) {
    case Type::kInt8: return {-128, 127};
    case Type::kUint8: return {0, 255};
    case Type::kInt16: return {-32768, 32767};
    case Type::kUint16: return {0, 65535};
    case Type::kInt32: return {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()};
    default: return {0, std::numeric_limits<std::uint32_t>::max()};
  }
}

// A word of the file in a message, cut short (a 16 MiB word must not become 16 MiB of stderr).
std::string quoted(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out = "'" + std::string(s.substr(0, kMax));
  if (s.size() > kMax) out += "…";
  return out + "'";
}

std::string str(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// --- the header ---

// What a property feeds: a vertex component, the face's corners, or nothing.
enum Slot : std::uint8_t { kSkip, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kCorners, kSlots };

struct Property {
  std::string name;
  bool list = false;
  Type count_type = Type::kUint8;  // lists only
  Type type = Type::kFloat32;      // the value's, or a list's entries'
  Slot slot = kSkip;
};

struct Element {
  enum Role { kOther, kVertex, kFace };
  std::string name;
  Role role = kOther;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  int line = 0, column = 0;  // of its count in the header
};

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t data_start = 0;  // the byte after end_header's newline
  int data_line = 0;           // the line it is on
  bool normals = false, uvs = false;
  std::uint64_t vertices = 0;
};

Error fail_at(const std::string& name, int line, int column, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = name + ":" + std::to_string(line) + (column > 0 ? ":" + std::to_string(column) : "");
  return e;
}

// Line and column of a byte offset (error paths only).
std::pair<int, int> line_column(std::string_view bytes, std::size_t offset) {
  int line = 1;
  std::size_t start = 0;
  for (std::size_t i = 0; i < offset && i < bytes.size(); ++i)
    if (bytes[i] == '\n') {
      ++line;
      start = i + 1;
    }
  return {line, static_cast<int>(offset - start) + 1};
}

struct Word {
  std::string_view text;
  int column;
};

std::vector<Word> split(std::string_view line) {
  std::vector<Word> out;
  std::size_t i = 0;
  while (i < line.size()) {
    if (line[i] == ' ' || line[i] == '\t') {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    out.push_back({line.substr(i, j - i), static_cast<int>(i) + 1});
    i = j;
  }
  return out;
}

// A count: decimal digits, as a 64-bit integer.
std::optional<std::uint64_t> parse_count(std::string_view s) {
  if (s.empty()) return std::nullopt;
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
    const auto d = static_cast<std::uint64_t>(c - '0');
    if (v > (std::numeric_limits<std::uint64_t>::max() - d) / 10) return std::nullopt;
    v = v * 10 + d;
  }
  return v;
}

Result<Header> parse_header(std::string_view bytes, const std::string& name) {
  Header h;
  std::size_t pos = 0;
  int line = 0;
  bool format = false;
  const char* const kExpected = "expected element, property, comment, obj_info or end_header";
  for (;;) {
    if (pos >= bytes.size()) {
      const auto [l, c] = line_column(bytes, bytes.size());
      return fail_at(name, l, c, line == 0 ? "the file is empty, expected a PLY header ('ply' on the first line)"
                                           : "the file ends inside the header: expected an end_header line");
    }
    ++line;
    const std::size_t end = bytes.find('\n', pos);
    std::string_view text = bytes.substr(pos, (end == std::string_view::npos ? bytes.size() : end) - pos);
    pos = end == std::string_view::npos ? bytes.size() : end + 1;
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    auto fail = [&](int column, std::string message) { return fail_at(name, line, column, std::move(message)); };
    if (line == 1) {
      if (text != "ply") return fail(1, "expected 'ply' on the first line: this is not a PLY file");
      continue;
    }
    const std::vector<Word> w = split(text);
    if (w.empty()) continue;
    const std::string_view key = w[0].text;
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (format) return fail(1, "a second format line");
      if (w.size() != 3) return fail(1, "expected 'format ascii 1.0', 'format binary_little_endian 1.0' or 'format binary_big_endian 1.0'");
      if (w[1].text == "ascii") h.format = Format::kAscii;
      else if (w[1].text == "binary_little_endian") h.format = Format::kBinaryLittle;
      else if (w[1].text == "binary_big_endian") h.format = Format::kBinaryBig;
      else return fail(w[1].column, "unknown format " + quoted(w[1].text) + ", expected ascii, binary_little_endian or binary_big_endian");
      if (w[2].text != "1.0") return fail(w[2].column, "PLY version " + quoted(w[2].text) + " is not supported, expected 1.0");
      format = true;
      continue;
    }
    if (key == "end_header" || key == "element") {
      if (!format) return fail(1, "expected a format line before " + std::string(key));
    }
    if (key == "end_header") {
      if (w.size() != 1) return fail(w[1].column, "unexpected " + quoted(w[1].text) + " after end_header");
      break;
    }
    if (key == "element") {
      if (w.size() != 3) return fail(1, "expected 'element NAME COUNT'");
      for (const Element& e : h.elements)
        if (e.name == w[1].text) return fail(w[1].column, "element " + quoted(w[1].text) + " is declared twice");
      Element e;
      e.name = std::string(w[1].text);
      e.role = e.name == "vertex" ? Element::kVertex : e.name == "face" ? Element::kFace : Element::kOther;
      e.line = line;
      e.column = w[2].column;
      const std::optional<std::uint64_t> count = parse_count(w[2].text);
      if (!count) {
        const bool digits = w[2].text.find_first_not_of("0123456789") == std::string_view::npos && !w[2].text.empty();
        return fail(w[2].column, "element count " + quoted(w[2].text) +
                                     (digits ? " is too large (more than 2^64 - 1)" : " is not a count, expected a non-negative integer"));
      }
      e.count = *count;
      h.elements.push_back(std::move(e));
      continue;
    }
    if (key == "property") {
      if (h.elements.empty()) return fail(1, "a property before any element line");
      Element& e = h.elements.back();
      Property p;
      std::size_t name_word = 2;
      if (w.size() >= 2 && w[1].text == "list") {
        if (w.size() != 5) return fail(1, "expected 'property list COUNT_TYPE TYPE NAME'");
        const std::optional<Type> count_type = type_named(w[2].text), type = type_named(w[3].text);
        if (!count_type || !is_integer(*count_type))
          return fail(w[2].column, "list count type " + quoted(w[2].text) + " is not an integer type (char, uchar, short, ushort, int, uint)");
        if (!type) return fail(w[3].column, "unknown type " + quoted(w[3].text) + ", expected char, uchar, short, ushort, int, uint, float or double");
        p.list = true;
        p.count_type = *count_type;
        p.type = *type;
        name_word = 4;
      } else {
        if (w.size() != 3) return fail(1, "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
        const std::optional<Type> type = type_named(w[1].text);
        if (!type) return fail(w[1].column, "unknown type " + quoted(w[1].text) + ", expected char, uchar, short, ushort, int, uint, float or double");
        p.type = *type;
      }
      p.name = std::string(w[name_word].text);
      for (const Property& q : e.properties)
        if (q.name == p.name) return fail(w[name_word].column, "property " + quoted(p.name) + " is declared twice in element " + quoted(e.name));
      e.properties.push_back(std::move(p));
      continue;
    }
    return fail(1, "unknown header line starting " + quoted(key) + ", " + kExpected);
  }
  h.data_start = pos;
  h.data_line = line + 1;
  // --- what the elements feed ---
  auto at_element = [&](const Element& e, std::string message) { return fail_at(name, e.line, 1, std::move(message)); };
  const Element* vertex = nullptr;
  for (Element& e : h.elements) {
    auto find = [&](const char* n) -> Property* {
      for (Property& p : e.properties)
        if (p.name == n) return &p;
      return nullptr;
    };
    if (e.role == Element::kVertex) {
      vertex = &e;
      h.vertices = e.count;
      // Scalars only, in groups that are all there or all absent.
      auto group = [&](std::initializer_list<std::pair<const char*, Slot>> names, bool required, bool* present) -> std::optional<Error> {
        int found = 0;
        for (const auto& [n, slot] : names) found += find(n) != nullptr;
        if (found == 0 && !required) return std::nullopt;
        if (found != static_cast<int>(names.size())) {
          std::string list;
          for (const auto& [n, slot] : names) list += (list.empty() ? "" : ", ") + std::string(n);
          for (const auto& [n, slot] : names)
            if (!find(n))
              return at_element(e, "element vertex has no property " + quoted(n) + (required ? ", expected " : ", expected all or none of ") + list);
        }
        for (const auto& [n, slot] : names) {
          Property* p = find(n);
          if (p->list) return at_element(e, "property " + quoted(n) + " of element vertex is a list, expected a number");
          p->slot = slot;
        }
        if (present) *present = true;
        return std::nullopt;
      };
      if (auto err = group({{"x", kX}, {"y", kY}, {"z", kZ}}, /*required=*/true, nullptr)) return *err;
      if (auto err = group({{"nx", kNx}, {"ny", kNy}, {"nz", kNz}}, false, &h.normals)) return *err;
      // pbrt-v4 and Mitsuba 3 take the first of these pairs the file has.
      for (const auto& [u, v] : {std::pair{"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}) {
        if (h.uvs) break;
        if (auto err = group({{u, kU}, {v, kV}}, false, &h.uvs)) return *err;
      }
    } else if (e.role == Element::kFace) {
      Property* a = find("vertex_indices");
      Property* b = find("vertex_index");
      if (a && b) return at_element(e, "element face has both vertex_indices and vertex_index, expected one");
      Property* p = a ? a : b;
      if (!p) return at_element(e, "element face has no property vertex_indices (or vertex_index)");
      if (!p->list || !is_integer(p->type))
        return at_element(e, "property " + quoted(p->name) + " of element face must be a list of integers, found " +
                                 (p->list ? "a list of " : "a ") + name_of(p->type));
      p->slot = kCorners;
    }
  }
  if (!vertex) return fail_at(name, line, 1, "the header declares no element vertex");
  return h;
}

// --- the data: one interface, two cursors ---

// A value read: integers exactly (integer types), every type as a double.
struct Number {
  std::int64_t integer = 0;
  double real = 0.0;
};

// The entry being read, for messages: "vertex 3", "face 7", "element 'edge' entry 2".
struct Context {
  const Element* element = nullptr;
  std::uint64_t index = 0;
  const Property* property = nullptr;
  std::string what() const {
    if (element->role == Element::kVertex) return "vertex " + std::to_string(index);
    if (element->role == Element::kFace) return "face " + std::to_string(index);
    return "element " + quoted(element->name) + " entry " + std::to_string(index);
  }
};

class Binary {
 public:
  using Pos = std::size_t;
  Binary(std::string_view data, std::size_t start, bool swap, const std::string& name)
      : data_(data), pos_(start), swap_(swap), name_(name) {}

  std::size_t available() const { return data_.size() - pos_; }
  Pos last() const { return last_; }
  Error fail(Pos at, const std::string& message) const {
    Error e = make_error(ErrorCode::kBadFile, "byte " + std::to_string(at) + ": " + message);
    e.where = name_;
    return e;
  }

  std::optional<Error> next(Type t, const Context& c, Number* out) {
    const std::size_t n = size_of(t);
    last_ = pos_;
    if (available() < n)
      return fail(pos_, c.what() + ": the file ends, expected " + a(t) + " (" + c.property->name + ")");
    const char* p = data_.data() + pos_;
    pos_ += n;
    switch (t) {
      case Type::kInt8: out->integer = load<std::int8_t>(p); break;
      case Type::kUint8: out->integer = load<std::uint8_t>(p); break;
      case Type::kInt16: out->integer = load<std::int16_t>(p); break;
      case Type::kUint16: out->integer = load<std::uint16_t>(p); break;
      case Type::kInt32: out->integer = load<std::int32_t>(p); break;
      case Type::kUint32: out->integer = load<std::uint32_t>(p); break;
      case Type::kFloat32: out->real = load<float>(p); return std::nullopt;
      case Type::kFloat64: out->real = load<double>(p); return std::nullopt;
    }
    out->real = static_cast<double>(out->integer);
    return std::nullopt;
  }
  // A list of `count` entries of type t fits in what is left.
  bool fits(std::uint64_t count, Type t) const { return count <= available() / size_of(t); }
  std::string left() const { return std::to_string(available()) + " bytes"; }
  std::optional<Error> skip(std::uint64_t count, Type t, const Context&) {  // fits() first
    pos_ += static_cast<std::size_t>(count) * size_of(t);
    return std::nullopt;
  }
  // `count` entries of `size` bytes each (earlier lists may have left less than the check before
  // reading assumed).
  std::optional<Error> skip_entries(std::uint64_t count, std::uint64_t size, const Context& c) {
    if (count > available() / size)
      return fail(pos_, "the file ends inside element " + quoted(c.element->name) + ", expected " + std::to_string(count) +
                            " entries of " + std::to_string(size) + " bytes (" + std::to_string(available()) + " bytes left)");
    pos_ += static_cast<std::size_t>(count * size);
    return std::nullopt;
  }
  std::optional<Error> finish() const {
    if (available() == 0) return std::nullopt;
    return fail(pos_, std::to_string(available()) + (available() == 1 ? " byte" : " bytes") + " after the last element: the header declares less data than the file holds");
  }

 private:
  template <class T>
  T load(const char* p) const {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap_) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
  std::string_view data_;
  std::size_t pos_ = 0, last_ = 0;
  bool swap_ = false;
  const std::string& name_;
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

class Ascii {
 public:
  struct Pos {
    int line = 0, column = 0;
  };
  Ascii(std::string_view data, std::size_t start, int line, const std::string& name)
      : data_(data), pos_(start), line_(line), line_start_(start), name_(name) {
    for (std::size_t i = start; i < data.size();) {  // the numbers the data holds
      while (i < data.size() && is_space(data[i])) ++i;
      if (i == data.size()) break;
      ++tokens_;
      while (i < data.size() && !is_space(data[i])) ++i;
    }
  }

  std::uint64_t available() const { return tokens_; }
  Pos last() const { return last_; }
  Error fail(Pos at, std::string message) const { return fail_at(name_, at.line, at.column, std::move(message)); }

  std::optional<Error> next(Type t, const Context& c, Number* out) {
    std::string_view tok;
    if (!token(&tok))
      return fail(last_, c.what() + ": the file ends, expected " + a(t) + " (" + c.property->name + ")");
    std::string_view s = tok;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);  // from_chars takes no '+'
    const char* end = s.data() + s.size();
    if (is_integer(t)) {
      std::int64_t v = 0;
      const auto [p, ec] = std::from_chars(s.data(), end, v);
      if (ec == std::errc::invalid_argument || p != end)
        return fail(last_, c.what() + ": " + quoted(tok) + " is not an integer (" + c.property->name + " is " + a(t) + ")");
      const auto [lo, hi] = range_of(t);
      if (ec == std::errc::result_out_of_range || v < lo || v > hi)
        return fail(last_, c.what() + ": " + quoted(tok) + " is out of range of " + name_of(t) + " (" + c.property->name + ")");
      out->integer = v;
      out->real = static_cast<double>(v);
      return std::nullopt;
    }
    double v = 0.0;
    const auto [p, ec] = std::from_chars(s.data(), end, v);
    if (ec == std::errc::invalid_argument || p != end)
      return fail(last_, c.what() + ": " + quoted(tok) + " is not a number (" + c.property->name + " is " + a(t) + ")");
    if (ec == std::errc::result_out_of_range) v = std::strtod(std::string(s).c_str(), nullptr);  // ±HUGE_VAL or ±0
    out->real = v;
    return std::nullopt;
  }
  bool fits(std::uint64_t count, Type) const { return count <= tokens_; }
  std::string left() const { return std::to_string(tokens_) + " numbers"; }
  std::optional<Error> skip(std::uint64_t count, Type t, const Context& c) {  // each a number of its type
    Number n;
    for (std::uint64_t i = 0; i < count; ++i)
      if (auto e = next(t, c, &n)) return e;
    return std::nullopt;
  }
  std::optional<Error> finish() {
    std::string_view tok;
    if (!token(&tok)) return std::nullopt;
    return fail(last_, quoted(tok) + " after the last element: the header declares fewer values than the file holds");
  }

 private:
  bool token(std::string_view* out) {
    while (pos_ < data_.size() && is_space(data_[pos_])) {
      if (data_[pos_] == '\n') {
        ++line_;
        line_start_ = pos_ + 1;
      }
      ++pos_;
    }
    last_ = Pos{line_, static_cast<int>(pos_ - line_start_) + 1};
    if (pos_ == data_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
    *out = data_.substr(start, pos_ - start);
    --tokens_;
    return true;
  }
  std::string_view data_;
  std::size_t pos_;
  int line_;
  std::size_t line_start_;
  std::uint64_t tokens_ = 0;  // left
  Pos last_;
  const std::string& name_;
};

// The least an entry of `e` takes: bytes (binary) or numbers (ASCII). A list takes at least its
// count, and the face's corners at least three entries.
std::uint64_t least(const Element& e, bool binary) {
  std::uint64_t n = 0;
  for (const Property& p : e.properties) {
    if (!p.list) n += binary ? size_of(p.type) : 1;
    else n += (binary ? size_of(p.count_type) : 1) + (p.slot == kCorners ? 3 * (binary ? size_of(p.type) : 1) : 0);
  }
  return n;
}

std::string noun(const Element& e) {
  return e.role == Element::kVertex ? "vertices" : e.role == Element::kFace ? "faces" : "entries";
}

template <class Cursor>
std::optional<Error> skip_list(Cursor& in, const Property& p, const Context& c) {
  Number count;
  if (auto e = in.next(p.count_type, c, &count)) return e;
  if (count.integer < 0)
    return in.fail(in.last(), c.what() + ": list " + quoted(p.name) + " has a negative count (" + std::to_string(count.integer) + ")");
  if (!in.fits(static_cast<std::uint64_t>(count.integer), p.type))
    return in.fail(in.last(), c.what() + ": list " + quoted(p.name) + " has " + std::to_string(count.integer) + " entries of type " +
                                  name_of(p.type) + ", more than the file holds after it (" + in.left() + ")");
  return in.skip(static_cast<std::uint64_t>(count.integer), p.type, c);
}

template <class Cursor>
std::optional<Error> read_data(Cursor& in, const Header& h, PlyMesh* m) {
  for (const Element& e : h.elements) {
    Context c{&e, 0, nullptr};
    if (e.properties.empty()) continue;  // entries of nothing
    if (e.role == Element::kVertex) {
      m->positions.reserve(static_cast<std::size_t>(e.count));
      if (h.normals) m->normals.reserve(static_cast<std::size_t>(e.count));
      if (h.uvs) m->uvs.reserve(static_cast<std::size_t>(e.count));
      double v[kSlots] = {};
      typename Cursor::Pos at[kSlots] = {};
      for (c.index = 0; c.index < e.count; ++c.index) {
        for (const Property& p : e.properties) {
          c.property = &p;
          if (p.list) {
            if (auto err = skip_list(in, p, c)) return err;
            continue;
          }
          Number n;
          if (auto err = in.next(p.type, c, &n)) return err;
          v[p.slot] = n.real;
          at[p.slot] = in.last();
        }
        // Single precision, as the scene holds them: a double beyond 3.4e38 is not finite either.
        auto check = [&](std::initializer_list<std::pair<Slot, const char*>> slots) -> std::optional<Error> {
          for (const auto& [slot, what] : slots)
            if (!std::isfinite(static_cast<float>(v[slot])))
              return in.fail(at[slot], c.what() + ": " + what + " (" + str(v[slot]) + ") is not finite in single precision");
          return std::nullopt;
        };
        if (auto err = check({{kX, "x"}, {kY, "y"}, {kZ, "z"}})) return err;
        m->positions.emplace_back(v[kX], v[kY], v[kZ]);
        if (h.normals) {
          if (auto err = check({{kNx, "nx"}, {kNy, "ny"}, {kNz, "nz"}})) return err;
          m->normals.emplace_back(v[kNx], v[kNy], v[kNz]);
        }
        if (h.uvs) {
          if (auto err = check({{kU, "u"}, {kV, "v"}})) return err;
          m->uvs.emplace_back(v[kU], v[kV]);
        }
      }
      continue;
    }
    if (e.role == Element::kFace) {
      m->faces.reserve(static_cast<std::size_t>(e.count));
      for (c.index = 0; c.index < e.count; ++c.index) {
        for (const Property& p : e.properties) {
          c.property = &p;
          if (p.slot != kCorners) {
            Number n;
            if (auto err = p.list ? skip_list(in, p, c) : in.next(p.type, c, &n)) return err;
            continue;
          }
          Number count;
          if (auto err = in.next(p.count_type, c, &count)) return err;
          if (count.integer != 3 && count.integer != 4)
            return in.fail(in.last(), c.what() + " has " + std::to_string(count.integer) + " vertices, expected 3 or 4 (triangles and quads)");
          glm::uvec4 f(kPlyTriangle);
          for (std::int64_t k = 0; k < count.integer; ++k) {
            Number index;
            if (auto err = in.next(p.type, c, &index)) return err;
            if (index.integer < 0 || static_cast<std::uint64_t>(index.integer) >= h.vertices)
              return in.fail(in.last(), c.what() + ": vertex index " + std::to_string(index.integer) + " is out of range, the file has " +
                                            std::to_string(h.vertices) + " vertices");
            f[static_cast<int>(k)] = static_cast<std::uint32_t>(index.integer);
          }
          m->faces.push_back(f);
        }
      }
      continue;
    }
    // --- any other element: skipped, every value read (ASCII: checked as a number of its type) ---
    if constexpr (std::is_same_v<Cursor, Binary>) {
      if (std::none_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.list; })) {
        if (auto err = in.skip_entries(e.count, least(e, true), c)) return err;
        continue;
      }
    }
    for (c.index = 0; c.index < e.count; ++c.index)
      for (const Property& p : e.properties) {
        c.property = &p;
        Number n;
        if (auto err = p.list ? skip_list(in, p, c) : in.next(p.type, c, &n)) return err;
      }
  }
  return in.finish();
}

}  // namespace

Result<PlyMesh> parse_ply(std::string_view bytes, const std::string& name, std::size_t max_elements) {
  Result<Header> header = parse_header(bytes, name);
  if (!header) return header.error();
  const Header& h = *header;
  const bool binary = h.format != Format::kAscii;
  std::optional<Ascii> ascii;
  std::optional<Binary> bin;
  if (binary) bin.emplace(bytes, h.data_start, (h.format == Format::kBinaryBig) != (std::endian::native == std::endian::big), name);
  else ascii.emplace(bytes, h.data_start, h.data_line, name);
  // --- every count against what the file holds, before anything is allocated ---
  const std::uint64_t available = binary ? bin->available() : ascii->available();
  std::uint64_t used = 0;
  for (const Element& e : h.elements) {
    const std::uint64_t each = least(e, binary);
    if (each == 0 || e.count == 0) continue;
    const std::uint64_t room = (available - used) / each;
    if (e.count > room) {
      const bool fixed = std::none_of(e.properties.begin(), e.properties.end(), [](const Property& p) { return p.list; });
      return fail_at(name, e.line, e.column,
                     "element " + quoted(e.name) + " declares " + std::to_string(e.count) + " " + noun(e) + " of " + (fixed ? "" : "at least ") +
                         std::to_string(each) + (binary ? " bytes" : " numbers") + " each, but the file has room for at most " +
                         std::to_string(room) + (used == 0 ? " after the header" : " after the elements before it"));
    }
    used += e.count * each;
  }
  const std::uint64_t limit = std::min<std::uint64_t>(max_elements, kMaxMeshElementsCeiling);
  for (const Element& e : h.elements)
    if (e.role != Element::kOther && e.count > limit) {
      Error err = make_error(ErrorCode::kLimit, limit_message("element " + e.name + " (" + std::to_string(e.count) + " " + noun(e) + ")",
                                                              static_cast<std::size_t>(limit), noun(e), "--max-mesh-elements"));
      err.where = name + ":" + std::to_string(e.line) + ":" + std::to_string(e.column);
      return err;
    }
  // --- the entries ---
  PlyMesh mesh;
  if (auto e = binary ? read_data(*bin, h, &mesh) : read_data(*ascii, h, &mesh)) return *e;
  return mesh;
}

Result<PlyMesh> read_ply_file(const std::string& path, const PlyReadOptions& options) {
  Result<std::string> bytes = read_input_file(path, options.max_file_bytes);
  if (!bytes) return bytes.error();
  if (is_gzip(*bytes)) {
    Result<std::string> inflated = gunzip(*bytes, options.max_file_bytes, path);
    if (!inflated) return inflated.error();
    return parse_ply(*inflated, path, options.max_elements);
  }
  return parse_ply(*bytes, path, options.max_elements);
}

}  // namespace pathex
