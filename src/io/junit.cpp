#include "io/junit.h"

#include <cstdio>

namespace pathex {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        // Control characters other than tab and newline are not allowed in XML 1.0.
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') out += '?';
        else out += c;
    }
  }
  return out;
}

std::string junit_xml(const std::string& suite, const std::vector<JUnitCase>& cases) {
  int failures = 0, errors = 0;
  double total = 0.0;
  for (const JUnitCase& c : cases) {
    failures += c.failed && !c.error ? 1 : 0;
    errors += c.error ? 1 : 0;
    total += c.time_s;
  }
  auto seconds = [](double t) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6f", t);
    return std::string(buf);
  };
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<testsuites name=\"pathex\" tests=\"" + std::to_string(cases.size()) + "\" failures=\"" + std::to_string(failures) +
       "\" errors=\"" + std::to_string(errors) + "\" time=\"" + seconds(total) + "\">\n";
  x += "  <testsuite name=\"" + xml_escape(suite) + "\" tests=\"" + std::to_string(cases.size()) + "\" failures=\"" +
       std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\" skipped=\"0\" time=\"" + seconds(total) + "\">\n";
  for (const JUnitCase& c : cases) {
    x += "    <testcase classname=\"" + xml_escape(c.classname) + "\" name=\"" + xml_escape(c.name) + "\" time=\"" +
         seconds(c.time_s) + "\"";
    if (!c.failed && !c.error) {
      x += "/>\n";
      continue;
    }
    const char* element = c.error ? "error" : "failure";
    x += ">\n      <" + std::string(element) + " message=\"" + xml_escape(c.message) + "\" type=\"" +
         (c.error ? "pathex.input" : "pathex.requirement") + "\">" + xml_escape(c.details) + "</" + element +
         ">\n    </testcase>\n";
  }
  x += "  </testsuite>\n</testsuites>\n";
  return x;
}

}  // namespace pathex
