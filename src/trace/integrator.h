// The integrator behind render() (trace/render.h): bidirectional path sampling over a profile's
// strategies, every sampled path labelled by its full-path string. Its stages live in their own
// files: the subpaths and the estimator in render.cpp, the joins in trace/joins/ (each makes one
// JoinResult from the two subpaths), the MIS weight in mis_weight.cpp over the one routine of
// trace/mis.h. This header declares it so that tests can drive the stages one at a time
// (tests/trace/mis_test.cpp checks its MIS weights on re-split paths).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stats/histogram.h"
#include "film/image.h"
#include "trace/accel/eye_ahead.h"
#include "trace/accel/first_vertex_split.h"
#include "trace/accel/nee_mis.h"
#include "trace/accel/path_ids.h"
#include "trace/bsdf.h"
#include "trace/joins/join.h"
#include "trace/joins/manifold.h"
#include "trace/mis.h"
#include "trace/prune.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"
#include "trace/strategy_table.h"
#include "trace/vertex.h"

namespace pathex::tracer {

using namespace accel;  // PathKey, PathIds
static_assert(kMaxVertices + 1 < kLengthShift, "every string the tracer forms packs into a PathKey");

// One sample's contributions as the pilot of the roulette thresholds' `auto` sees them
// (trace/accel/join_plan.h): its camera contributions and its splats' Σ c² (both less the emission
// seen directly, s + t = 2), its camera contributions by the eye vertices they use (t), each eye
// vertex z(t-1)'s plain joins with the light subpath (s >= 2, their summed contribution and how
// many were weighed), every join weighed (and how many by t), and the eye walk's roulette: at the
// step that finds z(j), its survival probability before the cap at 1 (0: no roulette there).
struct JoinTally {
  vec3 camera{0.0f};
  double splats = 0;
  std::array<vec3, kMaxVertices + 1> by_t{};
  std::array<vec3, kMaxVertices + 1> deep{};
  std::array<int, kMaxVertices + 1> deep_joins{};
  std::array<int, kMaxVertices + 1> joins_at{};
  std::array<float, kMaxVertices + 1> survive{};
  int joins = 0;
  void clear() { *this = JoinTally{}; }
};

class Integrator {
 public:
  // `filter`: the plan's (trace/plan.h), which paths are recorded (default: every path).
  Integrator(const RenderScene& rs, const StrategySet& strategies, const RenderOptions& o, PathFilter filter = {})
      : rs_(rs), cam_(rs.camera), strategies_(strategies), o_(o), filter_(std::move(filter)), table_(strategies.strategies) {
    max_bounces_ = std::min(o.max_bounces.value_or(16), kMaxVertices - 3);
    // `auto` unresolved (an Integrator built outside render(), as tests build them): the fixed default.
    eye_threshold_ = o.rr_threshold < 0.0f ? kDefaultEyeThreshold : o.rr_threshold;
    light_pick_ = rs.lights.empty() ? 0.0f : 1.0f / static_cast<float>(rs.lights.size());
    lens_hits_ = cam_.type == SensorType::kLens && table_.runs_at_t(ConnectorKind::kNone, 0);
    // Subpaths are only as long as a strategy can use: s = 1 and t = 1 take fresh samples, so a
    // light subpath is traced only for some s >= 2 (or for its first vertex, for (1, DD, 1)) and an
    // eye subpath beyond z0 for some t >= 2.
    for (const Strategy& st : strategies.strategies) {
      max_light_ = std::max(max_light_, st.s.hi == Range::kOpen ? kMaxVertices : st.s.hi);
      max_eye_ = std::max(max_eye_, st.t.hi == Range::kOpen ? kMaxVertices : st.t.hi);
    }
    // (A light splat from y0, the join (1, DD, 1), uses the light subpath's first vertex.)
    if (max_light_ < 2 && table_.plain(1, 1) < 0) max_light_ = 0;
    has_mirror_ = table_.runs(ConnectorKind::kMirror) && !rs.mirrors.empty();
    has_manifold_ = !rs.specular.shapes.empty() && table_.runs(ConnectorKind::kManifold);
    has_connectors_ = table_.runs(ConnectorKind::kDistantProjection) || table_.runs(ConnectorKind::kOrthoProjection) || has_mirror_ ||
                      has_manifold_;
    for (const Material* m : rs.material_of_shape) finite_of_shape_.push_back(bsdf::has_finite_component(*m) ? 1 : 0);
    absorbing_ = rs.absorbing;
    nee_pair_ = accel::nee_pair_only(table_, has_connectors_);
    max_light_ = std::min(max_light_, max_bounces_ + 1);
    max_eye_ = std::min(std::max(max_eye_, 1), max_bounces_ + 2);
  }

