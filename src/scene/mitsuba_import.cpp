// Mitsuba 3 scene import. pugixml parses the XML (kept as text, so that every element's offset
// becomes a line and column); the importer walks <scene>, resolving <default> parameters ($name),
// <include> files and <ref> ids, and turns each plugin of the subset into the scene model.
//
// Each plugin reads its properties through a Props object that marks them used; a property left
// unused, an unknown plugin type or tag is refused with its location.
#include "scene/mitsuba_import.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <pugixml.hpp>

#include "scene/import_common.h"
#include "scene/serialized.h"
#include "scene/metal_spectra.h"
#include "optics/internal_reflectance.h"

namespace pathex {
namespace {

using import::Location;
using import::located;
using glm::vec3;

#define MI_TRY(var, expr)          \
  auto var##_r = (expr);           \
  if (!var##_r) return var##_r.error(); \
  auto var = std::move(*var##_r)

// Mitsuba's named indices of refraction (its documentation's table).
std::optional<double> named_ior(const std::string& name) {
  static const std::map<std::string, double> table = {
      {"vacuum", 1.0},       {"helium", 1.000036},  {"hydrogen", 1.000132}, {"air", 1.000277},
      {"carbon dioxide", 1.00045}, {"water", 1.3330}, {"acetone", 1.36},    {"ethanol", 1.361},
      {"carbon tetrachloride", 1.461}, {"glycerol", 1.4729}, {"benzene", 1.501}, {"silicone oil", 1.52045},
      {"bromine", 1.661},    {"water ice", 1.31},   {"fused quartz", 1.458}, {"pyrex", 1.470},
      {"acrylic glass", 1.49}, {"polypropylene", 1.49}, {"bk7", 1.5046},   {"sodium chloride", 1.544},
      {"amber", 1.55},       {"pet", 1.5750},       {"diamond", 2.419}};
  auto it = table.find(name);
  if (it == table.end()) return std::nullopt;
  return it->second;
}

struct Doc {
  std::string path, text;
  pugi::xml_document xml;
};

class Importer;

// The properties and nested objects of one plugin element.
class Props {
 public:
  Props(Importer* im, pugi::xml_node node, std::string what) : im_(im), node_(node), what_(std::move(what)) {
    for (pugi::xml_node c : node.children()) {
      if (c.type() != pugi::node_element) continue;
      children_.push_back({c, false});
    }
  }
  const std::string& what() const { return what_; }
  pugi::xml_node find(const std::string& name) {
    for (Child& c : children_)
      if (c.node.attribute("name").value() == name) {
        c.used = true;
        return c.node;
      }
    return {};
  }
  // Nested objects with this tag (bsdf, emitter, film, ...), including <ref>s to them.
  std::vector<pugi::xml_node> nested(const std::string& tag);
  void ignore(std::initializer_list<const char*> names) {
    for (Child& c : children_)
      for (const char* n : names) c.used = c.used || c.node.attribute("name").value() == std::string(n) || c.node.name() == std::string(n);
  }
  std::optional<Error> unused() const;

  Result<double> number(const std::string& name, double fallback);
  Result<bool> boolean(const std::string& name, bool fallback);
  Result<std::string> string(const std::string& name, const std::string& fallback);
  Result<vec3> color(const std::string& name, vec3 fallback);
  Result<vec3> point(const std::string& name, vec3 fallback);
  Result<glm::mat4> transform(const std::string& name);

 private:
  struct Child {
    pugi::xml_node node;
    bool used;
  };
  Importer* im_;
  pugi::xml_node node_;
  std::string what_;
  std::vector<Child> children_;
};

class Importer {
 public:
  Importer(std::string path, const SceneLoadOptions& options)
      : main_(std::move(path)), options_(options), files_(main_, options), materials_budget_(options.max_material_nodes) {}

  Result<Scene> run() {
    if (auto e = read_file(main_, Location{main_}, 0)) return *e;
    return builder_.finish(main_, files_.included());
  }

  // --- locations and attributes ---
  Location where(pugi::xml_node n) const {
    for (const Doc& d : docs_) {
      if (n.root() != d.xml.root()) continue;
      const std::ptrdiff_t off = n.offset_debug();
      Location at{d.path};
      if (off < 0) return at;
      at.line = 1;
      std::size_t line_start = 0;
      for (std::size_t i = 0; i < static_cast<std::size_t>(off) && i < d.text.size(); ++i)
        if (d.text[i] == '\n') {
          ++at.line;
          line_start = i + 1;
        }
      // offset_debug points at the element's name; the column names its '<'.
      at.column = static_cast<int>(static_cast<std::size_t>(off) - line_start);
      return at;
    }
    return Location{main_};
  }

  // An attribute's value with $name parameters replaced by their <default>s.
  Result<std::string> attr(pugi::xml_node n, const char* name) const {
    std::string v = n.attribute(name).value();
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] != '$') {
        out += v[i];
        continue;
      }
      std::size_t j = i + 1;
      while (j < v.size() && (std::isalnum(static_cast<unsigned char>(v[j])) || v[j] == '_')) ++j;
      const std::string key = v.substr(i + 1, j - i - 1);
      auto it = defaults_.find(key);
      if (it == defaults_.end()) return located(where(n), "unknown parameter $" + excerpt(key) + " (no <default name=\"" + excerpt(key) + "\">)");
      out += it->second;
      i = j - 1;
    }
    return out;
  }

  Result<std::vector<double>> numbers(pugi::xml_node n, const char* name) const {
    MI_TRY(text, attr(n, name));
    for (char& c : text)
      if (c == ',') c = ' ';
    std::istringstream in(text);
    std::vector<double> out;
    std::string word;
    while (in >> word) {
      char* end = nullptr;
      const double x = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0' || !std::isfinite(x))
        return located(where(n), "bad number '" + excerpt(word) + "' in attribute " + name);
      out.push_back(x);
    }
    return out;
  }

  // <spectrum value="400:0.343, 404:0.445, …"/>: wavelength:value pairs (nm, increasing), as linear sRGB.
  Result<vec3> sampled_spectrum(pugi::xml_node n, const std::string& text, bool emission) const {
    std::vector<double> wavelengths, values;
    std::string list = text;
    for (char& c : list)
      if (c == ',') c = ' ';
    std::istringstream in(list);
    std::string word;
    while (in >> word) {
      const std::size_t colon = word.find(':');
      if (colon == std::string::npos || colon == 0)
        return located(where(n), "bad spectrum entry '" + excerpt(word) + "', expected wavelength:value");
      const std::string wavelength = word.substr(0, colon), value = word.substr(colon + 1);
      char* end1 = nullptr;
      char* end2 = nullptr;
      const double w = std::strtod(wavelength.c_str(), &end1);
      const double v = std::strtod(value.c_str(), &end2);
      if (*end1 != '\0' || value.empty() || *end2 != '\0' || !std::isfinite(w) || !std::isfinite(v))
        return located(where(n), "bad spectrum entry '" + excerpt(word) + "', expected wavelength:value");
      if (!wavelengths.empty() && !(w > wavelengths.back()))
        return located(where(n), "the spectrum's wavelengths must increase, found " + excerpt(word) + " after " + std::to_string(wavelengths.back()));
      wavelengths.push_back(w);
      values.push_back(v);
    }
    if (wavelengths.size() < 2) return located(where(n), "a sampled spectrum needs at least two wavelength:value pairs");
    if (!emission)
      for (double v : values)
        if (v < 0.0) return located(where(n), "a reflectance spectrum must be non-negative");
    return import::spectrum_to_rgb(wavelengths, values, emission);
  }

  Result<vec3> vector3(pugi::xml_node n, vec3 fallback) const {
    if (n.attribute("value")) {
      MI_TRY(v, numbers(n, "value"));
      if (v.size() == 1) return vec3(static_cast<float>(v[0]));
      if (v.size() != 3) return located(where(n), "expected 3 numbers in value");
      return vec3(v[0], v[1], v[2]);
    }
    vec3 out = fallback;
    const char* axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      if (!n.attribute(axes[i])) continue;
      MI_TRY(v, numbers(n, axes[i]));
      if (v.size() != 1) return located(where(n), std::string("expected one number in ") + axes[i]);
      out[i] = static_cast<float>(v[0]);
    }
    return out;
  }

