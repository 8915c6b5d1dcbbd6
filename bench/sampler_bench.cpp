// The cost of the tracer's random numbers (trace/rng.h, Sampler), per number, for each sampler:
// the pattern of a path as the integrator draws it (a camera point, then per vertex a component
// choice, a direction and a roulette number), one Sampler per (pixel, pass).
//
//     build/bench/sampler_bench
#include <benchmark/benchmark.h>

#include <cstdint>

#include "trace/rng.h"

namespace {

void BM_SamplerNumbers(benchmark::State& state) {
  const auto kind = static_cast<pathex::SamplerKind>(state.range(0));
  constexpr int kVertices = 8;
  constexpr std::uint64_t kPixels = 4096, kPasses = 16;
  float sum = 0.0f;
  std::uint64_t numbers = 0;
  for (auto _ : state) {
    for (std::uint64_t pixel = 0; pixel < kPixels; ++pixel)
      for (std::uint64_t pass = 0; pass < kPasses; ++pass) {
        pathex::Sampler s(7, pixel, pass, kind);
        const glm::vec2 film = s.get2d();
        sum += film.x + film.y;
        for (int v = 0; v < kVertices; ++v) {
          const float comp = s.get1d();
          const glm::vec2 d = s.get2d();
          const float rr = s.get1d();
          sum += comp + d.x + d.y + rr;
        }
        numbers += 2 + 4 * kVertices;
      }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns_per_number"] =
      benchmark::Counter(static_cast<double>(numbers), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetLabel(pathex::to_string(kind));
}
BENCHMARK(BM_SamplerNumbers)
    ->Arg(static_cast<int>(pathex::SamplerKind::kIndependent))
    ->Arg(static_cast<int>(pathex::SamplerKind::kSobol))
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
