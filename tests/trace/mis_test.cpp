// DESIGN §7: for any string, the strategies with nonzero density are exactly those whose
// language contains it, and their MIS weights sum to 1. For random full paths in every sample
// scene and every profile the tracer runs, each strategy's weight is computed from its own side
// (the vertices re-split at its join, densities recomputed as it would sample them) and summed.
//
// The renderer weighs every join by one routine (trace/mis.h) over each vertex's two densities:
// for a plain or projection join those the subpaths stored, with the four the join changes
// recomputed; for a connector that constructs vertices, every density recomputed from the path.
// The test pins the two sources equal on plain joins (the whole path's densities recomputed).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "io/profile_json.h"
#include "support/cli_run.h"
#include "scene/scene.h"
#include "optics/fresnel.h"
#include "trace/integrator.h"
#include "trace/joins/manifold.h"
#include "trace/render.h"

namespace pathex::tracer {

// Drives the integrator's stages by hand (its public interface): subpaths, joins, weights.
struct IntegratorTestAccess {
  using Thread = Integrator::Thread;
  // What the integrator derives from its scene and profile, derived here from the same: the
  // probability of picking each light, a light's letters c0 c1 and the sensor's c(k+1).
  static float light_pick(const Integrator& in) { return 1.0f / static_cast<float>(in.scene().lights.size()); }
  static const std::string& light_pair(const Integrator& in, int li) { return in.scene().lights[static_cast<std::size_t>(li)].letters; }
  static char sensor_direction_letter(const Integrator& in) { return in.scene().camera.letters[0]; }
  // Whether the plain join (s, DD, t) runs: the profile's strategy, and for t = 0 a thin lens that
  // light subpaths can hit because some (·, DD, 0) runs.
  static bool runs_plain(const Integrator& in, int s, int t) {
    bool lens_hits = false;
    for (int s2 = 0; s2 < 2 * kMaxVertices; ++s2) lens_hits = lens_hits || in.strategy(s2, 0) >= 0;
    return in.strategy(s, t) >= 0 && (t > 0 || (lens_hits && in.scene().camera.type == SensorType::kLens));
  }
  // One sample's eye and light subpaths, as render() traces them.
  static int trace_subpaths(const Integrator& in, Integrator::Thread& th, Sampler& rng, int px, int py, int* ns) {
    const int nt = in.eye_subpath(th, rng, px, py);
    // The light's first direction, drawn in advance as render() draws it: after the light's pick
    // and point (render.cpp's kLightRayDim).
    *ns = in.light_subpath(th, rng, rng.at2d(rng.dimension() + 3));
    th.ns = *ns;
    th.nt = nt;
    in.set_masks(th, *ns, nt);
    return nt;
  }
  // The full-path string of connection (s, t), spelled out from the vertices.
  // (The test's oracle for the renderer's packed labels, path_key(): L c0 … c(k+2) E from the
  // vertices' letters, the two join letters D.)
  static std::string label(const Integrator&, const Integrator::Thread& th, int s, int t) {
    const int k = s + t - 1;
    if (k < 1) return "";
    std::string out(static_cast<std::size_t>(k) + 5, 'D');
    out.front() = 'L';
    out.back() = 'E';
    const auto vertex = [&](int i) -> const Vertex& {  // x_i in light-to-eye order
      return i < s ? th.light[static_cast<std::size_t>(i)] : th.eye[static_cast<std::size_t>(k - i)];
    };
    const auto c = [&](int i) -> char& { return out[static_cast<std::size_t>(i) + 1]; };
    if (s > 0) {  // for s = 0 the eye path hit an area light: DD
      c(0) = vertex(0).pos_letter;
      c(1) = vertex(0).letter;
    }
    for (int i = 1; i <= k - 1; ++i) c(i + 1) = vertex(i).letter;
    if (t > 0) {
      c(k + 1) = vertex(k).letter;
      c(k + 2) = vertex(k).pos_letter;
    }
    c(s) = 'D';
    c(s + 1) = 'D';
    return out;
  }
  // The factor of the manifold connector's density in the weights of connection (s, t)'s path for a
  // chain whose eye end is x_b (its rate where it runs in a share of the samples).
  static double manifold_rate(const Integrator& in, const Thread& th, int s, int t, int b) {
    return in.manifold_rate(in.path_key(th, s, t, nullptr), b, s + t - 1);
  }
  // The same string as the renderer records it (packed, then spelled out).
  static std::string packed_label(const Integrator& in, const Integrator::Thread& th, int s, int t) {
    return unpack(in.path_key(th, s, t, nullptr));
  }
  // The path of connection (s, t) of the current subpaths (a fresh light point `y0` for s = 1).
  static Integrator::PathView plain_path(const Thread& th, int s, int t, const Vertex* y0 = nullptr) {
    Integrator::PathView x;
    x.light = th.light.data();
    x.light0 = s == 1 ? y0 : nullptr;
    x.eye = th.eye.data();
    x.s = s;
    x.t = t;
    return x;
  }
  // The weight of connection (s, t) of the current subpaths, as the renderer computes it.
  static float own_weight(const Integrator& in, Integrator::Thread& th, int s, int t) {
    in.set_masks(th, th.ns, th.nt);
    return in.mis_weight(th, plain_path(th, s, t), in.path_key(th, s, t, nullptr), ConnectorKind::kNone, nullptr);
  }
  // The path x0 … xk of connection (s, t) as one array (an eye vertex on a light becoming x0's
  // light vertex, a light vertex on the lens xk's camera vertex), as a connector's path is formed.
  static std::vector<Vertex> gather(const Integrator& in, const Thread& th, int s, int t) {
    std::vector<Vertex> path;
    for (int i = 0; i < s; ++i) path.push_back(th.light[static_cast<std::size_t>(i)]);
    for (int j = t - 1; j >= 0; --j) path.push_back(th.eye[static_cast<std::size_t>(j)]);
    if (s == 0) {
      path.front().kind = Kind::kLight;
      path.front().light = in.scene().light_of_shape[static_cast<std::size_t>(path.front().shape)];
    }
    if (t == 0) path.back().kind = Kind::kCamera;
    return path;
  }
  // A path x0 … xk held in one array (as gather() forms it): the view of strategy (s, m
  // constructed, ·) over it reads x0 … x(s-1) as the light vertices, the m after them as the chain
  // and the rest, from xk back, as the eye vertices.
  struct WholePath {
    std::vector<Vertex> x, reversed;
    explicit WholePath(std::vector<Vertex> path) : x(std::move(path)), reversed(x.rbegin(), x.rend()) {}
    Integrator::PathView at(int s, int m) const {
      Integrator::PathView v;
      v.light = x.data();
      v.chain = x.data() + s;
      v.eye = reversed.data();
      v.s = s;
      v.m = m;
      v.t = static_cast<int>(x.size()) - s - m;
      return v;
    }
  };
  // The weight of strategy `self` at split s (m constructed vertices) of `path` by the one routine,
  // with every density recomputed from the vertices (as the renderer weighs a connector's path).
  static float recomputed_weight(const Integrator& in, Thread& th, const WholePath& path, int s, int m, PathKey key,
                                 ConnectorKind self) {
    const Integrator::PathView x = path.at(s, m);
    const mis::Strategies st = in.techniques(th, x, key, self);
    if (st.alone()) return 1.0f;
    int lo = 0, hi = 0;
    st.read_range(&lo, &hi);
    in.path_densities(th, x, key, lo, hi);
    in.chain_densities(th, x, key, self, lo, hi);  // (nothing changes where the manifold does not run)
    return mis::weight(th.densities.data(), st, lo, hi);
  }
  // The same weight with every density recomputed from the path's vertices.
  static float general_weight(const Integrator& in, Integrator::Thread& th, int s, int t) {
    return recomputed_weight(in, th, WholePath(gather(in, th, s, t)), s, 0, in.path_key(th, s, t, nullptr), ConnectorKind::kNone);
  }
  // For the path of plain connection (s, t): the weights that the routine gives it, with every
  // density recomputed, as each strategy that could sample it, the plain joins (s2, DD, ·) whose
  // letters are D and the manifold's chains, each computed as its own strategy. *chains: how many
  // manifold chains could build it. Must sum to 1.
  static double whole_path_weight_sum(const Integrator& in, Integrator::Thread& th, int s, int t, int* chains, int* at_sensor = nullptr) {
    const WholePath path(gather(in, th, s, t));
    const PathKey key = in.path_key(th, s, t, nullptr);
    const int k = static_cast<int>(path.x.size()) - 1, n = k + 1;
    double sum = 0.0;
    *chains = 0;
    for (int s2 = 0; s2 <= n; ++s2)
      if (runs_plain(in, s2, n - s2) && packed_is_d(key, s2) && packed_is_d(key, s2 + 1))
        sum += recomputed_weight(in, th, path, s2, 0, key, ConnectorKind::kNone);
    for (int i = 1; i <= k - 1; ++i) {
      int m = 0;
      while (i + m <= k - 1 && !packed_is_d(key, i + m + 1)) ++m;
      if (m > 0 && in.manifold_at(path.at(i, m), key, i, m)) {
        ++*chains;
        if (at_sensor && i + m == k) ++*at_sensor;  // the chain ends at the camera: the connector at t = 1
        sum += recomputed_weight(in, th, path, i, m, key, ConnectorKind::kManifold);
      }
    }
    return sum;
  }
  // Next-event estimation (1, t) from eye vertex z(t-1), as connect() joins it: a light picked and
  // a point on it drawn from `rng` into *y0, the join's density into *join. False when there is
  // no DD join (no light, a Dirac light, z(t-1) not a finite surface).
  static bool nee_join(const Integrator& in, const Thread& th, int t, Sampler& rng, Vertex* y0, JoinDensity* join) {
    const Vertex& pt = th.eye[static_cast<std::size_t>(t - 1)];
    if (pt.kind != Kind::kSurface || !pt.finite || in.scene().lights.empty()) return false;
    const std::size_t li = in.scene().pick_light(rng);
    const RenderLight& l = in.scene().lights[li];
    if (light_pair(in, static_cast<int>(li))[1] != 'D') return false;
    vec3 err{0.0f};
    const std::optional<EndpointConnection> c = pathex::connect(l.params, in.scene().sample_point(l, rng, &err), pt.p);
    if (!c) return false;
    *y0 = Vertex{};
    y0->kind = Kind::kLight;
    y0->light = static_cast<int>(li);
    y0->pos_letter = light_pair(in, static_cast<int>(li))[0];
    y0->letter = 'D';
    y0->p = c->position;
    y0->n = c->normal;
    y0->ns = y0->n;
    y0->err = err;
    y0->pdf_fwd = light_pick(in) * l.pdf_pos;
    *join = JoinDensity{};
    bsdf::eval(*in.scene().material_of_shape[static_cast<std::size_t>(pt.shape)], pt.wo, c->wi, pt.ns, pt.n, &join->at_pt);
    join->w = -c->wi;
    join->d2 = c->distance * c->distance;
    return true;
  }
  // The weight of connection (s, t) of the current subpaths (a fresh light point `y0` for s = 1)
  // with the join's density `join` (null: recomputed), as the estimator computes it.
  static float weight_of(const Integrator& in, Thread& th, int s, int t, const Vertex* y0, const JoinDensity* join) {
    return in.mis_weight(th, plain_path(th, s, t, y0), in.path_key(th, s, t, y0), ConnectorKind::kNone, join);
  }
  // The same weight by pt-nee's fast path (trace/accel/nee_mis.h), as the estimator takes it when
  // in.nee_pair() and t >= 2.
  static float fast_weight_of(const Integrator& in, const Thread& th, int s, int t, const Vertex* y0, const JoinDensity* join) {
    return in.nee_pair_weight(plain_path(th, s, t, y0), in.path_key(th, s, t, y0), join);
  }
  // The density with which next-event estimation draws the point `on_light` of an area light.
  static float light_point_density(const Integrator& in, const Vertex& on_light) {
    return light_pick(in) * in.scene().lights[static_cast<std::size_t>(in.scene().light_of_shape[static_cast<std::size_t>(on_light.shape)])].pdf_pos;
  }
  static const Material& material(const Integrator& in, const Vertex& v) { return *in.scene().material_of_shape[static_cast<std::size_t>(v.shape)]; }
  // Whether (s, t) joins two vertices that can be joined (s = 0: an eye vertex on an area light;
  // t = 0: a light vertex on the lens; otherwise two surfaces with finite parts).
  static bool joinable(const Integrator& in, const Integrator::Thread& th, int s, int t) {
    const Vertex* qs = s > 0 ? &th.light[static_cast<std::size_t>(s - 1)] : nullptr;
    const Vertex* pt = t > 0 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
    if (s == 0) return pt->kind == Kind::kSurface && in.scene().light_of_shape[static_cast<std::size_t>(pt->shape)] >= 0;
    if (t == 0) return qs->kind == Kind::kLens;
    return qs->kind == Kind::kSurface && pt->kind == Kind::kSurface &&
           bsdf::has_finite_component(*in.scene().material_of_shape[static_cast<std::size_t>(qs->shape)]) &&
           bsdf::has_finite_component(*in.scene().material_of_shape[static_cast<std::size_t>(pt->shape)]);
  }
  // For the full path x0 … xk formed by connection (s, t) of the current subpaths: the sum, over
  // every strategy (s', t') with s' + t' = s + t that the profile runs and whose join letters are
  // D (and the projection connectors where the letters are DSD), of the MIS weight it computes
  // when it samples the same vertices. Must be 1.
  static float weight_sum(const Integrator& in, Thread& th, int s, int t) {
    // The full path in light-to-eye order, from the two subpaths as connected by (s, t).
    const int k = s + t - 1;
    std::vector<Vertex> x;
    for (int i = 0; i < s; ++i) x.push_back(th.light[static_cast<std::size_t>(i)]);
    for (int j = t - 1; j >= 0; --j) x.push_back(th.eye[static_cast<std::size_t>(j)]);
    if (s == 0) {  // the eye vertex on the emitter becomes the light vertex
      x[0].kind = Kind::kLight;
      x[0].light = in.scene().light_of_shape[static_cast<std::size_t>(x[0].shape)];
    } else if (in.scene().lights[static_cast<std::size_t>(x[0].light)].is_area()) {
      x[0].shape = in.scene().lights[static_cast<std::size_t>(x[0].light)].shape;  // so an eye path may hit it
    }
    const std::string letters = label(in, th, s, t);
    const Thread saved_light_eye = th;  // NOLINT: the subpaths, restored below
    float sum = 0.0f;
    for (int s2 = 0; s2 <= k + 1; ++s2) {
      const int t2 = k + 1 - s2;
      const auto letters_at = [&](int i, int count) { return letters.substr(static_cast<std::size_t>(i) + 1, static_cast<std::size_t>(count)); };
      bool plain = runs_plain(in, s2, t2) && letters_at(s2, 2) == "DD";
      if (s2 == 0 && x[0].kind == Kind::kLight && !in.scene().lights[static_cast<std::size_t>(x[0].light)].is_area()) plain = false;
      const bool distant = s2 == 1 && in.distant_of(t2) >= 0 && letters_at(0, 3) == "DSD";
      const bool ortho = t2 == 1 && in.ortho_of(s2) >= 0 && letters_at(k, 3) == "DSD";
      if (!plain && !distant && !ortho) continue;
      const ConnectorKind kind = distant ? ConnectorKind::kDistantProjection : ortho ? ConnectorKind::kOrthoProjection : ConnectorKind::kNone;
      // Re-split: light subpath x0 … x(s2-1), eye subpath xk … x(s2), with forward densities as
      // each side would have sampled them.
      for (int i = 0; i < s2; ++i) th.light[static_cast<std::size_t>(i)] = x[static_cast<std::size_t>(i)];
      for (int j = 0; j < t2; ++j) th.eye[static_cast<std::size_t>(j)] = x[static_cast<std::size_t>(k - j)];
      if (s2 > 0) {
        th.light[0].kind = Kind::kLight;
        th.light[0].pdf_fwd = light_pick(in) * in.scene().lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
        // An x0 drawn towards x1 (an image infinite light's, a rectangle's sampled by solid angle):
        // the density next-event estimation from x1 draws it with (Integrator::drawn_towards; x1's
        // own density follows from in.pdf()).
        if (k >= 1) th.light[0].pdf_fwd = in.light_origin_density(x[0].light, x[0].p, x[0].n, x[1]);
      }
      if (s2 == 0) {
        th.eye[static_cast<std::size_t>(t2 - 1)].kind = Kind::kSurface;
      }
      // Each vertex's direction to its predecessor on its new subpath.
      for (int i = 0; i < s2; ++i) {
        Vertex& v = th.light[static_cast<std::size_t>(i)];
        if (i == 0) v.wo = vec3(0.0f), v.d2_wo = 0.0f;
        else tracer::link(v, th.light[static_cast<std::size_t>(i - 1)]);
      }
      for (int j = 0; j < t2; ++j) {
        Vertex& v = th.eye[static_cast<std::size_t>(j)];
        if (j == 0) v.wo = vec3(0.0f), v.d2_wo = 0.0f;
        else tracer::link(v, th.eye[static_cast<std::size_t>(j - 1)]);
      }
      // The letter of x_i in this path (c_{i+1}); a Dirac there keeps both densities through it symbolic.
      auto specular = [&](int i) { return i >= 1 && i <= k - 1 && letters[static_cast<std::size_t>(i) + 2] == 'S'; };
      for (int i = 1; i < s2; ++i)
        th.light[static_cast<std::size_t>(i)].pdf_fwd =
            specular(i - 1) ? 0.0f
                            : in.pdf(i > 1 ? &th.light[static_cast<std::size_t>(i - 2)] : nullptr,
                                  th.light[static_cast<std::size_t>(i - 1)], th.light[static_cast<std::size_t>(i)]);
      for (int i = 0; i + 2 < s2; ++i)
        th.light[static_cast<std::size_t>(i)].pdf_rev =
            specular(i + 1) ? 0.0f
                            : in.pdf(&th.light[static_cast<std::size_t>(i + 2)], th.light[static_cast<std::size_t>(i + 1)],
                                  th.light[static_cast<std::size_t>(i)]);
      if (t2 > 0) th.eye[0].pdf_fwd = in.scene().camera.pdf_pos;
      for (int j = 1; j < t2; ++j)
        th.eye[static_cast<std::size_t>(j)].pdf_fwd =
            specular(k - (j - 1)) ? 0.0f
                                  : in.pdf(j > 1 ? &th.eye[static_cast<std::size_t>(j - 2)] : nullptr,
                                        th.eye[static_cast<std::size_t>(j - 1)], th.eye[static_cast<std::size_t>(j)]);
      for (int j = 0; j + 2 < t2; ++j)
        th.eye[static_cast<std::size_t>(j)].pdf_rev =
            specular(k - (j + 1)) ? 0.0f
                                  : in.pdf(&th.eye[static_cast<std::size_t>(j + 2)], th.eye[static_cast<std::size_t>(j + 1)],
                                        th.eye[static_cast<std::size_t>(j)]);
      // Parallel beams (a distant light's, an orthographic sensor's) give their first vertex a
      // density per area, as light_subpath() and eye_subpath() set it.
      if (s2 >= 2 && th.light[0].pdf_fwd > 0.0f && light_pair(in, th.light[0].light)[1] == 'S')
        th.light[1].pdf_fwd = parallel_jacobian(th.light[1], th.light[0], glm::normalize(th.light[1].p - th.light[0].p));
      if (t2 >= 2 && in.scene().camera.pdf_pos > 0.0f && sensor_direction_letter(in) == 'S')
        th.eye[1].pdf_fwd = parallel_jacobian(th.eye[1], th.eye[0], glm::normalize(th.eye[1].p - th.eye[0].p));
      in.set_masks(th, s2, t2);
      sum += in.mis_weight(th, plain_path(th, s2, t2), pack(letters), kind, nullptr);
    }
    th.light = saved_light_eye.light;
    th.eye = saved_light_eye.eye;
    in.set_masks(th, th.ns, th.nt);
    return sum;
  }
};

namespace {

struct MisCheck {
  std::string path;
  int s = 0, t = 0;
  double weight_sum = 0.0;
  double weight = 0.0;          // as the renderer computes it
  double weight_general = 0.0;  // with every density recomputed from the path
  std::string recorded;         // the label as the renderer packs and records it: must equal `path`
};

// Traces `samples` pairs of subpaths and checks every full path that a plain join (s, t) with
// s != 1 and t != 1 of the profile forms from their vertices.
std::vector<MisCheck> check_mis_weights(const Scene& scene, const Profile& profile, std::uint64_t seed, int samples,
                                        LightSampling light_sampling = LightSampling::kArea) {
  const StrategySet strategies = runnable_strategies(profile).expect("a profile the tracer runs");
  RenderScene rs = make_render_scene(scene).expect("a scene the tracer renders");
  if (light_sampling != LightSampling::kArea) sample_lights_by_solid_angle(rs, scene, light_sampling == LightSampling::kSolidAngle);
  RenderOptions o;
  o.seed = seed;
  o.max_bounces = std::min(8, profile.max_bounces.value_or(8));
  HistogramLayout layout;
  ClassImages images(1, 1, nullptr, {});
  const Integrator integrator(rs, strategies, o);
  Integrator::Thread th{Histogram(layout, nullptr), {ClassImages::PixelSum(images)}, {}, {}, 0, {}, {}, {}};
  th.images = &images;
  th.connectors.resize(strategies.strategies.size());
  const StrategyTable table(strategies.strategies);
  using A = IntegratorTestAccess;
  std::vector<MisCheck> out;
  for (int i = 0; i < samples; ++i) {
    const int px = i % rs.camera.width, py = (i / rs.camera.width) % rs.camera.height;
    Sampler rng(seed, static_cast<std::uint64_t>(i), 0);
    int ns = 0;
    const int nt = A::trace_subpaths(integrator, th, rng, px, py, &ns);
    for (int t = 0; t <= nt; ++t)
      for (int s = 0; s <= ns; ++s) {
        if (s == 1 || t == 1 || s + t < 2 || s + t - 2 > *o.max_bounces) continue;
        if (table.plain(s, t) < 0 || !A::joinable(integrator, th, s, t)) continue;
        const float sum = A::weight_sum(integrator, th, s, t);
        const float weight = A::own_weight(integrator, th, s, t);
        const float weight_general = A::general_weight(integrator, th, s, t);
        out.push_back({A::label(integrator, th, s, t), s, t, sum, weight, weight_general,
                       A::packed_label(integrator, th, s, t)});
      }
  }
  return out;
}

TEST(Mis, WeightsOfEveryStrategySumToOne) {
  const std::string dir = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes";
  std::size_t checked = 0;
  std::map<int, int> by_length;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    Result<Scene> scene = load_scene_file(entry.path().string());
    ASSERT_TRUE(scene.ok()) << scene.error().render();
    for (const char* renderer : {"bdpt", "pt-nee", "lt", "pbrt-v4-lightpath", "mitsuba3-ptracer", "pt-nee+distant",
                                 "pbrt-v4-path", "pbrt-v4-bdpt", "mitsuba3-path", "bdpt+ortho"}) {
      Result<Profile> profile = resolve_profile(renderer, Limits{});
      ASSERT_TRUE(profile.ok());
      for (const MisCheck& c : check_mis_weights(*scene, *profile, 11, 300)) {
        ++checked;
        ++by_length[static_cast<int>(c.path.size())];
        const auto where = [&] {
          return entry.path().filename().string() + " " + renderer + " " + c.path + " (s=" + std::to_string(c.s) +
                 ", t=" + std::to_string(c.t) + ")";
        };
        EXPECT_NEAR(c.weight_sum, 1.0, 1e-4) << where();
        EXPECT_EQ(c.recorded, c.path) << "the packed label differs: " << where();
        // The subpaths' stored densities give the weight that the path's recomputed ones give.
        EXPECT_NEAR(c.weight, c.weight_general, 1e-4 * std::max(1.0, c.weight_general)) << where();
      }
    }
  }
  EXPECT_GT(checked, 2000u);
  EXPECT_GE(by_length.size(), 5u);  // paths of many lengths
}

// Issue 39: where next-event estimation draws a rectangular or spherical lamp's points by the solid
// angle it subtends, x0's light density is that of next-event estimation from x1 and x1's the rest of the
// emission's joint density (Integrator::drawn_towards): the weights of every strategy still sum to 1
// on every path, and the subpaths' stored densities give the path's recomputed ones.
TEST(Mis, WeightsOfEveryStrategySumToOneWithSolidAngleLightSampling) {
  std::size_t checked = 0;
  for (const char* file : {"samples/scenes/cornell.json", "bench/scenes/tungsten-cornell-box.json", "samples/scenes/materials.json",
                           "samples/scenes/lamp-glass.json"}) {
    const Scene scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/" + file).expect("a scene");
    for (const char* renderer : {"bdpt", "pt-nee", "lt", "pbrt-v4-bdpt", "mitsuba3-ptracer"}) {
      const Profile profile = resolve_profile(renderer, Limits{}).expect("a built-in profile");
      for (const MisCheck& c : check_mis_weights(scene, profile, 13, 300, LightSampling::kSolidAngle)) {
        ++checked;
        const auto where = [&] { return std::string(file) + " " + renderer + " " + c.path + " (s=" + std::to_string(c.s) + ", t=" + std::to_string(c.t) + ")"; };
        EXPECT_NEAR(c.weight_sum, 1.0, 1e-4) << where();
        EXPECT_NEAR(c.weight, c.weight_general, 1e-4 * std::max(1.0, c.weight_general)) << where();
      }
    }
  }
  EXPECT_GT(checked, 500u);
}

// Where a profile's plain joins are the emitter hit and next-event estimation alone (pt-nee, pt,
// and pbrt-v4-path and mitsuba3-path where their distant connector cannot run), a path is weighed
// against one other strategy at most, and the two differ in one density: the point on the light,
// drawn from the light (its pick times its point's area density) by next-event estimation, or by
// the BSDF at the eye vertex before it (solid angle, to area at the light point) by the emitter
// hit. The one MIS routine must give the two-strategy power heuristic of those two numbers,
// computed here independently of it, on random paths of every sample scene. Fixed seed.
TEST(Mis, PathTracerWeightsAreTheTwoStrategyPowerHeuristic) {
  const std::string dir = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes";
  using A = IntegratorTestAccess;
  const auto heuristic = [](double own, double other) {  // a Dirac's density, stored as 0, counts as 1
    const double r = remap_density(static_cast<float>(other)) / remap_density(static_cast<float>(own));
    return 1.0 / (1.0 + r * r);
  };
  int scenes = 0, nee_weighed = 0, hits_weighed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    const Scene scene = load_scene_file(entry.path().string()).expect("a sample scene");
    ++scenes;
    for (const char* renderer : {"pt-nee", "pt", "pbrt-v4-path", "mitsuba3-path"}) {
      const Profile profile = resolve_profile(renderer, Limits{}).expect("a built-in profile");
      const StrategySet strategies = runnable_strategies(profile).expect("a profile the tracer runs");
      const RenderScene rs = make_render_scene(scene).expect("a scene the tracer renders");
      // Only where no connector can run (a distant-projection needs a distant light).
      bool connector = false;
      for (const Strategy& st : strategies.strategies)
        for (const RenderLight& l : rs.lights)
          connector = connector || (st.connector != ConnectorKind::kNone && std::holds_alternative<DistantLightParams>(l.params));
      if (connector) continue;
      RenderOptions o;
      o.seed = 17;
      o.max_bounces = std::min(8, profile.max_bounces.value_or(8));
      HistogramLayout layout;
      ClassImages images(1, 1, nullptr, {});
      const Integrator in(rs, strategies, o);
      // pt-nee's and pt's joins the estimator weighs by the fast path, which must equal the general
      // routine bit for bit (below). (pbrt-v4-path and mitsuba3-path run a distant connector: never.)
      const bool fast = in.nee_pair();
      EXPECT_EQ(fast, std::string(renderer) == "pt-nee" || std::string(renderer) == "pt") << renderer;
      const auto same_bits = [&](float a, float b) { return !fast || std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); };
      Integrator::Thread th{Histogram(layout, nullptr), {ClassImages::PixelSum(images)}, {}, {}, 0, {}, {}, {}};
      th.images = &images;
      th.connectors.resize(strategies.strategies.size());
      const StrategyTable table(strategies.strategies);
      for (int i = 0; i < 400; ++i) {
        Sampler rng(17, static_cast<std::uint64_t>(i), 0);
        int ns = 0;
        const int nt = A::trace_subpaths(in, th, rng, i % rs.camera.width, (i / rs.camera.width) % rs.camera.height, &ns);
        for (int t = 2; t <= nt && t - 2 <= *o.max_bounces; ++t) {
          const auto where = [&](int s) {
            return entry.path().filename().string() + " " + renderer + " " + A::label(in, th, s, t) + " (s=" + std::to_string(s) +
                   ", t=" + std::to_string(t) + ", sample " + std::to_string(i) + ")";
          };
          const Vertex& pt = th.eye[static_cast<std::size_t>(t - 1)];
          if (table.plain(0, t) >= 0 && A::joinable(in, th, 0, t)) {
            // The emitter hit against next-event estimation (1, t - 1) from z(t-2), where it runs
            // and z(t-2) is D.
            const bool other = t >= 3 && table.plain(1, t - 1) >= 0 && th.eye[static_cast<std::size_t>(t - 2)].letter == 'D';
            const double expected = other ? heuristic(pt.pdf_fwd, A::light_point_density(in, pt)) : 1.0;
            const float w = A::weight_of(in, th, 0, t, nullptr, nullptr);
            EXPECT_NEAR(w, expected, 1e-6) << where(0);
            EXPECT_PRED2(same_bits, A::fast_weight_of(in, th, 0, t, nullptr, nullptr), w) << where(0) << ", the fast path";
            if (w < 1.0f) ++hits_weighed;
          }
          Vertex y0;
          JoinDensity join;
          Sampler light_rng(17, static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(t));
          if (t + 1 - 2 <= *o.max_bounces && table.plain(1, t) >= 0 && A::nee_join(in, th, t, light_rng, &y0, &join)) {
            // Next-event estimation against the emitter hit (0, t + 1), where it runs and the light's
            // position letter is D: the BSDF's density towards y0, to area at y0.
            const vec3 e = y0.p - pt.p;
            const float d2 = glm::dot(e, e);
            const vec3 w_to = e / std::sqrt(d2);
            const float hit = bsdf::pdf(A::material(in, pt), pt.wo, w_to, pt.ns, pt.n) * abs_cos(y0, w_to) / d2;
            const bool other = table.plain(0, t + 1) >= 0 && y0.pos_letter == 'D';
            const double expected = other ? heuristic(y0.pdf_fwd, hit) : 1.0;
            const float w = A::weight_of(in, th, 1, t, &y0, &join);
            EXPECT_NEAR(w, expected, 1e-5 * expected) << where(1);
            EXPECT_NEAR(w, A::weight_of(in, th, 1, t, &y0, nullptr), 1e-6) << where(1) << ", the join's density recomputed";
            EXPECT_PRED2(same_bits, A::fast_weight_of(in, th, 1, t, &y0, &join), w) << where(1) << ", the fast path";
            EXPECT_PRED2(same_bits, A::fast_weight_of(in, th, 1, t, &y0, nullptr), A::weight_of(in, th, 1, t, &y0, nullptr))
                << where(1) << ", the fast path, the join's density recomputed";
            if (w < 1.0f) ++nee_weighed;
          }
        }
      }
    }
  }
  EXPECT_GE(scenes, 10);
  // Paths that both strategies sample (a weight below 1), not only the trivial ones.
  EXPECT_GT(nee_weighed, 1000);
  EXPECT_GT(hits_weighed, 300);
}

