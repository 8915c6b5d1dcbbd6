// pbrt-v4 scene import: a tokenizer that keeps line and column, and an interpreter of the
// directives in the subset (README "Importing pbrt-v4 and Mitsuba 3 scenes"). The interpreter
// keeps pbrt's graphics state (current transform, material, area light, ReverseOrientation) on an
// attribute stack and turns each Shape and LightSource into the scene model at once; the camera
// waits for the end, when the film's resolution is known.
//
// Every parameter a directive reads is marked used; one left unused is refused with its location,
// as is every directive, shape, material or light type outside the subset.
#include "scene/pbrt_import.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <numbers>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/import_common.h"
#include "scene/loop_subdivision.h"
#include "scene/metal_spectra.h"

namespace pathex {
namespace {

using import::Location;
using import::located;
using glm::vec3;

// --- tokens ---

struct Token {
  enum Kind { kWord, kString, kNumber, kOpen, kClose } kind = kWord;
  std::string text;  // a string's contents without quotes
  Location at;
};

// The tokens of one file, made one at a time as the interpreter asks for them: a file's memory is
// its text and one token, whatever it holds (16 Mi '[' used to become 16 Mi tokens and 1.3 GB
// before the first was read). A malformed token ends the stream and is kept as error().
class Lexer {
 public:
  Lexer(const std::string& text, const std::string& file) : text_(text), file_(file) {}
  bool done() {
    fill();
    return !has_;
  }
  const Token& peek() {  // only when !done()
    fill();
    return token_;
  }
  void advance() {
    fill();
    filled_ = false;
  }
  const std::optional<Error>& error() const { return error_; }

 private:
  void fill() {
    if (filled_) return;
    filled_ = true;
    has_ = false;
    if (error_) return;
    const std::string& text = text_;
    while (i_ < text.size()) {
      const char c = text[i_];
      if (c == '\n') {
        ++line_;
        line_start_ = ++i_;
      } else if (c == ' ' || c == '\t' || c == '\r') {
        ++i_;
      } else if (c == '#') {
        while (i_ < text.size() && text[i_] != '\n') ++i_;
      } else {
        break;
      }
    }
    if (i_ >= text.size()) return;
    const char c = text[i_];
    Token& t = token_;
    t.at = Location{file_, line_, static_cast<int>(i_ - line_start_) + 1};
    if (c == '[' || c == ']') {
      t.kind = c == '[' ? Token::kOpen : Token::kClose;
      t.text.assign(1, c);
      ++i_;
    } else if (c == '"') {
      std::size_t j = i_ + 1;
      while (j < text.size() && text[j] != '"' && text[j] != '\n') ++j;
      if (j >= text.size() || text[j] != '"') {
        error_ = located(t.at, "unterminated string, expected a closing '\"' on the same line");
        return;
      }
      t.kind = Token::kString;
      t.text.assign(text, i_ + 1, j - i_ - 1);
      i_ = j + 1;
    } else {
      std::size_t j = i_;
      while (j < text.size() && std::string_view(" \t\r\n[]\"#").find(text[j]) == std::string_view::npos) ++j;
      t.text.assign(text, i_, j - i_);
      const char f = t.text[0];
      t.kind = (std::isdigit(static_cast<unsigned char>(f)) || f == '-' || f == '+' || f == '.') ? Token::kNumber : Token::kWord;
      i_ = j;
    }
    has_ = true;
  }

  const std::string& text_;
  std::string file_;
  std::size_t i_ = 0, line_start_ = 0;
  int line_ = 1;
  Token token_;
  bool filled_ = false, has_ = false;
  std::optional<Error> error_;
};

// --- parameters: "type name" value or [values] ---

struct Param {
  std::string type, name;
  std::vector<double> numbers;
  std::vector<std::string> strings;
  std::vector<bool> bools;
  Location at;
  bool used = false;
  bool attribute = false;  // an Attribute default (GraphicsState)
};

class Params {
 public:
  std::vector<Param> list;

  Param* find(const std::string& name) {
    for (Param& p : list)
      if (p.name == name) {
        p.used = true;
        return &p;
      }
    return nullptr;
  }
  // Marks every parameter with one of these names used (render settings pathex does not need).
  void ignore(std::initializer_list<const char*> names) {
    for (Param& p : list)
      for (const char* n : names) p.used = p.used || p.name == n;
  }
  void ignore_all() {
    for (Param& p : list) p.used = true;
  }
  std::optional<Error> unused(const std::string& what) const {
    for (const Param& p : list)
      if (!p.used)
        return located(p.at, "parameter \"" + excerpt(p.type + " " + p.name) + "\"" + (p.attribute ? " (an Attribute default)" : "") + " of " + what +
                                 " is not supported");
    return std::nullopt;
  }

  Result<double> number(const std::string& name, double fallback, std::initializer_list<const char*> types = {"float"}) {
    Param* p = find(name);
    if (!p) return fallback;
    if (p->type == "texture")
      return located(p->at, "a texture for parameter '" + name + "' is not supported (pathex reads textures for reflectance, "
                            "transmittance, roughness, a mix's amount and a shape's alpha), give \"float " + name + "\" value");
    bool ok = false;
    for (const char* t : types) ok = ok || p->type == t;
    if (!ok || p->numbers.size() != 1) return located(p->at, "parameter '" + name + "' expects one " + *types.begin() + " value");
    return p->numbers[0];
  }
  // All numbers of a parameter of `type` (say point2), finite; empty when it is absent.
  Result<std::vector<double>> numbers_of(const std::string& name, const std::string& type) {
    Param* p = find(name);
    if (!p) return std::vector<double>{};
    if (p->type != type) return located(p->at, "parameter '" + name + "' expects " + type + " values");
    for (double x : p->numbers)
      if (!std::isfinite(x)) return located(p->at, "parameter '" + name + "' has a value that is not finite");
    return p->numbers;
  }
  Result<int> integer(const std::string& name, int fallback) {
    Result<double> x = number(name, fallback, {"integer"});
    if (!x) return x.error();
    if (*x != std::floor(*x) || std::fabs(*x) > 1e9) return located(find(name)->at, "parameter '" + name + "' expects an integer");
    return static_cast<int>(*x);
  }
  Result<bool> boolean(const std::string& name, bool fallback) {
    Param* p = find(name);
    if (!p) return fallback;
    if (p->type != "bool" || p->bools.size() != 1) return located(p->at, "parameter '" + name + "' expects one bool value (true or false)");
    return static_cast<bool>(p->bools[0]);
  }
  Result<std::string> string(const std::string& name, const std::string& fallback) {
    Param* p = find(name);
    if (!p) return fallback;
    if (p->type != "string" || p->strings.size() != 1) return located(p->at, "parameter '" + name + "' expects one string");
    return p->strings[0];
  }
  Result<vec3> point(const std::string& name, vec3 fallback) {
    Param* p = find(name);
    if (!p) return fallback;
    if ((p->type != "point3" && p->type != "point" && p->type != "vector3" && p->type != "vector") || p->numbers.size() != 3)
      return located(p->at, "parameter '" + name + "' expects one point3 (3 numbers)");
    return vec3(p->numbers[0], p->numbers[1], p->numbers[2]);
  }
  // A colour: "rgb" (or "color") with 3 values, or a "float" for a grey. Spectra are refused:
  // pathex transports RGB, and pbrt's RGB illuminants and reflectances render as their RGB.
  Result<vec3> rgb(const std::string& name, vec3 fallback, bool allow_float) {
    Param* p = find(name);
    if (!p) return fallback;
    if ((p->type == "rgb" || p->type == "color") && p->numbers.size() == 3) return vec3(p->numbers[0], p->numbers[1], p->numbers[2]);
    if (allow_float && p->type == "float" && p->numbers.size() == 1) return vec3(static_cast<float>(p->numbers[0]));
    if (p->type == "spectrum" || p->type == "blackbody")
      return located(p->at, "parameter \"" + p->type + " " + name + "\" is not supported: pathex renders in RGB, give \"rgb " + name + "\" [r g b]");
    if (p->type == "texture")
      return located(p->at, "a texture for parameter \"" + name + "\" is not supported here (pathex reads textures for reflectance, "
                            "transmittance, roughness, a mix's amount and a shape's alpha), give \"rgb " + name + "\" [r g b]");
    return located(p->at, "parameter '" + name + "' expects \"rgb " + name + "\" [r g b]");
  }
  // Triples of a point3 (`kind` "point") or normal3 (`kind` "normal") parameter; pbrt-v4 also takes the type without the 3.
  Result<std::vector<vec3>> points(const std::string& name, const std::string& kind = "point") {
    Param* p = find(name);
    if (!p) return std::vector<vec3>{};
    if ((p->type != kind + "3" && p->type != kind) || p->numbers.size() % 3 != 0)
      return located(p->at, "parameter '" + name + "' expects " + kind + "3 values (a multiple of 3 numbers)");
    std::vector<vec3> out;
    for (std::size_t i = 0; i < p->numbers.size(); i += 3) {
      const vec3 v(p->numbers[i], p->numbers[i + 1], p->numbers[i + 2]);
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return located(p->at, "parameter '" + name + "' has a value that is not finite");
      out.push_back(v);
    }
    return out;
  }
};

#define PBRT_TRY(var, expr)        \
  auto var##_r = (expr);           \
  if (!var##_r) return var##_r.error(); \
  auto var = std::move(*var##_r)

bool parse_number(const std::string& s, double* out) {
  std::string_view v = s;
  if (!v.empty() && v.front() == '+') v.remove_prefix(1);
  auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), *out);
  return ec == std::errc() && p == v.data() + v.size() && std::isfinite(*out);
}

// --- the interpreter ---

struct AreaLight {
  vec3 radiance{0.0f};
  bool two_sided = false;
};

// pbrt-v4's "interface" material: no surface at all (it only bounds media). Its shapes are not
// imported: a ray passes where they are. Letters: none (no vertex).
constexpr int kInterface = -2;

struct GraphicsState {
  glm::mat4 ctm{1.0f};
  int material = -1;  // builder index; -1: pbrt's default (diffuse, reflectance 0.5); kInterface
  std::optional<AreaLight> area;
  bool reverse = false;
  std::string interior;  // MediumInterface's interior medium for the shapes that follow ("" none)
  // pbrt-v4's Attribute "shape", "light" and "material" (in that order): parameters that later
  // directives of that kind take when they do not give them themselves, scoped like the rest of
  // the state. Shared with the states AttributeBegin pushed until an Attribute changes them, so
  // that a deep nesting copies nothing.
  std::array<std::shared_ptr<std::vector<Param>>, 3> attributes;
};
// Distinct parameters one kind of Attribute holds at once (a later one of the same name replaces
// the earlier); real scenes give a few.
inline constexpr std::size_t kMaxAttributeParams = 64;

class Importer {
 public:
  Importer(std::string main_file, const SceneLoadOptions& options)
      : main_file_(std::move(main_file)), options_(options), files_(main_file_, options), materials_budget_(options.max_material_nodes) {}