  Result<glm::mat4> transform(pugi::xml_node t) const {
    glm::mat4 m(1.0f);
    for (pugi::xml_node op : t.children()) {
      if (op.type() != pugi::node_element) continue;
      const std::string tag = op.name();
      glm::mat4 step(1.0f);
      if (tag == "translate") {
        MI_TRY(v, vector3(op, vec3(0.0f)));
        step = glm::translate(glm::mat4(1.0f), v);
      } else if (tag == "scale") {
        MI_TRY(v, vector3(op, vec3(1.0f)));
        step = glm::scale(glm::mat4(1.0f), v);
      } else if (tag == "rotate") {
        MI_TRY(axis, vector3(op, vec3(0.0f)));
        MI_TRY(angle, numbers(op, "angle"));
        if (angle.size() != 1 || glm::length(axis) == 0.0f) return located(where(op), "rotate needs an axis (x, y, z or value) and an angle");
        step = glm::rotate(glm::mat4(1.0f), glm::radians(static_cast<float>(angle[0])), glm::normalize(axis));
      } else if (tag == "matrix") {
        MI_TRY(v, numbers(op, "value"));
        if (v.size() != 16 && v.size() != 9) return located(where(op), "matrix needs 16 (or 9) numbers, row by row");
        if (v.size() == 9) {
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) step[c][r] = static_cast<float>(v[static_cast<std::size_t>(3 * r + c)]);
        } else {
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) step[c][r] = static_cast<float>(v[static_cast<std::size_t>(4 * r + c)]);
        }
        if (std::optional<std::string> why = import::matrix_problem(step)) return located(where(op), "the matrix " + *why);
      } else if (tag == "lookat") {
        MI_TRY(origin, numbers(op, "origin"));
        MI_TRY(target, numbers(op, "target"));
        std::vector<double> up = {0, 1, 0};
        if (op.attribute("up")) {
          MI_TRY(u, numbers(op, "up"));
          up = u;
        }
        if (origin.size() != 3 || target.size() != 3 || up.size() != 3) return located(where(op), "lookat needs origin, target and up as 3 numbers each");
        const vec3 o(origin[0], origin[1], origin[2]), tg(target[0], target[1], target[2]), u(up[0], up[1], up[2]);
        if (glm::length(tg - o) == 0.0f) return located(where(op), "lookat's origin and target coincide");
        const vec3 dir = glm::normalize(tg - o);
        if (glm::length(glm::cross(glm::normalize(u), dir)) < 1e-6f) return located(where(op), "lookat's up is parallel to the viewing direction");
        // Mitsuba's look_at: columns left = up × dir, up' = dir × left, dir, origin.
        const vec3 left = glm::normalize(glm::cross(glm::normalize(u), dir));
        step = glm::mat4(glm::vec4(left, 0), glm::vec4(glm::cross(dir, left), 0), glm::vec4(dir, 0), glm::vec4(o, 1));
      } else {
        return located(where(op), "transform operation <" + excerpt(tag) + "> is not supported, expected translate, rotate, scale, matrix or lookat");
      }
      m = step * m;  // each operation applies after the ones before it
    }
    return m;
  }

 private:
  friend class Props;
  bool is_area_emitter(const std::string& id) const { return area_emitters_.count(id) != 0; }
  bool is_texture(const std::string& id) const {
    auto it = ids_.find(id);
    return it != ids_.end() && std::string(it->second.name()) == "texture";
  }
  // What make_bsdf() found textured beside the Material it returns, and a mask's opacity texture
  // (-1: none), for the shape (docs/textures.md); the same for each top-level <bsdf id>.
  MaterialTextures material_textures_;
  int mask_alpha_ = -1;
  std::map<std::string, std::pair<MaterialTextures, int>> bsdf_textures_;
  std::map<std::pair<std::string, bool>, int> texture_ids_;  // (top-level <texture id>, as a float) -> Scene::textures
  std::string main_;
  SceneLoadOptions options_;
  import::SceneFiles files_;
  import::MaterialBudget materials_budget_;
  std::size_t mesh_elements_ = 0;  // vertices + triangles of the meshes so far (--max-mesh-elements)
  std::deque<Doc> docs_;
  std::map<std::string, std::string> defaults_;
  std::map<std::string, pugi::xml_node> ids_;       // every element with an id, in every file: ids are unique
  std::map<std::string, int> groups_;               // shapegroups made, by id
  std::map<std::string, Material> bsdf_materials_;  // top-level <bsdf id>, each made once; <ref>s share it
  std::string defining_;                            // the id of the top-level <bsdf> being made
  std::map<std::string, int> bsdf_index_;
  std::map<std::string, pugi::xml_node> area_emitters_;  // top-level area emitters by id, for shapes' <ref>s
  int default_material_ = -1;
  import::SceneBuilder builder_;

  std::optional<Error> read_file(const std::string& path, const Location& from, int depth) {
    Result<std::string> text = files_.read(path, from, depth, "<include>");
    if (!text) return text.error();
    Doc& d = docs_.emplace_back();
    d.path = path;
    d.text = std::move(*text);
    const pugi::xml_parse_result res = d.xml.load_buffer(d.text.data(), d.text.size());
    if (!res) {
      Location at{path, 1, 1};
      for (std::size_t i = 0; i < static_cast<std::size_t>(std::max<std::ptrdiff_t>(res.offset, 0)) && i < d.text.size(); ++i) {
        if (d.text[i] == '\n') {
          ++at.line;
          at.column = 1;
        } else {
          ++at.column;
        }
      }
      return located(at, std::string("not valid XML: ") + res.description());
    }
    const pugi::xml_node scene = d.xml.child("scene");
    if (!scene) return located(Location{path}, "expected a <scene> root element");
    if (auto e = check_document(d)) return e;
    if (auto e = check_version(scene)) return e;
    // Area emitters defined by id may come after the shapes that <ref> them (Mitsuba's cbox.xml).
    for (pugi::xml_node n : scene.children("emitter"))
      if (std::string(n.attribute("type").value()) == "area" && !std::string(n.attribute("id").value()).empty())
        area_emitters_[n.attribute("id").value()] = n;
    for (pugi::xml_node n : scene.children()) {
      if (n.type() != pugi::node_element) continue;
      if (auto e = top_level(n, depth)) return e;
    }
    return std::nullopt;
  }

  // What pugixml accepts and XML or Mitsuba do not: a second root element, an element with the
  // same attribute twice (pugixml keeps both, and the first would silently win), and two objects
  // with one id (the second would silently replace the first). The walk is iterative: the file
  // may nest as deep as it likes.
  std::optional<Error> check_document(const Doc& d) {
    int roots = 0;
    for (pugi::xml_node n : d.xml.children())
      if (n.type() == pugi::node_element && ++roots == 2)
        return located(where(n), "a second root element <" + excerpt(n.name()) + "> (a scene file has one root, <scene>)");
    std::vector<std::string_view> names;
    for (pugi::xml_node n = d.xml.first_child(); n;) {
      if (n.type() == pugi::node_element) {
        names.clear();
        for (pugi::xml_attribute a : n.attributes()) names.emplace_back(a.name());
        std::sort(names.begin(), names.end());
        for (std::size_t i = 1; i < names.size(); ++i)
          if (names[i] == names[i - 1])
            return located(where(n), "<" + excerpt(n.name()) + "> has the attribute \"" + excerpt(names[i]) + "\" twice");
        const std::string id = n.attribute("id").value();
        if (!id.empty() && std::string_view(n.name()) != "ref") {
          const auto [it, fresh] = ids_.emplace(id, n);
          if (!fresh)
            return located(where(n), "a second object with id \"" + excerpt(id) + "\" (the first is at " + where(it->second).str() + ")");
        }
      }
      if (n.first_child()) {
        n = n.first_child();
        continue;
      }
      while (n && !n.next_sibling()) n = n.parent();
      if (n) n = n.next_sibling();
    }
    return std::nullopt;
  }

  // Every file's <scene> says its format's version, as Mitsuba requires; pathex reads 3.x (0.5,
  // 0.6 and 2.x files name the same plugins and properties differently).
  std::optional<Error> check_version(pugi::xml_node scene) const {
    const char* const kReads = "; pathex reads Mitsuba 3 scenes (version 3.x)";
    if (!scene.attribute("version")) return located(where(scene), std::string("the <scene> has no version attribute") + kReads);
    const std::string v = scene.attribute("version").value();
    std::vector<std::string> parts(1);
    for (char c : v) {
      if (c == '.') parts.emplace_back();
      else parts.back() += c;
    }
    bool number = parts.size() <= 3;
    for (const std::string& part : parts)
      number = number && !part.empty() && part.size() <= 6 && part.find_first_not_of("0123456789") == std::string::npos;
    if (!number) return located(where(scene), "scene version \"" + v.substr(0, 40) + (v.size() > 40 ? "…" : "") + "\" is not a version number" + kReads);
    const int major = std::stoi(parts[0]);
    if (major == 3) return std::nullopt;
    const std::string release = major == 0 && parts.size() > 1 ? "0." + std::to_string(std::stoi(parts[1])) : std::to_string(major);
    return located(where(scene), "scene version " + v + " is Mitsuba " + release + kReads);
  }

  std::optional<Error> top_level(pugi::xml_node n, int depth) {
    const std::string tag = n.name();
    if (tag == "default") {
      const std::string name = n.attribute("name").value();
      if (name.empty() || !n.attribute("value")) return located(where(n), "<default> needs name and value");
      defaults_.emplace(name, n.attribute("value").value());  // the first definition wins
      return std::nullopt;
    }
    if (tag == "path") {  // a folder searched for the files the scene names, before the scene's own (Mitsuba's file resolver)
      Result<std::string> dir = attr(n, "value");
      if (!dir) return dir.error();
      files_.add_search_path(*dir);
      return std::nullopt;
    }
    if (tag == "include") {
      Result<std::string> file = attr(n, "filename");
      if (!file) return file.error();
      Result<std::string> path = files_.include(*file, where(n), "<include>");
      if (!path) return path.error();
      return read_file(*path, where(n), depth + 1);
    }
    if (tag == "bsdf") {
      const std::string id = n.attribute("id").value();
      if (id.empty()) return located(where(n), "a top-level <bsdf> needs an id");
      // Made now, used or not: an unsupported BSDF is refused even before a shape refers to it.
      // It is registered once made, so a <ref> inside it cannot reach it (issue 42: endless recursion).
      defining_ = id;
      Result<Material> m = bsdf(n, 1);
      defining_.clear();
      if (!m) return m.error();
      bsdf_materials_.emplace(id, std::move(*m));
      bsdf_textures_[id] = {std::move(material_textures_), mask_alpha_};
      return std::nullopt;
    }
    if (tag == "texture") {  // made where it is used (as a colour or a float)
      if (n.attribute("id").value() == std::string()) return located(where(n), "a top-level <texture> needs an id");
      return std::nullopt;
    }
    if (tag == "shape") return shape(n);
    if (tag == "emitter") return emitter(n);
    if (tag == "sensor") return sensor(n);
    if (tag == "integrator") return std::nullopt;  // how to estimate is pathex's choice (see the README)
    return located(where(n), "<" + excerpt(tag) + "> is not supported (pathex imports shapes, bsdfs, emitters, a sensor, includes and paths)");
  }

  // --- materials ---
  // `depth`: the nesting of <bsdf> elements, 1 for a top-level or a shape's (--max-scene-depth).
  // Every material made is charged to --max-material-nodes.
  Result<Material> bsdf(pugi::xml_node n, int depth) {
    MI_TRY(m, make_bsdf(n, depth));
    if (auto e = materials_budget_.charge(m, where(n))) return *e;
    return m;
  }
  // int_ior / ext_ior (numbers or Mitsuba's named indices), within valid_ior().
  Result<double> relative_ior(Props& p, pugi::xml_node n, double int_default) {
    double ior[2] = {int_default, 1.000277};
    const char* names[2] = {"int_ior", "ext_ior"};
    for (int i = 0; i < 2; ++i) {
      pugi::xml_node q = p.find(names[i]);
      if (!q) continue;
      if (std::string(q.name()) == "string") {
        MI_TRY(s, attr(q, "value"));
        std::optional<double> v = named_ior(s);
        if (!v) return located(where(q), "unknown index of refraction \"" + excerpt(s) + "\"");
        ior[i] = *v;
      } else {
        MI_TRY(v, p.number(names[i], ior[i]));
        ior[i] = v;
      }
    }
    const double eta = ior[0] / ior[1];
    if (!valid_ior(eta)) {
      std::ostringstream found;
      found << eta;
      return located(where(n), std::string("int_ior / ext_ior must be ") + kValidIor + ", found " + found.str());
    }
    return eta;
  }

  Result<Material> make_bsdf(pugi::xml_node n, int depth) {
    if (depth > options_.max_scene_depth) {
      Error e = located(where(n), limit_message("the nesting of materials", static_cast<std::size_t>(options_.max_scene_depth), "levels",
                                                "--max-scene-depth"));
      e.code = ErrorCode::kLimit;
      return e;
    }
    if (std::string(n.name()) == "ref") {
      MI_TRY(id, attr(n, "id"));
      if (!defining_.empty() && id == defining_)
        return located(where(n), "<ref id=\"" + excerpt(id) + "\"> inside the bsdf it names: a bsdf cannot contain itself");
      auto it = bsdf_materials_.find(id);
      if (it == bsdf_materials_.end()) return located(where(n), "unknown bsdf id \"" + excerpt(id) + "\"");
      std::tie(material_textures_, mask_alpha_) = bsdf_textures_[id];
      return it->second;
    }
    MI_TRY(type, attr(n, "type"));
    Props p(this, n, "<bsdf type=\"" + excerpt(type) + "\">");
    p.ignore({"id"});
    Material m;
    material_textures_ = {};
    mask_alpha_ = -1;
    if (type == "mask") {  // an opacity cut-out over a nested bsdf: the shape's alpha (docs/textures.md)
      const std::vector<pugi::xml_node> inner = p.nested("bsdf");
      if (inner.size() != 1) return located(where(n), "mask with " + std::to_string(inner.size()) + " nested BSDFs is not supported, expected one");
      MI_TRY(alpha, operand(p, "opacity", vec3(0.5f), true));
      MI_TRY(x, bsdf(inner[0], depth + 1));
      if (mask_alpha_ >= 0) return located(where(n), "a mask inside a mask is not supported");
      mask_alpha_ = alpha;
      m = x;
    } else if (type == "normalmap" || type == "bumpmap") {
      // A bump or normal map over a nested bsdf (docs/textures.md): only the shading normal turns.
      // normalmap: the RGB <texture name="normalmap">, 2 RGB − 1 in the shading frame; bumpmap: its
      // one nested float <texture> times `scale` (default 1), differentiated in (u, v).
      int index = -1;
      double scale = 1.0;
      if (type == "normalmap") {
        if (!p.find("normalmap")) return located(where(n), "normalmap needs a <texture name=\"normalmap\">");
        MI_TRY(t, operand(p, "normalmap", vec3(0.5f, 0.5f, 1.0f), false));
        index = t;
      } else {
        const std::vector<pugi::xml_node> tex = p.nested("texture");
        if (tex.size() != 1) return located(where(n), "bumpmap needs one nested <texture>, found " + std::to_string(tex.size()));
        MI_TRY(t, texture(tex[0], true));
        MI_TRY(sc, p.number("scale", 1.0));
        if (!std::isfinite(sc)) return located(where(p.find("scale")), "scale must be finite");
        index = t;
        scale = sc;
      }
      const std::vector<pugi::xml_node> inner = p.nested("bsdf");
      if (inner.size() != 1)
        return located(where(n), type + " with " + std::to_string(inner.size()) + " nested BSDFs is not supported, expected one");
      MI_TRY(x, bsdf(inner[0], depth + 1));
      if (material_textures_.perturb != NormalPerturbation::kNone)
        return located(where(inner[0]), "a bumpmap or normalmap inside a bumpmap or normalmap is not supported");
      material_textures_.perturb = type == "normalmap" ? NormalPerturbation::kNormalMap : NormalPerturbation::kBumpMitsuba;
      material_textures_.perturb_texture = index;
      material_textures_.bump_scale = static_cast<float>(scale);
      m = x;
    } else if (type == "twosided") {
      // pathex's reflective materials are two-sided already.
      const std::vector<pugi::xml_node> inner = p.nested("bsdf");
      if (inner.size() != 1) return located(where(n), "twosided with " + std::to_string(inner.size()) + " nested BSDFs is not supported, expected one");
      MI_TRY(x, bsdf(inner[0], depth + 1));
      if (std::holds_alternative<Dielectric>(x) || std::holds_alternative<RoughDielectric>(x) || std::holds_alternative<ThinDielectric>(x))
        return located(where(n), "a twosided dielectric is not supported");
      m = x;
    } else if (type == "diffuse") {
      MI_TRY(r, spectrum(p, "reflectance", vec3(0.5f), TexturedParam::kReflectance));
      if (glm::any(glm::lessThan(r, vec3(0.0f))) || glm::any(glm::greaterThan(r, vec3(1.0f))))
        return located(where(n), "diffuse reflectance must be within [0, 1]");
      m = Diffuse{r};
    } else if (type == "conductor" || type == "roughconductor") {  // letters: S (conductor), D (roughconductor)
      // Mitsuba 3's defaults: material "none" (eta 0, k 1: reflects everything at every angle).
      Conductor c;
      c.eta = vec3(0.0f);
      c.k = vec3(1.0f);
      MI_TRY(material, p.string("material", "none"));
      if (p.find("eta") || p.find("k")) {
        MI_TRY(eta, p.color("eta", vec3(0.0f)));
        MI_TRY(k, p.color("k", vec3(1.0f)));
        if (glm::any(glm::lessThan(eta, vec3(0.0f)))) return located(where(p.find("eta")), "conductor eta must be non-negative");
        if (glm::any(glm::lessThan(k, vec3(0.0f)))) return located(where(p.find("k")), "conductor k must be non-negative");
        c.eta = eta;
        c.k = k;
      } else if (material != "none") {
        const MetalSpectrum* metal = find_metal(material);
        if (!metal)
          return located(where(p.find("material")), "conductor material \"" + excerpt(material) + "\" is not supported: pathex has the measured "
                                                    "spectra of " + kMetalNames + " (pbrt-v4's tables); give eta and k as rgb for another");
        c.eta = vec3(metal->eta[0], metal->eta[1], metal->eta[2]);
        c.k = vec3(metal->k[0], metal->k[1], metal->k[2]);
      }
      MI_TRY(spec, spectrum(p, "specular_reflectance", vec3(1.0f), TexturedParam::kSpecularReflectance));
      if (glm::any(glm::lessThan(spec, vec3(0.0f))) || glm::any(glm::greaterThan(spec, vec3(1.0f))))
        return located(where(n), "specular_reflectance must be within [0, 1]");
      c.tint = spec;
      if (type == "roughconductor") {
        MI_TRY(a, mitsuba_alphas(p, n, true));
        c.alpha_u = a.alpha.x;
        c.alpha_v = a.alpha.y;
        c.distribution = a.kind;
      }
      // Smooth with eta 0, k 1 (material none) reflects specular_reflectance at every angle: exactly
      // a mirror, which the mirror and manifold connectors know (untextured: they take one
      // reflectance per shape; a textured one stays a conductor, evaluated per hit).
      if (c.smooth() && c.eta == vec3(0.0f) && c.k == vec3(1.0f) && material_textures_.empty()) m = Mirror{spec};
      else m = c;
    } else if (type == "dielectric" || type == "roughdielectric" || type == "thindielectric") {
      // letters: S (dielectric, thindielectric), D (roughdielectric, alpha at least 1e-3)
      MI_TRY(eta, relative_ior(p, n, 1.5046));
      MI_TRY(refl, p.color("specular_reflectance", vec3(1.0f)));
      MI_TRY(trans, p.color("specular_transmittance", vec3(1.0f)));
      if (refl != trans) return located(where(n), "different specular_reflectance and specular_transmittance are not supported: pathex's dielectric has one tint");
      if (type == "thindielectric") {
        m = ThinDielectric{static_cast<float>(eta), refl};
      } else if (type == "roughdielectric") {
        MI_TRY(a, mitsuba_alphas(p, n, true));
        if (std::max(a.alpha.x, a.alpha.y) >= kSmoothAlpha) m = RoughDielectric{static_cast<float>(eta), refl, a.alpha.x, a.alpha.y, a.kind};
        else m = Dielectric{static_cast<float>(eta), refl};
      } else {
        m = Dielectric{static_cast<float>(eta), refl};
      }
    } else if (type == "principled" || type == "principledthin") {
      return located(where(n), "bsdf \"" + type + "\" is not supported: it needs the Disney principled BSDF (sheen, clearcoat, "
                               "specular transmission and their blend), which pathex does not have");
    } else if (type == "plastic" || type == "roughplastic") {
      // Mitsuba's plastic as pbrt-v4's coateddiffuse with a coat of thickness 0 (README import
      // table): the same Fresnel-weighted coat over a Lambertian base with its internal
      // reflections. Mitsuba's default (nonlinear false) makes diffuse_reflectance the albedo under
      // the coat, ρ T(θo); the base that gives it is ρ / (1 − R̄ + ρ R̄) (R̄ the coat's internal
      // reflectance), which the walk's series ρ' (1 − R̄) / (1 − ρ' R̄) returns to ρ.
      MI_TRY(eta, relative_ior(p, n, 1.49));
      MI_TRY(spec, p.color("specular_reflectance", vec3(1.0f)));
      if (spec != vec3(1.0f)) return located(where(p.find("specular_reflectance")), "specular_reflectance other than 1 is not supported: pathex's coat reflects by the Fresnel equations alone");
      // A textured diffuse_reflectance: the map to the base is not linear in ρ, so it is applied per
      // hit to the value looked up (TextureMap::kPlastic in texture_eval.cpp's bind), as Mitsuba
      // applies its own to the value it looks up; mapping the texels would differ between them.
      MI_TRY(rho, spectrum(p, "diffuse_reflectance", vec3(0.5f), TexturedParam::kReflectance));
      if (glm::any(glm::lessThan(rho, vec3(0.0f))) || glm::any(glm::greaterThan(rho, vec3(1.0f))))
        return located(where(p.find("diffuse_reflectance")), "diffuse_reflectance must be within [0, 1]");
      MI_TRY(nonlinear, p.boolean("nonlinear", false));
      CoatedDiffuse c;
      c.eta = static_cast<float>(eta);
      c.thickness = 0.0f;
      c.max_depth = 64;  // (ρ R̄)^32 < 1e-7 of the series is left out
      if (type == "roughplastic") {
        MI_TRY(a, mitsuba_alphas(p, n));
        if (a.alpha.x != a.alpha.y) return located(where(n), "an anisotropic coat (alpha_u unlike alpha_v) is not supported: pathex's coat is isotropic");
        c.roughness = a.alpha.x < kSmoothAlpha ? 0.0f : a.alpha.x;
        c.distribution = a.kind;
      }
      const float r_bar = mean_internal_reflectance(c.eta);
      c.reflectance = nonlinear ? rho : rho / (1.0f - r_bar + rho * r_bar);
      for (TextureBinding& b : material_textures_.bindings)
        if (b.param == TexturedParam::kReflectance && !nonlinear) {
          b.map = TextureMap::kPlastic;
          b.r_bar = r_bar;
        }
      m = c;
    } else if (type == "blendbsdf") {
      int weight_texture = -1;
      if (pugi::xml_node wn = p.find("weight"); wn && (std::string(wn.name()) == "texture" || std::string(wn.name()) == "ref")) {
        MI_TRY(index, operand(p, "weight", vec3(0.5f), true));
        weight_texture = index;
      }
      MI_TRY(w, weight_texture >= 0 ? Result<double>(0.5) : p.number("weight", 0.5));
      if (w < 0 || w > 1) return located(where(n), "weight must be within [0, 1]");
      const std::vector<pugi::xml_node> inner = p.nested("bsdf");
      if (inner.size() != 2) return located(where(n), "blendbsdf needs two nested BSDFs, found " + std::to_string(inner.size()));
      MaterialTextures parts[2];
      Material a, b;
      for (int i = 0; i < 2; ++i) {
        MI_TRY(x, bsdf(inner[static_cast<std::size_t>(i)], depth + 1));
        (i == 0 ? a : b) = x;
        if (mask_alpha_ >= 0) return located(where(inner[static_cast<std::size_t>(i)]), "a mask inside a blendbsdf is not supported");
        if (material_textures_.amount >= 0)
          return located(where(inner[static_cast<std::size_t>(i)]), "a blendbsdf inside a blendbsdf whose weight is a texture is not supported");
        if (material_textures_.perturb != NormalPerturbation::kNone)
          return located(where(inner[static_cast<std::size_t>(i)]), "a bumpmap or normalmap inside a blendbsdf is not supported");
        parts[i] = std::move(material_textures_);
      }
      auto [mixed, textures] = import::blend_textured(a, parts[0], b, parts[1], static_cast<float>(w), weight_texture);
      m = std::move(mixed);
      material_textures_ = std::move(textures);
    } else {
      return located(where(n), "bsdf \"" + excerpt(type) + "\" is not supported, expected diffuse, conductor, roughconductor, dielectric, "
                               "roughdielectric, thindielectric, plastic, roughplastic, blendbsdf, mask, twosided, normalmap or bumpmap");
    }
    if (auto e = p.unused()) return *e;
    return m;
  }

  // The microfacets of roughconductor, roughdielectric and roughplastic: "distribution" beckmann
  // (Mitsuba's default) or ggx, and "alpha" (default 0.1) or "alpha_u" and "alpha_v", each within
  // [0, 1] (Mitsuba's alphas are the distribution's own: no remapping). Its tangents are the
  // shading frame's.
  struct MitsubaMicrofacet {
    glm::vec2 alpha;
    MicrofacetKind kind;
  };
  //
  // `textures` (roughconductor, roughdielectric: Mitsuba 3 takes their alphas as textures; false
  // for its roughplastic, whose alpha is a scalar): an alpha that is a texture binds TexturedParam::kAlphaU or kAlphaV
  // in material_textures_ with the placeholder 1, so the material is rough, letter D; per hit it is
  // clamped to [1e-3, 1] (texture_eval.cpp's bind).
  Result<MitsubaMicrofacet> mitsuba_alphas(Props& p, pugi::xml_node n, bool textures = false) {
    MI_TRY(dist, p.string("distribution", "beckmann"));
    if (dist != "ggx" && dist != "beckmann")
      return located(where(p.find("distribution")), "microfacet distribution \"" + excerpt(dist) + "\" is not supported, expected beckmann or ggx");
    p.ignore({"sample_visible"});
    if (p.find("alpha") && (p.find("alpha_u") || p.find("alpha_v"))) return located(where(p.find("alpha")), "give either alpha or alpha_u and alpha_v");
    glm::vec2 alpha;
    bool textured = false;
    const char* const names[2] = {"alpha_u", "alpha_v"};
    for (int i = 0; i < 2; ++i) {
      const std::string name = p.find(names[i]) ? names[i] : "alpha";
      pugi::xml_node t = p.find(name);
      if (t && is_texture_node(t) && !textures)
        return located(where(t), "a texture for '" + name + "' of roughplastic is not supported: Mitsuba 3's roughplastic takes one <float> " + name);
      if (t && is_texture_node(t)) {
        MI_TRY(index, operand(p, name, vec3(0.1f), true));
        material_textures_.bindings.push_back(TextureBinding{-1, i == 0 ? TexturedParam::kAlphaU : TexturedParam::kAlphaV, index, 1.0f});
        alpha[i] = 1.0f;
        textured = true;
        continue;
      }
      MI_TRY(a, p.number(name, 0.1));
      if (!(a >= 0.0) || a > 1.0) return located(where(n), "alpha must be within [0, 1]");
      alpha[i] = static_cast<float>(a);
    }
    if (textured) alpha = glm::max(alpha, glm::vec2(kSmoothAlpha));  // textured: the rough kind
    return MitsubaMicrofacet{alpha, dist == "ggx" ? MicrofacetKind::kGgx : MicrofacetKind::kBeckmann};
  }
  // A <texture>, or a <ref> to a top-level one.
  bool is_texture_node(pugi::xml_node t) const {
    return std::string(t.name()) == "texture" || (std::string(t.name()) == "ref" && is_texture(t.attribute("id").value()));
  }

  // A texture operand `name` of a bsdf or texture: a nested <texture>, a <ref> to a top-level one,
  // or a value (<rgb>, <float>, <spectrum>) made a constant texture; absent: `fallback`.
  Result<int> operand(Props& p, const std::string& name, vec3 fallback, bool is_float) {
    pugi::xml_node t = p.find(name);
    if (t && std::string(t.name()) == "ref" && is_texture(t.attribute("id").value())) {
      const std::string id = t.attribute("id").value();
      if (auto it = texture_ids_.find({id, is_float}); it != texture_ids_.end()) return it->second;
      MI_TRY(index, texture(ids_.at(id), is_float));
      return texture_ids_[{id, is_float}] = index;
    }
    if (t && std::string(t.name()) == "texture") return texture(t, is_float);
    if (is_float) {
      MI_TRY(x, p.number(name, fallback.x));
      return builder_.constant_texture(vec3(static_cast<float>(x)));
    }
    MI_TRY(v, p.color(name, fallback));
    return builder_.constant_texture(v);
  }

  // A bsdf's colour that may be a texture: its value, or for a texture a placeholder `fallback`
  // and a binding in material_textures_.
  Result<vec3> spectrum(Props& p, const std::string& name, vec3 fallback, TexturedParam param) {
    pugi::xml_node t = p.find(name);
    if (!t || !(std::string(t.name()) == "texture" || (std::string(t.name()) == "ref" && is_texture(t.attribute("id").value()))))
      return p.color(name, fallback);
    MI_TRY(index, operand(p, name, fallback, false));
    material_textures_.bindings.push_back(TextureBinding{-1, param, index, 1.0f});
    return fallback;
  }

  // Mitsuba 3's bitmap and checkerboard textures (docs/textures.md).
  Result<int> texture(pugi::xml_node n, bool is_float) {
    MI_TRY(type, attr(n, "type"));
    Props p(this, n, "<texture type=\"" + excerpt(type) + "\">");
    p.ignore({"id", "name"});
    Texture t;
    if (type != "bitmap" && type != "checkerboard")
      return located(where(n), "texture \"" + excerpt(type) + "\" is not supported, expected bitmap or checkerboard");
    MI_TRY(to_uv, p.transform("to_uv"));  // 2D affine: the x and y rows of the 4 x 4, translation from its last column
    t.uv = UvTransform{{to_uv[0][0], to_uv[1][0], to_uv[3][0], to_uv[0][1], to_uv[1][1], to_uv[3][1]}};
    if (type == "bitmap") {
      MI_TRY(file, p.string("filename", ""));
      if (file.empty()) return located(where(n), "bitmap needs a <string name=\"filename\">");
      MI_TRY(raw, p.boolean("raw", false));
      ImageReadOptions options;
      options.encoding = raw ? ImageEncoding::kLinear : ImageEncoding::kSrgb;
      options.max_file_bytes = options_.max_file_bytes;
      options.max_texels = options_.max_texels;
      // Every filter is the bilinear lookup: what a converged pixel averages anyway.
      MI_TRY(filter, p.string("filter_type", "bilinear"));
      if (filter != "bilinear" && filter != "nearest")
        return located(where(p.find("filter_type")), "filter_type \"" + excerpt(filter) + "\" is not supported, expected bilinear or nearest");
      MI_TRY(wrap, p.string("wrap_mode", "repeat"));
      if (wrap == "repeat") t.wrap = TextureWrap::kRepeat;
      else if (wrap == "clamp") t.wrap = TextureWrap::kClamp;
      else return located(where(p.find("wrap_mode")), "wrap_mode \"" + excerpt(wrap) + "\" is not supported, expected repeat or clamp");
      p.ignore({"format"});
      MI_TRY(image, builder_.add_image(files_.resolve(file), options, where(p.find("filename"))));
      t.kind = TextureKind::kImage;
      t.image = image;
      t.channel = is_float ? FloatChannel::kLuminance : FloatChannel::kNone;
    } else {
      // Mitsuba's cells are halves of the unit square: color0 where the fractional parts of (s, t)
      // are on the same side of ½, i.e. ⌊2s⌋ + ⌊2t⌋ even.
      for (float& x : t.uv.m) x *= 2.0f;
      MI_TRY(a, operand(p, "color0", vec3(0.4f), is_float));
      MI_TRY(b, operand(p, "color1", vec3(0.2f), is_float));
      t.kind = TextureKind::kCheckerboard;
      t.a = a;
      t.b = b;
    }
    if (auto e = p.unused()) return *e;
    return builder_.add_texture(t);
  }

  // The shape's material; `*alpha`: its mask's opacity texture, -1 for none.
  Result<int> material_of(Props& p, pugi::xml_node shape_node, int* alpha) {
    *alpha = -1;
    const std::vector<pugi::xml_node> b = p.nested("bsdf");
    if (b.size() > 1) return located(where(shape_node), "a shape with more than one BSDF");
    if (b.empty()) {
      if (default_material_ < 0) default_material_ = builder_.add_material("mitsuba default diffuse", Material{Diffuse{vec3(0.5f)}});
      return default_material_;
    }
    if (std::string(b[0].name()) == "ref") {
      MI_TRY(id, attr(b[0], "id"));
      MI_TRY(m, bsdf(b[0], 1));
      *alpha = mask_alpha_;
      if (auto it = bsdf_index_.find(id); it != bsdf_index_.end()) return it->second;
      return bsdf_index_[id] = builder_.add_material(id, m, std::move(material_textures_));
    }
    MI_TRY(m, bsdf(b[0], 1));
    *alpha = mask_alpha_;
    return builder_.add_material(where(b[0]).str(), m, std::move(material_textures_));
  }

  // --- shapes ---
  // --- instancing: <shape type="shapegroup" id=…> and <shape type="instance"> (scene.h ShapeGroup) ---
  // A shapegroup's shapes are placed by their own to_world, an instance by its to_world on top.
  Result<int> shapegroup(pugi::xml_node n) {
    const std::string id = n.attribute("id").value();
    if (auto it = groups_.find(id); it != groups_.end()) return it->second;  // made when an instance came first
    if (id.empty()) return located(where(n), "a shapegroup needs an id (instances <ref> it)");
    const int group = builder_.add_group(id, where(n).str());
    groups_[id] = group;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      if (std::string(c.name()) != "shape")
        return located(where(c), "<" + excerpt(c.name()) + "> in a shapegroup is not supported, expected shapes");
      const std::string type = c.attribute("type").value();
      if (type == "shapegroup" || type == "instance")
        return located(where(c), "a " + type + " inside a shapegroup is not supported: shapegroups do not nest");
      if (auto e = shape(c, group)) return *e;
    }
    return group;
  }

  std::optional<Error> instance(pugi::xml_node n) {
    pugi::xml_node ref;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      if (std::string(c.name()) == "ref" && !ref) ref = c;
      else if (!(std::string(c.name()) == "transform" && std::string(c.attribute("name").value()) == "to_world"))
        return located(where(c), "<" + excerpt(c.name()) + "> in an instance is not supported, expected one <ref> to a shapegroup and a to_world");
    }
    if (!ref) return located(where(n), "an instance needs a <ref id=…> to a shapegroup");
    MI_TRY(id, attr(ref, "id"));
    auto it = ids_.find(id);
    if (it == ids_.end()) return located(where(ref), "unknown id \"" + excerpt(id) + "\"");
    if (std::string(it->second.name()) != "shape" || std::string(it->second.attribute("type").value()) != "shapegroup")
      return located(where(ref), "the instance's <ref id=\"" + excerpt(id) + "\"> names a <" + excerpt(it->second.name()) +
                                     (it->second.attribute("type") ? " type=\"" + excerpt(it->second.attribute("type").value()) + "\"" : std::string()) +
                                     "> (at " + where(it->second).str() + "), expected a shapegroup");
    MI_TRY(group, shapegroup(it->second));
    Props p(this, n, "<shape type=\"instance\">");
    p.ignore({"ref", "id"});
    MI_TRY(m, p.transform("to_world"));
    builder_.add_instance(ShapeInstance{group, m, where(n).str()});
    return std::nullopt;
  }

  // `group`: the shapegroup the shape is a member of (-1: the world's).
  std::optional<Error> shape(pugi::xml_node n, int group = -1) {
    MI_TRY(type, attr(n, "type"));
    if (type == "shapegroup") {
      if (group >= 0) return located(where(n), "a shapegroup inside a shapegroup is not supported: shapegroups do not nest");
      Result<int> made = shapegroup(n);
      if (!made) return made.error();
      return std::nullopt;
    }
    if (type == "instance") return instance(n);
    Props p(this, n, "<shape type=\"" + excerpt(type) + "\">");
    p.ignore({"id"});
    Shape s;
    s.pointer = where(n).str();
    MI_TRY(mat, material_of(p, n, &s.alpha));
    s.material = mat;
    std::vector<pugi::xml_node> emitters = p.nested("emitter");
    if (emitters.size() > 1) return located(where(n), "a shape with more than one emitter");
    if (emitters.size() == 1) {
      if (std::string(emitters[0].name()) == "ref") emitters[0] = area_emitters_.at(emitters[0].attribute("id").value());
      MI_TRY(etype, attr(emitters[0], "type"));
      if (etype != "area") return located(where(emitters[0]), "emitter \"" + excerpt(etype) + "\" inside a shape is not supported, expected area");
      Props e(this, emitters[0], "<emitter type=\"area\">");
      MI_TRY(radiance, e.color("radiance", vec3(1.0f)));
      if (auto u = e.unused()) return u;
      if (auto bad = import::check_light_value(radiance, where(emitters[0]))) return bad;
      s.emission = radiance;
    }
    for (pugi::xml_node md : p.nested("medium")) {  // an absorbing interior (trace/media.h)
      MI_TRY(side, attr(md, "name"));
      if (side != "interior")
        return located(where(md), "an exterior medium is not supported: pathex's media are the absorbing interiors of shapes, surrounded by vacuum");
      MI_TRY(mtype, attr(md, "type"));
      if (mtype != "homogeneous")
        return located(where(md), "medium \"" + excerpt(mtype) + "\" is not supported: pathex has absorbing homogeneous media only");
      Props mp(this, md, "<medium type=\"homogeneous\">");
      MI_TRY(albedo, mp.color("albedo", vec3(0.75f)));
      if (albedo != vec3(0.0f))
        return located(where(md), "a scattering medium (albedo not 0; Mitsuba's default is 0.75) needs a volume letter that pathex's alphabet "
                                  "does not have; give <rgb name=\"albedo\" value=\"0\"/> for an absorbing one");
      MI_TRY(sigma_t, mp.color("sigma_t", vec3(1.0f)));
      MI_TRY(scale, mp.number("scale", 1.0));
      mp.ignore({"sample_emitters", "has_spectral_extinction", "phase"});
      if (auto u = mp.unused()) return u;
      s.absorption = sigma_t * static_cast<float>(scale);
      if (!(glm::all(glm::greaterThanEqual(s.absorption, vec3(0.0f))) && std::isfinite(s.absorption.x + s.absorption.y + s.absorption.z)))
        return located(where(md), "sigma_t × scale must be finite and non-negative");
    }
    MI_TRY(m, p.transform("to_world"));
    MI_TRY(flip, p.boolean("flip_normals", false));
    if (type == "serialized") {
      MI_TRY(file, p.string("filename", ""));
      if (file.empty()) return located(where(n), "<shape type=\"serialized\"> needs a filename");
      MI_TRY(index_value, p.number("shape_index", 0));
      if (!(index_value >= 0 && index_value <= 1e9 && index_value == std::floor(index_value)))
        return located(where(n), "shape_index must be an integer of 0 or more");
      const auto index = static_cast<std::size_t>(index_value);
      MI_TRY(face_normals, p.boolean("face_normals", false));
      MI_TRY(read, read_serialized_file(files_.resolve(file), index,
                                        SerializedReadOptions{options_.max_file_bytes, options_.max_mesh_elements}));
      mesh_elements_ += read.positions.size() + read.triangles.size();
      if (auto e = check_mesh_elements(mesh_elements_, options_, where(n).str())) return e;
      if (read.triangles.empty()) return located(where(n), "shape " + std::to_string(index) + " of '" + file + "' has no triangles");
      MeshShape mesh;
      mesh.file = file;
      mesh.positions = std::move(read.positions);
      mesh.triangles = std::move(read.triangles);
      mesh.uvs = std::move(read.uvs);
      // Smooth unless face_normals (the file's flag or the property), as Mitsuba: the file's normals, or its own angle-weighted ones.
      const bool flat = face_normals || read.face_normals;
      const bool compute = !flat && read.normals.empty();
      if (!flat && !compute) mesh.normals = std::move(read.normals);
      if (auto e = import::place_mesh(&mesh, m, flip, flip, where(n))) return e;
      if (compute) import::angle_weighted_normals(&mesh);
      s.geometry = std::move(mesh);
    } else if (type == "obj" || type == "ply") {
      MI_TRY(file, p.string("filename", ""));
      if (file.empty()) return located(where(n), "<shape type=\"" + excerpt(type) + "\"> needs a filename");
      MI_TRY(face_normals, p.boolean("face_normals", false));
      MeshShape mesh;
      if (type == "obj") {
        SceneLoadOptions whole = options_;
        whole.triangles = true;  // the faces are checked here whatever the command needs
        MI_TRY(obj, load_obj_mesh(files_.resolve(file), whole, &mesh_elements_));
        if (obj.triangles.empty()) return located(where(n), "the mesh '" + files_.resolve(file) + "' has no faces");
        mesh = std::move(obj);
      } else {
        MI_TRY(ply, import::load_ply_mesh(files_.resolve(file), where(n), options_));
        mesh = std::move(ply);
        mesh_elements_ += mesh.positions.size() + mesh.triangles.size();
        if (auto e = check_mesh_elements(mesh_elements_, options_, where(n).str())) return e;
      }
      mesh.file = file;
      // Mitsuba's OBJ and PLY loaders flip v (flip_tex_coords, default true): its bitmaps look v up from the top row.
      MI_TRY(flip_uv, p.boolean("flip_tex_coords", true));
      if (flip_uv)
        for (glm::vec2& uv : mesh.uvs) uv.y = 1.0f - uv.y;
      // Smooth unless face_normals: the file's normals, or (none, or an OBJ's, which pathex does not
      // read) Mitsuba's own angle-weighted ones, computed in world space as Mitsuba does.
      const bool compute = !face_normals && (type == "obj" || mesh.normals.empty());
      if (face_normals || compute) mesh.normals.clear();
      if (auto e = import::place_mesh(&mesh, m, flip, flip, where(n))) return e;
      if (compute) import::angle_weighted_normals(&mesh);
      s.geometry = std::move(mesh);
    } else if (type == "sphere") {
      MI_TRY(centre, p.point("center", vec3(0.0f)));
      MI_TRY(radius, p.number("radius", 1.0));
      float scale = 1.0f;
      if (!import::is_similarity(m, &scale)) return located(where(n), "a sphere under a non-uniform scale is not supported");
      if (!(radius > 0)) return located(where(n), "radius must be positive");
      if (flip && s.emissive()) return located(where(n), "a sphere emitting inwards (flip_normals) is not supported");
      s.geometry = SphereShape{import::apply_point(m, centre), static_cast<float>(radius) * scale};
    } else if (type == "rectangle") {
      const vec3 e1 = import::apply_vector(m, vec3(2, 0, 0)), e2 = import::apply_vector(m, vec3(0, 2, 0));
      if (!(glm::length(glm::cross(e1, e2)) > 0.0f)) return located(where(n), "the rectangle's area is zero");
      const bool front = (glm::dot(glm::cross(e1, e2), import::apply_normal(m, vec3(0, 0, 1))) > 0.0f) != flip;
      const vec3 corner = import::apply_point(m, vec3(-1, -1, 0));
      s.geometry = front ? QuadShape{corner, e1, e2} : QuadShape{corner, e2, e1};
    } else if (type == "disk") {
      const vec3 ex = import::apply_vector(m, vec3(1, 0, 0)), ey = import::apply_vector(m, vec3(0, 1, 0));
      const float r = glm::length(ex);
      if (!(r > 0.0f) || std::fabs(glm::length(ey) - r) > 1e-4f * r || std::fabs(glm::dot(ex, ey)) > 1e-4f * r * r)
        return located(where(n), "an elliptical disk (to_world scales x and y differently) is not supported");
      const vec3 normal = import::apply_normal(m, vec3(0, 0, 1));
      s.geometry = DiskShape{import::apply_point(m, vec3(0.0f)), flip ? -normal : normal, r};
    } else if (type == "cube") {  // a mesh in Mitsuba too: to_world mirrors its windings as an obj's
      MeshShape mesh = import::cube_mesh();
      if (auto e = import::place_mesh(&mesh, m, flip, flip, where(n))) return e;
      s.geometry = std::move(mesh);
    } else if (type == "cylinder") {  // a tessellated tube (import::tube_mesh), facing outwards unless flip_normals
      MI_TRY(p0, p.point("p0", vec3(0.0f)));
      MI_TRY(p1, p.point("p1", vec3(0.0f, 0.0f, 1.0f)));
      MI_TRY(radius, p.number("radius", 1.0));
      if (!(radius > 0)) return located(where(n), "radius must be positive");
      const float length = glm::length(p1 - p0);
      if (!(length > 0.0f)) return located(where(n), "the cylinder's p0 and p1 coincide");
      // A right-handed frame around the axis (its turn about the axis moves only the uv seam).
      const vec3 d = (p1 - p0) / length;
      const vec3 t1 = glm::normalize(glm::cross(std::fabs(d.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0), d)), t2 = glm::cross(d, t1);
      MeshShape mesh = import::tube_mesh(static_cast<float>(radius), 0.0f, length);
      const glm::mat4 axis(glm::vec4(t1, 0.0f), glm::vec4(t2, 0.0f), glm::vec4(d, 0.0f), glm::vec4(p0, 1.0f));
      // The tube's normals give its front side: outwards whatever to_world's handedness, as Mitsuba's analytic one.
      if (auto e = import::place_mesh(&mesh, m * axis, flip, flip, where(n))) return e;
      s.geometry = std::move(mesh);
    } else {
      return located(where(n), "shape \"" + excerpt(type) + "\" is not supported, expected obj, ply, serialized, sphere, rectangle, disk, cube or cylinder");
    }
    if (auto e = p.unused()) return e;
    if (s.alpha >= 0 && s.emissive()) return located(where(n), "a mask (an opacity cut-out) on an area light is not supported");
    if (group >= 0)
      if (std::optional<std::string> why = import::make_group_member(&s, group)) return located(where(n), *why);
    builder_.add_shape(std::move(s));
    return std::nullopt;
  }

  // --- emitters ---
  std::optional<Error> emitter(pugi::xml_node n) {
    MI_TRY(type, attr(n, "type"));
    Props p(this, n, "<emitter type=\"" + excerpt(type) + "\">");
    p.ignore({"id"});
    if (type == "area") {  // defined once by id, used by the shapes that <ref> it (Mitsuba's cbox.xml does)
      const std::string id = n.attribute("id").value();
      if (id.empty()) return located(where(n), "an area emitter must be inside a <shape> or have an id that shapes <ref>");
      area_emitters_[id] = n;
      return std::nullopt;
    }
    if (type == "envmap") {  // a latitude-longitude image, +Y up (docs/lights.md)
      p.ignore({"mis_compensation"});  // how Mitsuba samples it, not the light
      if (builder_.has_environment_image()) return located(where(n), "a second envmap is not supported: a scene has at most one image infinite light");
      MI_TRY(file, p.string("filename", ""));
      if (file.empty()) return located(where(n), "the envmap has no filename");
      MI_TRY(scale, p.number("scale", 1.0));
      if (!(scale >= 0.0)) return located(where(n), "scale must not be negative");
      MI_TRY(m, p.transform("to_world"));
      float s = 1.0f;
      if (!import::is_similarity(m, &s)) return located(where(n), "an envmap whose to_world scales non-uniformly or shears is not supported");
      Result<EnvironmentImage> img =
          load_environment_image(files_.resolve(file), file, /*equal_area=*/false, vec3(static_cast<float>(scale)), options_, builder_.texels());
      if (!img) {
        Error e = located(where(n), "the image '" + excerpt(file, kMaxPathBytes) + "': " + img.error().message);
        e.code = img.error().code;
        return e;
      }
      if (std::optional<std::string> bad = settle_environment_values(&*img)) return located(where(n), *bad);
      img->to_world = glm::mat3(m) / s;
      if (auto u = p.unused()) return u;
      builder_.add_environment_image(std::move(*img), where(n).str());
      return std::nullopt;
    }
    if (type == "constant") {  // the same radiance from every direction
      MI_TRY(radiance, p.color("radiance", vec3(1.0f)));
      if (auto bad = import::check_light_value(radiance, where(n))) return bad;
      if (auto u = p.unused()) return u;
      builder_.add_environment(radiance, where(n).str());
      return std::nullopt;
    }
    if (type != "point" && type != "spot" && type != "directional")
      return located(where(n), "emitter \"" + excerpt(type) + "\" is not supported, expected point, spot, directional, constant, or area inside a shape");
    const bool has_to_world = static_cast<bool>(p.find("to_world"));
    MI_TRY(m, p.transform("to_world"));
    if (type == "directional") {
      MI_TRY(e, p.color("irradiance", vec3(1.0f)));
      vec3 d = import::apply_vector(m, vec3(0, 0, 1));
      if (pugi::xml_node dn = p.find("direction")) {
        if (has_to_world) return located(where(dn), "give direction or to_world, not both");
        MI_TRY(v, vector3(dn, vec3(0.0f)));
        d = v;
      }
      if (!(glm::length(d) > 0.0f)) return located(where(n), "the direction is zero");
      if (auto bad = import::check_light_value(e, where(n))) return bad;
      if (auto u = p.unused()) return u;
      builder_.add_distant(d, e);
      return std::nullopt;
    }
    MI_TRY(intensity, p.color("intensity", vec3(1.0f)));
    if (auto bad = import::check_light_value(intensity, where(n))) return bad;
    vec3 position = import::apply_point(m, vec3(0.0f));
    if (pugi::xml_node pn = p.find("position")) {
      if (has_to_world) return located(where(pn), "give position or to_world, not both");
      MI_TRY(v, vector3(pn, vec3(0.0f)));
      position = v;
    }
    if (type == "point") {
      if (auto u = p.unused()) return u;
      builder_.add_light(PointLight{position, intensity});
      return std::nullopt;
    }
    MI_TRY(cutoff, p.number("cutoff_angle", 20.0));
    MI_TRY(beam, p.number("beam_width", cutoff * 0.75));
    if (!(cutoff > 0.0) || cutoff > 180.0) return located(where(n), "cutoff_angle must be within (0, 180]");
    if (!(beam >= 0.0) || beam > cutoff) return located(where(n), "beam_width must be within [0, cutoff_angle]");
    float s = 1.0f;
    if (!import::is_similarity(m, &s)) return located(where(n), "a spot light under a non-uniform scale is not supported");
    if (auto u = p.unused()) return u;
    // Mitsuba 3: full intensity within beam_width, then linear in the angle down to 0 at cutoff_angle.
    builder_.add_light(SpotLight{position, glm::normalize(import::apply_vector(m, vec3(0, 0, 1))), intensity, static_cast<float>(cutoff),
                                 static_cast<float>(beam), SpotFalloff::kLinear});
    return std::nullopt;
  }

  // --- the sensor ---
  std::optional<Error> sensor(pugi::xml_node n) {
    if (builder_.has_camera()) return located(where(n), "a second <sensor> (pathex renders one camera)");
    MI_TRY(type, attr(n, "type"));
    if (type != "perspective" && type != "thinlens" && type != "orthographic")
      return located(where(n), "sensor \"" + excerpt(type) + "\" is not supported, expected perspective, thinlens or orthographic");
    Props p(this, n, "<sensor type=\"" + excerpt(type) + "\">");
    p.ignore({"id", "near_clip", "far_clip", "shutter_open", "shutter_close", "sampler"});
    Camera c;
    c.width = 768;
    c.height = 576;
    const std::vector<pugi::xml_node> films = p.nested("film");
    if (films.size() > 1) return located(where(n), "a sensor with more than one film");
    if (films.size() == 1) {
      MI_TRY(ftype, attr(films[0], "type"));
      if (ftype != "hdrfilm") return located(where(films[0]), "film \"" + excerpt(ftype) + "\" is not supported, expected hdrfilm");
      Props f(this, films[0], "<film type=\"hdrfilm\">");
      MI_TRY(w, f.number("width", 768));
      MI_TRY(h, f.number("height", 576));
      if (w != std::floor(w) || h != std::floor(h) || w < 1 || h < 1 || w > 16384 || h > 16384)
        return located(where(films[0]), "width and height must be integers within 1..16384");
      c.width = static_cast<int>(w);
      c.height = static_cast<int>(h);
      f.ignore({"rfilter", "pixel_format", "component_format", "file_format", "sample_border", "banner", "id"});
      if (auto u = f.unused()) return u;
    }
    MI_TRY(m, p.transform("to_world"));
    const vec3 ex = import::apply_vector(m, vec3(1, 0, 0)), ey = import::apply_vector(m, vec3(0, 1, 0));
    const vec3 ez = import::apply_vector(m, vec3(0, 0, 1));
    if (!(glm::length(ex) > 0.0f && glm::length(ey) > 0.0f && glm::length(ez) > 0.0f) ||
        std::fabs(glm::dot(glm::normalize(ex), glm::normalize(ey))) > 1e-4f || std::fabs(glm::dot(glm::normalize(ex), glm::normalize(ez))) > 1e-4f ||
        std::fabs(glm::dot(glm::normalize(ey), glm::normalize(ez))) > 1e-4f)
      return located(where(n), "the sensor's to_world must not shear");
    c.position = import::apply_point(m, vec3(0.0f));
    c.look_at = c.position + glm::normalize(ez);
    c.up = glm::normalize(ey);
    const vec3 image_right = -glm::normalize(ex);  // Mitsuba's image x runs along camera -x
    const float aspect = static_cast<float>(c.width) / static_cast<float>(c.height);
    if (type == "orthographic") {
      // The film spans [-1, 1] x [-1/aspect, 1/aspect] in camera space, scaled by to_world.
      c.type = SensorType::kOrthographic;
      c.film_width = 2.0f * glm::length(ex);
      c.film_height = 2.0f / aspect * glm::length(ey);
    } else {
      float scale = 1.0f;
      if (!import::is_similarity(m, &scale) || std::fabs(scale - 1.0f) > 1e-3f)
        return located(where(n), "a perspective sensor's to_world must be rigid (no scale)");
      // Mitsuba 3's parse_fov: `fov` along `fov_axis` (x by default), or else `focal_length` ("50mm"
      // by default) on a 36 x 24 mm film, its fov along the diagonal.
      pugi::xml_node fov_node = p.find("fov");
      pugi::xml_node focal_node = p.find("focal_length");
      if (fov_node && focal_node) return located(where(focal_node), "give fov or focal_length, not both (as Mitsuba 3)");
      double fov = 0.0;
      std::string axis = "diagonal";
      if (fov_node) {
        MI_TRY(f, p.number("fov", 0.0));
        MI_TRY(a, p.string("fov_axis", "x"));
        fov = f;
        axis = a;
      } else {
        p.ignore({"fov_axis"});  // Mitsuba 3 reads no fov_axis with a focal length
        MI_TRY(focal, p.string("focal_length", "50mm"));
        std::string digits = focal.size() > 2 && focal.substr(focal.size() - 2) == "mm" ? focal.substr(0, focal.size() - 2) : focal;
        char* end = nullptr;
        const double mm = std::strtod(digits.c_str(), &end);
        if (digits.empty() || end != digits.c_str() + digits.size() || !(mm > 0.0) || !std::isfinite(mm))
          return located(focal_node ? where(focal_node) : where(n), "focal_length \"" + excerpt(focal) + "\" must be of the form <x>mm with x > 0");
        fov = glm::degrees(2.0 * std::atan(std::sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * mm)));
      }
      if (!(fov > 0 && fov < 180)) return located(fov_node ? where(fov_node) : where(n), "fov must be within (0, 180)");
      const float t = std::tan(glm::radians(static_cast<float>(fov)) * 0.5f);
      float tan_y = 0.0f;
      if (axis == "x" || (axis == "smaller" && aspect <= 1.0f) || (axis == "larger" && aspect > 1.0f)) tan_y = t / aspect;
      else if (axis == "y" || axis == "smaller" || axis == "larger") tan_y = t;
      else if (axis == "diagonal") tan_y = t / std::sqrt(1.0f + aspect * aspect);
      else return located(where(n), "fov_axis \"" + excerpt(axis) + "\" is not supported, expected x, y, diagonal, smaller or larger");
      c.fov_degrees = glm::degrees(2.0f * std::atan(tan_y));
      if (type == "thinlens") {
        c.type = SensorType::kLens;
        MI_TRY(ar, p.number("aperture_radius", 0.0));
        MI_TRY(fd, p.number("focus_distance", 0.0));
        if (!(ar > 0) || !(fd > 0)) return located(where(n), "thinlens needs a positive aperture_radius and focus_distance");
        c.aperture_radius = static_cast<float>(ar);
        c.focus_distance = static_cast<float>(fd);
      } else {
        p.ignore({"focus_distance"});  // a pinhole has no focus (Mitsuba's own cbox.xml gives one to its perspective sensor)
      }
    }
    if (auto u = p.unused()) return u;
    builder_.set_camera(c, image_right);
    return std::nullopt;
  }
};