// An integrator of `strategies` over `scene` and one thread's state, as the manifold MIS tests
// below drive them (by IntegratorTestAccess).
struct ManifoldRig {
  RenderScene rs;
  RenderOptions o;
  HistogramLayout layout;
  ClassImages images;
  Integrator in;
  Integrator::Thread th;
  ManifoldRig(const Scene& scene, const StrategySet& strategies, std::uint64_t seed, LightSampling light_sampling = LightSampling::kArea)
      : rs(render_scene(scene, light_sampling)),
        o(options(seed)),
        images(1, 1, nullptr, {}),
        in(rs, strategies, o),
        th{Histogram(layout, nullptr), {ClassImages::PixelSum(images)}, {}, {}, 0, {}, {}, {}} {
    th.images = &images;
    th.connectors.resize(strategies.strategies.size());
  }
  static RenderScene render_scene(const Scene& scene, LightSampling light_sampling) {
    RenderScene r = make_render_scene(scene).expect("a scene the tracer renders");
    if (light_sampling != LightSampling::kArea) sample_lights_by_solid_angle(r, scene, light_sampling == LightSampling::kSolidAngle);
    return r;
  }
  static RenderOptions options(std::uint64_t seed) {
    RenderOptions r;
    r.seed = seed;
    r.max_bounces = 8;
    return r;
  }
};

