// Tracer benchmarks (issue 4). Run:
//   build/bench/trace_bench --benchmark_min_time=4
// Each case renders the embedded Cornell box (or a generated mesh). The machines are shared and
// noisy, so every target that is a ratio is measured interleaved: each iteration times both
// sides back to back (in process CPU time; wall time for the thread count), and the counter is
// the median of the per-iteration ratios (the thread speedup: the ratio of the summed times).
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <time.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include "bias/bias.h"
#include "classify/classifier.h"
#include "io/class_file.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"
#include "trace/embree_scene.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex {
namespace {

const Scene& cornell() {
  static const Scene s = load_scene_json(default_scene_json(), ".", "default").expect("a benchmark input");
  return s;
}

RenderOptions options(int threads, std::uint64_t spp) {
  RenderOptions o;
  o.threads = threads;
  o.spp = spp;
  o.max_bounces = 8;
  return o;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Process CPU time in seconds: on a shared machine, time the host gives to others is not counted.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The baseline: a plain rtcIntersect1 loop over the same Embree scene, one thread, casting
// exactly `count` rays: camera rays through random pixels, each followed by up to three random
// bounces (comparable coherence), the minimum of work around each ray. Returns the hits.
std::uint64_t plain_embree_loop(const RenderScene& rs, std::uint64_t count, std::uint64_t seed) {
  const PinholeParams& cam = std::get<PinholeParams>(rs.camera.params);  // the Cornell box's
  std::uint64_t rays = 0, hits = 0;
  for (std::uint64_t path = 0; rays < count; ++path) {
    Sampler rng(seed, path, 0);
    const glm::vec2 u = rng.get2d();
    const float sx = (2.0f * u.x - 1.0f) * cam.tan_half_x, sy = (1.0f - 2.0f * u.y) * cam.tan_half_y;
    glm::vec3 o = cam.position, d = glm::normalize(cam.forward + sx * cam.right + sy * cam.up);
    for (int bounce = 0; bounce < 4 && rays < count; ++bounce) {
      RTCRayHit rh{};
      rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
      rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
      rh.ray.tnear = 1e-4f;
      rh.ray.tfar = std::numeric_limits<float>::infinity();
      rh.ray.mask = 0xFFFFFFFFu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      rtcIntersect1(rs.geometry->handle(), &ctx, &rh);
      ++rays;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      ++hits;
      o = o + d * rh.ray.tfar;
      glm::vec3 n = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
      if (glm::dot(n, d) > 0) n = -n;
      o += n * 1e-4f;
      const glm::vec3 nd = n + sample_uniform_sphere(rng.get2d());  // zero when the sample is exactly -n
      const float len2 = glm::dot(nd, nd);
      d = len2 > 1e-12f ? nd / std::sqrt(len2) : n;
    }
  }
  return hits;
}

// The tracer's rays per second against the plain loop's, interleaved: each iteration renders
// (one thread, all rays it casts: subpath extensions and shadow rays), then casts the same number
// of rays in the plain loop, so that both see the same machine; `ratio` is the median over
// iterations of the tracer's rate over the plain loop's (CPU time).
void BM_TracerRays(benchmark::State& state) {
  const char* const names[] = {"bdpt", "pt-nee", "pt", "lt"};
  const Profile profile = resolve_profile(names[state.range(0)], Limits{}).expect("a benchmark input");
  Result<RenderScene> rs = make_render_scene(cornell());
  if (!rs) {
    state.SkipWithError(rs.error().render().c_str());
    return;
  }
  std::uint64_t rays = 0;
  double tracer_s = 0, plain_s = 0;
  std::vector<double> ratios;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    Result<RenderOutput> out = render(cornell(), profile, nullptr, options(1, 4));
    const double t1 = cpu_seconds();
    if (!out) {
      state.SkipWithError(out.error().render().c_str());
      return;
    }
    benchmark::DoNotOptimize(plain_embree_loop(*rs, out->rays, rays));
    const double t2 = cpu_seconds();
    rays += out->rays;
    tracer_s += t1 - t0;
    plain_s += t2 - t1;
    ratios.push_back((t2 - t1) / (t1 - t0));
  }
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays) / tracer_s);
  state.counters["plain_rays_per_s"] = benchmark::Counter(static_cast<double>(rays) / plain_s);
  state.counters["ratio"] = benchmark::Counter(median(ratios));
  state.SetLabel(profile.name + ", 1 thread");
}
BENCHMARK(BM_TracerRays)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// Classification overhead, interleaved: each iteration renders (the CLI's default 16 spp) the
// same scene both ways. Arg 20: the 20-class file with an image layer per class against no
// classifier and no layers at all (the strictest baseline: no path is classified, the image is
// the total alone). Arg 21: the 20 classes classified, no class layers, against the same (the
// automaton's share alone). Arg 5: what a user of the CLI sees, `pathex trace --classes
// samples/classes/twenty.json` against `pathex trace` with no class file, which classifies by
// the five built-in classes and writes their layers. Arg 0: a control, no classes on both
// sides. `overhead_pct` is the median over iterations of the CPU time of the first side over
// the second, minus 1: the median shrugs off an iteration that the shared machine slowed on one
// side only.
void BM_RenderClasses(benchmark::State& state) {
  const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("a benchmark input");
  ClassTable table;
  std::vector<const PathClass*> classes, builtin_classes;
  (void)read_class_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/twenty.json", ClassOptions{}, &table);
  for (const auto& c : table.user_classes()) classes.push_back(c.get());
  for (const auto& c : ClassTable::builtins().builtin_classes())  // as src/cli/trace.cpp
    if (c->name != "all") builtin_classes.push_back(c.get());
  const Classifier none = Classifier::build({}, Limits{}).expect("a benchmark input");
  const Classifier twenty = Classifier::build(classes, Limits{}).expect("a benchmark input");
  const Classifier builtin = Classifier::build(builtin_classes, Limits{}).expect("a benchmark input");
  const int arg = static_cast<int>(state.range(0));
  const bool control = arg == 0;
  RenderOptions plain = options(1, 16), classified = options(1, 16);
  if (arg == 20 || arg == 5)
    for (int i = 0; i < twenty.num_classes(); ++i) classified.layer_classes.push_back(i);
  if (arg == 5)
    for (int i = 0; i < builtin.num_classes(); ++i) plain.layer_classes.push_back(i);
  const Classifier* const base = arg == 5 ? &builtin : &none;
  std::vector<double> ratios;
  std::size_t image_bytes = 0;
  bool classes_first = false;  // alternated, so that neither side always runs on a warm cache
  for (auto _ : state) {
    double with_s = 0, without_s = 0;
    for (int side = 0; side < 2; ++side) {
      const bool with = (side == 0) == classes_first;
      const double t0 = cpu_seconds();
      Result<RenderOutput> out = with ? render(cornell(), bdpt, control ? &none : &twenty, classified)
                                      : render(cornell(), bdpt, base, plain);
      (with ? with_s : without_s) += cpu_seconds() - t0;
      if (!out) {
        state.SkipWithError(out.error().render().c_str());
        return;
      }
      if (with) image_bytes = out->images.memory_bytes();
    }
    ratios.push_back(with_s / without_s);
    classes_first = !classes_first;
  }
  state.counters["overhead_pct"] = benchmark::Counter(100.0 * (median(ratios) - 1.0));
  state.counters["image_MiB"] = benchmark::Counter(static_cast<double>(image_bytes) / (1024.0 * 1024.0));
  const std::string label = std::to_string(classes.size()) + " classes, " + std::to_string(classified.layer_classes.size()) + " class layers";
  state.SetLabel(control     ? std::string("control: no classes against none")
                 : arg == 5 ? label + ", against the CLI's default (" + std::to_string(builtin_classes.size()) + " built-in classes and layers)"
                            : label + ", against no classes");
}
BENCHMARK(BM_RenderClasses)->Arg(0)->Arg(20)->Arg(21)->Arg(5)->Unit(benchmark::kMillisecond)->UseRealTime();

