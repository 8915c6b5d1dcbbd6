// The renderer: bidirectional path sampling driven by a renderer profile, with every sampled path
// labelled by its exact full-path string (DESIGN §7).
//
// The profile's plain-join strategies (s, DD, t) are run as BDPT connections between a light
// subpath of s vertices and an eye subpath of t vertices; s = 0 is an eye path hitting an area
// light, s = 1 next-event estimation, t = 1 a light-tracing splat to the camera, t = 0 a light
// path hitting a finite lens. The projection connectors run too: distant-projection (0, DSD, t)
// joins an eye subpath of t vertices to the aperture point of a distant light found by
// projecting its last vertex against the light's direction, and ortho-projection (s, DSD, 0)
// joins a light subpath of s vertices to the film point of an orthographic sensor found by
// projecting its last vertex along the view direction. Contributions are combined with the
// power heuristic over the strategies the profile runs; for a given string exactly the
// strategies whose language contains it have nonzero density, so deltas are handled by letters,
// never by huge numbers. The mirror connector (s, DSD, t), s, t >= 1, joins y(s-1) and z(t-1)
// across a planar mirror by the image method (trace/joins/mirror.h); in its profiles a path it
// could also sample is weighed over whole-path densities. The manifold connector (s, DS+D, t),
// s >= 1, t >= 2, joins y(s-1) and z(t-1) across a chain of smooth glass by a Newton walk
// (trace/joins/manifold.h); in its profiles every path is weighed over whole-path densities. Every join, plain or connector, returns one JoinResult (trace/joins/join.h)
// that the estimator weighs and queues in one place; the strategy running each (s, chain, t) comes
// from one StrategyTable (trace/strategy_table.h) built from the profile. Shadow rays are queued per thread and traced sixteen at a time as one Embree packet
// (OcclusionBatch); a contribution is recorded once all its segments (one for a shadow ray, two across
// a mirror) are found clear.
//
// Determinism: every random number is a function of (seed, pixel, pass, dimension), and all
// sums are exact (stats/histogram.h), so results are bit-identical whatever the thread count.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "classify/classifier.h"
#include "stats/histogram.h"
#include "film/image.h"
#include "core/error.h"
#include "schedule/pass_deal.h"
#include "schedule/pass_set.h"
#include "reach/profile.h"
#include "scene/scene.h"
#include "trace/accel/split_counts.h"
#include "trace/joins/manifold.h"
#include "trace/rng.h"

