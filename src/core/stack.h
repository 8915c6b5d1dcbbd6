// The stack that the syntax tree's recursion runs on.
//
// Recursion over an expression's tree (the parser, the printer, the Thompson construction, nested
// & and ~) is at most Limits::max_depth levels deep, and --max-depth stops at kMaxDepthCeiling.
// What a level costs in stack depends on the build: under 2 KiB in a release build, about 10 KiB
// under AddressSanitizer, whose frames carry redzones (measured with `ulimit -s` on a `pathex
// explain` run on its main thread: at the ceiling's deepest trees the release build survives
// with 2 MiB, not 1 MiB; the sanitized build with 10 MiB, not 8 MiB, the usual main-thread stack). So the command line does not rely on the stack it was started with: both
// mains run it on a thread with an explicit stack of kCommandLineStackBytes (address space only;
// pages are touched as the recursion reaches them). tests/regex/parser_test.cpp runs every
// recursive routine at the ceiling on a quarter of that stack, so the ceiling keeps a margin of
// four in every build the tests run in, the sanitized one included.
#pragma once

#include <cstddef>
#include <functional>

namespace pathex {

inline constexpr std::size_t kCommandLineStackBytes = std::size_t{64} << 20;

// Runs fn on a new thread with a stack of stack_bytes and waits for it to finish; an exception
// that fn throws is rethrown here. Returns false, without running fn, when the thread cannot be
// created (the system refused the stack), so that the caller can report it.
[[nodiscard]] bool run_on_stack(std::size_t stack_bytes, const std::function<void()>& fn);

}  // namespace pathex
