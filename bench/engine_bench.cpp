// Benchmarks for the engine (issue 2) and the checker (issue 3). Run:
//   build/bench/engine_bench --benchmark_min_time=0.5
// The CLI cases spawn the real binary, so they include process start, as a user sees it.
#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "io/class_file.h"

extern char** environ;

namespace pathex {
namespace {

// A typical 40-character class: caustics seen through glass, no two mirrors in a row.
constexpr const char* kTypical40 = "L..(S|D)*DS+D.*..E & ~(L.*SSS.*E) | LDDDE";

void BM_CompileTypical40(benchmark::State& state) {
  const ClassOptions options;
  for (auto _ : state) {
    Result<PathClass> c = compile_class(kTypical40, options);
    benchmark::DoNotOptimize(c);
  }
  state.SetLabel(std::to_string(std::string(kTypical40).size()) + " chars, " +
                 std::to_string(compile_class(kTypical40, options).expect("the typical class compiles").dfa.num_states) +
                 " DFA states");
}
BENCHMARK(BM_CompileTypical40)->Unit(benchmark::kMicrosecond);

// 20 classes from samples/classes/twenty.json, 4 MB of random valid paths of 6..30 letters.
void BM_Classify20Classes(benchmark::State& state) {
  ClassTable table;
  Result<bool> loaded = read_class_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/twenty.json", ClassOptions{}, &table);
  if (!loaded) {
    state.SkipWithError(loaded.error().render().c_str());
    return;
  }
  std::vector<const PathClass*> classes;
  for (const auto& c : table.user_classes()) classes.push_back(c.get());
  Result<Classifier> cl = Classifier::build(classes, Limits{});
  if (!cl) {
    state.SkipWithError(cl.error().render().c_str());
    return;
  }
  std::mt19937_64 rng(7);
  std::string buffer;
  std::vector<std::pair<std::size_t, std::size_t>> paths;
  while (buffer.size() < (4u << 20)) {
    const std::size_t len = 4 + rng() % 25;
    const std::size_t start = buffer.size();
    buffer += 'L';
    for (std::size_t i = 0; i < len; ++i) buffer += (rng() & 1) ? 'S' : 'D';
    buffer += 'E';
    paths.push_back({start, buffer.size() - start});
  }
  std::uint64_t sink = 0;
  for (auto _ : state) {
    for (const auto& [start, len] : paths) sink += cl->classify(std::string_view(buffer.data() + start, len));
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(buffer.size()));
  state.SetLabel(std::to_string(classes.size()) + " classes, " + std::to_string(cl->forward().num_states()) +
                 " states; items = letters");
}
BENCHMARK(BM_Classify20Classes)->Unit(benchmark::kMillisecond);

int spawn_and_wait(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) return -1;
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void BM_CliExplain(benchmark::State& state) {
  for (auto _ : state)
    if (spawn_and_wait({PATHEX_BINARY, "explain", "L..S+D.*..E & ~(L.*SS.*E)"}) != 0) state.SkipWithError("explain failed");
}
BENCHMARK(BM_CliExplain)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CliQueryThreeRenderers(benchmark::State& state) {
  for (auto _ : state)
    if (spawn_and_wait({PATHEX_BINARY, "query", "--renderer", "pt-nee", "--renderer", "lt", "--renderer", "bdpt",
                        "L..S+D.*..E & ~(L.*SS.*E)"}) != 0)
      state.SkipWithError("query failed");
}
BENCHMARK(BM_CliQueryThreeRenderers)->Unit(benchmark::kMillisecond)->UseRealTime();

// 100 cases over 13 profiles, bounds 4..12, three requirements each.
void BM_CliCheck100Cases(benchmark::State& state) {
  const std::string path = (std::filesystem::temp_directory_path() / "pathex-bench-check100.json").string();
  {
    const char* renderers[] = {"pt", "pt-nee", "lt", "bdpt", "bdpt+mirror", "bdpt+ortho", "pt-nee+distant",
                               "pt-nee+manifold", "pbrt-v4-path", "pbrt-v4-bdpt", "pbrt-v4-lightpath",
                               "mitsuba3-path", "mitsuba3-ptracer"};
    const char* classes[] = {"$caustic", "LSDSDE", "L.*DD.*E", "$direct", "LDS.*DSE", "L..S+D.*..E & ~(L.*SS.*E)"};
    std::ofstream f(path);
    f << "{\"cases\": [\n";
    for (int i = 0; i < 100; ++i) {
      f << (i ? ",\n" : "") << "{\"name\": \"case" << i << "\", \"renderer\": \"" << renderers[i % 13]
        << "\", \"max_bounces\": " << 4 + i % 9 << ", \"require\": [{\"class\": \"" << classes[i % 6]
        << "\", \"verdict\": \"not-unreachable\"}, {\"class\": \"" << classes[(i + 1) % 6]
        << "\", \"verdict\": \"reachable\"}, {\"covers-scene\": true}]}";
    }
    f << "\n]}\n";
  }
  for (auto _ : state) {
    const int rc = spawn_and_wait({PATHEX_BINARY, "check", path});
    if (rc != 0 && rc != 1) state.SkipWithError("check failed");
  }
  std::filesystem::remove(path);
}
BENCHMARK(BM_CliCheck100Cases)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace pathex

BENCHMARK_MAIN();