  Result<Scene> run() {
    if (auto e = parse_file(main_file_, Location{main_file_}, 0)) return *e;
    if (auto e = resolve_instances()) return *e;
    if (auto e = make_camera()) return *e;
    return builder_.finish(main_file_, files_.included());
  }

 private:
  std::string main_file_;
  SceneLoadOptions options_;
  import::SceneFiles files_;
  import::MaterialBudget materials_budget_;
  std::size_t mesh_elements_ = 0;  // vertices + triangles of the meshes so far (--max-mesh-elements)
  import::SceneBuilder builder_;
  GraphicsState gs_;
  std::vector<GraphicsState> stack_;
  std::vector<Location> stack_at_;
  std::vector<bool> stack_is_attribute_;
  bool in_world_ = false;
  // --- instancing: ObjectBegin/ObjectEnd/ObjectInstance (scene.h ShapeGroup) ---
  struct Object {
    int group = -1;  // builder group index
    Location at;     // its ObjectBegin
  };
  std::map<std::string, Object> objects_;
  std::string object_;              // the object being defined ("" outside ObjectBegin/ObjectEnd)
  std::size_t object_depth_ = 0;    // stack_.size() inside it (ObjectBegin pushes the state, as pbrt-v4)
  struct Use {
    std::string name;
    glm::mat4 ctm;
    Location at;
  };
  std::vector<Use> uses_;  // ObjectInstance, resolved once the file is read (pbrt-v4 allows a use before the definition)
  std::map<std::string, glm::mat4> coordinate_systems_;
  std::map<std::string, Material> named_materials_;
  std::map<std::string, MaterialTextures> named_material_textures_;  // of the named materials that have any
  // What material() found textured, beside the Material it returns (docs/textures.md).
  MaterialTextures material_textures_;
  struct NamedTexture {
    int index;
    bool is_float;
  };
  std::map<std::string, NamedTexture> named_textures_;
  std::set<std::string> interface_names_;  // named materials of type "interface"
  std::map<std::string, vec3> media_;       // MakeNamedMedium: σa × scale of each absorbing medium
  std::map<std::string, int> named_material_index_;
  int default_material_ = -1;
  // The camera and film, combined once the file is read.
  std::string camera_type_ = "perspective";
  Params camera_params_;
  glm::mat4 camera_from_world_{1.0f};
  Location camera_at_;
  int width_ = 1280, height_ = 720;

  using Stream = Lexer;

  Result<std::vector<double>> numbers(Stream& s, int count, const Location& at, const std::string& directive) {
    std::vector<double> out;
    const bool bracket = !s.done() && s.peek().kind == Token::kOpen;
    if (bracket) s.advance();
    while (static_cast<int>(out.size()) < count) {
      if (s.done() || s.peek().kind != Token::kNumber)
        return located(s.done() ? at : s.peek().at, directive + " expects " + std::to_string(count) + " numbers");
      double x = 0;
      if (!parse_number(s.peek().text, &x)) return located(s.peek().at, "bad number '" + excerpt(s.peek().text) + "'");
      out.push_back(x);
      s.advance();
    }
    if (bracket) {
      if (s.done() || s.peek().kind != Token::kClose) return located(s.done() ? at : s.peek().at, directive + " expects ']' after " + std::to_string(count) + " numbers");
      s.advance();
    }
    return out;
  }

  Result<std::string> quoted(Stream& s, const Location& at, const std::string& directive) {
    if (s.done() || s.peek().kind != Token::kString) return located(s.done() ? at : s.peek().at, directive + " expects a quoted name");
    std::string text = s.peek().text;
    s.advance();
    return text;
  }

  Result<Params> params(Stream& s) {
    Params out;
    while (!s.done() && s.peek().kind == Token::kString) {
      Param p;
      p.at = s.peek().at;
      std::istringstream decl(s.peek().text);
      std::string extra;
      if (!(decl >> p.type >> p.name) || (decl >> extra))
        return located(p.at, "bad parameter declaration \"" + excerpt(s.peek().text) + "\", expected \"type name\"");
      s.advance();
      const bool bracket = !s.done() && s.peek().kind == Token::kOpen;
      if (bracket) s.advance();
      int count = 0;
      while (!s.done() && s.peek().kind != Token::kClose && (bracket || count == 0)) {
        const Token& t = s.peek();
        if (t.kind == Token::kNumber) {
          double x = 0;
          if (!parse_number(t.text, &x)) return located(t.at, "bad number '" + excerpt(t.text) + "'");
          p.numbers.push_back(x);
        } else if (t.kind == Token::kString && (p.type == "string" || p.type == "texture" || p.type == "spectrum")) {
          p.strings.push_back(t.text);
        } else if ((t.kind == Token::kString || t.kind == Token::kWord) && (t.text == "true" || t.text == "false")) {
          p.bools.push_back(t.text == "true");
        } else if (!bracket) {
          break;
        } else {
          return located(t.at, "unexpected '" + excerpt(t.text) + "' in the values of parameter \"" + excerpt(p.type + " " + p.name) + "\"");
        }
        s.advance();
        ++count;
      }
      if (bracket) {
        if (s.done()) return located(p.at, "parameter \"" + excerpt(p.type + " " + p.name) + "\" expects ']'");
        s.advance();
      }
      if (count == 0) return located(p.at, "parameter \"" + p.type + " " + p.name + "\" has no value");
      if (p.type == "bool" && p.bools.size() != static_cast<std::size_t>(count)) return located(p.at, "parameter \"bool " + p.name + "\" expects true or false");
      out.list.push_back(std::move(p));
    }
    return out;
  }

  // --- files ---
  std::optional<Error> parse_file(const std::string& path, const Location& from, int depth) {
    Result<std::string> text = files_.read(path, from, depth, "Include/Import");
    if (!text) return text.error();
    Lexer s(*text, path);
    while (!s.done()) {
      const Token t = s.peek();
      if (t.kind != Token::kWord) return located(t.at, "expected a directive, found '" + excerpt(t.text) + "'");
      s.advance();
      // A directive that stopped at a malformed token reports the token.
      if (auto e = directive(t.text, t.at, s, depth)) return s.error() ? s.error() : e;
    }
    if (s.error()) return s.error();
    if (depth == 0 && !object_.empty())
      return located(objects_.at(object_).at, "ObjectBegin \"" + excerpt(object_) + "\" has no matching ObjectEnd");
    if (depth == 0 && !stack_.empty())
      return located(stack_at_.back(), std::string(stack_is_attribute_.back() ? "AttributeBegin" : "TransformBegin") + " has no matching End");
    return std::nullopt;
  }

