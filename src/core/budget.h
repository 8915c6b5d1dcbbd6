// The work budget (Limits::max_work, --max-work).
//
// A state cap alone does not stop every hang: a profile of 400 strategies builds 400 small
// languages and 400 unions, `(S{1000}&D*){1000}` compiles the same small intersection a thousand
// times, and counting members of a 10,000-state language up to length 10,000 touches 10^8 big
// numbers, each step within --max-states. So every top-level operation (compiling a class or a
// profile, answering a query, building a classifier) runs under a budget of work units, charged
// where the work is done:
//   - one unit per automaton state built: Thompson NFA states, product pairs, states minimised;
//   - one unit per NFA state in each subset of the subset construction (a DFA state costs what
//     its ε-closure costs);
//   - one unit per (length, state) cell of the counting and enumeration tables.
// Past the budget the operation stops with a kLimit error naming --max-work. The default (see
// Limits) keeps every operation under about a second on one core; tests assert the counters.
//
// This is the one place where the engine unwinds with an exception: the charge points sit deep
// inside constructions (product, minimisation) that cannot otherwise fail, and threading a Result
// through each of them would make all of the language algebra fallible for the sake of one limit.
// The exception never leaves the library: within_budget() turns it into an Error at the
// operation's edge, and without a budget in force charging does nothing.
#pragma once

#include <cstddef>
#include <memory>
#include <utility>

#include "core/error.h"
#include "core/limits.h"

namespace pathex {

class WorkBudget {
 public:
  // Puts a budget of `limit` units in force on this thread for the object's lifetime, unless one
  // is in force already (the outer one then keeps counting: nested operations share it).
  explicit WorkBudget(std::size_t limit);
  ~WorkBudget();
  WorkBudget(const WorkBudget&) = delete;
  WorkBudget& operator=(const WorkBudget&) = delete;

  std::size_t spent() const;   // units charged to the budget in force
  std::size_t limit() const;   // its limit
  bool exhausted() const;      // a charge went past the limit

  // Charges the budget in force, if any; past its limit, unwinds to the nearest within_budget().
  static void charge(std::size_t units);

  struct State;  // limit and units spent; one per budget in force

 private:
  std::unique_ptr<State> own_;  // set when this object put the budget in force
  State* active_ = nullptr;  // the budget in force when it was made
};

// While one exists, no budget is in force on this thread: for the engine's own constants (the
// built-in classes, fixed chain languages), which are built once, on first use, whatever
// operation happens to need them first, and must not be charged to (or fail with) that operation.
class ExemptFromBudget {
 public:
  ExemptFromBudget();
  ~ExemptFromBudget();
  ExemptFromBudget(const ExemptFromBudget&) = delete;
  ExemptFromBudget& operator=(const ExemptFromBudget&) = delete;

 private:
  void* saved_;
};

// Thrown by WorkBudget::charge; caught only by within_budget().
struct WorkBudgetExceeded {
  std::size_t limit;
};

// "the work of this operation exceeds the limit of N units (raise it with --max-work)"
Error work_limit_error(std::size_t limit);

// Runs f() (which returns a Result) under the budget in force, or a new one of limits.max_work
// units; a budget overrun becomes the kLimit error.
template <class F>
auto within_budget(const Limits& limits, F&& f) -> decltype(f()) {
  WorkBudget budget(limits.max_work);
  try {
    return std::forward<F>(f)();
  } catch (const WorkBudgetExceeded& e) {
    return work_limit_error(e.limit);
  }
}

}  // namespace pathex
