// JUnit XML, the report format CI systems read (Jenkins, GitLab, GitHub test reporters): one
// <testsuite> per check file, one <testcase> per requirement, <failure> with message and details.
// A check file that cannot be run (bad JSON, an unknown renderer, a missing scene) is one
// <testcase> with an <error>, so that CI shows the failure instead of a missing report.
#pragma once

#include <string>
#include <vector>

namespace pathex {

struct JUnitCase {
  std::string classname;  // the check case's name
  std::string name;       // the requirement, e.g. "LSDSDE is reachable"
  double time_s = 0.0;
  bool failed = false;    // a requirement that does not hold: <failure>
  bool error = false;     // the check could not be run (bad input): <error>
  std::string message;    // one line
  std::string details;    // the counterexample, several lines
};

std::string junit_xml(const std::string& suite, const std::vector<JUnitCase>& cases);
std::string xml_escape(const std::string& s);

}  // namespace pathex