  // --- directives ---
  std::optional<Error> directive(const std::string& name, const Location& at, Stream& s, int depth) {
    auto transform_op = [&](int count, auto apply) -> std::optional<Error> {
      Result<std::vector<double>> v = numbers(s, count, at, name);
      if (!v) return v.error();
      apply(*v);
      return std::nullopt;
    };
    if (name == "Translate")
      return transform_op(3, [&](const std::vector<double>& v) { gs_.ctm = glm::translate(gs_.ctm, vec3(v[0], v[1], v[2])); });
    if (name == "Scale")
      return transform_op(3, [&](const std::vector<double>& v) { gs_.ctm = glm::scale(gs_.ctm, vec3(v[0], v[1], v[2])); });
    if (name == "Rotate") {
      Result<std::vector<double>> v = numbers(s, 4, at, name);
      if (!v) return v.error();
      const vec3 axis((*v)[1], (*v)[2], (*v)[3]);
      if (glm::length(axis) == 0.0f) return located(at, "Rotate's axis is zero");
      gs_.ctm = glm::rotate(gs_.ctm, glm::radians(static_cast<float>((*v)[0])), glm::normalize(axis));
      return std::nullopt;
    }
    if (name == "LookAt") {
      Result<std::vector<double>> v = numbers(s, 9, at, name);
      if (!v) return v.error();
      const vec3 eye((*v)[0], (*v)[1], (*v)[2]), look((*v)[3], (*v)[4], (*v)[5]), up((*v)[6], (*v)[7], (*v)[8]);
      if (glm::length(look - eye) == 0.0f) return located(at, "LookAt's eye and look-at points coincide");
      const vec3 dir = glm::normalize(look - eye);
      if (glm::length(glm::cross(glm::normalize(up), dir)) < 1e-6f) return located(at, "LookAt's up vector is parallel to the viewing direction");
      // pbrt's LookAt: camera +x is up × dir, +y the new up, +z dir (a left-handed camera space).
      const vec3 right = glm::normalize(glm::cross(glm::normalize(up), dir));
      const vec3 new_up = glm::cross(dir, right);
      glm::mat4 world_from_camera(glm::vec4(right, 0), glm::vec4(new_up, 0), glm::vec4(dir, 0), glm::vec4(eye, 1));
      gs_.ctm = gs_.ctm * glm::inverse(world_from_camera);
      return std::nullopt;
    }
    if (name == "Transform" || name == "ConcatTransform") {
      Result<std::vector<double>> v = numbers(s, 16, at, name);
      if (!v) return v.error();
      float m[16];
      for (int i = 0; i < 16; ++i) m[i] = static_cast<float>((*v)[static_cast<std::size_t>(i)]);
      const glm::mat4 t = glm::make_mat4(m);  // pbrt lists the matrix column by column, as glm stores it
      if (std::optional<std::string> why = import::matrix_problem(t)) return located(at, name + "'s matrix " + *why);
      gs_.ctm = name == "Transform" ? t : gs_.ctm * t;
      return std::nullopt;
    }
    if (name == "Identity") {
      gs_.ctm = glm::mat4(1.0f);
      return std::nullopt;
    }
    if (name == "CoordinateSystem" || name == "CoordSysTransform") {
      PBRT_TRY(n, quoted(s, at, name));
      if (name == "CoordinateSystem") {
        coordinate_systems_[n] = gs_.ctm;
        return std::nullopt;
      }
      auto it = coordinate_systems_.find(n);
      if (it == coordinate_systems_.end()) return located(at, "unknown coordinate system \"" + excerpt(n) + "\"");
      gs_.ctm = it->second;
      return std::nullopt;
    }
    if (name == "ReverseOrientation") {
      gs_.reverse = !gs_.reverse;
      return std::nullopt;
    }
    if (name == "AttributeBegin" || name == "TransformBegin") {
      stack_.push_back(gs_);
      stack_at_.push_back(at);
      stack_is_attribute_.push_back(name == "AttributeBegin");
      return std::nullopt;
    }
    if (name == "AttributeEnd" || name == "TransformEnd") {
      const bool attribute = name == "AttributeEnd";
      if (stack_.empty() || stack_is_attribute_.back() != attribute || (!object_.empty() && stack_.size() == object_depth_))
        return located(at, name + " has no matching " + (attribute ? "AttributeBegin" : "TransformBegin"));
      if (attribute) gs_ = stack_.back();
      else gs_.ctm = stack_.back().ctm;
      stack_.pop_back();
      stack_at_.pop_back();
      stack_is_attribute_.pop_back();
      return std::nullopt;
    }
    if (name == "ObjectBegin" || name == "ObjectEnd" || name == "ObjectInstance") return object_directive(name, at, s);
    if (name == "Include" || name == "Import") {
      PBRT_TRY(file, quoted(s, at, name));
      PBRT_TRY(path, files_.include(file, at, name));
      return parse_file(path, at, depth + 1);
    }
    if (name == "WorldBegin") {
      if (in_world_) return located(at, "a second WorldBegin");
      in_world_ = true;
      gs_.ctm = glm::mat4(1.0f);
      coordinate_systems_["world"] = gs_.ctm;
      return std::nullopt;
    }
    // --- hints and settings (README "Importing pbrt-v4 and Mitsuba 3 scenes": directives) ---
    if (name == "ColorSpace") {  // anywhere, as in pbrt-v4; the RGB values after it are in that space
      PBRT_TRY(space, quoted(s, at, name));
      if (space != "srgb") return located(at, "color space \"" + excerpt(space) + "\" is not supported, expected \"srgb\"");
      return std::nullopt;
    }
    if (name == "Option") return option(s, at);
    if (name == "Attribute") {
      PBRT_TRY(target, quoted(s, at, name));
      PBRT_TRY(ps, params(s));
      if (target == "medium" || target == "texture") return std::nullopt;  // media and textures are refused where they are made
      const int kind = target == "shape" ? 0 : target == "light" ? 1 : target == "material" ? 2 : -1;
      if (kind < 0) return located(at, "Attribute target \"" + target + "\" is not supported, expected shape, light, material, medium or texture");
      std::shared_ptr<std::vector<Param>>& list = gs_.attributes[static_cast<std::size_t>(kind)];
      if (!list) list = std::make_shared<std::vector<Param>>();
      else if (list.use_count() > 1) list = std::make_shared<std::vector<Param>>(*list);  // copied on the first change in a scope
      for (Param& p : ps.list) {
        p.attribute = true;
        auto same = std::find_if(list->begin(), list->end(), [&](const Param& q) { return q.name == p.name; });
        if (same != list->end()) {
          *same = std::move(p);
        } else {
          if (list->size() >= kMaxAttributeParams)
            return located(p.at, "more than " + std::to_string(kMaxAttributeParams) + " parameters of Attribute \"" + target + "\" at once");
          list->push_back(std::move(p));
        }
      }
      return std::nullopt;
    }
    if (name == "TransformTimes") {  // the shutter interval of moving transforms, which pathex refuses
      if (in_world_) return located(at, "TransformTimes must come before WorldBegin");
      Result<std::vector<double>> v = numbers(s, 2, at, name);
      if (!v) return v.error();
      return std::nullopt;
    }
    if (name == "ActiveTransform") {
      if (s.done() || s.peek().kind != Token::kWord) return located(at, "ActiveTransform expects All, StartTime or EndTime");
      const Token which = s.peek();  // a copy: advance() reuses the lexer's token
      s.advance();
      if (which.text == "All") return std::nullopt;
      if (which.text == "StartTime" || which.text == "EndTime")
        return located(which.at, "ActiveTransform " + which.text + " (a moving transform, motion blur) is not supported: pathex renders static scenes");
      return located(which.at, "ActiveTransform expects All, StartTime or EndTime");
    }
    // --- media (trace/media.h): absorbing interiors of shapes ---
    if (name == "MediumInterface") {
      PBRT_TRY(inside, quoted(s, at, name));
      std::string outside = inside;
      if (!s.done() && s.peek().kind == Token::kString) {
        outside = s.peek().text;
        s.advance();
      }
      if (!outside.empty())
        return located(at, "an exterior medium (\"" + excerpt(outside) + "\") is not supported: pathex's media are the absorbing "
                           "interiors of shapes, surrounded by vacuum (give MediumInterface \"" + excerpt(inside) + "\" \"\")");
      if (!inside.empty() && media_.count(inside) == 0)
        return located(at, "medium \"" + excerpt(inside) + "\" is not defined (MakeNamedMedium must come first)");
      gs_.interior = inside;
      return std::nullopt;
    }
    if (name == "MakeNamedMedium") {
      PBRT_TRY(medium, quoted(s, at, name));
      PBRT_TRY(ps, params(s));
      PBRT_TRY(type, ps.string("type", ""));
      if (type != "homogeneous")
        return located(at, "medium type \"" + excerpt(type) + "\" is not supported: pathex has absorbing homogeneous media only");
      for (const char* refused : {"preset", "Le"})
        if (Param* q = ps.find(refused)) return located(q->at, std::string("medium parameter '") + refused + "' is not supported: pathex's media only absorb");
      if (ps.find("sigma_s") == nullptr)
        return located(at, "medium \"" + excerpt(medium) + "\" scatters (pbrt-v4's default sigma_s is not 0): a scattering medium needs a "
                           "volume letter that pathex's alphabet does not have; give \"rgb sigma_s\" [0 0 0] for an absorbing one");
      PBRT_TRY(sigma_s, ps.rgb("sigma_s", vec3(0.0f), true));
      if (sigma_s != vec3(0.0f))
        return located(ps.find("sigma_s")->at, "a scattering medium (sigma_s not 0) needs a volume letter that pathex's alphabet does not have");
      PBRT_TRY(sigma_a, ps.rgb("sigma_a", vec3(0.0011f, 0.0024f, 0.014f), true));
      PBRT_TRY(scale, ps.number("scale", 1.0));
      const vec3 absorption = sigma_a * static_cast<float>(scale);
      if (!(glm::all(glm::greaterThanEqual(absorption, vec3(0.0f))) && std::isfinite(absorption.x + absorption.y + absorption.z)))
        return located(at, "medium \"" + excerpt(medium) + "\": sigma_a × scale must be finite and non-negative");
      ps.ignore({"g", "Lescale"});  // g shapes scattering, Lescale emission: neither exists here
      if (auto e = ps.unused("MakeNamedMedium \"" + excerpt(medium) + "\"")) return e;
      media_[medium] = absorption;
      return std::nullopt;
    }
    if (name == "Texture") {  // Texture "name" "spectrum" | "float" "class" parameters (docs/textures.md)
      PBRT_TRY(tname, quoted(s, at, name));
      PBRT_TRY(ttype, quoted(s, at, name));
      PBRT_TRY(tclass, quoted(s, at, name));
      PBRT_TRY(ps, params(s));
      if (!in_world_) return located(at, "Texture must come after WorldBegin");
      if (ttype != "spectrum" && ttype != "float")
        return located(at, "texture type \"" + excerpt(ttype) + "\" is not supported, expected \"spectrum\" or \"float\"");
      PBRT_TRY(index, texture(tclass, ttype == "float", ps, at));
      if (auto e = ps.unused("Texture \"" + excerpt(tname) + "\"")) return e;
      named_textures_[tname] = NamedTexture{index, ttype == "float"};
      return std::nullopt;
    }
    // --- directives with a type and parameters ---
    static const char* const kTyped[] = {"Camera", "Film", "Sampler", "Integrator", "PixelFilter", "Accelerator", "Shape",
                                         "LightSource", "AreaLightSource", "Material", "MakeNamedMaterial", "NamedMaterial"};
    bool typed = false;
    for (const char* k : kTyped) typed = typed || name == k;
    if (!typed)
      return located(at, "directive '" + excerpt(name) + "' is not supported (pathex imports shapes, materials, lights, a camera, transforms and Include/Import)");
    PBRT_TRY(type, quoted(s, at, name));
    PBRT_TRY(ps, params(s));
    const bool scene_wide = name == "Camera" || name == "Film" || name == "Sampler" || name == "Integrator" ||
                            name == "PixelFilter" || name == "Accelerator";
    if (scene_wide && in_world_) return located(at, name + " must come before WorldBegin");
    if (!scene_wide && !in_world_) return located(at, name + " must come after WorldBegin");
    const std::string what = name + " \"" + excerpt(type) + "\"";
    if (name == "Sampler" || name == "Integrator" || name == "PixelFilter" || name == "Accelerator") {
      ps.ignore_all();  // how to estimate (and to intersect) is pathex's choice (--renderer, --spp); see the README
      return std::nullopt;
    }
    // Attribute defaults: what the directive does not give itself.
    const int kind = name == "Shape" ? 0 : name == "LightSource" || name == "AreaLightSource" ? 1
                   : name == "Material" || name == "MakeNamedMaterial" ? 2 : -1;
    if (const std::vector<Param>* defaults = kind < 0 ? nullptr : gs_.attributes[static_cast<std::size_t>(kind)].get())
      for (const Param& d : *defaults)
        if (std::none_of(ps.list.begin(), ps.list.end(), [&](const Param& p) { return p.name == d.name; })) ps.list.push_back(d);
    if (name == "Film") {
      if (type != "rgb") return located(at, "film \"" + excerpt(type) + "\" is not supported, expected \"rgb\"");
      PBRT_TRY(w, ps.integer("xresolution", 1280));
      PBRT_TRY(h, ps.integer("yresolution", 720));
      if (w < 1 || h < 1 || w > 16384 || h > 16384) return located(at, "the film resolution must be within 1..16384");
      width_ = w;
      height_ = h;
      ps.ignore({"filename", "savefp16"});
      return ps.unused(what);
    }
    if (name == "Camera") {
      // pbrt-v4 lets the last Camera win; a second one is more likely a mistake than a choice.
      if (!camera_at_.file.empty())
        return located(at, "a second Camera (the first is at " + camera_at_.str() + "): pathex renders one camera");
      if (type != "perspective" && type != "orthographic")
        return located(at, "camera \"" + excerpt(type) + "\" is not supported, expected \"perspective\" or \"orthographic\"");
      camera_type_ = type;
      camera_params_ = std::move(ps);
      camera_from_world_ = gs_.ctm;
      camera_at_ = at;
      coordinate_systems_["camera"] = glm::inverse(gs_.ctm);
      return std::nullopt;  // made at the end, with the film
    }
    if (name == "MakeNamedMaterial") {
      PBRT_TRY(mtype, ps.string("type", ""));
      if (mtype.empty()) return located(at, "MakeNamedMaterial \"" + excerpt(type) + "\" needs a \"string type\" parameter");
      interface_names_.erase(type);
      if (mtype == "interface") {
        named_materials_.erase(type);
        named_material_textures_.erase(type);
        named_material_index_.erase(type);
        interface_names_.insert(type);
        return ps.unused("material \"interface\"");
      }
      PBRT_TRY(m, material(mtype, ps, at));
      if (mtype != "mix")
        if (auto e = perturbation(ps)) return e;
      if (auto e = ps.unused("material \"" + excerpt(mtype) + "\"")) return e;
      if (auto e = materials_budget_.charge(m, at)) return e;
      named_materials_[type] = m;
      named_material_textures_[type] = std::move(material_textures_);
      named_material_index_.erase(type);
      return std::nullopt;
    }
    if (name == "NamedMaterial") {
      if (interface_names_.count(type) != 0) {
        gs_.material = kInterface;
        return ps.unused(what);
      }
      PBRT_TRY(index, named_index(type, at));
      gs_.material = index;
      return ps.unused(what);
    }
    if (name == "Material") {
      if (type == "interface") {
        gs_.material = kInterface;
        return ps.unused(what);
      }
      PBRT_TRY(m, material(type, ps, at));
      if (type != "mix")
        if (auto e = perturbation(ps)) return e;
      if (auto e = ps.unused(what)) return e;
      if (auto e = materials_budget_.charge(m, at)) return e;
      gs_.material = builder_.add_material(at.str(), m, std::move(material_textures_));
      return std::nullopt;
    }
    if (name == "AreaLightSource") {
      if (type != "diffuse") return located(at, "area light \"" + excerpt(type) + "\" is not supported, expected \"diffuse\"");
      PBRT_TRY(l, ps.rgb("L", vec3(1.0f), false));
      PBRT_TRY(scale, ps.number("scale", 1.0));
      PBRT_TRY(two, ps.boolean("twosided", false));
      if (ps.find("power")) return located(ps.find("power")->at, "parameter 'power' is not supported: give L and scale");
      if (auto e = ps.unused(what)) return e;
      if (auto e = import::check_light_value(l * static_cast<float>(scale), at)) return e;
      gs_.area = AreaLight{l * static_cast<float>(scale), two};
      return std::nullopt;
    }
    if (name == "LightSource") {
      if (auto e = light(type, ps, at)) return e;
      return ps.unused(what);
    }
    // Shape
    if (auto e = shape(type, ps, at)) return e;
    return ps.unused(what);
  }