// Where bdpt's light tracing (and its other joins) and the manifold connector both sample a path,
// the whole-path weights of all of them sum to 1: random paths of the glass-sphere scenes formed by
// every plain join of bdpt+manifold's subpaths, those a manifold chain could build among them. The
// renderer's weight of each plain join (its subpaths' stored densities, changed across a chain the
// manifold could build: chain_densities()) must equal the whole path's. With the lamps sampled by
// area and (issue 39) by the cone they subtend, x0's density then next-event estimation's from x1.
// And with the connector run for a share of the samples (--manifold-rate 0.25, issue 40): that
// share is the factor of its density where light tracing could join the path (the camera sees the
// chain's eye end directly, or past a diffuse vertex), 1 where the camera sees it through glass.
// With the connector ending at the camera too (t = 1, issue 40's twelfth session: the lamp seen
// through the ball, the floor seen through it), at a pinhole and at a thin lens (lamp-glass.json
// with a lens, whose light paths may also hit the lens: the strategy t = 0): the eye walk's density
// of the chain's light end is the sensor's direction density times |dω_b/dA_a| across its axis.
TEST(Mis, ManifoldAndPlainJoinWeightsSumToOne) {
  const Profile profile = parse_profile(R"({"name": "bdpt+manifold", "strategies": [
      {"name": "bdpt", "s": "0..", "chain": "DD", "t": "0.."},
      {"name": "manifold", "s": "1..", "chain": "DS+D", "t": "1..", "connector": "manifold"}]})",
                                        "bdpt+manifold.json", Limits{})
                              .expect("a valid profile");
  const StrategySet strategies = runnable_strategies(profile).expect("a profile the tracer runs");
  const std::string lamp_glass = test::read_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/lamp-glass.json");
  std::string with_lens = lamp_glass;
  const std::string pinhole = R"("type": "pinhole")";
  ASSERT_NE(with_lens.find(pinhole), std::string::npos);
  with_lens.replace(with_lens.find(pinhole), pinhole.size(), R"("type": "lens", "aperture_radius": 0.05, "focus_distance": 3.5)");
  for (const double rate : {1.0, 0.25})
  for (const LightSampling light_sampling : {LightSampling::kArea, LightSampling::kSolidAngle})
  for (const char* name : {"point-glass.json", "lamp-glass.json", "lamp-glass.json with a thin lens"}) {
    if (rate < 1.0 && light_sampling != LightSampling::kArea) continue;
    const bool lens = std::string(name).find("lens") != std::string::npos;
    const Scene scene = lens ? load_scene_json(with_lens, std::string(PATHEX_SOURCE_DIR) + "/samples/scenes", "lamp-glass-lens").expect("the variant")
                             : load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/" + name).expect("the sample");
    ManifoldRig rig(scene, strategies, 5, light_sampling);
    rig.o.manifold.rate = rate;  // the integrator reads its options by reference
    const Integrator& integrator = rig.in;
    const RenderScene& rs = rig.rs;
    const RenderOptions& o = rig.o;
    Integrator::Thread& th = rig.th;
    using A = IntegratorTestAccess;
    int checked = 0, shared = 0, at_sensor = 0;
    for (int i = 0; i < 10000; ++i) {
      Sampler rng(5, static_cast<std::uint64_t>(i), 0);
      int ns = 0;
      const int nt = A::trace_subpaths(integrator, th, rng, i % rs.camera.width, (i / rs.camera.width) % rs.camera.height, &ns);
      for (int t = 0; t <= nt; ++t)
        for (int s = 0; s <= ns; ++s) {
          if (t == 1 || s + t < 2 || s + t - 2 > *o.max_bounces || !A::joinable(integrator, th, s, t)) continue;
          // (s = 1: the light subpath's y0 stands for next-event estimation's fresh point, whose
          // path the whole-path weights take alike; the join's own weight is checked below s = 1.)
          int chains = 0, sensor_chains = 0;
          const double sum = A::whole_path_weight_sum(integrator, th, s, t, &chains, &sensor_chains);
          ++checked;
          if (chains > 0) ++shared;
          if (sensor_chains > 0) ++at_sensor;
          const std::string where = std::string(name) + " " + to_string(light_sampling) + " rate " + std::to_string(rate) + " " + A::label(integrator, th, s, t) + " (s=" + std::to_string(s) +
                                    ", t=" + std::to_string(t) + ")";
          EXPECT_NEAR(sum, 1.0, 1e-4) << where;
          // The join's own densities read the cosines at its ends: where the join runs along a
          // surface (two points of one planar face) they are rounding, and the two sources differ.
          const std::vector<Vertex> x = A::gather(integrator, th, s, t);
          const vec3 w = s > 0 && t > 0 ? glm::normalize(x[static_cast<std::size_t>(s)].p - x[static_cast<std::size_t>(s - 1)].p) : vec3(0.0f);
          if (s == 1 || (s > 0 && t > 0 && std::min(abs_cos(x[static_cast<std::size_t>(s - 1)], w), abs_cos(x[static_cast<std::size_t>(s)], w)) < 1e-3f)) continue;
          const float general = A::general_weight(integrator, th, s, t);
          EXPECT_NEAR(A::own_weight(integrator, th, s, t), general, 1e-4 * std::max(1.0f, general)) << where;
        }
    }
    EXPECT_GT(checked, 1000) << name;
    EXPECT_GT(shared, 50) << name;  // paths that the manifold and the plain joins both sample
    EXPECT_GT(at_sensor, 50) << name;  // paths whose chain ends at the camera (the floor seen through the ball)
  }
}