  using PathView = tracer::PathView;  // a full path over the subpaths' vertices (trace/vertex.h)

  // A weighted JoinResult on its way to record() (estimate() makes it): with its segments queued
  // for visibility, or none needed.
  struct Pending {
    PathKey key = 0;
    vec3 c{0.0f};
    int strategy = 0, batch = 0;
    int technique = 0;       // Technique::code(): the strategy at this (s, chain, t), for the histogram
    bool splat = false;      // to raster point (rx, ry); else to the sample's own pixel, column px
    bool connector = false;  // counted in the connector's statistics
    float rx = 0.0f, ry = 0.0f;
    int px = 0;
    // Segments that must all be clear: this lane's and the segments - 1 before it in the batch
    // (the mirror connector tests two). 0 marks a lane whose contribution sits on a later lane.
    int segments = 1;
    std::uint64_t pass = 0;  // the sample's pass (shadow rays are traced a while after it)
  };

  struct Thread {
    Histogram hist;
    // The current row's camera contributions, pixel by pixel; flushed to the image at the row's
    // end (finish_row()), after the row's last shadow rays.
    std::vector<ClassImages::PixelSum> row;
    std::array<Vertex, kMaxVertices> eye, light;
    std::uint64_t rays = 0;
    std::vector<ConnectorStats> connectors;  // indexed by profile strategy (only connectors' are used)
    PathIds ids;
    JoinResult join{};  // the join being made (joins build into it; estimate() consumes it)
    std::vector<ChainVertex> manifold_seed{};       // the manifold connector's chain being solved
    std::vector<ManifoldSolution> manifold_found{};  // and the distinct chains its first batch found
    std::vector<ChainVertex> mis_chain{};            // a path's chain whose MIS densities are computed (chain_densities())
    // The MIS weight's working space (mis_weight()): the strategies that sample the path being
    // weighed, and the densities of its vertices that the weight reads.
    std::array<mis::Technique, 2 * mis::kMaxPath + 2> techniques{};
    std::array<mis::Densities, mis::kMaxPath> densities{};
    // Each subpath vertex's densities as its walk stored them (store_densities(), once per sample).
    std::array<mis::Densities, kMaxVertices> light_densities{}, eye_densities{};
    // The subpaths' letters packed (set by set_masks()): light_mask has c0 c1 of y0, then
    // bit i + 1 for y_i's letter; eye_masks[t] has the eye subpath's last t + 1 letters (z(t-1)
    // … z0 and z0's spatial letter) as they sit after c(s) in any connection with t eye vertices.
    PathKey light_mask = 0;
    std::array<PathKey, kMaxVertices + 1> eye_masks{};
    ClassImages* images = nullptr;  // the shared image that splats go to
    ClassImages::SplatBuffer splats = ClassImages::SplatBuffer();  // they go through this; render() flushes it at the end
    int ns = 0, nt = 0;        // the current subpaths' lengths
    int px = 0;                // the current sample's column
    bool joins_ready = false;  // set_masks() runs on the sample's first recorded contribution
    // Shadow rays queued by connect(), traced when the batch is full and when a row ends
    // (finish_row()); pending[lane] is what lane's ray decides on. A row is one thread's work
    // from start to end, so which rays share a packet does not depend on the thread count.
    OcclusionBatch shadow = OcclusionBatch();
    std::array<Pending, OcclusionBatch::kCapacity> pending{};
    // The sample in progress (pass, row), and the first non-finite contribution this thread
    // recorded, for the warning that names it (render() keeps the earliest over the threads).
    std::uint64_t pass = 0;
    int py = 0;
    std::optional<NonfiniteSample> first_nonfinite{};
    FirstVertexSplit split{};  // --splits: the run of the sample in progress, its camera ray and hit
    EyeAhead ahead{};  // the eye subpath's first ray and hit, made in a packet before the sample (trace/accel/eye_packets.h)
    JoinTally* tally = nullptr;  // set by the pilot of the roulette thresholds' auto only (trace/accel/join_plan.h)
  };

