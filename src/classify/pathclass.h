// Path classes: expressions turned into sets of valid full paths.
//
// compile_class() is the one road from text to language: parse (full, Heckbert or LPE notation),
// compile to a minimal DFA, reverse if the expression is written eye-first (LPEs always are),
// expand Heckbert's L and E (an LPE's C and L) into the light and sensor letter pairs, and
// intersect with the universe
// U = L[SD]{4,}E. Named classes ($name) come from a ClassTable: the built-ins plus, in order,
// the entries of a class file, each of which may refer to the ones before it.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "alphabet/alphabet.h"
#include "automata/dfa.h"
#include "core/error.h"
#include "core/limits.h"
#include "regex/ast.h"

namespace pathex {

// kLpe: OSL light path expressions, camera first (regex/lpe.h); their classes' trees are full
// notation, so full-notation expressions may name them.
enum class Notation { kFull, kHeckbert, kLpe };
// "full", "heckbert", "lpe"; nullopt for anything else.
std::optional<Notation> notation_from_string(std::string_view s);
std::string to_string(Notation n);

// Which lights and sensors Heckbert and LPE notation (and a scene) may put at the ends. Default: all.
struct EndTypes {
  std::vector<LightType> lights{kAllLightTypes.begin(), kAllLightTypes.end()};
  std::vector<SensorType> sensors{kAllSensorTypes.begin(), kAllSensorTypes.end()};
};

struct ClassOptions {
  Notation notation = Notation::kFull;
  EndTypes ends;
  Limits limits;
};

struct PathClass {
  std::string name;         // "" for an anonymous expression
  std::string text;         // as written
  std::string description;  // for built-ins and class-file entries that have one
  Notation notation = Notation::kFull;
  Regex ast;                // the parse, names expanded
  bool eye_first = false;   // written E…L; the language is the reversal
  Regex light_ast;          // a tree of the class's language read light-first: ast, reversed if eye_first;
                            // what `$name` stands for in later expressions
  Dfa dfa;                  // minimal DFA of the class: full paths, ∩ U
  bool render = false;      // a class file's "render": true (only such classes are rendered)
};

class ClassTable;

Result<PathClass> compile_class(std::string_view text, const ClassOptions& options,
                                const ClassTable* names = nullptr);

// Built-in and user-defined names. Lookups see the built-ins and every class added so far.
class ClassTable {
 public:
  // A table holding only the built-ins ($all, $local, $emission, $direct, $indirect, $caustic).
  static const ClassTable& builtins();
  ClassTable();

  // Compiles `text` under `name` (which must be new) and appends it.
  Result<const PathClass*> add(const std::string& name, std::string_view text, const ClassOptions& options,
                               std::string description = "");
  const PathClass* find(std::string_view name) const;
  // Marks a class of this table as requested ("render": true in its class file).
  void set_render(const PathClass* c, bool render);
  // The classes added by the user, in order (built-ins excluded).
  const std::vector<std::unique_ptr<PathClass>>& user_classes() const { return user_; }
  // Built-ins in their documented order.
  const std::vector<std::unique_ptr<PathClass>>& builtin_classes() const { return builtin_; }

 private:
  struct BuiltinTag {};
  explicit ClassTable(BuiltinTag);
  bool is_builtin_table_ = false;
  std::vector<std::unique_ptr<PathClass>> builtin_;
  std::vector<std::unique_ptr<PathClass>> user_;
};

// The classic Heckbert universe L[SD]*E mapped to full paths: L (light pairs) [SD]* (sensor pairs) E.
Dfa ends_universe(const EndTypes& ends);

}  // namespace pathex