// pt-nee+manifold (no light subpath) at --manifold-rate 0.25: the rate is the factor of the
// connector's density on every path of an area light (issue 40, twenty-second session), also where the
// camera sees the chain's eye end through the glass (the caustic seen through the ball, which the
// eye's hits of the lamp through the ball sample too). On eye paths that hit the lamp (s = 0), the
// whole-path weights of the emitter hit, next-event estimation and every chain sum to 1, the
// renderer's weight of the emitter hit equals the whole path's, and where the camera sees the chain's
// eye end through the ball the connector's factor is the rate (98 such paths, where it was 1 before the change).
TEST(Mis, PtNeeManifoldWeightsSumToOneWithTheRateThroughGlass) {
  const Profile profile = parse_profile(test::read_file(std::string(PATHEX_SOURCE_DIR) + "/samples/renderers/pt-nee+manifold.json"),
                                        "pt-nee+manifold.json", Limits{})
                              .expect("the sample profile");
  const StrategySet strategies = runnable_strategies(profile).expect("a profile the tracer runs");
  // The lamp ten times larger (radius 0.4), so that eye paths hit it through the ball often.
  std::string text = test::read_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/lamp-glass.json");
  const std::string small = R"("radius": 0.04)";
  ASSERT_NE(text.find(small), std::string::npos);
  text.replace(text.find(small), small.size(), R"("radius": 0.4)");
  const Scene scene = load_scene_json(text, std::string(PATHEX_SOURCE_DIR) + "/samples/scenes", "lamp-glass-large").expect("the variant");
  ManifoldRig rig(scene, strategies, 7);
  rig.o.manifold.rate = 0.25;
  using A = IntegratorTestAccess;
  int checked = 0, through = 0;
  for (int i = 0; i < 1000000; ++i) {
    Sampler rng(7, static_cast<std::uint64_t>(i), 0);
    int ns = 0;
    const int nt = A::trace_subpaths(rig.in, rig.th, rng, i % rig.rs.camera.width, (i / rig.rs.camera.width) % rig.rs.camera.height, &ns);
    for (int t = 2; t <= nt; ++t) {
      if (t - 2 > *rig.o.max_bounces || !A::joinable(rig.in, rig.th, 0, t)) continue;
      int chains = 0;
      const double sum = A::whole_path_weight_sum(rig.in, rig.th, 0, t, &chains);
      ++checked;
      // The camera sees the eye subpath's vertex z3 through the ball (z1, z2 S) and a chain lies beyond it.
      if (chains > 0 && t >= 4 && rig.th.eye[1].letter == 'S' && rig.th.eye[2].letter == 'S' && rig.th.eye[3].letter == 'D') {
        ++through;
        EXPECT_EQ(A::manifold_rate(rig.in, rig.th, 0, t, t - 4), 0.25);  // z3 is x_(k-3), k = t - 1
      }
      const std::string where = A::label(rig.in, rig.th, 0, t) + " (s=0, t=" + std::to_string(t) + ")";
      EXPECT_NEAR(sum, 1.0, 1e-4) << where;
      const float general = A::general_weight(rig.in, rig.th, 0, t);
      EXPECT_NEAR(A::own_weight(rig.in, rig.th, 0, t), general, 1e-4 * std::max(1.0f, general)) << where;
    }
  }
  EXPECT_GT(checked, 5000) << through;
  EXPECT_GT(through, 40) << checked;  // emitter hits seen through the ball with a chain (the ball again) before the lamp
}