  // The path of join `jr` over th's subpaths.
  static PathView path_of(const Thread& th, const JoinResult& jr);
  // The subpaths' letters packed (th.light_mask, th.eye_masks), for path_key(), and each vertex's
  // two densities for the MIS weight (store_densities()): once per sample, at its first join.
  void set_masks(Thread& th, int ns, int nt) const {
    th.joins_ready = true;
    store_densities(th, ns, nt);
    th.light_mask = 0;
    if (ns > 0) th.light_mask = letter_bit(th.light[0].pos_letter, 0) | letter_bit(th.light[0].letter, 1);
    for (int i = 1; i < ns; ++i) th.light_mask |= letter_bit(th.light[static_cast<std::size_t>(i)].letter, i + 1);
    th.eye_masks[0] = letter_bit(th.eye[0].pos_letter, 0);
    for (int t = 1; t <= nt; ++t)
      th.eye_masks[static_cast<std::size_t>(t)] =
          (th.eye_masks[static_cast<std::size_t>(t - 1)] << 1) | letter_bit(th.eye[static_cast<std::size_t>(t - 1)].letter, 0);
  }
  // The packed full-path string of connection (s, t): the vertices' letters in light-to-eye order,
  // the two join letters D (a fresh endpoint `sampled` standing for y0 when s = 1, t != 1).
  // (A projection connector's chain keeps its S letter: the caller sets that bit afterwards.)
  PathKey path_key(const Thread& th, int s, int t, const Vertex* sampled) const {
    PathKey m = 0;
    if (s > 0) {
      m = th.light_mask & (bit(s + 1) - 1);
      if (s == 1 && t != 1 && sampled) m = letter_bit(sampled->pos_letter, 0) | letter_bit(sampled->letter, 1);
    }
    if (t > 0) m |= th.eye_masks[static_cast<std::size_t>(t)] << (s + 1);
    m &= ~(bit(s) | bit(s + 1));  // the join letters
    return m | static_cast<PathKey>(s + t + 2) << kLengthShift;
  }

  // The profile's strategy that runs the plain join (s, DD, t), or -1.
  int strategy(int s, int t) const { return table_.plain(s, t); }

  bool traces_eye_rays() const { return max_eye_ >= 2; }  // an eye subpath goes past z0
  // Whether some eye vertex joins with the light subpath's vertices (s >= 2, t >= 2: bdpt's joins,
  // which --rr-join-threshold thins).
  bool joins_with_light_subpath() const {
    for (int t = 2; t <= max_eye_; ++t)
      for (int s = 2; s <= std::min(max_light_, max_bounces_ + 2 - t); ++s)
        if (strategy(s, t) >= 0) return true;
    return false;
  }
  // One sample: pixel (px, py), pass `pass`. Its camera contributions collect in th.row (the
  // caller flushes them with finish_row()); light-tracing splats go through th.splats.
  void sample(Thread& th, int px, int py, std::uint64_t pass) const;
  void sample_run(Thread& th, int px, int py, std::uint64_t pass) const;  // one of its --splits runs
  // After a row's samples: traces the shadow rays still queued, records what they let through,
  // and adds the row's camera contributions to row y of the image.
  void finish_row(Thread& th, ClassImages& images, int y) const {
    trace_shadows(th);
    for (std::size_t x = 0; x < th.row.size(); ++x) th.row[x].flush(images, static_cast<int>(x), y);
  }

  const RenderScene& scene() const { return rs_; }

  // --- the sensor and the lights: the one emitter model (trace/emitters.h) ---
  // Densities as the walks and the MIS ratios keep them: a Dirac part's is 0 (trace/emitters.h).
  // Solid-angle density of the sensor's ray leaving `v` (a point of the sensor) towards w, and of
  // light l's leaving `v` (a point of the light) (mis_weight.cpp).
  float sensor_pdf_dir(const Vertex& v, const vec3& w) const;
  float light_pdf_dir(const RenderLight& l, const Vertex& v, const vec3& w) const;
  // Next-event estimation could join a light point to v: a surface with a finite part (by its
  // shape: a connector's chain vertex too), a sensor point with a finite direction.
  bool joinable(const Vertex& v) const {
    return v.kind == Kind::kSurface ? finite_of_shape_[static_cast<std::size_t>(v.shape)] != 0 : cam_.letters[0] == 'D';
  }
  // Light `light`'s x0 has next-event estimation's density from x1 (RenderLight::drawn_towards,
  // trace/emitters.h draws_towards()): an image infinite light, a rectangle sampled by solid angle.
  bool drawn_towards(int light, const Vertex& x1) const {
    return rs_.lights[static_cast<std::size_t>(light)].drawn_towards(joinable(x1));
  }
  // v is x0 of a path whose x1 is `x1`, drawn towards x1 (a light vertex, or an eye vertex that hit
  // the light).
  bool origin_drawn_towards(const Vertex& v, const Vertex& x1) const;
  // x0's light density (the pick times the light's): next-event estimation's from x1 where the
  // light draws towards it, else its area density (0 for a Dirac position).
  float light_origin_density(int light, const vec3& x0, const vec3& n0, const Vertex& x1) const {
    return light_pick_ * rs_.lights[static_cast<std::size_t>(light)].origin_density(x0, n0, x1.p, joinable(x1));
  }
  // x1's light density after such an x0 (drawn_towards() holds): the rest of the emission's joint density.
  float light_step_density(int light, const Vertex& x0, const Vertex& x1) const {
    const vec3 w = glm::normalize(x1.p - x0.p);
    return towards_step_density(rs_.lights[static_cast<std::size_t>(light)].params, x0.p, x0.n, x1.p, abs_cos(x1, w));
  }