namespace pathex {

struct RenderPlan;  // trace/plan.h

// Passes a pixel takes back to back (the last chunk may be shorter). Progress is reported, and a
// cancelled render stops, after whole chunks, so every finished pass covers the whole image.
inline constexpr std::uint64_t kPassesPerChunk = 4;

// How next-event estimation draws the points of spherical and rectangular lights (`pathex trace
// --light-sampling`): every light by area; spheres by the cone they subtend at the point they join
// (pbrt-v4's Sphere::Sample), the rest by area; or spheres so and rectangles by the solid angle
// they subtend (Ureña et al. 2013, trace/spherical_rect.h). Other lights (meshes, disks,
// parallelograms) are drawn by area always.
enum class LightSampling : std::uint8_t { kArea, kSphereCone, kSolidAngle };
constexpr const char* to_string(LightSampling s) {
  return s == LightSampling::kSolidAngle ? "solid-angle" : s == LightSampling::kSphereCone ? "sphere-cone" : "area";
}
// The setting a name gives (a shard's), kArea for any other.
inline LightSampling light_sampling_named(const std::string& name) {
  for (LightSampling s : {LightSampling::kSphereCone, LightSampling::kSolidAngle})
    if (name == to_string(s)) return s;
  return LightSampling::kArea;
}

// RenderOptions::rr_threshold's and rr_join_threshold's `auto`: chosen per scene from a pilot
// (trace/accel/join_plan.h) where the profile joins eye vertices with a light subpath (bdpt);
// elsewhere the eye's is kDefaultEyeThreshold and the joins' none.
inline constexpr float kEyeThresholdAuto = -1.0f;
inline constexpr float kJoinThresholdAuto = -1.0f;
inline constexpr float kDefaultEyeThreshold = 0.3f;

struct RenderOptions {
  std::uint64_t spp = 16;              // samples (passes) per pixel
  // The passes to take (a shard's share, what a resumed render still lacks); unset: [0, spp).
  // The outputs of renders of disjoint pass sets add up exactly to the render of their union.
  std::optional<PassSet> passes;
  // Where the chunks come from instead (then `passes` is ignored): a deal shared with other
  // processes (schedule/pass_deal.h), of which this render takes the chunks it is handed.
  PassDealer* dealer = nullptr;
  std::uint64_t seed = 1;
  int threads = 0;                     // 0: all cores
  std::optional<int> max_bounces;      // interior vertices, k - 1; unset: the profile's bound, else 16
  // Russian roulette (pathex trace --rr-depth, --rr-threshold, --rr-light-threshold): from the
  // rr_depth-th vertex of a subpath on (its camera or light point is the first), a walk whose
  // throughput relative to its start has fallen below its threshold survives with probability
  // throughput / threshold; 0 turns roulette off. Eye subpaths use rr_threshold, light subpaths
  // rr_light_threshold: a light vertex is joined to every eye vertex (bdpt), so it costs more and
  // its walk is cut sooner. Defaults chosen by efficiency on several scenes (issue 39,
  // docs/efficiency.md). The eye's default, kEyeThresholdAuto (`auto`): under bdpt's joins the
  // threshold of kEyeThresholds (0.3, 0.5, 1) a pilot's model finds most efficient for the scene,
  // with the join roulette's below (trace/accel/join_plan.h); elsewhere kDefaultEyeThreshold (0.3).
  // render() resolves it before the render.
  int rr_depth = 3;
  float rr_threshold = kEyeThresholdAuto;
  float rr_light_threshold = 1.0f;
  // --rr-join-threshold: an eye vertex whose throughput r (relative to its subpath's start, as the
  // roulette above measures it) is below this makes its joins with the light subpath's vertices
  // (s >= 2: bdpt's shadow-ray joins) with probability r / threshold, each weighted by its
  // inverse; 0: always. The eye walk goes on for its own joins (next-event estimation, emitter
  // hits). Where the light subpath's joins with the eye's first vertices already reach the deep
  // paths these would, they cost more than they lower the error (at 1: bdpt on cornell.json
  // 1.13-1.15x, Tungsten's box 1.04x); where the deep eye vertices' joins carry the light (a closed
  // sphere round a point light) the error grows more than the CPU falls (0.82x). So the default,
  // kJoinThresholdAuto (`auto`), chooses it per scene from a pilot (trace/accel/join_plan.h; issue
  // 39, docs/efficiency.md); render() resolves it before the render.
  float rr_join_threshold = kJoinThresholdAuto;
  // --splits: runs of each sample after its camera ray and first hit, each weighted 1 / splits
  // (trace/accel/first_vertex_split.h; issue 39, docs/efficiency.md). 0 (`--splits auto`): counts
  // per pixel (camera rays, runs after each), from a pilot (trace/accel/split_plan.h), or from
  // split_map when one is given (tests). Unset: the profile's, resolved_splits() (below).
  std::optional<int> splits;
  std::shared_ptr<const tracer::SplitMap> split_map;
  SamplerKind sampler = SamplerKind::kSobol;  // --sampler
  // --light-sampling; the default chosen by efficiency on several scenes (issue 39, docs/tracer.md).
  LightSampling light_sampling = LightSampling::kSphereCone;
  // The standard error's batches (`pathex trace --batches`, --replicates; stats/histogram.h,
  // "Batches"): B batches, R replicates of each pixel (R divides B), B / R pixel groups. Under
  // `sobol` each replicate is an independently scrambled sequence of spp / R points: fewer
  // replicates keep more of the quasi-Monte Carlo gain, more groups make the standard error itself
  // more precise (its relative error is about 1/sqrt(2 · dof), dof = B − B / R). Measured: bench/README.md.
  // replicates 0: default_replicates(batches, the sensor's pixels) — 2, or more on a sensor of fewer
  // pixels than B / 2 (a spot meter: one group of B), resolved by render().
  int batches = kDefaultBatches;
  int replicates = 0;
  std::vector<int> layer_classes;      // classifier classes that get an image layer
  // Accumulate the images at all. Off (`pathex trace --no-images`), the render keeps only the
  // histogram, which is the same either way, and RenderOutput::images is empty (0 × 0): no
  // per-pixel sums, no splat buffers, none of the image's memory traffic.
  bool images = true;
  ManifoldOptions manifold{};          // pathex trace --manifold-*: the manifold connector's limits
  // Called from one thread after each chunk: samples done of the total (with a dealer, the passes
  // it has dealt to every taker).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  const std::atomic<bool>* cancel = nullptr;  // set to stop early; the result is marked incomplete
};

// What a connector did during a render (DESIGN §4): every attempt either succeeds (its
// contribution is recorded) or fails for one reason.
struct ConnectorStats {
  std::string strategy;            // the profile's name for the strategy
  std::string connector;           // "mirror", "distant-projection", "ortho-projection", "manifold"
  std::uint64_t attempts = 0;      // joins tried (one per eye or light vertex where it may stand)
  std::uint64_t successes = 0;     // contributions recorded
  std::uint64_t outside = 0;       // the projection missed the aperture (or the film); off the mirror
  std::uint64_t occluded = 0;      // a segment it built was blocked (any of them)
  std::uint64_t no_transport = 0;  // built, but the BSDF or emission towards it is zero
  // The manifold connector's own failures (trace/joins/manifold.h, ManifoldFailure; zero for the
  // others): its seed blocked or a built segment blocked count as `occluded`.
  std::uint64_t no_solution = 0, singular = 0, wrong_type = 0, too_short = 0, iteration_limit = 0;
  std::uint64_t walks = 0;       // chains handed to the Newton solver
  std::uint64_t iterations = 0;  // Newton iterations over all of them (mean: iterations / walks)
  std::uint64_t repeats = 0;     // seeds of a first batch that solved to a chain already found in it
  std::uint64_t truncated = 0;   // chains not found again within max_trials seeds (their weight is low)