// Shadow rays alone, interleaved: the same 64 Ki segments between points on the Cornell box's
// surfaces (sampled by area, so about a quarter are blocked) tested one by one with
// EmbreeScene::visible() and in full OcclusionBatch packets of 16; `speedup` is the median of
// the per-iteration ratios of single-ray time over batched time.
void BM_ShadowRays(benchmark::State& state) {
  Result<RenderScene> rs = make_render_scene(cornell());
  if (!rs) {
    state.SkipWithError(rs.error().render().c_str());
    return;
  }
  const EmbreeScene& es = *rs->geometry;
  struct Segment {
    glm::vec3 a, na, ea, b, nb, eb;
  };
  std::vector<Segment> segments;
  std::mt19937 pick(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const auto shapes = static_cast<unsigned>(cornell().shapes.size());
  for (int i = 0; i < 65536; ++i) {
    const SurfaceSample a = es.sample_shape(static_cast<int>(pick() % shapes), {u01(pick), u01(pick)});
    const SurfaceSample b = es.sample_shape(static_cast<int>(pick() % shapes), {u01(pick), u01(pick)});
    segments.push_back({a.position, a.normal, a.error, b.position, b.normal, b.error});
  }
  std::vector<double> ratios;
  std::uint64_t visible_single = 0, visible_batched = 0;
  OcclusionBatch batch;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    for (const Segment& g : segments) visible_single += es.visible(g.a, g.na, g.ea, g.b, g.nb, g.eb);
    const double t1 = cpu_seconds();
    for (const Segment& g : segments) {
      batch.add(es, g.a, g.na, g.ea, g.b, g.nb, g.eb);
      if (!batch.full()) continue;
      batch.trace(es);
      for (int lane = 0; lane < batch.size(); ++lane) visible_batched += batch.visible(lane);
      batch.clear();
    }
    const double t2 = cpu_seconds();
    ratios.push_back((t1 - t0) / (t2 - t1));
  }
  if (visible_single != visible_batched) state.SkipWithError("batched and single answers differ");
  state.counters["speedup"] = benchmark::Counter(median(ratios));
  state.counters["visible"] = benchmark::Counter(static_cast<double>(visible_single) /
                                                 (static_cast<double>(state.iterations()) * static_cast<double>(segments.size())));
  state.SetLabel("64 Ki segments, one by one against packets of 16");
}
BENCHMARK(BM_ShadowRays)->Unit(benchmark::kMillisecond)->UseRealTime();

