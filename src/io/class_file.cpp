#include "io/class_file.h"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace pathex {
namespace {

Error file_error(const std::string& filename, const std::string& pointer, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = filename + (pointer.empty() ? "" : ":" + pointer);
  return e;
}

bool valid_name(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

}  // namespace

Result<bool> read_text_file(const std::string& filename, std::string* out) {
  std::ifstream in(filename, std::ios::binary);
  if (!in) return file_error(filename, "", "cannot open the file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  *out = ss.str();
  return true;
}

Result<bool> load_class_file(const std::string& text, const std::string& filename, const ClassOptions& options,
                             ClassTable* table) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& ex) {
    return file_error(filename, "", std::string("not valid JSON: ") + ex.what());
  }
  if (!doc.is_object()) return file_error(filename, "", "expected a JSON object with a \"classes\" array");
  for (const auto& [key, value] : doc.items()) {
    if (key != "classes" && key != "$schema" && key != "description")
      return file_error(filename, "/" + key, "unknown key '" + key + "', expected \"classes\"");
  }
  if (!doc.contains("classes")) return file_error(filename, "", "missing \"classes\" array");
  const auto& classes = doc["classes"];
  if (!classes.is_array()) return file_error(filename, "/classes", "expected an array of class entries");
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const std::string ptr = "/classes/" + std::to_string(i);
    const auto& entry = classes[i];
    if (!entry.is_object()) return file_error(filename, ptr, "expected an object with \"name\" and \"expr\"");
    for (const auto& [key, value] : entry.items()) {
      if (key != "name" && key != "expr" && key != "notation" && key != "description")
        return file_error(filename, ptr + "/" + key,
                          "unknown key '" + key + "', expected one of name, expr, notation, description");
    }
    if (!entry.contains("name") || !entry["name"].is_string())
      return file_error(filename, ptr + "/name", "expected a string class name");
    if (!entry.contains("expr") || !entry["expr"].is_string())
      return file_error(filename, ptr + "/expr", "expected a string expression");
    const std::string name = entry["name"];
    if (!valid_name(name))
      return file_error(filename, ptr + "/name",
                        "invalid class name '" + name + "', expected a letter or '_' then letters, digits, '_' or '-'");
    // Entries are full notation unless they say otherwise, whatever --notation says for the
    // command line's own expressions: a class file means the same thing in every command.
    ClassOptions opts = options;
    opts.notation = Notation::kFull;
    if (entry.contains("notation")) {
      const auto& n = entry["notation"];
      const auto parsed = n.is_string() ? notation_from_string(n.get<std::string>()) : std::nullopt;
      if (!parsed) return file_error(filename, ptr + "/notation", "expected \"full\", \"heckbert\" or \"lpe\"");
      opts.notation = *parsed;
    }
    std::string description;
    if (entry.contains("description")) {
      if (!entry["description"].is_string()) return file_error(filename, ptr + "/description", "expected a string");
      description = entry["description"];
    }
    Result<const PathClass*> added = table->add(name, entry["expr"].get<std::string>(), opts, description);
    if (!added) {
      Error e = added.error();
      e.where = filename + ":" + ptr + (e.code == ErrorCode::kBadValue ? "/name" : "/expr");
      return e;
    }
  }
  return true;
}

Result<bool> read_class_file(const std::string& filename, const ClassOptions& options, ClassTable* table) {
  std::string text;
  Result<bool> r = read_text_file(filename, &text);
  if (!r) return r;
  return load_class_file(text, filename, options, table);
}

}  // namespace pathex