  // --- instancing (pbrt-v4's ObjectBegin "name" … ObjectEnd, ObjectInstance "name") ---
  // An object's shapes are placed by the CTM at each shape (inside the object) and each instance
  // by the CTM at its ObjectInstance: world = CTM(instance) * CTM(shape), as pbrt-v4 composes
  // them (renderFromInstance * renderFromObject). Moving transforms are refused everywhere
  // (ActiveTransform), so neither CTM can be animated.
  std::optional<Error> object_directive(const std::string& name, const Location& at, Stream& s) {
    if (!in_world_) return located(at, name + " must come after WorldBegin");
    if (name == "ObjectEnd") {
      if (object_.empty()) return located(at, "ObjectEnd has no matching ObjectBegin");
      if (stack_.size() != object_depth_)
        return located(at, "ObjectEnd inside the AttributeBegin at " + stack_at_.back().str() + " (which needs its AttributeEnd first)");
      gs_ = stack_.back();
      stack_.pop_back();
      stack_at_.pop_back();
      stack_is_attribute_.pop_back();
      object_.clear();
      return std::nullopt;
    }
    PBRT_TRY(n, quoted(s, at, name));
    if (!object_.empty())
      return located(at, name + " inside the definition of object \"" + excerpt(object_) + "\" (ObjectBegin at " +
                             objects_.at(object_).at.str() + "): objects do not nest");
    if (name == "ObjectInstance") {
      uses_.push_back({n, gs_.ctm, at});
      return std::nullopt;
    }
    if (auto it = objects_.find(n); it != objects_.end())
      return located(at, "object \"" + excerpt(n) + "\" is defined twice (first at " + it->second.at.str() + ")");
    objects_[n] = Object{builder_.add_group(n, at.str()), at};
    object_ = n;
    stack_.push_back(gs_);  // ObjectBegin is an AttributeBegin too
    stack_at_.push_back(at);
    stack_is_attribute_.push_back(true);
    object_depth_ = stack_.size();
    return std::nullopt;
  }

  std::optional<Error> resolve_instances() {
    for (const Use& u : uses_) {
      auto it = objects_.find(u.name);
      if (it == objects_.end()) return located(u.at, "ObjectInstance of unknown object \"" + excerpt(u.name) + "\" (no ObjectBegin defines it)");
      builder_.add_instance(ShapeInstance{it->second.group, u.ctm, u.at.str()});
    }
    return std::nullopt;
  }

  // A shape into the world, or into the object being defined (import::make_group_member).
  std::optional<Error> place(Shape s, const Location& at) {
    if (!object_.empty())
      if (std::optional<std::string> why = import::make_group_member(&s, objects_.at(object_).group)) return located(at, *why);
    builder_.add_shape(std::move(s));
    return std::nullopt;
  }

  // --- materials ---
  Result<int> named_index(const std::string& n, const Location& at) {
    if (auto it = named_material_index_.find(n); it != named_material_index_.end()) return it->second;
    auto it = named_materials_.find(n);
    if (it == named_materials_.end()) return located(at, "unknown named material \"" + excerpt(n) + "\"");
    auto t = named_material_textures_.find(n);
    const int index = builder_.add_material(n, it->second, t == named_material_textures_.end() ? MaterialTextures{} : t->second);
    named_material_index_[n] = index;
    return index;
  }

  // pbrt-v4's Option "type name" value: rendering settings. Those that do not change the light are
  // accepted and ignored; forcediffuse true (every material rendered diffuse) is refused.
  std::optional<Error> option(Stream& s, const Location& at) {
    PBRT_TRY(ps, params(s));
    if (ps.list.size() != 1) return located(at, "Option expects one parameter, such as \"bool disablepixeljitter\" true");
    const Param& p = ps.list[0];
    static const char* const kIgnored[] = {"disablepixeljitter", "disabletexturefiltering", "disablewavelengthjitter", "displacementedgescale",
                                           "msereferenceimage", "msereferenceout", "rendercoordsys", "seed", "pixelstats", "wavefront"};
    for (const char* k : kIgnored)
      if (p.name == k) return std::nullopt;
    if (p.name == "forcediffuse") {
      if (p.type != "bool" || p.bools.size() != 1) return located(p.at, "Option forcediffuse expects one bool value");
      if (p.bools[0]) return located(p.at, "Option forcediffuse true (every material rendered as diffuse) is not supported: remove it or set it false");
      return std::nullopt;
    }
    return located(p.at, "unknown Option \"" + p.name + "\"");
  }

  // GGX alphas (u, v) from pbrt's roughness parameters: "roughness" for both, "uroughness" and
  // "vroughness" for each, remapped by sqrt unless remaproughness is false (pbrt-v4's
  // TrowbridgeReitzDistribution::RoughnessToAlpha). Below 1e-3 in both, pbrt-v4 renders the
  // surface smooth (EffectivelySmooth), and so does pathex. The anisotropy follows the shading
  // frame's tangents, not pbrt's dpdu.
  //
  // Each of roughness, uroughness, vroughness may be a float texture (pbrt-v4 reads
  // uroughness, else roughness): it binds TexturedParam::kAlphaU or kAlphaV in material_textures_
  // (remapped per hit: pbrt-v4 remaps the value it looked up) and its placeholder alpha is 1, so the
  // material is the rough kind, letter D; per hit its alpha is clamped to [1e-3, 1], never smooth.
  struct Alphas {
    glm::vec2 a{0.0f};
    int texture[2] = {-1, -1};  // the float texture of alpha u and of alpha v, -1: a value
    bool textured() const { return texture[0] >= 0 || texture[1] >= 0; }
  };
  // `prefix`: coatedconductor's "interface." and "conductor.".
  Result<Alphas> alphas(Params& ps, const Location& at, const char* what, const std::string& prefix = "") {
    PBRT_TRY(remap, ps.boolean("remaproughness", true));
    Alphas out;
    const char* const names[2] = {"uroughness", "vroughness"};
    for (int i = 0; i < 2; ++i) {
      const std::string name = prefix + (ps.find(prefix + names[i]) ? names[i] : "roughness");
      if (Param* p = ps.find(name); p && p->type == "texture") {
        PBRT_TRY(index, operand(ps, name, vec3(0.0f), true));
        material_textures_.bindings.push_back(TextureBinding{-1, i == 0 ? TexturedParam::kAlphaU : TexturedParam::kAlphaV, index, 1.0f,
                                                             remap ? TextureMap::kSqrt : TextureMap::kLinear});
        out.texture[i] = index;
        out.a[i] = 1.0f;
        continue;
      }
      PBRT_TRY(r, ps.number(name, 0.0));
      if (r < 0) return located(at, "roughness must be non-negative");
      out.a[i] = static_cast<float>(remap ? std::sqrt(r) : r);
    }
    ps.find(prefix + "roughness");  // read or overridden by uroughness and vroughness, as in pbrt-v4
    if (out.a.x > 1.0f || out.a.y > 1.0f)
      return located(at, std::string(what) + " roughness gives GGX alpha " + fmt_number(std::max(out.a.x, out.a.y)) + ", pathex accepts at most 1");
    if (out.textured()) out.a = glm::max(out.a, glm::vec2(kSmoothAlpha));  // textured: the rough kind
    return out;
  }