// lamp-glass.json under the built-in bdpt+manifold, seed 3 (the rig keeps references to both).
struct LampGlassRig {
  Scene scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/lamp-glass.json").expect("the sample");
  StrategySet strategies = runnable_strategies(resolve_profile("bdpt+manifold", Limits{}).expect("a built-in profile")).expect("runs");
  ManifoldRig rig{scene, strategies, 3};
  // Sample i's subpaths at seed 3 (pixel i of the frame, row by row): the eye subpath's length; *ns the light's.
  int trace(int i, int* ns) {
    Sampler rng(3, static_cast<std::uint64_t>(i), 0);
    return IntegratorTestAccess::trace_subpaths(rig.in, rig.th, rng, i % rig.rs.camera.width, (i / rig.rs.camera.width) % rig.rs.camera.height, ns);
  }
};

// The renderer's weights of the three strategies that sample one path, against the power heuristic of
// their densities computed independently; and their sum, 1.
// Counted: the paths checked, and how often each strategy took the lead (a weight above ½).
struct PowerHeuristicChecks {
  int checked = 0;
  std::array<int, 3> leads{};
  void expect(const std::array<float, 3>& weights, const std::array<double, 3>& densities, const std::string& where) {
    const double sum2 = densities[0] * densities[0] + densities[1] * densities[1] + densities[2] * densities[2];
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(weights[i], densities[i] * densities[i] / sum2, 2e-3) << where << " (strategy " << i << ")";
      leads[i] += weights[i] > 0.5f ? 1 : 0;
    }
    EXPECT_NEAR(weights[0] + weights[1] + weights[2], 1.0, 1e-4) << where;
    ++checked;
  }
};

