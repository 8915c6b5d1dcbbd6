// Tracer benchmarks (issue 4). Run:
//   build/bench/trace_bench --benchmark_min_time=1
// Each case renders the embedded Cornell box (or a generated mesh) and reports rays per second;
// compare ratios measured in one run: the machines are shared and noisy.
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <embree3/rtcore.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "classify/classifier.h"
#include "io/class_file.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex {
namespace {

const Scene& cornell() {
  static const Scene s = *load_scene_json(default_scene_json(), ".", "default");
  return s;
}

RenderOptions options(int threads, std::uint64_t spp) {
  RenderOptions o;
  o.threads = threads;
  o.spp = spp;
  o.max_bounces = 8;
  return o;
}

// The tracer's own rate: all rays it casts (subpath extensions and shadow rays) per second.
void BM_TracerRays(benchmark::State& state) {
  const char* const names[] = {"bdpt", "pt-nee", "pt", "lt"};
  const Profile bdpt = *resolve_profile(names[state.range(0)], Limits{});
  std::uint64_t rays = 0;
  double seconds = 0;
  for (auto _ : state) {
    Result<RenderOutput> out = render(cornell(), bdpt, nullptr, options(1, 4));
    rays += out->rays;
    seconds += out->time_s;
  }
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays) / seconds);
  state.SetLabel(bdpt.name + ", 1 thread");
}
BENCHMARK(BM_TracerRays)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// The baseline: a plain rtcIntersect1 loop over the same Embree scene, casting camera rays and
// then one random bounce per hit (comparable coherence), one thread.
void BM_PlainEmbreeLoop(benchmark::State& state) {
  Result<RenderScene> rs = make_render_scene(cornell());
  const RenderCamera& cam = rs->camera;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    std::uint64_t hits = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x)
        for (int p = 0; p < 4; ++p) {
          Sampler rng(1, static_cast<std::uint64_t>(y * cam.width + x), static_cast<std::uint64_t>(p));
          const float sx = (2.0f * (static_cast<float>(x) + rng.get1d()) / static_cast<float>(cam.width) - 1.0f) * cam.tan_x;
          const float sy = (1.0f - 2.0f * (static_cast<float>(y) + rng.get1d()) / static_cast<float>(cam.height)) * cam.tan_y;
          glm::vec3 o = cam.position, d = glm::normalize(cam.forward + sx * cam.right + sy * cam.up);
          for (int bounce = 0; bounce < 4; ++bounce) {
            RTCRayHit rh{};
            rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
            rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
            rh.ray.tnear = 1e-4f;
            rh.ray.tfar = std::numeric_limits<float>::infinity();
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            rtcIntersect1(rs->geometry->handle(), &ctx, &rh);
            ++rays;
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
            ++hits;
            o = o + d * rh.ray.tfar;
            glm::vec3 n = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
            if (glm::dot(n, d) > 0) n = -n;
            o += n * 1e-4f;
            d = glm::normalize(n + sample_uniform_sphere(rng.get2d()));
          }
        }
    benchmark::DoNotOptimize(hits);
  }
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PlainEmbreeLoop)->Unit(benchmark::kMillisecond)->UseRealTime();

// Classification overhead: the same render with no classes, with the 20-class file (labels
// classified, an image layer per class: Arg 20), and with the 20 classes but no class layers
// (Arg 21: the automaton's share alone).
void BM_RenderClasses(benchmark::State& state) {
  const Profile bdpt = *resolve_profile("bdpt", Limits{});
  ClassTable table;
  std::vector<const PathClass*> classes;
  if (state.range(0) > 0) {
    (void)read_class_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/twenty.json", ClassOptions{}, &table);
    for (const auto& c : table.user_classes()) classes.push_back(c.get());
  }
  const Classifier cl = *Classifier::build(classes, Limits{});
  RenderOptions o = options(1, 4);
  if (state.range(0) == 20)
    for (int i = 0; i < cl.num_classes(); ++i) o.layer_classes.push_back(i);
  for (auto _ : state) benchmark::DoNotOptimize(render(cornell(), bdpt, &cl, o));
  state.SetLabel(std::to_string(classes.size()) + " classes, " + std::to_string(o.layer_classes.size()) + " class layers");
}
BENCHMARK(BM_RenderClasses)->Arg(0)->Arg(20)->Arg(21)->Unit(benchmark::kMillisecond)->UseRealTime();

// Thread scaling: one against two threads on the same render.
void BM_RenderThreads(benchmark::State& state) {
  const Profile bdpt = *resolve_profile("bdpt", Limits{});
  for (auto _ : state) benchmark::DoNotOptimize(render(cornell(), bdpt, nullptr, options(static_cast<int>(state.range(0)), 8)));
}
BENCHMARK(BM_RenderThreads)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// A one-million-triangle OBJ (a displaced grid) under the Cornell light: load and render, with
// the process's peak memory.
void BM_MillionTriangles(benchmark::State& state) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pathex-bench-mesh";
  std::filesystem::create_directories(dir);
  const int n = 708;  // (n-1)^2 * 2 = 1,000,000 triangles... 707^2*2 = 999,698
  {
    std::ofstream obj(dir / "grid.obj");
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float x = static_cast<float>(i) / static_cast<float>(n - 1), z = static_cast<float>(j) / static_cast<float>(n - 1);
        obj << "v " << x * 2 - 1 << " " << 0.05f * std::sin(20 * x) * std::cos(20 * z) << " " << z * 2 - 1 << "\n";
      }
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i + 1, b = a + 1, c = a + n, d = c + 1;
        obj << "f " << a << " " << c << " " << b << "\nf " << b << " " << c << " " << d << "\n";
      }
    std::ofstream scene(dir / "mesh.json");
    scene << R"({"camera": {"type": "pinhole", "position": [0, 2, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 45,
                 "width": 64, "height": 64},
      "materials": {"white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [{"type": "mesh", "file": "grid.obj", "material": "white"}],
      "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [5, 5, 5]}]})";
  }
  const Profile pt = *resolve_profile("pt-nee", Limits{});
  for (auto _ : state) {
    Result<Scene> s = load_scene_file((dir / "mesh.json").string());
    if (!s) {
      state.SkipWithError(s.error().render().c_str());
      return;
    }
    benchmark::DoNotOptimize(render(*s, pt, nullptr, options(0, 1)));
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_MiB"] = static_cast<double>(ru.ru_maxrss) / 1024.0;
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_MillionTriangles)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace pathex

BENCHMARK_MAIN();