  // A conductor's eta or k: "rgb" (or a float), or one of pbrt-v4's named metal spectra
  // ("spectrum eta" "metal-Au-eta"), turned into RGB from its measured table (scene/metal_spectra.h).
  Result<vec3> metal_rgb(Params& ps, const std::string& name, vec3 fallback) {
    Param* p = ps.find(name);
    if (!p || p->type != "spectrum") return ps.rgb(name, fallback, true);
    const std::string which = name.substr(name.rfind('.') + 1);  // coatedconductor's "conductor.eta" is an eta
    if (p->strings.size() != 1)
      return located(p->at, "parameter \"spectrum " + name + "\" with sampled values is not supported: give a named metal spectrum "
                            "(\"metal-Cu-" + which + "\") or \"rgb " + name + "\" [r g b]");
    const std::string& s = p->strings[0];
    const bool is_eta = s.size() > 4 && s.compare(s.size() - 4, 4, "-eta") == 0;
    const bool is_k = s.size() > 2 && s.compare(s.size() - 2, 2, "-k") == 0;
    const MetalSpectrum* metal = nullptr;
    if (s.rfind("metal-", 0) == 0 && (is_eta || is_k)) metal = find_metal(s.substr(6, s.size() - 6 - (is_eta ? 4 : 2)));
    if (!metal)
      return located(p->at, "unknown spectrum \"" + excerpt(s) + "\" for " + name + ", expected metal-<name>-eta or metal-<name>-k with <name> one of " +
                                kMetalNames);
    const float* v = is_eta ? metal->eta : metal->k;
    return vec3(v[0], v[1], v[2]);
  }

  // A texture operand `name` of a texture or material: "texture name" "tex" (a named texture of
  // the same kind, float or spectrum), or a value ("float", or "rgb" for a spectrum texture)
  // made a constant texture; absent: `fallback`.
  Result<int> operand(Params& ps, const std::string& name, vec3 fallback, bool is_float) {
    Param* p = ps.find(name);
    if (p && p->type == "texture") {
      if (p->strings.size() != 1) return located(p->at, "parameter '" + name + "' expects one texture name");
      auto it = named_textures_.find(p->strings[0]);
      if (it == named_textures_.end()) return located(p->at, "unknown texture \"" + excerpt(p->strings[0]) + "\"");
      if (it->second.is_float != is_float)
        return located(p->at, "texture \"" + excerpt(p->strings[0]) + "\" is a " + (it->second.is_float ? "float" : "spectrum") + " texture, parameter '" +
                                  name + "' expects a " + (is_float ? "float" : "spectrum") + " one");
      return it->second.index;
    }
    if (is_float) {
      PBRT_TRY(x, ps.number(name, fallback.x));
      return builder_.constant_texture(vec3(static_cast<float>(x)));
    }
    PBRT_TRY(v, ps.rgb(name, fallback, true));
    return builder_.constant_texture(v);
  }

  // A material's RGB parameter that may be a texture: its value, or for "texture name" a
  // placeholder `fallback` and a binding in material_textures_ (`scale`: what the value is multiplied by).
  Result<vec3> spectrum(Params& ps, const std::string& name, vec3 fallback, TexturedParam param, float scale = 1.0f) {
    Param* p = ps.find(name);
    if (!p || p->type != "texture") return ps.rgb(name, fallback, true);
    PBRT_TRY(index, operand(ps, name, fallback, false));
    material_textures_.bindings.push_back(TextureBinding{-1, param, index, scale});
    return fallback;
  }

  // A material's bump or normal map (docs/textures.md): pbrt-v4's "texture displacement" (a float
  // texture or value, applied as BumpMap() does) or "string normalmap" (an image file read with a
  // linear encoding, looked up at (u, 1 − v) with wrap repeat, as NormalMap() does). Into material_textures_.
  std::optional<Error> perturbation(Params& ps) {
    Param* d = ps.find("displacement");
    Param* nm = ps.find("normalmap");
    if (d && nm) return located(nm->at, "a material with both displacement and normalmap is not supported: pbrt-v4 applies one of them");
    if (d) {
      PBRT_TRY(index, operand(ps, "displacement", vec3(0.0f), true));
      material_textures_.perturb = NormalPerturbation::kBumpPbrt;
      material_textures_.perturb_texture = index;
    } else if (nm) {
      PBRT_TRY(file, ps.string("normalmap", ""));
      if (file.empty()) return located(nm->at, "normalmap needs an image file name");
      ImageReadOptions options;
      options.max_file_bytes = options_.max_file_bytes;
      options.max_texels = options_.max_texels;
      options.encoding = ImageEncoding::kLinear;
      PBRT_TRY(image, builder_.add_image(files_.resolve(file), options, nm->at));
      Texture t;
      t.kind = TextureKind::kImage;
      t.image = image;
      t.flip_t = true;
      material_textures_.perturb = NormalPerturbation::kNormalMap;
      material_textures_.perturb_texture = builder_.add_texture(t);
    }
    return std::nullopt;
  }

  // pbrt-v4's textures that pathex reads (docs/textures.md): imagemap, checkerboard (2D), scale,
  // mix, constant, all with the "uv" mapping.
  Result<int> texture(const std::string& cls, bool is_float, Params& ps, const Location& at) {
    const vec3 one(1.0f), zero(0.0f);
    Texture t;
    if (cls == "imagemap" || cls == "checkerboard") {
      PBRT_TRY(mapping, ps.string("mapping", "uv"));
      if (mapping != "uv")
        return located(ps.find("mapping")->at, "texture mapping \"" + excerpt(mapping) + "\" is not supported: pathex's textures use the "
                                                 "surface's (u, v) (mapping \"uv\")");
      PBRT_TRY(su, ps.number("uscale", 1.0));
      PBRT_TRY(sv, ps.number("vscale", 1.0));
      PBRT_TRY(du, ps.number("udelta", 0.0));
      PBRT_TRY(dv, ps.number("vdelta", 0.0));
      t.uv = UvTransform{{static_cast<float>(su), 0.0f, static_cast<float>(du), 0.0f, static_cast<float>(sv), static_cast<float>(dv)}};
    }
    if (cls == "imagemap") {
      PBRT_TRY(file, ps.string("filename", ""));
      if (file.empty()) return located(at, "imagemap needs a \"string filename\"");
      PBRT_TRY(encoding, ps.string("encoding", "sRGB"));
      ImageReadOptions options;
      options.max_file_bytes = options_.max_file_bytes;
      options.max_texels = options_.max_texels;
      if (encoding == "sRGB") {
        options.encoding = ImageEncoding::kSrgb;
      } else if (encoding == "linear") {
        options.encoding = ImageEncoding::kLinear;
      } else {
        double g = 0.0;
        if (encoding.rfind("gamma ", 0) != 0 || !parse_number(encoding.substr(6), &g) || !(g > 0.0 && g <= 10.0))
          return located(ps.find("encoding")->at, "imagemap encoding \"" + excerpt(encoding) + "\" is not supported, expected \"sRGB\", "
                                                    "\"linear\" or \"gamma g\" with g in (0, 10]");
        options.encoding = ImageEncoding::kGamma;
        options.gamma = static_cast<float>(g);
      }
      // Every filter is the bilinear lookup (no mip-mapping): what a converged pixel averages anyway.
      PBRT_TRY(filter, ps.string("filter", "bilinear"));
      if (filter != "bilinear" && filter != "point" && filter != "trilinear" && filter != "ewa" && filter != "EWA")
        return located(ps.find("filter")->at, "imagemap filter \"" + excerpt(filter) + "\" is not supported, expected bilinear, point, trilinear or ewa");
      PBRT_TRY(wrap, ps.string("wrap", "repeat"));
      if (wrap == "repeat") t.wrap = TextureWrap::kRepeat;
      else if (wrap == "clamp") t.wrap = TextureWrap::kClamp;
      else if (wrap == "black") t.wrap = TextureWrap::kBlack;
      else return located(ps.find("wrap")->at, "imagemap wrap \"" + excerpt(wrap) + "\" is not supported, expected repeat, clamp or black");
      PBRT_TRY(scale, ps.number("scale", 1.0));
      PBRT_TRY(invert, ps.boolean("invert", false));
      ps.ignore({"maxanisotropy"});
      PBRT_TRY(image, builder_.add_image(files_.resolve(file), options, ps.find("filename")->at));
      t.kind = TextureKind::kImage;
      t.image = image;
      t.flip_t = true;  // pbrt-v4 looks up t = 1 − v
      t.channel = is_float ? FloatChannel::kPbrt : FloatChannel::kNone;
      t.scale = static_cast<float>(scale);
      t.invert = invert;
      return builder_.add_texture(t);
    }
    if (cls == "checkerboard") {
      PBRT_TRY(dimension, ps.integer("dimension", 2));
      if (dimension != 2)
        return located(ps.find("dimension")->at, "checkerboard dimension " + std::to_string(dimension) + " is not supported: pathex's "
                                                   "textures use the surface's (u, v) (dimension 2)");
      PBRT_TRY(a, operand(ps, "tex1", one, is_float));
      PBRT_TRY(b, operand(ps, "tex2", zero, is_float));
      t.kind = TextureKind::kCheckerboard;
      t.a = a;
      t.b = b;
      return builder_.add_texture(t);
    }
    if (cls == "scale") {
      PBRT_TRY(a, operand(ps, "tex", one, is_float));
      PBRT_TRY(b, operand(ps, "scale", one, true));
      t.kind = TextureKind::kScale;
      t.a = a;
      t.b = b;
      return builder_.add_texture(t);
    }
    if (cls == "mix") {
      PBRT_TRY(a, operand(ps, "tex1", zero, is_float));
      PBRT_TRY(b, operand(ps, "tex2", one, is_float));
      PBRT_TRY(amount, operand(ps, "amount", vec3(0.5f), true));
      t.kind = TextureKind::kMix;
      t.a = a;
      t.b = b;
      t.amount = amount;
      return builder_.add_texture(t);
    }
    if (cls == "constant") {
      PBRT_TRY(v, operand(ps, "value", one, is_float));
      return v;
    }
    return located(at, "texture \"" + excerpt(cls) + "\" is not supported, expected imagemap, checkerboard, scale, mix or constant");
  }