// Where light tracing, the emitter hit and the manifold connector sample one path through the
// glass ball of lamp-glass.json (LDDSSDDSE: lamp x0, the ball's two refractions x1 x2, the floor
// x3, the camera x4), their densities are over the areas of x0, x3 and x4, the chain a function of
// its ends: the manifold draws x0 from the lamp and x3 from the camera; light tracing draws x3
// through the chain with the lamp's cosine density times the two refractions' Fresnel choices
// times |dω_0/dA_3|, the emitter hit draws x0 with the floor's cosine density times the choices
// times |dω_3/dA_0|. The two generalized geometry terms are computed here by solving the chain
// from each end (solve_chain), independently of the renderer's one solve and reciprocity; the
// weights of all three strategies, as the renderer computes them (light tracing's from its
// subpaths' stored densities too), must be the power heuristic of these densities. Fixed seed.
TEST(Mis, ManifoldWeightsUseTheChainsGeneralizedGeometryTerm) {
  LampGlassRig lamp_glass;
  ManifoldRig& rig = lamp_glass.rig;
  const Integrator& in = rig.in;
  const RenderScene& rs = rig.rs;
  Integrator::Thread& th = rig.th;
  using A = IntegratorTestAccess;
  const double pi = std::numbers::pi;
  PowerHeuristicChecks checks;  // light tracing, the manifold, the emitter hit
  for (int i = 0; i < 20000; ++i) {
    int ns = 0;
    lamp_glass.trace(i, &ns);
    if (ns < 4 || !th.light[3].finite || A::label(in, th, 4, 1) != "LDDSSDDSE") continue;
    const std::vector<Vertex> x = A::gather(in, th, 4, 1);
    const glm::dvec3 p0(x[0].p), p3(x[3].p), n0(x[0].n), n3(x[3].n);
    const vec3 w4 = glm::normalize(x[3].p - x[4].p);
    const double e3 = in.sensor_pdf_dir(x[4], w4) * abs_cos(x[3], w4) / glm::dot(x[3].p - x[4].p, x[3].p - x[4].p);
    if (!(e3 > 0.0)) continue;  // x3 outside the frame
    // The chain, light side first, and the same chain from the floor's end.
    std::vector<ChainVertex> from_light, from_floor;
    double choices = 1.0;
    for (int v = 1; v <= 2; ++v) {
      const float before = glm::dot(x[v - 1].p - x[v].p, x[v].n), after = glm::dot(x[v + 1].p - x[v].p, x[v].n);
      ASSERT_LT(before * after, 0.0f) << "two refractions";  // (x3 on the floor: not an internal reflection)
      const double eta_light = before > 0.0f ? 1.0 : 1.5, eta_eye = after > 0.0f ? 1.0 : 1.5;
      from_light.push_back({&rs.geometry->shape_geometry(x[v].shape), x[v].shape, 0, 1.5, eta_light, eta_eye, false, glm::dvec3(x[v].p), 0});
      choices *= 1.0 - fresnel_dielectric(glm::dot(glm::normalize(x[v - 1].p - x[v].p), x[v].n), 1.5f);
    }
    for (auto it = from_light.rbegin(); it != from_light.rend(); ++it) {
      from_floor.push_back(*it);
      std::swap(from_floor.back().eta_light, from_floor.back().eta_eye);
    }
    const ManifoldWalk to_floor = solve_chain(from_light, p0, p3, n3, 1.0, ManifoldOptions{});
    const ManifoldWalk to_lamp = solve_chain(from_floor, p3, p0, n0, 1.0, ManifoldOptions{});
    if (to_floor.failure != ManifoldFailure::kNone || to_lamp.failure != ManifoldFailure::kNone) continue;
    const double lamp = A::light_pick(in) * rs.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;  // x0 drawn on the lamp
    const double lamp_dir = std::fabs(glm::dot(glm::normalize(x[1].p - x[0].p), x[0].n)) / pi;      // its cosine emission
    const double floor_dir = std::fabs(glm::dot(glm::normalize(x[2].p - x[3].p), x[3].n)) / pi;     // the floor's cosine density
    const double manifold = lamp * e3;
    const double light_tracing = lamp * lamp_dir * choices * to_floor.dw_db;
    const double emitter_hit = floor_dir * choices * to_lamp.dw_db * e3;
    const PathKey key = in.path_key(th, 4, 1, nullptr);
    const float w_lt = A::own_weight(in, th, 4, 1);
    const A::WholePath whole(x);
    const float w_lt_whole = A::recomputed_weight(in, th, whole, 4, 0, key, ConnectorKind::kNone);
    const float w_manifold = A::recomputed_weight(in, th, whole, 1, 2, key, ConnectorKind::kManifold);
    const float w_hit = A::recomputed_weight(in, th, whole, 0, 0, key, ConnectorKind::kNone);
    const std::string where = "sample " + std::to_string(i) + ", |dω0/dA3| " + std::to_string(to_floor.dw_db);
    EXPECT_NEAR(w_lt_whole, w_lt, 1e-4) << where;
    checks.expect({w_lt, w_manifold, w_hit}, {light_tracing, manifold, emitter_hit}, where);
  }
  EXPECT_GT(checks.checked, 30);
  // Both light tracing and the manifold take the lead somewhere on the caustic.
  EXPECT_GT(checks.leads[0], 3);
  EXPECT_GT(checks.leads[1], 3);
}