  // The material at surface vertex `v` (RenderScene::material_at).
  const Material& material_at(const Vertex& v, MaterialScratch* scratch) const { return rs_.material_at(v.shape, v.uv, scratch); }

  // --- densities used by MIS (mis_weight.cpp) ---
  // Solid-angle density at `v` of sampling the unit direction `wn`, given the unit direction
  // `wp` to v's other neighbour (null when it has none: a surface then has no density).
  float pdf_dir(const Vertex& v, const vec3* wp, const vec3& wn) const;
  // Area density at `next` of sampling it from `v` whose other neighbour is `prev`.
  float pdf(const Vertex* prev, const Vertex& v, const Vertex& next) const;

  // --- subpaths ---
  // A template on the direction: the walk's tests of its direction are not branches. What the
  // scene cannot have (RenderScene::features, trace/scene_features.h) it skips.
  template <TransportMode mode>
  // From path[0] along (o, d), drawn with density pdf_dir, with throughput beta.
  int random_walk(Thread& th, Sampler& rng, std::array<Vertex, kMaxVertices>& path, vec3 o, vec3 d, float pdf_dir, vec3 beta,
                  int max_vertices) const;
  int eye_subpath(Thread& th, Sampler& rng, int px, int py) const;
  // u_ray: the numbers of the light's first direction (Sampler::at2d_now at kLightRayDim).
  int light_subpath(Thread& th, Sampler& rng, glm::vec2 u_ray) const;