// Eye subpaths' first rays, interleaved (issue 39): Tungsten's Cornell box (bench/scenes), the
// camera rays of every pixel's first 4 passes in the order the render makes them (4 pixels of 4
// passes to a packet), each traced one by one with EmbreeScene::intersect() and in packets of 16
// with RayPacket (trace/accel/eye_packets.h); `speedup` is the median of the per-iteration ratios
// of single-ray time over packet time, and every packet hit must equal intersect()'s, field by field.
void BM_EyeRayPackets(benchmark::State& state) {
  static const Scene box = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/bench/scenes/tungsten-cornell-box.json").expect("a benchmark input");
  Result<RenderScene> rs = make_render_scene(box);
  if (!rs) {
    state.SkipWithError(rs.error().render().c_str());
    return;
  }
  const EmbreeScene& es = *rs->geometry;
  std::vector<EndpointRay> rays;
  for (int y = 0; y < rs->camera.height; ++y)
    for (int x = 0; x < rs->camera.width; ++x)
      for (std::uint64_t pass = 0; pass < 4; ++pass) {
        Sampler rng(1, static_cast<std::uint64_t>(y * rs->camera.width + x), pass, SamplerKind::kSobol, 2);
        if (const std::optional<EndpointRay> r = rs->camera.primary_ray(rng, x, y)) rays.push_back(*r);
      }
  const auto same = [](const std::optional<Hit>& a, const std::optional<Hit>& b) {
    return a.has_value() == b.has_value() && (!a || (a->t == b->t && a->position == b->position && a->normal == b->normal &&
                                                     a->error == b->error && a->shape == b->shape && a->primitive == b->primitive));
  };
  std::vector<std::optional<Hit>> single(rays.size()), batched(rays.size());
  std::vector<double> ratios;
  std::uint64_t differ = 0;
  RayPacket packet;
  for (auto _ : state) {
    const double t0 = cpu_seconds();
    for (std::size_t i = 0; i < rays.size(); ++i) single[i] = es.intersect(rays[i].origin, rays[i].direction, glm::vec3(0.0f), glm::vec3(0.0f), HitDetail::kNoUv);
    const double t1 = cpu_seconds();
    for (std::size_t i = 0; i < rays.size(); i += RayPacket::kCapacity) {
      const std::size_t n = std::min<std::size_t>(RayPacket::kCapacity, rays.size() - i);
      for (std::size_t k = 0; k < n; ++k) packet.add(rays[i + k].origin, rays[i + k].direction);
      packet.trace(es);
      for (std::size_t k = 0; k < n; ++k) batched[i + k] = packet.hit(es, static_cast<int>(k), HitDetail::kNoUv);
      packet.clear();
    }
    const double t2 = cpu_seconds();
    ratios.push_back((t1 - t0) / (t2 - t1));
    for (std::size_t i = 0; i < rays.size(); ++i) differ += !same(batched[i], single[i]);
  }
  if (differ != 0) state.SkipWithError("a packet's hit differs from intersect()'s");
  state.counters["speedup"] = benchmark::Counter(median(ratios));
  state.SetLabel(std::to_string(rays.size()) + " camera rays of Tungsten's box, one by one against packets of 16");
}
BENCHMARK(BM_EyeRayPackets)->Unit(benchmark::kMillisecond)->UseRealTime();