  Result<Material> material(const std::string& type, Params& ps, const Location& at) {
    material_textures_ = {};
    if (type == "diffuse") {
      PBRT_TRY(r, spectrum(ps, "reflectance", vec3(0.5f), TexturedParam::kReflectance));
      if (glm::any(glm::lessThan(r, vec3(0.0f))) || glm::any(glm::greaterThan(r, vec3(1.0f))))
        return located(at, "diffuse reflectance must be within [0, 1]");
      return Material{Diffuse{r}};
    }
    if (type == "conductor") {  // letters: S when smooth, D when rough
      Conductor c;  // pbrt-v4's default: metal-Cu-eta, metal-Cu-k
      if (Param* r = ps.find("reflectance")) {
        // pbrt-v4: eta = 1 and k = 2 sqrt(r) / sqrt(1 − r), r clamped to [0, 0.9999], which
        // reflects r at normal incidence. A texture: that map per hit (texture_eval.cpp's bind).
        if (ps.find("eta") || ps.find("k")) return located(r->at, "conductor takes either reflectance or eta and k, not both");
        PBRT_TRY(refl, spectrum(ps, "reflectance", vec3(1.0f), TexturedParam::kConductorReflectance));
        const vec3 rc = glm::clamp(refl, vec3(0.0f), vec3(0.9999f));
        c.eta = vec3(1.0f);
        c.k = 2.0f * glm::sqrt(rc) / glm::sqrt(vec3(1.0f) - rc);
      } else {
        PBRT_TRY(eta, metal_rgb(ps, "eta", c.eta));
        PBRT_TRY(k, metal_rgb(ps, "k", c.k));
        if (!(glm::all(glm::greaterThan(eta, vec3(0.0f))))) return located(ps.find("eta")->at, "conductor eta must be positive");
        if (glm::any(glm::lessThan(k, vec3(0.0f)))) return located(ps.find("k")->at, "conductor k must be non-negative");
        c.eta = eta;
        c.k = k;
      }
      PBRT_TRY(a, alphas(ps, at, "conductor"));
      c.alpha_u = a.a.x;
      c.alpha_v = a.a.y;
      return Material{c};
    }
    if (type == "dielectric" || type == "thindielectric") {  // letters: S when smooth (always for thin), D when rough
      const bool thin = type == "thindielectric";
      Param* eta_p = ps.find("eta");
      if (eta_p && eta_p->type != "float")
        return located(eta_p->at, "parameter \"" + eta_p->type + " eta\" is not supported: give \"float eta\" (pathex's dielectric has one index)");
      PBRT_TRY(eta, ps.number("eta", 1.5));
      if (!valid_ior(eta)) return located(at, type + " eta must be " + kValidIor + ", found " + fmt_number(eta));
      if (thin) return Material{ThinDielectric{static_cast<float>(eta), vec3(1.0f)}};
      PBRT_TRY(a, alphas(ps, at, "dielectric"));
      if (std::max(a.a.x, a.a.y) >= kSmoothAlpha) return Material{RoughDielectric{static_cast<float>(eta), vec3(1.0f), a.a.x, a.a.y}};
      return Material{Dielectric{static_cast<float>(eta), vec3(1.0f)}};
    }
    if (type == "diffusetransmission") {  // letters: D
      PBRT_TRY(scale, ps.number("scale", 1.0));
      PBRT_TRY(r, spectrum(ps, "reflectance", vec3(0.25f), TexturedParam::kReflectance, static_cast<float>(scale)));
      PBRT_TRY(t, spectrum(ps, "transmittance", vec3(0.25f), TexturedParam::kTransmittance, static_cast<float>(scale)));
      // pbrt-v4 clamps each of scale · reflectance and scale · transmittance to [0, 1].
      const vec3 rs = glm::clamp(r * static_cast<float>(scale), vec3(0.0f), vec3(1.0f));
      const vec3 ts = glm::clamp(t * static_cast<float>(scale), vec3(0.0f), vec3(1.0f));
      return Material{DiffuseTransmission{rs, ts}};
    }
    if (type == "measured")
      return located(at, "material \"measured\" is not supported: it needs the RGL measured-BSDF file reader and its "
                         "spectral tables, which pathex does not have");
    if (type == "subsurface")
      return located(at, "material \"subsurface\" is not supported: it needs volumetric path tracing under the surface "
                         "(a medium and random walks inside it), which pathex does not have");
    if (type == "hair")
      return located(at, "material \"hair\" is not supported: it needs pbrt-v4's hair BSDF on curve shapes, which pathex "
                         "does not have");
    if (type == "coateddiffuse" || type == "coatedconductor") {  // pbrt-v4's layered models (trace/bsdf_layered.h), its defaults
      const bool metal = type == "coatedconductor";
      const std::string eta_name = metal ? "interface.eta" : "eta";
      CoatedDiffuse c;
      if (!metal) {
        PBRT_TRY(r, spectrum(ps, "reflectance", vec3(0.5f), TexturedParam::kReflectance));
        if (glm::any(glm::lessThan(r, vec3(0.0f))) || glm::any(glm::greaterThan(r, vec3(1.0f))))
          return located(ps.find("reflectance")->at, "coateddiffuse reflectance must be within [0, 1]");
        c.reflectance = r;
      }
      PBRT_TRY(albedo, ps.rgb("albedo", vec3(0.0f), true));
      if (glm::any(glm::lessThan(albedo, vec3(0.0f))) || glm::any(glm::greaterThan(albedo, vec3(1.0f))))
        return located(ps.find("albedo")->at, type + " albedo must be within [0, 1]");
      Param* eta_p = ps.find(eta_name);
      if (eta_p && eta_p->type != "float")
        return located(eta_p->at, "parameter \"" + eta_p->type + " " + eta_name + "\" is not supported: give \"float " + eta_name + "\" (pathex's coat has one index)");
      PBRT_TRY(eta, ps.number(eta_name, 1.5));
      if (!valid_ior(eta)) return located(eta_p ? eta_p->at : at, type + " " + eta_name + " must be " + kValidIor + ", found " + fmt_number(eta));
      PBRT_TRY(a2, alphas(ps, at, type.c_str(), metal ? "interface." : ""));
      if (metal && a2.textured()) return located(at, "a texture for coatedconductor's interface roughness is not supported");
      if (a2.a.x != a2.a.y || a2.texture[0] != a2.texture[1]) return located(at, "anisotropic roughness (uroughness != vroughness) is not supported");
      const float a = a2.a.x;
      PBRT_TRY(thickness, ps.number("thickness", 0.01));
      if (!(thickness >= 0.0 && thickness <= 1e6)) return located(ps.find("thickness")->at, type + " thickness must be within [0, 1e6]");
      PBRT_TRY(g, ps.number("g", 0.0));
      if (!(g > -1.0 && g < 1.0)) return located(ps.find("g")->at, type + " g must be within (-1, 1)");
      PBRT_TRY(depth, ps.integer("maxdepth", 10));
      if (depth < 1 || depth > kMaxCoatDepth)
        return located(ps.find("maxdepth")->at, type + " maxdepth must be within [1, " + std::to_string(kMaxCoatDepth) + "]");
      PBRT_TRY(samples, ps.integer("nsamples", 1));
      if (samples < 1 || samples > kMaxCoatSamples)
        return located(ps.find("nsamples")->at, type + " nsamples must be within [1, " + std::to_string(kMaxCoatSamples) + "]");
      c.albedo = albedo;
      c.roughness = a < 1e-3f ? 0.0f : a;  // pbrt treats alpha < 1e-3 as smooth
      c.eta = static_cast<float>(eta);
      c.thickness = static_cast<float>(thickness);
      c.g = static_cast<float>(std::clamp(g, -0.999, 0.999));
      c.max_depth = depth;
      c.samples = samples;
      if (metal) {
        // The base: pbrt-v4's conductor.eta and conductor.k (default copper) or reflectance r
        // (η = 1, k = 2√r/√(1 − r), r clamped to [0, 0.9999]), both divided by the coat's eta.
        c.base = CoatBase::kConductor;
        Conductor& k = c.conductor;
        if (Param* r = ps.find("reflectance")) {
          if (ps.find("conductor.eta") || ps.find("conductor.k"))
            return located(r->at, "coatedconductor takes either reflectance or conductor.eta and conductor.k, not both");
          if (r->type == "texture") return located(r->at, "a texture for coatedconductor's reflectance is not supported");
          PBRT_TRY(refl, ps.rgb("reflectance", vec3(1.0f), true));
          const vec3 rc = glm::clamp(refl, vec3(0.0f), vec3(0.9999f));
          k.eta = vec3(1.0f);
          k.k = 2.0f * glm::sqrt(rc) / glm::sqrt(vec3(1.0f) - rc);
        } else {
          for (const char* name : {"conductor.eta", "conductor.k"})
            if (Param* p = ps.find(name); p && p->type == "texture") return located(p->at, std::string("a texture for coatedconductor's ") + name + " is not supported");
          PBRT_TRY(ce, metal_rgb(ps, "conductor.eta", k.eta));
          PBRT_TRY(ck, metal_rgb(ps, "conductor.k", k.k));
          if (!(glm::all(glm::greaterThan(ce, vec3(0.0f))))) return located(ps.find("conductor.eta")->at, "coatedconductor conductor.eta must be positive");
          if (glm::any(glm::lessThan(ck, vec3(0.0f)))) return located(ps.find("conductor.k")->at, "coatedconductor conductor.k must be non-negative");
          k.eta = ce;
          k.k = ck;
        }
        k.eta /= c.eta;
        k.k /= c.eta;
        PBRT_TRY(ca, alphas(ps, at, "coatedconductor", "conductor."));
        if (ca.textured()) return located(at, "a texture for coatedconductor's conductor roughness is not supported");
        k.alpha_u = ca.a.x;
        k.alpha_v = ca.a.y;
        if (c.smooth() && k.smooth() && albedo != vec3(0.0f))
          return located(ps.find("albedo")->at, "coatedconductor with a smooth interface over a smooth conductor and a scattering layer (albedo > 0) is "
                                                "not supported: pathex samples it as one delta reflection, which needs albedo 0");
      }
      return Material{c};
    }
    if (type == "mix") {
      Param* m = ps.find("materials");
      if (!m || m->type != "string" || m->strings.size() != 2) return located(m ? m->at : at, "mix needs \"string materials\" [\"a\" \"b\"]");
      int amount_texture = -1;
      if (Param* a = ps.find("amount"); a && a->type == "texture") {
        PBRT_TRY(index, operand(ps, "amount", vec3(0.5f), true));
        amount_texture = index;
      }
      PBRT_TRY(amount, amount_texture >= 0 ? Result<double>(0.5) : ps.number("amount", 0.5));
      if (amount < 0 || amount > 1) return located(at, "mix amount must be within [0, 1]");
      Material parts[2];
      MaterialTextures part_textures[2];
      for (int i = 0; i < 2; ++i) {
        if (interface_names_.count(m->strings[static_cast<std::size_t>(i)]) != 0)
          return located(m->at, "mix with the interface material \"" + excerpt(m->strings[static_cast<std::size_t>(i)]) +
                                    "\" (no surface) is not supported");
        auto it = named_materials_.find(m->strings[static_cast<std::size_t>(i)]);
        if (it == named_materials_.end()) return located(m->at, "unknown named material \"" + excerpt(m->strings[static_cast<std::size_t>(i)]) + "\"");
        parts[i] = it->second;
        if (auto t = named_material_textures_.find(it->first); t != named_material_textures_.end()) part_textures[i] = t->second;
        if (part_textures[i].perturb != NormalPerturbation::kNone)
          return located(m->at, "a mix of \"" + excerpt(it->first) + "\", which has a bump or normal map, is not supported");
        if (part_textures[i].amount >= 0)
          return located(m->at, "a mix of \"" + excerpt(it->first) + "\", itself a mix by a texture amount, is not supported");
      }
      auto [mixed, textures] = import::blend_textured(parts[0], part_textures[0], parts[1], part_textures[1], static_cast<float>(amount), amount_texture);
      material_textures_ = std::move(textures);
      return mixed;
    }
    return located(at, "material \"" + excerpt(type) + "\" is not supported, expected diffuse, coateddiffuse, coatedconductor, conductor, dielectric, "
                       "thindielectric, diffusetransmission, interface or mix");
  }