  static constexpr std::size_t kMaxRuns = 2 * kMaxVertices;  // the most joins of one kind per sample
  // --- joins (trace/joins/): each makes th.join from the two subpaths, or returns false ---
  // Random numbers: each join draws from a block of its own, per kind and subpath length (render.cpp).
  enum class JoinBlock : std::uint64_t { kEmitter, kLens, kSplat, kNee, kShadow, kDistant, kOrtho, kMirrorLight, kMirrorEye, kManifoldLight, kManifoldEye, kJoinRoulette };
  static constexpr std::uint64_t kJoinDims = 2048;  // after the eye's and the light subpath's blocks
  static constexpr std::uint64_t kDimsPerJoin = 4;
  static void join_numbers(Sampler& rng, JoinBlock block, int index) {
    rng.set_dimension(kJoinDims + (static_cast<std::uint64_t>(block) * kMaxRuns + static_cast<std::uint64_t>(index)) * kDimsPerJoin);
  }
  bool join_emitter(Thread& th, int t) const;  // (0, DD, t): z(t-1) lies on an area light
  bool join_lens(Thread& th, int s) const;     // (s, DD, 0): y(s-1) lies on the lens
  // (s, DD, 1): y(s-1) joined to a fresh sensor point (kNone), or ortho-projection (s, DSD, 0):
  // to the film point on its line of sight (kOrthoProjection).
  bool join_sensor(Thread& th, Sampler& rng, int s, ConnectorKind kind) const;
  // (1, DD, t): z(t-1) joined to a fresh light point (kNone), or distant-projection (0, DSD, t):
  // to the aperture point on the line through it against the light (kDistantProjection).
  bool join_light(Thread& th, Sampler& rng, int t, ConnectorKind kind) const;
  bool join_shadow(Thread& th, int s, int t) const;  // (s, DD, t), s, t >= 2: a shadow ray between y(s-1) and z(t-1)
  // Whether eye vertex z = z(t-1) makes its joins with the light subpath (s >= 2): 1 / q with
  // probability q = min(1, z.rr_throughput / --rr-join-threshold), the weight they then carry, else 0.
  float join_roulette(Sampler& rng, const Vertex& z, int t) const;
  // The scattering function at a join's end vertex v towards unit w (leaving v along the join): a
  // light vertex's directional emission (its beta holds the spatial part), else its BSDF, with the
  // shading-normal correction at the light end (mode kImportance); the BSDF's densities for free
  // into *pdfs when given. Every join evaluates its ends here.
  vec3 end_f(const Vertex& v, const vec3& w, TransportMode mode, bsdf::JoinPdfs* pdfs = nullptr) const;
  // A plain or projection join's end (its start: JoinResult::begin): its contribution, the S
  // letters a projection adds, the one segment to test (none: from is null). False when black.
  bool end_join(Thread& th, vec3 contrib, PathKey chain_s, const Vertex* from, const Vertex* to) const;
  // The one way to make an endpoint vertex, for a subpath (y0, z0) and for a join's fresh end: into
  // y a vertex of light li at p, into z a sensor vertex at p (normal n, none for a point sensor),
  // with its letter (c1, c(k+1)) and its forward density. fresh_*: into th.join (light0, eye0).
  Vertex& light_vertex(Vertex& y, std::size_t li, const vec3& p, const vec3& n, const vec3& err, char letter) const;
  Vertex& sensor_vertex(Vertex& z, const vec3& p, const vec3& n, char letter) const;
  Vertex& fresh_sensor_vertex(Thread& th, const EndpointConnection& c, char letter) const {
    th.join.has_eye0 = true;
    return sensor_vertex(th.join.eye0, c.position, c.normal, letter);
  }
  Vertex& fresh_light_vertex(Thread& th, std::size_t li, const vec3& p, const vec3& n, const vec3& err, char letter) const {
    th.join.has_light0 = true;
    return light_vertex(th.join.light0, li, p, n, err, letter);
  }
  // The profile's strategy running a projection connector with this many eye (distant: its chain
  // is c0 c1 c2, so (0, DSD, t)) or light (ortho: (s, DSD, 0)) vertices, or -1.
  int distant_of(int t) const { return table_.at(0, ConnectorKind::kDistantProjection, t); }
  int ortho_of(int s) const { return table_.at(s, ConnectorKind::kOrthoProjection, 0); }
  // The mirror connector (s, DSD, t), s, t >= 1 (trace/joins/mirror_join.cpp).
  void connect_mirror(Thread& th, Sampler& rng, int s, int t, int batch) const;
  int mirror_of(int s, int t) const { return table_.at(s, ConnectorKind::kMirror, t); }
  // A connector's light end for s = 1: a fresh light sample in th.join.light0 from random-number
  // block `block` (one per t), or null when the light picked has a Dirac direction (no D end).
  const Vertex* fresh_light_end(Thread& th, Sampler& rng, int t, JoinBlock block) const;
  // The letters of the path that a connector's chain of m specular vertices (the mirror's one, the
  // manifold's) makes between a (c(s): y(s-1), or the fresh light end for s = 1) and z(t-1).
  PathKey chain_key(Thread& th, const Vertex& a, int s, int t, int m) const;
  // The manifold connector (s, DS+D, t), s, t >= 1 (trace/joins/manifold.h): y(s-1) (a fresh light
  // sample for s = 1) joined to z(t-1) (a fresh sensor point for t = 1, a pinhole or thin lens,
  // splatted) across a chain of smooth glass by specular manifold sampling (manifold_join.cpp).
  void connect_manifold(Thread& th, Sampler& rng, int s, int t, int batch) const;
  // One chain's contribution between a and b, its |dω_a/dA_b| times its inverse probability `weight`.
  void emit_manifold(Thread& th, int s, int t, int batch, int strategy_index, const Vertex& a, const Vertex& b,
                     const std::vector<ChainVertex>& chain, double weight) const;
  int manifold_of(int s, int t) const { return table_.at(s, ConnectorKind::kManifold, t); }
  // Whether the manifold connector (s, DS^mD, ·) could build the chain x_s … x(s+m-1) of path x
  // (letters `key`): the profile runs it there, its eye end is a surface, and every chain vertex is
  // a reflection or refraction on smooth glass or a reflection on a mirror.
  bool manifold_at(const PathView& x, PathKey key, int s, int m) const;
  // --- the MIS weight (trace/mis_weight.cpp; the routine itself is trace/mis.h) ---
  // Each subpath vertex's two densities as the weight reads them (th.light_densities, eye_densities).
  void store_densities(Thread& th, int ns, int nt) const;
  // The power-heuristic weight of path x (letters `key`) as strategy `self` sampled it (at split
  // x.s, its x.m constructed vertices after it), against every strategy of the profile that samples
  // the same path. `join`: the densities the join computed at its two ends (null: recomputed).
  float mis_weight(Thread& th, const PathView& x, PathKey key, ConnectorKind self, const JoinDensity* join) const;
  // mis_weight() of a plain join (x.t >= 2) of pt-nee's pair of strategies (nee_pair()) by the fast
  // path (trace/accel/nee_mis.h): equal bit for bit (tests/trace/mis_test.cpp).
  float nee_pair_weight(const PathView& x, PathKey key, const JoinDensity* join) const;
  bool nee_pair() const { return nee_pair_; }
  // The strategies that sample path x, `self` the own one (connectors listed in th.techniques).
  mis::Strategies techniques(Thread& th, const PathView& x, PathKey key, ConnectorKind self) const;
  void connector_techniques(Thread& th, const PathView& x, PathKey key, ConnectorKind self, mis::Strategies& st) const;  // its connectors
  // th.densities[lo … hi) of a plain or projection join's path: the subpaths' stored densities
  // copied, the four the join changes recomputed in the copy.
  void join_densities(Thread& th, const PathView& x, ConnectorKind self, const JoinDensity* join, int lo, int hi) const;
  // th.densities[lo … hi) of a path with constructed vertices: every one computed from the vertices.
  void path_densities(Thread& th, const PathView& x, PathKey key, int lo, int hi) const;
  // th.densities[lo … hi) (already filled) changed where the manifold connector could build a run
  // x_i … x(i+m-1) of S vertices between a = x(i-1) and b = x(i+m) (trace/joins/manifold_join.cpp):
  // every strategy's density then is over the areas of the path's other vertices, the chain a
  // function of its ends, as the manifold's own is. A walk that crosses the chain samples b from a
  // with a's direction density times the generalized geometry term |dω_a/dA_b| (and the Dirac
  // lobes' choices), a from b likewise; the chain's vertices count 1 for both walks.
  // The share of samples running the manifold join with eye end x_b of x0 … xk (its MIS factor).
  double manifold_rate(PathKey key, int b, int k) const;
  void chain_densities(Thread& th, const PathView& x, PathKey key, ConnectorKind self, int lo, int hi) const;
  // The estimator's one consumer of joins: weighs th.join by MIS over every strategy of the
  // profile, then records it, or queues its segments and records it once all are found clear.
  void estimate(Thread& th, int batch) const;
  void record(Thread& th, const Pending& r) const;
  static void tally(JoinTally& tally, const Pending& r);  // the pilot's (JoinTally)
  // A contribution that is not finite (a bug: counted, and the first one kept for the warning).
  // Out of line and cold, so that record()'s code stays small.
  [[gnu::cold, gnu::noinline]] void record_nonfinite(Thread& th, const Pending& r) const;
  void trace_shadows(Thread& th) const;

