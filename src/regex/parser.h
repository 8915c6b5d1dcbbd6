// Parser: expression text -> Regex (the AST of ast.h). Recursive descent over the grammar in
// grammar/pathex.ebnf; whitespace between tokens is ignored. Errors are values carrying the
// 1-based column of the offending character, so the CLI can put a caret under it.
//
// `$name` is resolved while parsing: the named class's tree is copied in, so the result is
// self-contained and the brute-force oracle can walk it without a symbol table.
#pragma once

#include <functional>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"
#include "regex/ast.h"

namespace pathex {

// Returns the tree a name stands for, or nullptr if the name is unknown.
using NameLookup = std::function<const Regex*(std::string_view name)>;

Result<Regex> parse(std::string_view text, const Limits& limits, const NameLookup& names = {});

}  // namespace pathex
