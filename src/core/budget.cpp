#include "core/budget.h"

namespace pathex {

struct WorkBudget::State {
  std::size_t limit = 0;
  std::size_t spent = 0;
};

namespace {
thread_local WorkBudget::State* current = nullptr;
}  // namespace

WorkBudget::WorkBudget(std::size_t limit) {
  if (current == nullptr) {
    own_ = std::make_unique<State>(State{limit, 0});
    current = own_.get();
  }
  active_ = current;
}

WorkBudget::~WorkBudget() {
  if (own_ != nullptr) current = nullptr;
}

std::size_t WorkBudget::spent() const { return active_->spent; }
std::size_t WorkBudget::limit() const { return active_->limit; }
bool WorkBudget::exhausted() const { return active_->spent > active_->limit; }

void WorkBudget::charge(std::size_t units) {
  State* s = current;
  if (s == nullptr) return;
  if (s->spent > s->limit || units > s->limit - s->spent) {
    s->spent = s->limit + 1;  // saturates: once over, every later charge unwinds as well
    throw WorkBudgetExceeded{s->limit};
  }
  s->spent += units;
}

ExemptFromBudget::ExemptFromBudget() : saved_(current) { current = nullptr; }
ExemptFromBudget::~ExemptFromBudget() { current = static_cast<WorkBudget::State*>(saved_); }

Error work_limit_error(std::size_t limit) {
  return make_error(ErrorCode::kLimit, limit_message("the work of this operation", limit, "units", "--max-work"));
}

}  // namespace pathex