  int current_material() {
    if (gs_.material >= 0) return gs_.material;
    if (default_material_ < 0) default_material_ = builder_.add_material("pbrt default diffuse", Material{Diffuse{vec3(0.5f)}});
    return default_material_;
  }

  // --- lights ---
  // pbrt-v4's ImageInfiniteLight (docs/lights.md): an equal-area square image in the light's
  // space (the CTM at the LightSource), times scale, scaled to `illuminance` when given.
  std::optional<Error> image_infinite_light(Params& ps, Param& filename, const Location& at) {
    if (Param* l = ps.find("L")) return located(l->at, "give \"L\" or \"filename\", not both (as pbrt-v4)");
    if (builder_.has_environment_image()) return located(at, "a second image infinite light is not supported: a scene has at most one");
    PBRT_TRY(file, ps.string("filename", ""));
    PBRT_TRY(scale, ps.number("scale", 1.0));
    PBRT_TRY(illuminance, ps.number("illuminance", -1.0));
    float s = 1.0f;
    if (!import::is_similarity(gs_.ctm, &s)) return located(at, "an image infinite light under a non-uniform scale or shear is not supported");
    Result<EnvironmentImage> img =
        load_environment_image(files_.resolve(file), file, /*equal_area=*/true, vec3(static_cast<float>(scale)), options_, builder_.texels());
    if (!img) {
      Error e = located(filename.at, "the image '" + excerpt(file, kMaxPathBytes) + "': " + img.error().message);
      e.code = img.error().code;
      return e;
    }
    if (illuminance > 0.0) {
      const double k = pbrt_image_illuminance(*img);
      if (!(k > 0.0)) return located(at, "illuminance is given but the image's upper hemisphere is black: nothing to scale");
      for (vec3& t : img->texels) t *= static_cast<float>(illuminance / k);
    }
    if (std::optional<std::string> bad = settle_environment_values(&*img)) return located(at, *bad);
    img->to_world = glm::mat3(gs_.ctm) / s;
    builder_.add_environment_image(std::move(*img), at.str());
    return std::nullopt;
  }

  std::optional<Error> light(const std::string& type, Params& ps, const Location& at) {
    const bool point = type == "point", spot = type == "spot", distant = type == "distant", infinite = type == "infinite";
    for (const char* p : {"power", "illuminance"})
      if (Param* q = ps.find(p); q && !(infinite && std::string(p) == "illuminance"))
        return located(q->at, "parameter '" + std::string(p) + "' is not supported: give the light's I or L and scale");
    if (!point && !spot && !distant && !infinite)
      return located(at, "light \"" + excerpt(type) + "\" is not supported, expected point, spot, distant, infinite or an AreaLightSource");
    if (infinite) {
      if (Param* q = ps.find("portal"))
        return located(q->at, "portals are not supported: render the light without its portal (pbrt-v4 uses the portal only to sample it)");
      if (Param* f = ps.find("filename")) return image_infinite_light(ps, *f, at);
    }
    PBRT_TRY(value, ps.rgb(distant || infinite ? "L" : "I", vec3(1.0f), false));
    PBRT_TRY(scale, ps.number("scale", 1.0));
    vec3 emitted = value * static_cast<float>(scale);
    if (infinite) {  // the same radiance from every direction: no transform changes it
      PBRT_TRY(illuminance, ps.number("illuminance", -1.0));
      // pbrt-v4: the upper hemisphere's illuminance of a uniform L is π L (in luminance).
      const double lum = 0.2126 * emitted.x + 0.7152 * emitted.y + 0.0722 * emitted.z;
      if (illuminance > 0.0 && lum > 0.0) emitted *= static_cast<float>(illuminance / (std::numbers::pi * lum));
      if (auto e = import::check_light_value(emitted, at)) return e;
      builder_.add_environment(emitted, at.str());
      return std::nullopt;
    }
    if (auto e = import::check_light_value(emitted, at)) return e;
    PBRT_TRY(from, ps.point("from", vec3(0.0f)));
    if (point) {
      builder_.add_light(PointLight{import::apply_point(gs_.ctm, from), emitted});
      return std::nullopt;
    }
    PBRT_TRY(to, ps.point("to", vec3(0.0f, 0.0f, 1.0f)));
    const vec3 dir = import::apply_vector(gs_.ctm, to - from);
    if (!(glm::length(dir) > 0.0f)) return located(at, "the light's from and to coincide");
    if (distant) {
      builder_.add_distant(dir, emitted);  // pbrt's "L" of a distant light is its irradiance
      return std::nullopt;
    }
    PBRT_TRY(cone, ps.number("coneangle", 30.0));
    PBRT_TRY(delta, ps.number("conedeltaangle", 5.0));
    float s = 1.0f;
    if (!import::is_similarity(gs_.ctm, &s)) return located(at, "a spot light under a non-uniform scale is not supported");
    if (!(cone > 0.0) || cone > 180.0) return located(at, "coneangle must be within (0, 180]");
    if (!(delta >= 0.0)) return located(at, "conedeltaangle must not be negative");
    // pbrt-v4: smoothstep in cos θ from cos(coneangle) to cos(coneangle − conedeltaangle); a delta
    // past the cone's angle starts the falloff on the axis.
    builder_.add_light(SpotLight{import::apply_point(gs_.ctm, from), glm::normalize(dir), emitted, static_cast<float>(cone),
                                 static_cast<float>(std::max(0.0, cone - delta)), SpotFalloff::kSmoothstep});
    return std::nullopt;
  }

  static std::string fmt_number(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }

  // --- shapes ---
  std::optional<Error> shape(const std::string& type, Params& ps, const Location& at) {
    if (gs_.material == kInterface) {  // no surface: nothing to import
      if (gs_.area) return located(at, "an area light on a shape of material \"interface\" (no surface) is not supported");
      if (!gs_.interior.empty())
        return located(at, "a medium bounded by the \"interface\" material (no surface) is not supported: pathex's media fill the inside of a "
                           "transmissive surface, such as a dielectric");
      ps.ignore_all();
      return std::nullopt;
    }
    Shape s;
    if (Param* p = ps.find("alpha")) {  // an alpha cut-out: a float texture or value (docs/textures.md)
      if (gs_.area) return located(p->at, "an alpha cut-out on an area light is not supported");
      PBRT_TRY(alpha, operand(ps, "alpha", vec3(1.0f), true));
      const Texture& t = builder_.texture(alpha);
      if (t.kind == TextureKind::kConstant && !(t.value.x >= 0.0f && t.value.x <= 1.0f)) return located(p->at, "alpha must be within [0, 1]");
      if (t.kind != TextureKind::kConstant || t.value.x < 1.0f) s.alpha = alpha;
    }
    s.pointer = at.str();
    s.material = current_material();
    if (!gs_.interior.empty()) s.absorption = media_.at(gs_.interior);  // defined: checked by MediumInterface
    if (gs_.area) {
      s.emission = gs_.area->radiance;
      s.two_sided = gs_.area->two_sided;
    }
    // pbrt's front side: the parametric normal, flipped by ReverseOrientation and by a transform
    // that swaps handedness (shapes.cpp: flipNormal = reverseOrientation ^ transformSwapsHandedness).
    const bool flip = gs_.reverse != import::swaps_handedness(gs_.ctm);
    const glm::mat4& m = gs_.ctm;
    if (type == "sphere" || type == "disk") {
      if (Param* p = ps.find("phimax"); p && !(p->numbers.size() == 1 && p->numbers[0] >= 360.0))
        return located(p->at, "partial " + type + "s (phimax) are not supported");
      float scale = 1.0f;
      if (!import::is_similarity(m, &scale)) return located(at, "a " + type + " under a non-uniform scale is not supported");
      PBRT_TRY(radius, ps.number("radius", 1.0));
      if (!(radius > 0)) return located(at, "radius must be positive");
      if (type == "sphere") {
        for (const char* z : {"zmin", "zmax"})
          if (Param* p = ps.find(z)) return located(p->at, "partial spheres (" + std::string(z) + ") are not supported");
        if (flip && s.emissive() && !s.two_sided)
          return located(at, "a sphere emitting inwards (ReverseOrientation or a mirroring transform) is not supported");
        s.geometry = SphereShape{import::apply_point(m, vec3(0.0f)), static_cast<float>(radius) * scale};
      } else {
        PBRT_TRY(height, ps.number("height", 0.0));
        PBRT_TRY(inner, ps.number("innerradius", 0.0));
        if (inner != 0.0) return located(ps.find("innerradius")->at, "disks with a hole (innerradius) are not supported");
        const vec3 n = import::apply_normal(m, vec3(0, 0, 1));
        s.geometry = DiskShape{import::apply_point(m, vec3(0, 0, static_cast<float>(height))), flip ? -n : n,
                               static_cast<float>(radius) * scale};
      }
      return place(std::move(s), at);
    }
    if (type == "trianglemesh" || type == "bilinearmesh" || type == "plymesh") {
      // "S" (per-vertex tangents) orients anisotropic BSDFs only, which pathex's meshes take from the normal.
      ps.ignore({"faceIndices", "S"});
      MeshShape mesh;
      if (type == "plymesh") {
        if (Param* p = ps.find("displacement")) return located(p->at, "displacement is not supported");
        ps.ignore({"edgelength"});
        PBRT_TRY(file, ps.string("filename", ""));
        if (file.empty()) return located(at, "plymesh needs a \"string filename\"");
        PBRT_TRY(ply, import::load_ply_mesh(files_.resolve(file), at, options_));
        mesh = std::move(ply);
        mesh_elements_ += mesh.positions.size() + mesh.triangles.size();
        if (auto e = check_mesh_elements(mesh_elements_, options_, at.str())) return e;
        mesh.file = file;
      } else {
        PBRT_TRY(p, ps.points("P"));
        const std::size_t corners = type == "trianglemesh" ? 3 : 4;
        PBRT_TRY(idx, mesh_indices(ps, type, p.size(), corners, at));
        mesh_elements_ += p.size() + idx.size() / corners * (corners - 2);  // a patch: 4 vertices and 2 triangles at most
        if (auto e = check_mesh_elements(mesh_elements_, options_, at.str())) return e;
        mesh.positions = p;
        PBRT_TRY(normals, ps.points("N", "normal"));
        if (!normals.empty() && normals.size() != p.size())
          return located(ps.find("N")->at, "\"normal N\" has " + std::to_string(normals.size()) + " normals for " + std::to_string(p.size()) +
                                               " points, expected one per point");
        if (corners == 3) mesh.normals = std::move(normals);  // bilinear patches: flat, as the planar ones pathex takes are
        PBRT_TRY(uv, ps.numbers_of("uv", "point2"));
        if (!uv.empty() && uv.size() != 2 * p.size())
          return located(ps.find("uv")->at, "\"point2 uv\" has " + std::to_string(uv.size() / 2) + " pairs for " + std::to_string(p.size()) +
                                                " points, expected one per point");
        for (std::size_t i = 0; corners == 3 && i + 1 < uv.size(); i += 2)
          mesh.uvs.emplace_back(static_cast<float>(uv[i]), static_cast<float>(uv[i + 1]));
        if (corners == 3) {
          for (std::size_t i = 0; i < idx.size(); i += 3) mesh.triangles.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
        } else {
          // A bilinear patch p00 p10 p01 p11 that is a planar parallelogram is a quad; planar
          // otherwise it is two triangles; a curved patch is refused.
          for (std::size_t i = 0; i < idx.size(); i += 4) {
            const vec3 p00 = import::apply_point(m, p[idx[i]]), p10 = import::apply_point(m, p[idx[i + 1]]);
            const vec3 p01 = import::apply_point(m, p[idx[i + 2]]), p11 = import::apply_point(m, p[idx[i + 3]]);
            const vec3 n = glm::cross(p10 - p00, p01 - p00);
            const float size = std::max(glm::length(p10 - p00), glm::length(p01 - p00));
            if (!(glm::length(n) > 0.0f)) return located(at, "a degenerate bilinear patch (zero area)");
            if (std::fabs(glm::dot(p11 - p00, glm::normalize(n))) > 1e-5f * size)
              return located(at, "a curved (non-planar) bilinear patch is not supported");
            Shape q = s;
            if (glm::length(p11 - (p10 + p01 - p00)) <= 1e-5f * size) {
              q.geometry = flip ? QuadShape{p00, p01 - p00, p10 - p00} : QuadShape{p00, p10 - p00, p01 - p00};
            } else {
              MeshShape tri;
              tri.positions = {p00, p10, p11, p01};
              tri.triangles = {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 3)};
              if (flip)
                for (glm::uvec3& t : tri.triangles) std::swap(t.y, t.z);
              q.geometry = std::move(tri);
            }
            if (auto e = place(std::move(q), at)) return e;
          }
          return std::nullopt;
        }
      }
      if (auto e = add_mesh(std::move(s), std::move(mesh), m, flip, at)) return e;
      return std::nullopt;
    }
    if (type == "loopsubdiv") return loop_subdivision(std::move(s), ps, m, flip, at);
    if (type == "cylinder") {  // a tessellated tube (import::tube_mesh)
      if (Param* p = ps.find("phimax"); p && !(p->numbers.size() == 1 && p->numbers[0] >= 360.0))
        return located(p->at, "partial cylinders (phimax) are not supported");
      PBRT_TRY(radius, ps.number("radius", 1.0));
      PBRT_TRY(zmin, ps.number("zmin", -1.0));
      PBRT_TRY(zmax, ps.number("zmax", 1.0));
      if (!(radius > 0)) return located(at, "radius must be positive");
      if (zmin == zmax) return located(at, "a cylinder of zero height (zmin equals zmax)");
      MeshShape mesh = import::tube_mesh(static_cast<float>(radius), static_cast<float>(std::min(zmin, zmax)), static_cast<float>(std::max(zmin, zmax)));
      if (auto e = add_mesh(std::move(s), std::move(mesh), m, flip, at)) return e;
      return std::nullopt;
    }
    return located(at, "shape \"" + excerpt(type) + "\" is not supported, expected trianglemesh, plymesh, bilinearmesh, loopsubdiv, sphere, disk or cylinder");
  }