 private:
  const RenderScene& rs_;
  const RenderSensor& cam_;
  const StrategySet& strategies_;
  const RenderOptions& o_;
  PathFilter filter_;  // the plan's: which paths are recorded, where subpaths stop
  int max_bounces_ = 16;
  float eye_threshold_ = kDefaultEyeThreshold;  // RenderOptions::rr_threshold, resolved
  StrategyTable table_;  // which strategy runs each (s, chain, t)
  bool has_connectors_ = false;  // a connector strategy runs (a mirror one only when the scene has a planar mirror)
  bool has_mirror_ = false;      // a mirror strategy runs and the scene has a planar mirror
  bool has_manifold_ = false;    // a manifold strategy runs and the scene has specular surfaces (RenderScene::specular)
  // A full path has s + t = k + 1 <= max_bounces + 2 vertices (kMaxVertices bounds max_bounces).
  static_assert(kMaxVertices <= StrategyTable::kMaxSplits, "plain_splits() covers every path");
  std::vector<std::uint8_t> finite_of_shape_;  // the shape's material has a finite BSDF part
  int max_light_ = 0;  // longest light subpath any strategy uses (0: none)
  int max_eye_ = 1;    // longest eye subpath any strategy uses
  float light_pick_ = 0.0f;
  bool lens_hits_ = false;
  bool absorbing_ = false;  // some shape has an absorbing interior (trace/media.h)
  bool nee_pair_ = false;   // the plain joins are at most (0, n) and (1, n - 1), no connector (accel::nee_pair_only)
};

}  // namespace pathex::tracer
