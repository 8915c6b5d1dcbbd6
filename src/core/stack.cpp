#include "core/stack.h"

#include <pthread.h>

#include <exception>

namespace pathex {
namespace {

struct StackJob {
  const std::function<void()>* fn;
  std::exception_ptr error;
};

extern "C" void* run_stack_job(void* arg) {
  auto* job = static_cast<StackJob*>(arg);
  try {
    (*job->fn)();
  } catch (...) {
    job->error = std::current_exception();
  }
  return nullptr;
}

}  // namespace

bool run_on_stack(std::size_t stack_bytes, const std::function<void()>& fn) {
  pthread_attr_t attr;
  if (pthread_attr_init(&attr) != 0) return false;
  StackJob job{&fn, nullptr};
  pthread_t thread;
  const bool started = pthread_attr_setstacksize(&attr, stack_bytes) == 0 &&
                       pthread_create(&thread, &attr, run_stack_job, &job) == 0;
  pthread_attr_destroy(&attr);
  if (!started) return false;
  pthread_join(thread, nullptr);
  if (job.error) std::rethrow_exception(job.error);
  return true;
}

}  // namespace pathex