  // The "integer indices" of a mesh of `points` points, `corners` per face (without indices, a
  // mesh of exactly one face's points is that face), each in range.
  Result<std::vector<long long>> mesh_indices(Params& ps, const std::string& type, std::size_t points, std::size_t corners, const Location& at) {
    std::vector<long long> idx;
    if (Param* ip = ps.find("indices")) {
      if (ip->type != "integer") return located(ip->at, "indices must be integers");
      for (double x : ip->numbers) {
        if (x != std::floor(x) || std::fabs(x) > 1e15) return located(ip->at, "indices must be integers");
        idx.push_back(static_cast<long long>(x));
      }
    } else if (points == corners) {
      for (std::size_t i = 0; i < corners; ++i) idx.push_back(static_cast<long long>(i));
    }
    if (points == 0 || idx.empty() || idx.size() % corners != 0)
      return located(at, type + " needs \"point3 P\" and \"integer indices\" (" + std::to_string(corners) + " per " +
                             (corners == 3 ? "triangle" : "patch") + ")");
    for (long long i : idx)
      if (i < 0 || i >= static_cast<long long>(points)) return located(ps.find("indices")->at, "index " + std::to_string(i) + " is out of range, expected 0.." + std::to_string(points - 1));
    return idx;
  }

  // pbrt-v4's "loopsubdiv": the control mesh subdivided at load (scene/loop_subdivision.h), then a
  // mesh with per-vertex normals like a trianglemesh with "N". pbrt-v4 reads "scheme" and ignores it.
  std::optional<Error> loop_subdivision(Shape s, Params& ps, const glm::mat4& m, bool flip, const Location& at) {
    ps.ignore({"scheme"});
    PBRT_TRY(levels, ps.integer("levels", 3));
    if (levels < 0) return located(ps.find("levels")->at, "levels must be 0 or more");
    PBRT_TRY(p, ps.points("P"));
    PBRT_TRY(idx, mesh_indices(ps, "loopsubdiv", p.size(), 3, at));
    MeshShape control;
    control.positions = std::move(p);
    for (std::size_t i = 0; i < idx.size(); i += 3) control.triangles.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
    std::size_t edges = 0;
    if (auto why = import::loop_check(control, &edges)) return located(ps.find("indices") ? ps.find("indices")->at : at, *why);
    const import::LoopCounts n = import::loop_counts(control.positions.size(), edges, control.triangles.size(), levels);
    const std::uint64_t most = std::numeric_limits<std::size_t>::max() - mesh_elements_;  // saturating
    mesh_elements_ += static_cast<std::size_t>(n.vertices >= most || n.triangles >= most - n.vertices ? most : n.vertices + n.triangles);
    if (auto e = check_mesh_elements(mesh_elements_, options_, at.str())) return e;
    return add_mesh(std::move(s), import::loop_subdivide(control, levels), m, flip, at);
  }

  // A mesh in object space, placed by `m` with its front side pbrt's: the winding's, reversed by
  // `flip` (ReverseOrientation xor a mirroring transform), or with per-vertex normals theirs,
  // negated by ReverseOrientation alone (a mirroring transform carries normals correctly).
  std::optional<Error> add_mesh(Shape s, MeshShape mesh, const glm::mat4& m, bool flip, const import::Location& at) {
    if (auto e = import::place_mesh(&mesh, m, /*flip_normals=*/gs_.reverse, /*flip_winding=*/flip, at)) return e;
    s.geometry = std::move(mesh);
    return place(std::move(s), at);
  }

  // --- the camera, once the film is known ---
  std::optional<Error> make_camera() {
    Params& ps = camera_params_;
    const Location at = camera_at_.file.empty() ? Location{main_file_} : camera_at_;
    const std::string what = "Camera \"" + excerpt(camera_type_) + "\"";
    for (const char* p : {"screenwindow", "frameaspectratio"})
      if (Param* q = ps.find(p)) return located(q->at, "parameter '" + std::string(p) + "' is not supported");
    ps.ignore({"shutteropen", "shutterclose"});
    const glm::mat4 world_from_camera = glm::inverse(camera_from_world_);
    float scale = 1.0f;
    if (!import::is_similarity(world_from_camera, &scale) || std::fabs(scale - 1.0f) > 1e-3f)
      return located(at, "the camera's transform must be rigid (rotations, translations and mirroring only)");
    Camera c;
    c.width = width_;
    c.height = height_;
    c.position = import::apply_point(world_from_camera, vec3(0.0f));
    const vec3 forward = glm::normalize(import::apply_vector(world_from_camera, vec3(0, 0, 1)));
    c.look_at = c.position + forward;
    c.up = glm::normalize(import::apply_vector(world_from_camera, vec3(0, 1, 0)));
    const vec3 right = glm::normalize(import::apply_vector(world_from_camera, vec3(1, 0, 0)));
    // pbrt's screen window spans [-1, 1] on the shorter image axis.
    const float aspect = static_cast<float>(width_) / static_cast<float>(height_);
    const float y_extent = aspect >= 1.0f ? 1.0f : 1.0f / aspect;
    PBRT_TRY(lens, ps.number("lensradius", 0.0));
    PBRT_TRY(focus, ps.number("focaldistance", 1e6));
    if (lens < 0 || !(focus > 0)) return located(at, "lensradius must be non-negative and focaldistance positive");
    if (camera_type_ == "perspective") {
      PBRT_TRY(fov, ps.number("fov", 90.0));
      if (!(fov > 0 && fov < 180)) return located(at, "fov must be within (0, 180)");
      const float tan_y = std::tan(glm::radians(static_cast<float>(fov)) * 0.5f) * y_extent;
      c.fov_degrees = glm::degrees(2.0f * std::atan(tan_y));
      if (lens > 0) {
        c.type = SensorType::kLens;
        c.aperture_radius = static_cast<float>(lens);
        c.focus_distance = static_cast<float>(focus);
      }
    } else {
      if (lens > 0) return located(at, "an orthographic camera with a lens is not supported");
      c.type = SensorType::kOrthographic;
      c.film_height = 2.0f * y_extent;
      c.film_width = c.film_height * aspect;
    }
    if (auto e = ps.unused(what)) return e;
    builder_.set_camera(c, right);
    return std::nullopt;
  }
};

}  // namespace

Result<Scene> load_scene_pbrt(const std::string& path, const SceneLoadOptions& options) { return Importer(path, options).run(); }

}  // namespace pathex
