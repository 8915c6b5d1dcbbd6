// Explicit size limits. Every stage that could grow without bound checks one of these and fails
// with ErrorCode::kLimit naming the limit and the CLI option that raises it, instead of hanging or
// exhausting memory. Defaults are chosen so that every realistic path class fits with room to spare
// while a pathological one, such as (S|D)*S(S|D){40} whose DFA has 2^41 states, fails in well
// under a second.
//
// Each limit also has a ceiling: the largest value an option accepts (negative values are refused
// too). The ceilings are what the implementation provably survives: recursion over the syntax
// tree is at most max_depth frames deep (every other input-dependent loop is iterative), and the
// work budget bounds the time of everything else.
#pragma once

#include <cstddef>
#include <string>

namespace pathex {

struct Limits {
  std::size_t max_states = 100000;   // --max-states: states of any NFA or DFA built
  int max_depth = 100;               // --max-depth: nesting depth of parentheses and operators
  int max_repeat = 1000;             // --max-repeat: the largest n or m in {n}, {n,}, {n,m}
  std::size_t max_length = 100000;   // --max-length: letters in one full-path string
  std::size_t max_work = 20000000;   // --max-work: work units of one operation (see core/budget.h)
  std::size_t max_file_bytes = std::size_t{64} << 20;  // --max-file-size: bytes of one input file
  // What an imported scene may make pathex spend (scene/scene.h, SceneLoadOptions):
  std::size_t max_scene_bytes = std::size_t{256} << 20;  // --max-scene-size: a scene's text, included files counted in
  int max_scene_depth = 64;                              // --max-scene-depth: nesting of a scene's materials
  std::size_t max_material_nodes = 1000000;              // --max-material-nodes: components its materials expand to
  std::size_t max_mesh_elements = 50000000;              // --max-mesh-elements: vertices + triangles of its meshes
  std::size_t max_texels = std::size_t{1} << 26;         // --max-texels: pixels of its images (textures, environment maps)
};

// The ceilings of the options above and of --max-bounces. At kMaxDepthCeiling the syntax tree's
// recursion (parser, printer, Thompson construction, nested & and ~) needs under 2 MiB of stack in
// a release build and about 10 MiB under AddressSanitizer; the command line runs on a 64 MiB stack
// (core/stack.h), and ParserLimits.TheDepthCeilingRunsOnAQuarterOfTheCommandLineStack walks a tree
// of that height in every recursive routine on a quarter of it.
inline constexpr std::size_t kMaxStatesCeiling = 10000000;
inline constexpr int kMaxDepthCeiling = 1000;
inline constexpr int kMaxRepeatCeiling = 100000;
inline constexpr std::size_t kMaxLengthCeiling = 100000000;
inline constexpr std::size_t kMaxWorkCeiling = 4000000000;
inline constexpr std::size_t kMaxFileBytesCeiling = std::size_t{16} << 30;
inline constexpr int kMaxBouncesCeiling = 10000;
// The scene limits' ceilings. Material nesting is the one recursion (Mitsuba's nested <bsdf>
// elements): 1000 levels need well under 1 MiB of stack; 100 M material components take about
// 3 GB; a mesh's vertex indices are 32-bit.
inline constexpr std::size_t kMaxSceneBytesCeiling = std::size_t{64} << 30;
inline constexpr int kMaxSceneDepthCeiling = 1000;
inline constexpr std::size_t kMaxMaterialNodesCeiling = 100000000;
inline constexpr std::size_t kMaxMeshElementsCeiling = 4000000000;
// 2^32 texels of linear RGB floats are 48 GiB.
inline constexpr std::size_t kMaxTexelsCeiling = std::size_t{1} << 32;

// "the DFA exceeds the limit of 100000 states (raise it with --max-states)" and friends.
std::string limit_message(const std::string& what, std::size_t limit, const std::string& unit,
                          const std::string& option);

}  // namespace pathex