// The connector ending at the camera (t = 1, issue 40's twelfth session) on paths of lamp-glass.json
// where the floor is seen through the ball (LDDDSSDSE: lamp x0, floor x1, the ball's two
// refractions x2 x3, the pinhole x4), which next-event estimation (1, DD, 4), the emitter hit
// (0, DD, 5) and the manifold (2, DSSD, 1) from the light subpath's floor vertex all sample: the
// eye walk draws x1 through the chain with the pinhole's direction density times the refractions'
// choices times |dω_4/dA_1|, computed here by solving the chain from the pinhole's end (the
// renderer solves it from x1 and takes the camera's side by reciprocity, across the camera's axis);
// the manifold draws x1 from the lamp. The three weights must be the power heuristic of these
// densities. Fixed seed.
TEST(Mis, ManifoldAtTheCameraWeighsTheEyeWalksChainDensity) {
  LampGlassRig lamp_glass;
  ManifoldRig& rig = lamp_glass.rig;
  rig.o.manifold.rate = 1.0;
  const Integrator& in = rig.in;
  const RenderScene& rs = rig.rs;
  Integrator::Thread& th = rig.th;
  using A = IntegratorTestAccess;
  const double pi = std::numbers::pi;
  PowerHeuristicChecks checks;  // next-event estimation, the emitter hit, the manifold
  for (int i = 0; i < 20000; ++i) {
    int ns = 0;
    const int nt = lamp_glass.trace(i, &ns);
    if (ns < 1 || nt < 4 || A::label(in, th, 1, 4) != "LDDDSSDSE") continue;
    const std::vector<Vertex> x = A::gather(in, th, 1, 4);
    const glm::dvec3 p1(x[1].p), p4(x[4].p), n1(x[1].n);
    std::vector<ChainVertex> from_camera;  // x3, x2: the chain with its ends swapped
    double choices = 1.0;
    bool refractions = true;  // (not a reflection off the ball and one inside it)
    for (int v = 3; v >= 2; --v) {
      const float towards_floor = glm::dot(x[v - 1].p - x[v].p, x[v].n), towards_camera = glm::dot(x[v + 1].p - x[v].p, x[v].n);
      refractions = refractions && towards_floor * towards_camera < 0.0f;
      from_camera.push_back({&rs.geometry->shape_geometry(x[v].shape), x[v].shape, 0, 1.5, towards_camera > 0.0f ? 1.0 : 1.5,
                             towards_floor > 0.0f ? 1.0 : 1.5, false, glm::dvec3(x[v].p), 0});
      choices *= 1.0 - fresnel_dielectric(glm::dot(glm::normalize(x[v + 1].p - x[v].p), x[v].n), 1.5f);
    }
    if (!refractions) continue;
    const ManifoldWalk to_floor = solve_chain(from_camera, p4, p1, n1, 1.0, ManifoldOptions{});  // |dω_4 / dA_1|
    if (to_floor.failure != ManifoldFailure::kNone) continue;
    const double camera_dir = in.sensor_pdf_dir(x[4], glm::normalize(x[3].p - x[4].p));
    const vec3 e01 = x[1].p - x[0].p;
    if (!(glm::dot(e01, x[0].n) > 0.0f)) continue;  // the light subpath's lamp point faces away from x1: no path
    const double d2 = glm::dot(e01, e01);
    const double lamp = A::light_pick(in) * rs.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
    const double cos0 = std::fabs(glm::dot(glm::normalize(e01), x[0].n)), cos1 = std::fabs(glm::dot(glm::normalize(e01), x[1].n));
    const double eye_1 = camera_dir * choices * to_floor.dw_db;  // the eye walk's density of x1
    const double nee = lamp * eye_1;
    const double emitter_hit = (cos1 / pi) * cos0 / d2 * eye_1;   // the floor's cosine density towards x0
    const double manifold = lamp * (cos0 / pi) * cos1 / d2;       // the lamp's cosine emission towards x1
    const PathKey key = in.path_key(th, 1, 4, nullptr);
    const A::WholePath whole(x);
    const float w_nee = A::recomputed_weight(in, th, whole, 1, 0, key, ConnectorKind::kNone);
    const float w_hit = A::recomputed_weight(in, th, whole, 0, 0, key, ConnectorKind::kNone);
    const float w_manifold = A::recomputed_weight(in, th, whole, 2, 2, key, ConnectorKind::kManifold);
    const std::string where = "sample " + std::to_string(i) + ", |dω4/dA1| " + std::to_string(to_floor.dw_db);
    checks.expect({w_nee, w_hit, w_manifold}, {nee, emitter_hit, manifold}, where);
  }
  EXPECT_GT(checks.checked, 30);
  EXPECT_GT(checks.leads[0], 3);  // next-event estimation and the manifold each lead somewhere
  EXPECT_GT(checks.leads[2], 3);
}

}  // namespace
}  // namespace pathex::tracer
