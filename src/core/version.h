// The version of this build of pathex: the project version and the commit it was built from
// ("0.1.0 (6efe412a1b2c)", "-dirty" when the tree had changes), generated at every build by
// cmake/version.cmake. Shard files record it, and renders of different builds are not merged.
#pragma once

namespace pathex {

const char* pathex_version();

}  // namespace pathex