// Thread scaling, interleaved: each iteration renders with one thread and then with two (wall
// time); `speedup` is the summed one-thread time over the summed two-thread time.
void BM_RenderThreads(benchmark::State& state) {
  const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("a benchmark input");
  double one_s = 0, two_s = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(render(cornell(), bdpt, nullptr, options(1, 8)));
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(render(cornell(), bdpt, nullptr, options(2, 8)));
    const auto t2 = std::chrono::steady_clock::now();
    one_s += std::chrono::duration<double>(t1 - t0).count();
    two_s += std::chrono::duration<double>(t2 - t1).count();
  }
  state.counters["speedup"] = benchmark::Counter(one_s / two_s);
  state.SetLabel("8 spp, 1 thread then 2");
}
BENCHMARK(BM_RenderThreads)->Unit(benchmark::kMillisecond)->UseRealTime();

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
  const Profile pt = resolve_profile("pt-nee", Limits{}).expect("a benchmark input");
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

// pathex bias against the reference render it is made of (issue 18: "one reference render plus
// < 1 %"), interleaved: each iteration runs run_bias (pt-nee against bdpt, the built-in classes,
// their images and the missed layer, the checker's languages, the per-class queries and the
// per-path verdicts) and, alone, the bdpt render `pathex trace` would run (the built-in classes
// and their layers) with its report, on the same scene, spp, seed and bound, one thread.
// `overhead_pct` is the median of the per-iteration ratios minus 1, `extra_ms` the median of the
// differences (what bias adds whatever the render's length). Arg 0: a control, the plain
// render against itself; 1: the Cornell box; 2: the point light and mirror
// (samples/scenes/point-mirror-caustic.json).
void BM_BiasOverhead(benchmark::State& state) {
  const int arg = static_cast<int>(state.range(0));
  static const Scene mirror =
      load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-mirror-caustic.json").expect("a benchmark input");
  const Scene& scene = arg == 2 ? mirror : cornell();
  const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("a benchmark input");
  const Profile pt_nee = resolve_profile("pt-nee", Limits{}).expect("a benchmark input");
  std::vector<const PathClass*> classes;
  std::vector<ClassInfo> infos;
  for (const auto& c : ClassTable::builtins().builtin_classes())  // as src/cli/trace.cpp and bias.cpp
    if (c->name != "all") {
      classes.push_back(c.get());
      infos.push_back({c->name, c->text});
    }
  const Classifier builtin = Classifier::build(classes, Limits{}).expect("a benchmark input");
  const std::uint64_t spp = arg == 2 ? 256 : 16;
  BiasOptions bo;
  bo.spp = spp;
  bo.threads = 1;
  RenderOptions plain = options(1, spp);
  plain.max_bounces = reference_bound("pt-nee", std::nullopt, std::nullopt).expect("a bound");
  for (int i = 0; i < builtin.num_classes(); ++i) plain.layer_classes.push_back(i);
  const auto reference_alone = [&]() -> bool {
    Result<RenderOutput> out = render(scene, bdpt, &builtin, plain);
    return out && make_report(out->histogram, RunInfo{}, &builtin, infos).ok();
  };
  std::vector<double> ratios, extra;
  bool bias_first = false;  // alternated, so that neither side always runs on a warm cache
  for (auto _ : state) {
    double bias_s = 0, plain_s = 0;
    for (int side = 0; side < 2; ++side) {
      const bool with = (side == 0) == bias_first;
      const double t0 = cpu_seconds();
      bool ok = true;
      if (with && arg != 0) {
        Result<Profile> ref = choose_reference("", scene, pt_nee, bo);
        ok = ref && run_bias(scene, "bench", pt_nee, *ref, classes, bo).ok();
      } else {
        ok = reference_alone();
      }
      (with ? bias_s : plain_s) += cpu_seconds() - t0;
      if (!ok) {
        state.SkipWithError("a render failed");
        return;
      }
    }
    ratios.push_back(bias_s / plain_s);
    extra.push_back(bias_s - plain_s);
    bias_first = !bias_first;
  }
  state.counters["overhead_pct"] = benchmark::Counter(100.0 * (median(ratios) - 1.0));
  state.counters["extra_ms"] = benchmark::Counter(1000.0 * median(extra));
  state.SetLabel(arg == 0 ? "control: the bdpt render against itself"
                 : arg == 1 ? "Cornell box, pt-nee against bdpt, 16 spp"
                            : "point light and mirror, pt-nee against bdpt, 256 spp");
}
BENCHMARK(BM_BiasOverhead)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(31);

}  // namespace
}  // namespace pathex

BENCHMARK_MAIN();
