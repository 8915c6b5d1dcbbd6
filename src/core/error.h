// Errors are values. Every stage that can reject user input returns a Result<T>: either the value
// or an Error carrying a code, where it happened (a 1-based column in an expression, a line in a
// file, a JSON pointer) and what was expected. Only the CLI turns an Error into text and exit
// code 2; the library never prints and never exits.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace pathex {

enum class ErrorCode {
  kSyntax,         // the expression does not follow the grammar
  kUnknownName,    // $name that is neither built in nor defined earlier
  kLimit,          // an explicit size limit (states, depth, repetition, length) was exceeded
  kBadPath,        // a full-path string is malformed
  kBadFile,        // a file could not be read or has the wrong shape
  kBadValue,       // a value is out of range or of the wrong type
  kUsage,          // options that contradict each other
};

struct Error {
  ErrorCode code = ErrorCode::kSyntax;
  std::string message;   // what was found and what was expected, one sentence, no location
  std::string source;    // the text the position refers to (an expression, a path), may be empty
  int column = 0;        // 1-based column into `source`; 0 when not applicable
  std::string where;     // a file name, "file:line", or a JSON pointer; may be empty

  // "where: column N: message" followed, when a source is known, by the source and a caret line.
  std::string render() const;
};

inline Error make_error(ErrorCode code, std::string message) {
  Error e;
  e.code = code;
  e.message = std::move(message);
  return e;
}

// A piece of the input echoed in a message, cut to its first `max_bytes` bytes (at a UTF-8
// character boundary) followed by "…" when longer, so that a 16 MiB token gives one line of
// stderr, not 16 MiB.
std::string excerpt(std::string_view text, std::size_t max_bytes = 64);
// A file name is cut only past the longest path Linux opens (PATH_MAX), which no file that exists has.
inline constexpr std::size_t kMaxPathBytes = 4096;

// Dereferencing a Result that was never checked is a bug even when it happens to hold a value:
// the day the input changes it aborts (issue 17: `*compile(...)` of a constant that a user's
// --max-bounces made too large). So a Result remembers whether ok() (or operator bool) was asked,
// and every accessor of the value or the error refuses to run before that: an unchecked access
// aborts with the source line on the first test that runs it, whichever way the Result went.
// Together with [[nodiscard]] on the type, the only way to reach a value is to look first.
[[noreturn]] void result_misuse(const char* what, const char* file, unsigned line);

// Where an accessor was called, like C++20's source location but built on the builtins that GCC
// and clang-14 both have (clang-14, the fuzz build's compiler, cannot compile the standard
// library's source-location header).
struct CallSite {
  const char* file = "";
  unsigned line = 0;
  static constexpr CallSite current(const char* file = __builtin_FILE(), unsigned line = __builtin_LINE()) {
    return {file, line};
  }
};

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}          // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}      // NOLINT(google-explicit-constructor)
  [[nodiscard]] bool ok() const {
    checked_ = true;
    return v_.index() == 0;
  }
  explicit operator bool() const { return ok(); }

  T& value(CallSite at = CallSite::current()) & { return get(at); }
  const T& value(CallSite at = CallSite::current()) const& { return get(at); }
  T&& value(CallSite at = CallSite::current()) && { return std::move(get(at)); }
  // Operators cannot take the caller's location; a misuse through them is reported without it.
  T& operator*() & { return get(CallSite{}); }
  const T& operator*() const& { return get(CallSite{}); }
  T* operator->() { return &get(CallSite{}); }
  const T* operator->() const { return &get(CallSite{}); }
  // For results that cannot fail, such as the engine's own constant expressions compiled under
  // default limits: the value, or an abort naming `why` and the error (a bug, never bad input).
  T expect(const char* why) && {
    if (!ok()) result_misuse(why, get_error(CallSite{}).render().c_str(), 0);
    return std::move(get(CallSite{}));
  }
  const Error& error(CallSite at = CallSite::current()) const { return get_error(at); }
  Error& error(CallSite at = CallSite::current()) { return get_error(at); }

 private:
  T& get(const CallSite& at) const {
    if (!checked_) result_misuse("value of a Result read before ok() was checked", at.file, at.line);
    if (v_.index() != 0) result_misuse("value of a Result read although it holds an error", at.file, at.line);
    return const_cast<T&>(*std::get_if<0>(&v_));
  }
  Error& get_error(const CallSite& at) const {
    if (!checked_) result_misuse("error of a Result read before ok() was checked", at.file, at.line);
    if (v_.index() != 1) result_misuse("error of a Result read although it holds a value", at.file, at.line);
    return const_cast<Error&>(*std::get_if<1>(&v_));
  }

  std::variant<T, Error> v_;
  mutable bool checked_ = false;
};

}  // namespace pathex