  // The counts, in a fixed order (the shard file's, output/shard.h, and the MPI reduction's). Each is
  // a sum over samples, and a sample's counts depend on (seed, pixel, pass) alone, so the counts
  // of a render are those of its threads, shards, resumed parts or MPI ranks added.
  static constexpr std::size_t kCounts = 14;
  template <class Self>  // ConnectorStats or const ConnectorStats
  static std::array<decltype(&std::declval<Self&>().attempts), kCounts> counts_of(Self& s) {
    return {&s.attempts,  &s.successes,  &s.outside,  &s.occluded,        &s.no_transport, &s.no_solution, &s.singular,
            &s.wrong_type, &s.too_short, &s.iteration_limit, &s.walks, &s.iterations,   &s.repeats,     &s.truncated};
  }
  // Adds another thread's (or shard's) counts; the names stay this one's.
  ConnectorStats& operator+=(const ConnectorStats& o) {
    const auto to = counts_of(*this);
    const auto from = counts_of(o);
    for (std::size_t i = 0; i < kCounts; ++i) *to[i] += *from[i];
    return *this;
  }
};

// Where a render's first non-finite contribution arose (they are bugs: DESIGN §7). "First" is by
// (pass, row, column) of the sample that made the contribution, the same for every thread count.
struct NonfiniteSample {
  std::string strategy;  // the profile's name for the strategy
  std::string path;      // its full-path string
  std::uint64_t pass = 0;
  int x = 0, y = 0;      // the pixel of a camera sample (for a splat: the sample's column and row)
  std::tuple<std::uint64_t, int, int> order() const { return {pass, y, x}; }
};

// A light that emitted only towards the shapes a requested path can reach first (the plan's
// emission narrowing, trace/plan.h; trace/emission_cones.h).
struct AimedLight {
  int light = 0;             // index into the scene's "lights"
  std::string kind;          // "point" or "spot"
  std::size_t shapes = 0;    // the shapes with a specular component it emitted towards
  float share = 0.0f;        // the cones' solid angles over 4π (an upper bound of the share of directions)
};

// What the roulette thresholds' `auto` took (trace/accel/join_plan.h): the eye's and the joins'
// (0: none); whether the pilot's model found them worth taking over the first pair (the eye's
// default or the eye threshold given, no join roulette or the join threshold given), and the
// efficiency it finds for its best pair against the first's.
struct RouletteThresholds {
  float eye = kDefaultEyeThreshold;
  float join = 0;
  double gain = 1;
  bool taken = false;
};

struct RenderOutput {
  Histogram histogram;
  ClassImages images;
  std::vector<std::string> strategy_names;
  std::uint64_t spp_done = 0;  // passes completed (all pixels) — spp unless cancelled
  PassSet passes_done{};       // which ones (spp_done of them)
  bool complete = true;
  double time_s = 0;
  std::uint64_t rays = 0;      // rays cast (intersections and shadow rays)
  std::vector<ConnectorStats> connectors{};  // one per connector strategy of the profile, in its order
  std::optional<NonfiniteSample> first_nonfinite{};  // when histogram.nonfinite() > 0
  std::vector<AimedLight> aimed{};                   // the lights whose emission was aimed
  std::optional<RouletteThresholds> roulette{};      // under --rr-threshold or --rr-join-threshold auto, where a pilot ran
};

// The strategies of a profile the tracer runs: plain joins and the mirror, projection and manifold
// connectors (the manifold's eye end a surface, t >= 2, or a pinhole's or thin lens's point, t = 1).
// The tracer looks them up by (s, chain, t) in a StrategyTable (trace/strategy_table.h).
struct StrategySet {
  std::vector<Strategy> strategies;
};

Result<StrategySet> runnable_strategies(const Profile& profile);

// --manifold-rate's and --manifold-seeds' defaults (issue 40), which render() and the shard header resolve.
// The rate applies where another strategy of the profile samples the path too (Integrator::manifold_rate()):
// where the profile has light subpaths (s >= 2: light tracing, bdpt's joins), to the joins whose eye end the
// camera sees directly or past a diffuse vertex (those it sees through specular vertices only run in every
// sample: there the rate halved bdpt+manifold's caustic seen through the ball); else (pt-nee+manifold) to
// every join whose light end is not a point (an eye path hits an area light: on the caustic seen through the
// ball the variance then grows as q^-0.26, not 1/q, the emitter hit taking the fold). There the connector
// runs in kShareWithOtherPaths of the samples (measured best on lamp-glass.json: bench/README.md, issue 40,
// tenth, eleventh and twenty-second sessions). One seed a
// batch where the profile has light subpaths, else kManifoldSeeds (pt-nee+manifold: its caustics seen
// through the glass and under a point light have no other strategy; one seed measured 0.3-0.7x there).
inline constexpr double kShareWithOtherPaths = 0.125;
inline constexpr int kManifoldSeeds = 4;
bool manifold_shares_paths(const Profile& profile);
ManifoldOptions resolved_manifold(const Profile& profile, ManifoldOptions o);

// --splits' default (issue 39), which render() and the shard header resolve: auto (0) where every
// eye vertex samples a light (next-event estimation, s = 1, t >= 2) and the profile has no light
// subpath beyond that one light point and no manifold connector: pt-nee, pt-nee+distant,
// pt-nee+mirror, pbrt-v4-path, mitsuba3-path. Else 1: under light tracing or bdpt's joins a run
// repeats the light subpath and its joins, which the pilot neither prices nor sees (its splats),
// and auto lost there (0.30x on Tungsten's box, 0.39x on point-glass.json); a manifold walk is not
// priced by the pilot's rays either (pt-nee+manifold 0.46x on point-glass.json); and without
// next-event estimation (pt) a run finds the light by chance, a heavy tail the pilot's few runs
// underrate (pt 0.88x / 0.67x on cornell.json at 16 / 64 spp; bench/README.md, issue 39, eleventh
// and twelfth sessions).
bool has_light_subpath(const Profile& profile);
int resolved_splits(const Profile& profile, std::optional<int> splits);

// A render of `plan` (trace/plan.h, plan_render()): its strategies, its lights' emission
// narrowing, and only the paths its filter records.
Result<RenderOutput> render(const Scene& scene, const RenderPlan& plan, const Classifier* classifier,
                            const RenderOptions& options);
// A render of `profile` whole, every path recorded (the plan whole_plan(profile)).
Result<RenderOutput> render(const Scene& scene, const Profile& profile, const Classifier* classifier,
                            const RenderOptions& options);

}  // namespace pathex
