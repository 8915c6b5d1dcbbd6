// Errors are values. Every stage that can reject user input returns a Result<T>: either the value
// or an Error carrying a code, where it happened (a 1-based column in an expression, a line in a
// file, a JSON pointer) and what was expected. Only the CLI turns an Error into text and exit
// code 2; the library never prints and never exits.
#pragma once

#include <string>
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

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}          // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}      // NOLINT(google-explicit-constructor)
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Error& error() const { return std::get<1>(v_); }
  Error& error() { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

}  // namespace pathex
