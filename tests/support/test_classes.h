// What the tracer tests share to render with their own classes: full-notation expressions compiled
// into named classes (each named by its text) with a classifier over them, and the closed-form
// check of an estimate.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "stats/histogram.h"
#include "classify/pathclass.h"

namespace pathex::test {

struct TestClasses {
  std::vector<std::unique_ptr<PathClass>> classes;
  std::vector<const PathClass*> pointers;
  std::vector<ClassInfo> infos;
  std::unique_ptr<Classifier> classifier;
};

// Heap-held, so the classifier's pointers to its classes stay valid however the result is moved.
inline std::unique_ptr<TestClasses> test_classes(const std::vector<std::string>& exprs) {
  auto t = std::make_unique<TestClasses>();
  for (const std::string& c : exprs) {
    Result<PathClass> pc = compile_class(c, ClassOptions{});
    EXPECT_TRUE(pc.ok()) << c;
    if (!pc) continue;
    t->classes.push_back(std::make_unique<PathClass>(std::move(*pc)));
    t->classes.back()->name = c;
    t->pointers.push_back(t->classes.back().get());
    t->infos.push_back({c, c});
  }
  t->classifier = std::make_unique<Classifier>(Classifier::build(t->pointers, Limits{}).expect("a test input"));
  return t;
}

// |estimate − expected| within `sigmas` standard errors plus `rel` of |expected|; finite throughout.
inline void expect_close(const Estimate& e, double expected, double sigmas, double rel, const std::string& what) {
  EXPECT_TRUE(std::isfinite(e.luminance)) << what;
  EXPECT_TRUE(std::isfinite(e.std_error)) << what;
  EXPECT_LE(std::fabs(e.luminance - expected), sigmas * e.std_error + rel * std::fabs(expected))
      << what << ": estimate " << e.luminance << " ± " << e.std_error << ", expected " << expected;
}

}  // namespace pathex::test