// --- Props ---

std::optional<Error> Props::unused() const {
  for (const Child& c : children_) {
    if (c.used) continue;
    const std::string name = c.node.attribute("name").value();
    return located(im_->where(c.node), "<" + excerpt(c.node.name()) + (name.empty() ? "" : " name=\"" + excerpt(name) + "\"") + "> in " + what_ +
                                           " is not supported");
  }
  return std::nullopt;
}

Result<double> Props::number(const std::string& name, double fallback) {
  pugi::xml_node n = find(name);
  if (!n) return fallback;
  const std::string tag = n.name();
  if (tag != "float" && tag != "integer") return located(im_->where(n), "'" + name + "' must be a <float>");
  MI_TRY(v, im_->numbers(n, "value"));
  if (v.size() != 1) return located(im_->where(n), "'" + name + "' expects one number");
  return v[0];
}

Result<bool> Props::boolean(const std::string& name, bool fallback) {
  pugi::xml_node n = find(name);
  if (!n) return fallback;
  MI_TRY(v, im_->attr(n, "value"));
  if (std::string(n.name()) != "boolean" || (v != "true" && v != "false")) return located(im_->where(n), "'" + name + "' must be a <boolean> true or false");
  return v == "true";
}

Result<std::string> Props::string(const std::string& name, const std::string& fallback) {
  pugi::xml_node n = find(name);
  if (!n) return fallback;
  if (std::string(n.name()) != "string") return located(im_->where(n), "'" + name + "' must be a <string>");
  return im_->attr(n, "value");
}

