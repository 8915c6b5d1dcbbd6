#include "io/class_file.h"

#include <cctype>

#include "io/input_file.h"
#include "io/json_reader.h"

namespace pathex {
namespace {

bool valid_name(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

}  // namespace

Result<bool> load_class_file(const std::string& text, const std::string& filename, const ClassOptions& options,
                             ClassTable* table) {
  Result<nlohmann::json> parsed = parse_json(text, filename);
  if (!parsed) return parsed.error();
  const nlohmann::json& doc = *parsed;
  const JsonReader reader(filename);
  if (!doc.is_object()) return reader.fail("", "expected a JSON object with a \"classes\" array");
  for (const auto& [key, value] : doc.items()) {
    if (key != "classes" && key != "$schema" && key != "description")
      return reader.fail("/" + pointer_token(key), "unknown key '" + key + "', expected \"classes\"");
  }
  if (!doc.contains("classes")) return reader.fail("", "missing \"classes\" array");
  const auto& classes = doc.at("classes");
  if (!classes.is_array()) return reader.fail("/classes", "expected an array of class entries");
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const std::string ptr = "/classes/" + std::to_string(i);
    const auto& entry = classes[i];
    if (!entry.is_object()) return reader.fail(ptr, "expected an object with \"name\" and \"expr\"");
    for (const auto& [key, value] : entry.items()) {
      if (key != "name" && key != "expr" && key != "notation" && key != "description" && key != "render")
        return reader.fail(ptr + "/" + pointer_token(key),
                          "unknown key '" + key + "', expected one of name, expr, notation, description, render");
    }
    if (!entry.contains("name") || !entry.at("name").is_string())
      return reader.fail(ptr + "/name", "expected a string class name");
    if (!entry.contains("expr") || !entry.at("expr").is_string())
      return reader.fail(ptr + "/expr", "expected a string expression");
    const std::string name = entry.at("name").get<std::string>();
    if (!valid_name(name))
      return reader.fail(ptr + "/name",
                        "invalid class name '" + name + "', expected a letter or '_' then letters, digits, '_' or '-'");
    // `pathex trace` writes a layer per class beside the image's own "total" layer (classes.exr,
    // total.png): a class of that name would collide with it only after the whole render.
    if (name == "total")
      return reader.fail(ptr + "/name",
                         "the class name 'total' is reserved for the image's total layer, expected another name");
    // Entries are full notation unless they say otherwise, whatever --notation says for the
    // command line's own expressions: a class file means the same thing in every command.
    ClassOptions opts = options;
    opts.notation = Notation::kFull;
    if (entry.contains("notation")) {
      const auto& n = entry.at("notation");
      const auto chosen = n.is_string() ? notation_from_string(n.get<std::string>()) : std::nullopt;
      if (!chosen) return reader.fail(ptr + "/notation", "expected \"full\", \"heckbert\" or \"lpe\"");
      opts.notation = *chosen;
    }
    std::string description;
    if (entry.contains("description")) {
      if (!entry.at("description").is_string()) return reader.fail(ptr + "/description", "expected a string");
      description = entry.at("description").get<std::string>();
    }
    bool render = false;
    if (entry.contains("render")) {
      if (!entry.at("render").is_boolean()) return reader.fail(ptr + "/render", "expected true or false");
      render = entry.at("render").get<bool>();
    }
    Result<const PathClass*> added = table->add(name, entry.at("expr").get<std::string>(), opts, description);
    if (!added) {
      Error e = added.error();
      e.where = filename + ":" + ptr + (e.code == ErrorCode::kBadValue ? "/name" : "/expr");
      return e;
    }
    table->set_render(*added, render);
  }
  return true;
}

Result<bool> read_class_file(const std::string& filename, const ClassOptions& options, ClassTable* table) {
  Result<std::string> text = read_input_file(filename, options.limits.max_file_bytes);
  if (!text) return text.error();
  return load_class_file(*text, filename, options, table);
}

}  // namespace pathex
