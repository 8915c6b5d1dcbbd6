// Renderer profiles: the JSON document, then the profile's reachable language (which is what
// query, check and trace compute from it), under its own bound and under a small one.
#include "fuzz_support.h"
#include "io/profile_json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  const Limits limits = fuzz::small_limits();
  Result<Profile> p = parse_profile(std::string(fuzz::as_text(data, size)), "fuzz.json", limits);
  if (!p) {
    if (p.error().message.empty()) fuzz::finding("an error without a message");
    return 0;
  }
  (void)reachable_language(*p, p->max_bounces, limits);
  (void)reachable_language(*p, 4, limits);
  return 0;
}