std::vector<pugi::xml_node> Props::nested(const std::string& tag) {
  std::vector<pugi::xml_node> out;
  for (Child& c : children_) {
    const bool ref = std::string(c.node.name()) == "ref";
    const bool emitter_ref = ref && im_->is_area_emitter(c.node.attribute("id").value());
    const bool texture_ref = ref && im_->is_texture(c.node.attribute("id").value());
    if (c.node.name() == tag || (ref && tag == "bsdf" && !emitter_ref && !texture_ref) || (emitter_ref && tag == "emitter")) {
      c.used = true;
      out.push_back(c.node);
    }
  }
  return out;
}

Result<vec3> Props::color(const std::string& name, vec3 fallback) {
  pugi::xml_node n = find(name);
  if (!n) return fallback;
  const std::string tag = n.name();
  if (tag == "texture" || (tag == "ref" && im_->is_texture(n.attribute("id").value())))
    return located(im_->where(n), "a texture for '" + name + "' is not supported here (pathex reads textures for reflectances, alphas, a "
                                  "blendbsdf's weight and a mask's opacity), give an <rgb>");
  if (tag != "rgb" && tag != "float" && tag != "spectrum") return located(im_->where(n), "'" + name + "' must be an <rgb>");
  // An emitter's spectrum is light, every other one a reflectance (Mitsuba's Properties::get_texture).
  const bool emission = what_.rfind("<emitter", 0) == 0;
  if (tag == "spectrum") {
    if (n.attribute("filename")) return located(im_->where(n), "a <spectrum> from a file is not supported: give its wavelength:value pairs");
    const std::string text = n.attribute("value").value();
    if (text.find(':') != std::string::npos) return im_->sampled_spectrum(n, text, emission);
  }
  MI_TRY(v, im_->numbers(n, "value"));
  if (tag == "spectrum" && v.size() != 1) return located(im_->where(n), "a <spectrum> value is one number or wavelength:value pairs");
  if (tag == "spectrum" && emission) return static_cast<float>(v[0]) * import::equal_energy_rgb();  // Mitsuba's uniform light spectrum
  if (v.size() == 1) return vec3(static_cast<float>(v[0]));
  if (tag != "rgb" || v.size() != 3) return located(im_->where(n), "'" + name + "' expects 3 numbers");
  return vec3(v[0], v[1], v[2]);
}

Result<vec3> Props::point(const std::string& name, vec3 fallback) {
  pugi::xml_node n = find(name);
  if (!n) return fallback;
  if (std::string(n.name()) != "point" && std::string(n.name()) != "vector") return located(im_->where(n), "'" + name + "' must be a <point>");
  return im_->vector3(n, fallback);
}

Result<glm::mat4> Props::transform(const std::string& name) {
  pugi::xml_node n = find(name);
  if (!n) return glm::mat4(1.0f);
  if (std::string(n.name()) != "transform") return located(im_->where(n), "'" + name + "' must be a <transform>");
  return im_->transform(n);
}

}  // namespace

Result<Scene> load_scene_mitsuba(const std::string& path, const SceneLoadOptions& options) { return Importer(path, options).run(); }

}  // namespace pathex
