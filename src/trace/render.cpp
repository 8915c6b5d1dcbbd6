// Bidirectional path sampling with full-path labels.
//
// For each pixel and pass: an eye subpath z0 z1 … from the sensor and a light subpath y0 y1 …
// from a light, each extended by local sampling (BSDF sampling, Russian roulette from
// RenderOptions::rr_depth vertices on, below rr_threshold; at most max_bounces interior vertices
// on the full path).
// Then every (s, t) pair the profile runs is evaluated: s = 0 an eye vertex on an area light,
// s = 1 a fresh light sample (next-event estimation), t = 1 a fresh sensor sample (a splat), t = 0
// a light vertex on a thin lens, otherwise a shadow ray between y(s-1) and z(t-1).
//
// Labels: each vertex keeps the letter of the scattering event sampled there (the component a
// BSDF chose; a light's and a sensor's two letters). The full-path string of a connection is
// those letters in light-to-eye order with the two join letters set to D (a join evaluates only
// finite parts). A strategy (s', t') has nonzero density for that string exactly when the
// profile runs it and the string's letters c(s') and c(s'+1) are both D; the power heuristic
// sums over those strategies only, using the pdf-ratio recurrence of pbrt's BDPT with Dirac
// densities kept symbolic (stored as 0, remapped to 1, and their strategies excluded by letter).
#include "trace/render.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>

#include "trace/accel/path_ids.h"
#include "trace/bsdf.h"
#include "trace/frame.h"
#include "trace/prune.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex {

// --- strategies the tracer runs ---

int StrategySet::find(int s, int t) const { return find_connector(ConnectorKind::kNone, s, t); }

int StrategySet::find_connector(ConnectorKind k, int s, int t) const {
  for (std::size_t i = 0; i < strategies.size(); ++i)
    if (strategies[i].connector == k && strategies[i].s.contains(s) && strategies[i].t.contains(t)) return static_cast<int>(i);
  return -1;
}

Result<StrategySet> runnable_strategies(const Profile& profile) {
  StrategySet set;
  for (const Strategy& st : profile.strategies) {
    if (st.connector == ConnectorKind::kManifold)
      return make_error(ErrorCode::kUsage, "renderer '" + profile.name + "' uses the connector '" + to_string(st.connector) +
                                               "' (strategy '" + st.name +
                                               "'), which the tracer does not run yet; it runs plain joins (s, DD, t) and the "
                                               "mirror, distant-projection and ortho-projection connectors");
    set.strategies.push_back(st);
  }
  return set;
}

namespace {

using glm::vec3;
constexpr int kMaxVertices = 64;  // per subpath; max_bounces is clamped so paths fit

// Passes go to batches round-robin: every batch covers the whole image, passes are i.i.d., and
// an interrupted render still spreads what it has over all batches (so its error is defined).
int batch_of(std::uint64_t pass, int batches) { return static_cast<int>(pass % static_cast<std::uint64_t>(batches)); }

// Random-number dimensions (trace/rng.h): each stage of a sample draws from its own block, so that
// adding a strategy leaves every other strategy's numbers unchanged. The eye and the light subpath
// draw at most 4 + 4 per vertex; each connection (kind, subpath length) then draws at most 4.
constexpr std::uint64_t kEyeDims = 0;
constexpr std::uint64_t kLightDims = 1024;
constexpr std::uint64_t kJoinDims = 2048;
constexpr std::uint64_t kDimsPerJoin = 4;
static_assert(4 + 4 * 64 <= kLightDims - kEyeDims, "a subpath's numbers fit its block");

float max_component(const vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
bool is_black(const vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

// --- vertices ---

enum class Kind : std::uint8_t { kCamera, kLight, kSurface, kLens };

struct Vertex {
  Kind kind = Kind::kSurface;
  char letter = 'D';     // scattering letter: surface c_i; light c1 (direction); sensor c(k+1)
  char pos_letter = 'D'; // lights c0 and sensors c(k+2)
  bool finite = true;    // can be a join end: not a surface, or a surface with a finite BSDF part
  vec3 p{0.0f};
  vec3 n{0.0f};          // geometric normal (unit); zero for points (point, spot, pinhole, laser)
  vec3 err{0.0f};        // bound on p's rounding error (Hit::error): how far a ray leaving p is offset
  vec3 ns{0.0f};         // shading normal
  vec3 beta{1.0f};       // throughput up to and including this vertex
  vec3 wo{0.0f};         // unit direction to the vertex before it on its subpath (zero for the first)
  float d2_wo = 0.0f;    // squared distance to that vertex
  float pdf_fwd = 0.0f;  // area density of sampling this vertex in its subpath's direction
  float pdf_rev = 0.0f;  // area density of sampling it from the other direction
  int shape = -1;        // surfaces and area-light points
  int light = -1;        // light vertices
  // Without short-circuits: which components are zero follows the scene's orientation, which no
  // branch predictor guesses (this test was an eighth of the tracer's mispredicted branches).
  bool has_normal() const { return (n.x != 0.0f) | (n.y != 0.0f) | (n.z != 0.0f); }
};

// Sets v.wo and v.d2_wo from its predecessor's position.
void link(Vertex& v, const Vertex& pred) {
  const vec3 e = pred.p - v.p;
  v.d2_wo = glm::dot(e, e);
  v.wo = v.d2_wo > 0.0f ? e / std::sqrt(v.d2_wo) : vec3(0.0f);
}

using namespace accel;  // PathKey, PathIds
static_assert(kMaxVertices + 1 < kLengthShift, "every string the tracer forms packs into a PathKey");

// |cos| at `v` towards `w` (1 for vertices without a surface, such as point lights).
float abs_cos(const Vertex& v, const vec3& w) {
  // Arithmetic, not a choice (which compiled to a branch that mispredicted at every point vertex):
  // a point's n is zero, so its |cos| term is 0 and the added 1 is the whole value.
  return std::fabs(glm::dot(v.n, w)) + static_cast<float>(!v.has_normal());
}


// --- the integrator ---

class Integrator {
 public:
  // `general_mis` (for tests) turns off the per-sample MIS sums, leaving the general recurrence.
  Integrator(const RenderScene& rs, const StrategySet& strategies, const RenderOptions& o, const Classifier* cl,
             bool general_mis = false)
      : rs_(rs), cam_(rs.camera), strategies_(strategies), o_(o), classifier_(cl) {
    max_bounces_ = std::min(o.max_bounces.value_or(16), kMaxVertices - 3);
    light_pick_ = rs.lights.empty() ? 0.0f : 1.0f / static_cast<float>(rs.lights.size());
    lens_hits_ = cam_.type == SensorType::kLens;
    bool any_t0 = false;
    for (int s = 0; s < 2 * kMaxVertices; ++s) any_t0 = any_t0 || strategies.find(s, 0) >= 0;
    lens_hits_ = lens_hits_ && any_t0;
    // Subpaths are only as long as a strategy can use: s = 1 and t = 1 take fresh samples, so a
    // light subpath is traced only for some s >= 2 and an eye subpath beyond z0 for some t >= 2.
    for (const Strategy& st : strategies.strategies) {
      max_light_ = std::max(max_light_, st.s.hi == Range::kOpen ? kMaxVertices : st.s.hi);
      max_eye_ = std::max(max_eye_, st.t.hi == Range::kOpen ? kMaxVertices : st.t.hi);
    }
    if (max_light_ < 2) max_light_ = 0;
    strategy_of_.assign(kMaxRuns * kMaxRuns, -1);
    for (std::size_t a = 0; a < kMaxRuns; ++a)
      for (std::size_t b = 0; b < kMaxRuns; ++b)
        strategy_of_[a * kMaxRuns + b] = static_cast<std::int16_t>(strategies.find(static_cast<int>(a), static_cast<int>(b)));
    // runs_mask_[n] bit s2: the profile runs (s2, n - s2); t2 = 0 only when light paths can hit the lens.
    for (std::size_t n = 0; n < runs_mask_.size(); ++n)
      for (int s2 = 0; s2 <= static_cast<int>(n); ++s2)
        if (strategy(s2, static_cast<int>(n) - s2) >= 0 && (s2 < static_cast<int>(n) || lens_hits_))
          runs_mask_[n] |= std::uint64_t{1} << s2;
    for (std::size_t i = 0; i < kMaxRuns; ++i) {
      distant_of_[i] = static_cast<std::int16_t>(strategies.find_connector(ConnectorKind::kDistantProjection, 0, static_cast<int>(i)));
      ortho_of_[i] = static_cast<std::int16_t>(strategies.find_connector(ConnectorKind::kOrthoProjection, static_cast<int>(i), 0));
      has_connectors_ = has_connectors_ || distant_of_[i] >= 0 || ortho_of_[i] >= 0;
    }
    mirror_of_.assign(kMaxRuns * kMaxRuns, -1);
    for (std::size_t a = 1; a < kMaxRuns; ++a)
      for (std::size_t b = 1; b < kMaxRuns; ++b) {
        const int m = strategies.find_connector(ConnectorKind::kMirror, static_cast<int>(a), static_cast<int>(b));
        mirror_of_[a * kMaxRuns + b] = static_cast<std::int16_t>(m);
        has_mirror_ = has_mirror_ || (m >= 0 && !rs.mirrors.empty());
      }
    if (rs.mirrors.empty()) std::fill(mirror_of_.begin(), mirror_of_.end(), std::int16_t{-1});
    has_connectors_ = has_connectors_ || has_mirror_;
    mirror_shape_.assign(rs.material_of_shape.size(), 0);
    for (const PlanarMirror& m : rs.mirrors) mirror_shape_[static_cast<std::size_t>(m.shape)] = 1;
    eye0_runs_ = (runs_mask_[1] >> 1) & 1;
    all_runs_ = !has_connectors_ && !general_mis;  // the per-sample sums below know plain joins only
    for (std::size_t n = 1; n < runs_mask_.size(); ++n) {
      const std::uint64_t below = (std::uint64_t{1} << n) - 1;  // s2 < n: t2 >= 1
      all_runs_ = all_runs_ && (runs_mask_[n] & below) == below && ((runs_mask_[n] >> n) & 1) == (eye0_runs_ ? 1u : 0u);
    }
    for (const Material* m : rs.material_of_shape) finite_of_shape_.push_back(bsdf::has_finite_component(*m) ? 1 : 0);
    sensor_pair_ = {letter_char(dir_letter(cam_.params)), letter_char(pos_letter(cam_.params))};
    for (const RenderLight& l : rs.lights) light_pairs_.push_back({letter_char(pos_letter(l.params)), letter_char(dir_letter(l.params))});
    max_light_ = std::min(max_light_, max_bounces_ + 1);
    max_eye_ = std::min(std::max(max_eye_, 1), max_bounces_ + 2);
  }

  // A weighted contribution on its way to record(): with its shadow ray pending, or none needed.
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
    Vertex sampled;  // connect()'s fresh light or sensor sample
    Vertex sampled_eye{}, mirror_vertex{};  // the mirror connector's fresh sensor sample and mirror vertex
    std::vector<Vertex> path{};         // a whole path x0 … xk for path_weight()
    std::vector<double> rel{}, eye_density{};  // path_weight()'s density ratios and remapped ef
    // The subpaths' letters packed (set by prepare_joins()): light_mask has c0 c1 of y0, then
    // bit i + 1 for y_i's letter; eye_masks[t] has the eye subpath's last t + 1 letters (z(t-1)
    // … z0 and z0's spatial letter) as they sit after c(s) in any connection with t eye vertices.
    PathKey light_mask = 0;
    std::array<PathKey, kMaxVertices + 1> eye_masks{};
    ClassImages* images = nullptr;  // the shared image that splats go to
    ClassImages::SplatBuffer splats = ClassImages::SplatBuffer();  // they go through this; render() flushes it at the end
    std::array<double, kMaxVertices> light_ratio{}, eye_ratio{};  // set by prepare_joins()
    // With every strategy run (all_runs_), the MIS sums over each subpath's fixed part, from its
    // start to vertex j (set by prepare_joins()): light_acc[j] = Σ_{i <= j, strategy (i, ·)
    // samples the letters} Π_{m=i..j} light_ratio[m]², and eye_acc likewise.
    std::array<double, kMaxVertices> light_acc{}, eye_acc{};
    // 1 / (remapped forward density) of each vertex (set by prepare_joins()): a weight multiplies
    // by it rather than dividing on its critical path.
    std::array<double, kMaxVertices> light_inv_fwd{}, eye_inv_fwd{};
    int ns = 0, nt = 0;        // the current subpaths' lengths
    int px = 0;                // the current sample's column
    bool joins_ready = false;  // prepare_joins() runs on the sample's first recorded contribution
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
  };

  // A vertex's density ratio in the MIS sums, a Dirac's densities (stored as 0) counting as 1.
  // Branch-free (0 + 1 is exact): Dirac vertices come and go along a path unpredictably.
  static double remap(float f) { return static_cast<double>(f) + static_cast<double>(f == 0.0f); }
  static double ratio(const Vertex& v) { return remap(v.pdf_rev) / remap(v.pdf_fwd); }
  static double inv_fwd(const Vertex& v) { return 1.0 / remap(v.pdf_fwd); }
  // Per sample, before its first recorded contribution: the letter masks, and each vertex's
  // ratio of reverse to forward density (a join changes only the two nearest each end).
  void prepare_joins(Thread& th, int ns, int nt) const {
    for (int i = 0; i < ns; ++i) {
      th.light_ratio[static_cast<std::size_t>(i)] = ratio(th.light[static_cast<std::size_t>(i)]);
      th.light_inv_fwd[static_cast<std::size_t>(i)] = inv_fwd(th.light[static_cast<std::size_t>(i)]);
    }
    for (int i = 0; i < nt; ++i) {
      th.eye_ratio[static_cast<std::size_t>(i)] = ratio(th.eye[static_cast<std::size_t>(i)]);
      th.eye_inv_fwd[static_cast<std::size_t>(i)] = inv_fwd(th.eye[static_cast<std::size_t>(i)]);
    }
    th.joins_ready = true;
    th.light_mask = 0;
    if (ns > 0) th.light_mask = letter_bit(th.light[0].pos_letter, 0) | letter_bit(th.light[0].letter, 1);
    for (int i = 1; i < ns; ++i) th.light_mask |= letter_bit(th.light[static_cast<std::size_t>(i)].letter, i + 1);
    th.eye_masks[0] = letter_bit(th.eye[0].pos_letter, 0);
    for (int t = 1; t <= nt; ++t)
      th.eye_masks[static_cast<std::size_t>(t)] =
          (th.eye_masks[static_cast<std::size_t>(t - 1)] << 1) | letter_bit(th.eye[static_cast<std::size_t>(t - 1)].letter, 0);
    if (!all_runs_) return;
    // Strategy (i, ·) on the light side joins at y(i-1) and y_i: letters c_i and c_(i+1), bits i
    // and i + 1 of light_mask. On the eye side strategy (·, j) joins at z_j and z(j-1): letters
    // z_j's and z(j-1)'s (z0's spatial letter for j = 0, which also needs the lens).
    double acc = 0.0;
    for (int j = 0; j < ns; ++j) {
      const double r = th.light_ratio[static_cast<std::size_t>(j)];
      acc = r * r * (static_cast<double>(((th.light_mask >> j) & 3) == 0) + acc);
      th.light_acc[static_cast<std::size_t>(j)] = acc;
    }
    acc = 0.0;
    for (int j = 0; j < nt; ++j) {
      const char before = j > 0 ? th.eye[static_cast<std::size_t>(j - 1)].letter : th.eye[0].pos_letter;
      const bool runs = th.eye[static_cast<std::size_t>(j)].letter == 'D' && before == 'D' && (j > 0 || eye0_runs_);
      const double r = th.eye_ratio[static_cast<std::size_t>(j)];
      acc = r * r * (static_cast<double>(runs) + acc);
      th.eye_acc[static_cast<std::size_t>(j)] = acc;
    }
  }
  // The packed full-path string of connection (s, t), as full_path() spells it.
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

  // The profile's strategy that runs (s, t), or -1.
  int strategy(int s, int t) const {
    return static_cast<std::size_t>(s) < kMaxRuns && static_cast<std::size_t>(t) < kMaxRuns
               ? strategy_of_[static_cast<std::size_t>(s) * kMaxRuns + static_cast<std::size_t>(t)]
               : -1;
  }

  // One sample: pixel (px, py), pass `pass`. Its camera contributions collect in th.row (the
  // caller flushes them with finish_row()); light-tracing splats go through th.splats.
  void sample(Thread& th, int px, int py, std::uint64_t pass) const;
  // After a row's samples: traces the shadow rays still queued, records what they let through,
  // and adds the row's camera contributions to row y of the image.
  void finish_row(Thread& th, ClassImages& images, int y) const {
    trace_shadows(th);
    // All the row's words are requested before the first is added to: the adds are atomic, and an
    // atomic add to a line not in cache waits for it, one line after another.
    for (std::size_t x = 0; x < th.row.size(); ++x) th.row[x].prefetch(images, static_cast<int>(x), y);
    for (std::size_t x = 0; x < th.row.size(); ++x) th.row[x].flush(images, static_cast<int>(x), y);
  }

  // For the full path x0 … xk formed by connection (s, t) of the current subpaths: the sum, over
  // every strategy (s', t') with s' + t' = s + t that the profile runs and whose join letters are
  // D, of the MIS weight (s', t') computes when it samples the same vertices. Must be 1.
  float weight_sum(Thread& th, int s, int t) const;
  // weight_sum() when (s, t) joins two vertices that can be joined (s = 0: an eye vertex on an
  // area light; t = 0: a light vertex on the lens; otherwise two surfaces with finite parts), else -1.
  float weight_sum_if_valid(Thread& th, int s, int t) const {
    const Vertex* qs = s > 0 ? &th.light[static_cast<std::size_t>(s - 1)] : nullptr;
    const Vertex* pt = t > 0 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
    if (s == 0) {
      if (pt->kind != Kind::kSurface || rs_.light_of_shape[static_cast<std::size_t>(pt->shape)] < 0) return -1.0f;
    } else if (t == 0) {
      if (qs->kind != Kind::kLens) return -1.0f;
    } else {
      if (qs->kind != Kind::kSurface || pt->kind != Kind::kSurface) return -1.0f;
      if (!bsdf::has_finite_component(*rs_.material_of_shape[static_cast<std::size_t>(qs->shape)]) ||
          !bsdf::has_finite_component(*rs_.material_of_shape[static_cast<std::size_t>(pt->shape)]))
        return -1.0f;
    }
    return weight_sum(th, s, t);
  }
  std::string label(const Thread& th, int s, int t) const {
    std::string out;
    full_path(th, s, t, nullptr, out);
    return out;
  }
  // The weight of connection (s, t) of the current subpaths, as the renderer computes it.
  float own_weight(Thread& th, int s, int t) const {
    prepare_joins(th, th.ns, th.nt);
    return mis_weight(th, s, t, nullptr, path_key(th, s, t, nullptr));
  }
  // The same string as the renderer records it (packed, then spelled out).
  std::string packed_label(const Thread& th, int s, int t) const { return unpack(path_key(th, s, t, nullptr)); }
  int trace_subpaths(Thread& th, Sampler& rng, int px, int py, int* ns) const {
    const int nt = eye_subpath(th, rng, px, py);
    *ns = light_subpath(th, rng);
    th.ns = *ns;
    th.nt = nt;
    prepare_joins(th, *ns, nt);
    return nt;
  }

 private:
  // --- the sensor and the lights: the one emitter model (trace/emitters.h) ---
  // Densities as the MIS ratios keep them: a Dirac part's is stored as 0.
  static float finite_part(float pdf, bool delta) { return delta ? 0.0f : pdf; }
  // Solid-angle density of the sensor's ray leaving `v` (a point of the sensor) towards w.
  float sensor_pdf_dir(const Vertex& v, const vec3& w) const {
    const RayPdf p = pdf_ray(cam_.params, v.p, w);
    return finite_part(p.dir, p.delta_dir);
  }
  // Solid-angle density of the light's ray leaving `v` (a point of the light) towards w.
  float light_pdf_dir(const RenderLight& l, const Vertex& v, const vec3& w) const {
    const RayPdf p = pdf_ray(l.params, SurfacePoint{v.p, v.n, l.pdf_pos}, w);
    return finite_part(p.dir, p.delta_dir);
  }
  // A light chosen uniformly by u, and a point on it drawn from u2 (area lights; the others
  // ignore the point).
  std::size_t pick_light(float u) const {
    return std::min(rs_.lights.size() - 1, static_cast<std::size_t>(u * static_cast<float>(rs_.lights.size())));
  }
  // *error: the point's rounding-error bound (SurfaceSample::error), which offsets rays leaving it.
  SurfacePoint sample_point(const RenderLight& l, glm::vec2 u2, vec3* error) const {
    *error = aperture_error(l);
    if (!l.is_area()) return {};
    const SurfaceSample ss = rs_.geometry->sample_shape(l.shape, u2);
    *error = ss.error;
    return {ss.position, ss.normal, l.pdf_pos};
  }
  // The error bound of a distant light's aperture points (zero for other lights): the aperture is
  // no shape, but it may coincide with one (a window pane).
  static vec3 aperture_error(const RenderLight& l) {
    const auto* d = std::get_if<DistantLightParams>(&l.params);
    return d ? parallelogram_error(d->corner, d->edge1, d->edge2) : vec3(0.0f);
  }
  // Where a point or spot light is (the integrator picks an area light's points itself).
  static vec3 light_position(const LightParams& l) {
    if (const auto* p = std::get_if<PointLightParams>(&l)) return p->position;
    if (const auto* p = std::get_if<SpotLightParams>(&l)) return p->position;
    return vec3(0.0f);
  }
  // Pixel coordinates of a raster position in [0,1)² (the product may round up to the width).
  void to_pixels(glm::vec2 raster, float* rx, float* ry) const {
    const float w = static_cast<float>(cam_.width), h = static_cast<float>(cam_.height);
    *rx = std::min(raster.x * w, std::nextafter(w, 0.0f));
    *ry = std::min(raster.y * h, std::nextafter(h, 0.0f));
  }

  // --- densities used by MIS ---
  // Solid-angle density at `v` of sampling the unit direction `wn`, given the unit direction
  // `wp` to v's other neighbour (null when it has none: a surface then has no density).
  float pdf_dir(const Vertex& v, const vec3* wp, const vec3& wn) const {
    switch (v.kind) {
      case Kind::kCamera: return sensor_pdf_dir(v, wn);
      case Kind::kLight: return light_pdf_dir(rs_.lights[static_cast<std::size_t>(v.light)], v, wn);
      case Kind::kSurface:
        return wp ? bsdf::pdf(*rs_.material_of_shape[static_cast<std::size_t>(v.shape)], *wp, wn, v.ns, v.n) : 0.0f;
      case Kind::kLens: return 0.0f;
    }
    return 0.0f;
  }
  // Area density at `next` of sampling it from `v` whose other neighbour is `prev`.
  float pdf(const Vertex* prev, const Vertex& v, const Vertex& next) const {
    const vec3 d = next.p - v.p;
    const float d2 = glm::dot(d, d);
    if (d2 == 0.0f) return 0.0f;
    const vec3 wn = d / std::sqrt(d2);
    const vec3 wp = prev ? glm::normalize(prev->p - v.p) : vec3(0.0f);
    return pdf_dir(v, prev ? &wp : nullptr, wn) * abs_cos(next, wn) / d2;  // solid angle at v to area at next
  }
  // Density of choosing the point `v` on its area light (for an eye vertex that hit it).
  float pdf_light_origin(const Vertex& v) const {
    const int li = rs_.light_of_shape[static_cast<std::size_t>(v.shape)];
    return light_pick_ * rs_.lights[static_cast<std::size_t>(li)].pdf_pos;
  }

  // --- subpaths ---
  template <TransportMode mode>  // a template: the walk's tests of its direction are not branches
  int random_walk(Thread& th, Sampler& rng, std::array<Vertex, kMaxVertices>& path, int count, vec3 o, vec3 d,
                  float pdf_dir, int max_vertices) const;
  int eye_subpath(Thread& th, Sampler& rng, int px, int py) const;
  int light_subpath(Thread& th, Sampler& rng) const;

  // --- connections ---
  // The five kinds of connection, one instantiation of connect() each, so that the kind is not a
  // branch taken anew (and mispredicted) on every call.
  enum class Connection {
    kEmitter,  // s = 0: the eye subpath's last vertex lies on an area light
    kLens,     // t = 0: the light subpath's last vertex lies on the lens
    kSplat,    // t = 1: a light vertex joined to a fresh sensor sample
    kNee,      // s = 1: an eye vertex joined to a fresh light sample
    kJoin,     // s, t >= 2: a shadow ray between two subpath vertices
    kDistant,  // distant-projection (0, DSD, t): an eye vertex joined to a distant light's aperture
    kOrtho,    // ortho-projection (s, DSD, 0): a light vertex joined to an orthographic film
  };
  // How a contribution's two subpaths are joined, as MIS must know it: a plain join (both join
  // letters D) or a projection connector, which builds the endpoint on its Dirac side.
  enum class JoinKind : std::uint8_t { kPlain, kDistant, kOrtho };
  // The profile's strategy running a connector at this subpath length, or -1.
  int distant_of(int t) const { return static_cast<std::size_t>(t) < kMaxRuns ? distant_of_[static_cast<std::size_t>(t)] : -1; }
  int ortho_of(int s) const { return static_cast<std::size_t>(s) < kMaxRuns ? ortho_of_[static_cast<std::size_t>(s)] : -1; }
  // Density of the far end of a parallel beam per unit area there, relative to the near end's:
  // points x and y on one line along w, with unit normals (zero: no surface), map areas as
  // dA_x |cos θ_x| = dA_y |cos θ_y|.
  static float parallel_jacobian(const Vertex& far, const Vertex& near, const vec3& w) {
    const float c = abs_cos(near, w);
    return c > 0.0f ? abs_cos(far, w) / c : 0.0f;
  }
  template <Connection C>
  void connect(Thread& th, Sampler& rng, int s, int t, int batch) const;
  // The mirror connector (s, DSD, t), s, t >= 1: y(s-1) (a fresh light sample for s = 1) joined to
  // z(t-1) (a fresh sensor sample for t = 1) across each planar mirror by the image method.
  void connect_mirror(Thread& th, Sampler& rng, int s, int t, int batch) const;
  int mirror_of(int s, int t) const {
    return static_cast<std::size_t>(s) < kMaxRuns && static_cast<std::size_t>(t) < kMaxRuns
               ? mirror_of_[static_cast<std::size_t>(s) * kMaxRuns + static_cast<std::size_t>(t)]
               : -1;
  }
  // --- MIS over whole paths, for profiles with the mirror connector ---
  // Which strategy sampled a contribution, for path_weight().
  enum class SelfKind : std::uint8_t { kPlain, kDistant, kOrtho, kMirror };
  // Puts the path x0 … xk of a contribution into th.path: s light vertices (fresh_light for y0 when
  // given), `middle` when given (the mirror vertex), t eye vertices (fresh_eye for z0 when given).
  void gather(Thread& th, int s, int t, const Vertex* fresh_light, const Vertex* middle, const Vertex* fresh_eye) const;
  // Whether the path of connection (s, t) with letters `key` could also be sampled by the mirror
  // connector (then every strategy weighs it with path_weight()).
  bool mirror_can_sample(const Thread& th, int s, int t, PathKey key) const;
  // The power-heuristic weight of strategy `self` (kPlain: split s; kMirror: mirror vertex x_s)
  // for the path in th.path with letters `key`, from every vertex's two area densities.
  float path_weight(Thread& th, PathKey key, SelfKind self, int s) const;
  // What connect() has already computed for its join, handed to mis_weight() so that it is not
  // computed twice: the unit direction w from the light end qs to the eye end pt, their squared
  // distance, and the BSDF densities at each end that its BSDF evaluation gave for free.
  struct Join {
    vec3 w{0.0f};
    float d2 = 0.0f;
    bsdf::JoinPdfs at_qs;  // wo = qs->wo, wi = w
    bsdf::JoinPdfs at_pt;  // wo = pt->wo, wi = -w
  };
  float mis_weight(const Thread& th, int s, int t, const Vertex* sampled, PathKey key, const Join* join = nullptr,
                   JoinKind self = JoinKind::kPlain) const;
  // The full-path letters of the path made by s light and t eye vertices (with `sampled`
  // replacing y0 for s = 1 or z0 for t = 1), join letters set to D. "" if the path is too short.
  // Writes into `out`, a per-thread buffer, so that labelling allocates nothing.
  void full_path(const Thread& th, int s, int t, const Vertex* sampled, std::string& out) const;
  void record(Thread& th, const Pending& r) const;
  void trace_shadows(Thread& th) const;

  const RenderScene& rs_;
  const RenderSensor& cam_;
  const StrategySet& strategies_;
  const RenderOptions& o_;
  const Classifier* classifier_;
  int max_bounces_ = 16;
  static constexpr std::size_t kMaxRuns = 2 * kMaxVertices;
  std::vector<std::int16_t> strategy_of_;  // [s * kMaxRuns + t]: the profile's strategy running (s, t), or -1
  std::array<std::int16_t, kMaxRuns> distant_of_{}, ortho_of_{};  // see distant_of(), ortho_of()
  bool has_connectors_ = false;
  std::vector<std::int16_t> mirror_of_;  // [s * kMaxRuns + t]: the profile's mirror strategy at (s, t), or -1
  bool has_mirror_ = false;              // a mirror strategy runs and the scene has a planar mirror
  std::vector<std::uint8_t> mirror_shape_;  // the shape is a planar mirror
  // [n]: bit s2 set when the profile runs (s2, n - s2) and, for n - s2 = 0, light paths can hit the
  // lens. A full path has s + t = k + 1 <= max_bounces + 2 < 64 (kMaxVertices bounds max_bounces).
  static_assert(kMaxVertices <= 64, "runs_mask_ holds s + t <= kMaxVertices - 1");
  std::array<std::uint64_t, 64> runs_mask_{};
  // The profile runs every (s, t) with t >= 1 (full BDPT), and (s, 0) for all s or none
  // (eye0_runs_): which strategies sample a path then depends on its letters alone, so the MIS
  // sums over each subpath's fixed part are computed once per sample (prepare_joins()).
  bool all_runs_ = false;
  bool eye0_runs_ = false;
  std::vector<std::uint8_t> finite_of_shape_;  // the shape's material has a finite BSDF part
  std::string sensor_pair_;               // the sensor's letters c(k+1) c(k+2)
  std::vector<std::string> light_pairs_;  // each light's letters c0 c1
  int max_light_ = 0;  // longest light subpath any strategy uses (0: none)
  int max_eye_ = 1;    // longest eye subpath any strategy uses
  float light_pick_ = 0.0f;
  bool lens_hits_ = false;
};

template <TransportMode mode>
int Integrator::random_walk(Thread& th, Sampler& rng, std::array<Vertex, kMaxVertices>& path, int count, vec3 o, vec3 d,
                            float pdf_dir, int max_vertices) const {
  vec3 beta = path[static_cast<std::size_t>(count - 1)].beta;
  // Russian roulette compares the throughput with the subpath's start, so that a light subpath
  // (whose throughput starts at the light's power) is treated like an eye subpath.
  const float beta_start = std::max(max_component(beta), 1e-30f);
  float eta2 = 1.0f;  // the product of η² over the refractions so far (radiance walks)
  // `beta` passed in the first vertex already includes the first direction's weight: the caller
  // stores it in path[count - 1].beta and we continue from there.
  SubpathPrefix live(o_.only, mode == TransportMode::kImportance, path[0].pos_letter, path[0].letter);  // trace/prune.h
  while (count < max_vertices && live.alive()) {
    Vertex& prev = path[static_cast<std::size_t>(count - 1)];
    ++th.rays;
    const std::optional<Hit> hit = rs_.geometry->intersect(o, d, prev.n, prev.err, HitDetail::kNoUv);  // zero for points: no offset
    // --- a light subpath may end on the lens (strategy t = 0) ---
    if (mode == TransportMode::kImportance && lens_hits_) {
      const std::optional<EndpointConnection> lens = hit_lens(cam_.params, o, d);
      if (lens && (!hit || lens->distance < hit->t)) {
        Vertex& v = path[static_cast<std::size_t>(count)];
        v = Vertex{};
        v.kind = Kind::kLens;
        v.p = lens->position;
        v.n = lens->normal;
        v.ns = lens->normal;
        v.beta = beta;
        link(v, prev);
        v.pdf_fwd = v.d2_wo > 0.0f ? pdf_dir * std::fabs(glm::dot(v.n, d)) / v.d2_wo : 0.0f;
        v.letter = 'D';
        v.pos_letter = 'D';
        return count + 1;
      }
    }
    if (!hit) break;
    Vertex& v = path[static_cast<std::size_t>(count)];
    v = Vertex{};
    v.kind = Kind::kSurface;
    v.p = hit->position;
    v.n = hit->normal;
    v.err = hit->error;
    v.ns = hit->shading_normal;
    v.shape = hit->shape;
    v.finite = finite_of_shape_[static_cast<std::size_t>(v.shape)] != 0;
    v.wo = -d;
    const vec3 e = v.p - prev.p;
    v.d2_wo = glm::dot(e, e);
    v.beta = beta;
    // Solid angle at prev to area at v, along the unit ray direction d.
    // 0 for coincident points (and a subnormal distance, whose inverse would overflow): no density.
    const float inv_d2 = v.d2_wo >= std::numeric_limits<float>::min() ? 1.0f / v.d2_wo : 0.0f;
    const float to_area_v = std::fabs(glm::dot(v.n, d)) * inv_d2;
    v.pdf_fwd = pdf_dir * to_area_v;
    ++count;
    if (count >= max_vertices) break;
    // --- scatter ---
    const Material& m = *rs_.material_of_shape[static_cast<std::size_t>(v.shape)];
    const vec3 wo = -d;
    const float u_comp = rng.get1d();
    const glm::vec2 u = rng.get2d();
    const std::optional<BsdfSample> bs = bsdf::sample(m, wo, v.ns, v.n, u_comp, u, mode);
    if (!bs || is_black(bs->weight) || bs->pdf <= 0.0f) break;
    v.letter = letter_char(bs->letter);
    beta *= bs->weight * bsdf::shading_normal_correction(wo, bs->wi, v.ns, v.n, mode);
    // A Dirac's densities stay symbolic: 0 here, remapped to 1 in the MIS ratios, and every
    // strategy that would join at this vertex is excluded by its letter S.
    pdf_dir = bs->is_delta ? 0.0f : bs->pdf;
    const float pdf_rev_dir = bs->is_delta ? 0.0f : bs->pdf_rev;
    prev.pdf_rev = pdf_rev_dir * abs_cos(prev, d) * inv_d2;
    // --- Russian roulette, never mislabelling: the vertices so far stay valid prefixes ---
    // From vertex rr_depth on, a walk whose throughput relative to its start (a refraction's
    // radiance scaling 1/η² undone, so that entering glass is no loss) is below rr_threshold
    // survives with probability throughput / threshold, and a survivor carries the threshold.
    if (mode == TransportMode::kRadiance) eta2 *= bs->eta * bs->eta;
    if (count >= o_.rr_depth && o_.rr_threshold > 0.0f) {
      const float u_rr = rng.get1d();  // drawn at every vertex, so the dimensions stay aligned
      const float survive = max_component(beta) * eta2 / (beta_start * o_.rr_threshold);
      if (survive < 1.0f) {
        if (u_rr >= survive) break;
        beta *= 1.0f / survive;
      }
    }
    o = v.p;
    d = bs->wi;
    if (!std::isfinite(beta.x + beta.y + beta.z)) break;
    live.extend(v.letter);  // --only: a subpath no requested class can complete stops (DESIGN §11)
  }
  return count;
}

int Integrator::eye_subpath(Thread& th, Sampler& rng, int px, int py) const {
  Vertex& z0 = th.eye[0];
  z0 = Vertex{};
  z0.kind = Kind::kCamera;
  z0.beta = vec3(1.0f);
  z0.letter = sensor_pair_[0];
  z0.pos_letter = sensor_pair_[1];
  const glm::vec2 uf = rng.get2d();
  const glm::vec2 ul = rng.get2d();
  const glm::vec2 raster{(static_cast<float>(px) + uf.x) / static_cast<float>(cam_.width),
                         (static_cast<float>(py) + uf.y) / static_cast<float>(cam_.height)};
  const std::optional<EndpointRay> r = sample_ray(cam_.params, raster, ul);
  z0.pdf_fwd = cam_.pdf_pos;
  if (!r) return 1;
  z0.p = r->origin;
  z0.n = r->pdf.delta_pos ? vec3(0.0f) : r->normal;  // a point sensor has no surface
  z0.ns = z0.n;
  // Importance over the sampling density is 1 for every sensor: pixel values are radiance.
  const int n = random_walk<TransportMode::kRadiance>(th, rng, th.eye, 1, r->origin, r->direction,
                                                      finite_part(r->pdf.dir, r->pdf.delta_dir), max_eye_);
  // An orthographic sensor's rays are a parallel beam (see light_subpath()).
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.eye[1].pdf_fwd = parallel_jacobian(th.eye[1], z0, r->direction);
  return n;
}

int Integrator::light_subpath(Thread& th, Sampler& rng) const {
  if (rs_.lights.empty() || max_light_ == 0) return 0;
  const std::size_t li = pick_light(rng.get1d());
  const RenderLight& l = rs_.lights[li];
  Vertex& y0 = th.light[0];
  y0 = Vertex{};
  y0.kind = Kind::kLight;
  y0.light = static_cast<int>(li);
  y0.pos_letter = light_pairs_[li][0];
  y0.letter = light_pairs_[li][1];
  const SurfacePoint x = sample_point(l, rng.get2d(), &y0.err);
  const std::optional<EndpointRay> r = sample_ray(l.params, x, rng.get2d());
  y0.pdf_fwd = light_pick_ * l.pdf_pos;  // 0 for Dirac positions
  if (!r) {  // no emission from this sample: y0 alone, carrying nothing
    y0.p = x.position;
    y0.beta = vec3(0.0f);
    return 1;
  }
  y0.p = r->origin;
  y0.n = r->normal;
  y0.ns = y0.n;
  // y0 keeps the spatial part of the emission, L_e⁽⁰⁾ / p (a join at y0 evaluates the directional
  // part); the walk continues with the first ray's whole throughput.
  y0.beta = spatial_emission(l.params) / (light_pick_ * (r->pdf.delta_pos ? 1.0f : r->pdf.pos));
  const vec3 beta1 = r->weight / light_pick_;
  if (is_black(beta1)) return 1;
  const vec3 saved = y0.beta;
  th.light[0].beta = beta1;
  const int n = random_walk<TransportMode::kImportance>(th, rng, th.light, 1, y0.p, r->direction,
                                                        finite_part(r->pdf.dir, r->pdf.delta_dir), max_light_);
  th.light[0].beta = saved;
  // A Dirac direction from a finite-area origin (a distant light's aperture) is a parallel beam:
  // its first vertex has a finite density per area, which the distant-projection connector's
  // MIS weight compares with the eye's.
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.light[1].pdf_fwd = parallel_jacobian(th.light[1], y0, r->direction);
  return n;
}

void Integrator::full_path(const Thread& th, int s, int t, const Vertex* sampled, std::string& out) const {
  const int k = s + t - 1;
  out.clear();
  if (k < 1) return;
  out.assign(static_cast<std::size_t>(k) + 5, 'D');  // L c0 … c(k+2) E: c_i is out[i + 1]
  out.front() = 'L';
  out.back() = 'E';
  auto vertex = [&](int i) -> const Vertex& {  // x_i in light-to-eye order
    // A fresh sensor sample replaces z0 when t = 1; otherwise a fresh light sample replaces y0 when s = 1.
    if (i < s) return (s == 1 && t != 1 && i == 0 && sampled) ? *sampled : th.light[static_cast<std::size_t>(i)];
    const int j = k - i;
    return (t == 1 && j == 0 && sampled) ? *sampled : th.eye[static_cast<std::size_t>(j)];
  };
  auto c = [&](int i) -> char& { return out[static_cast<std::size_t>(i) + 1]; };
  // Light end: for s = 0 the eye path hit an area light, DD.
  if (s > 0) {
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
}

float Integrator::mis_weight(const Thread& th, int s, int t, const Vertex* sampled, PathKey key, const Join* join,
                             JoinKind self) const {
  // Strategy (s2, t2) samples this string when the profile runs it and its join letters c(s2),
  // c(s2+1) are both D: one mask for all of them, bit s2 (runs_mask_ holds the profile's part).
  // When no other strategy can sample this string (pt, lt, and many strings of every profile),
  // the weight is 1 and no density needs recomputing.
  const int n = s + t;
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));  // bit i: c_i and c_(i+1) are D
  std::uint64_t others = runs_mask_[static_cast<std::size_t>(n)] & d_pairs;
  if (self == JoinKind::kPlain) others &= ~(std::uint64_t{1} << s);
  // The projection connectors sample the split (1, n - 1) of strings beginning DSD (a distant
  // light) and the split (n - 1, 1) of strings ending DSD (an orthographic sensor). Their density
  // is the plain split's with the projected endpoint's area density (light choice aside) replaced
  // by 1, so their ratios to the plain recurrence's carry a factor 1 / pdf_pos (`conn_w2`, squared).
  double conn_w2_first = 0.0, conn_w2_last = 0.0, self_w2 = 1.0;
  if (has_connectors_) {
    const auto dsd_at = [&](int i) { return ((key >> i) & 7) == 2; };  // c_i c_(i+1) c_(i+2) = DSD
    if (n - 1 >= 1 && distant_of(n - 1) >= 0 && dsd_at(0) && !(self == JoinKind::kDistant)) {
      const Vertex& x0 = s == 1 && t != 1 && sampled ? *sampled : th.light[0];
      const double pos = rs_.lights[static_cast<std::size_t>(x0.light)].pdf_pos;
      conn_w2_first = 1.0 / (pos * pos);
      others |= std::uint64_t{1} << 1;
    }
    if (n - 1 >= 1 && ortho_of(n - 1) >= 0 && dsd_at(n - 1) && !(self == JoinKind::kOrtho)) {
      conn_w2_last = 1.0 / (static_cast<double>(cam_.pdf_pos) * cam_.pdf_pos);
      others |= std::uint64_t{1} << (n - 1);
    }
    if (self == JoinKind::kDistant) {
      const double pos = rs_.lights[static_cast<std::size_t>((sampled ? *sampled : th.light[0]).light)].pdf_pos;
      self_w2 = pos * pos;
    }
    if (self == JoinKind::kOrtho) self_w2 = static_cast<double>(cam_.pdf_pos) * cam_.pdf_pos;
  }
  if (others == 0) return 1.0f;
  // The loops below reach only as far as the farthest strategy that can: the light side down to
  // s2 = light_lo, the eye side up to s2 = eye_hi; densities beyond are not needed.
  const std::uint64_t below = others & ((std::uint64_t{1} << s) - 1), above = others & ~below;
  const int light_lo = below != 0 ? std::countr_zero(below) : s;
  const int eye_hi = above != 0 ? 63 - std::countl_zero(above) : s;
  const int eye_lo = n - eye_hi;  // the eye loop's last index: t when it does not run
  const std::array<Vertex, kMaxVertices>& L = th.light;
  const std::array<Vertex, kMaxVertices>& E = th.eye;
  // The join's vertices; a fresh sample stands for z0 when t = 1, else for y0 when s = 1.
  const Vertex* qs = s > 0 ? (s == 1 && t != 1 && sampled ? sampled : &L[static_cast<std::size_t>(s - 1)]) : nullptr;
  const Vertex* pt = t > 0 ? (t == 1 && sampled ? sampled : &E[static_cast<std::size_t>(t - 1)]) : nullptr;
  const Vertex* qsm = s > 1 ? &L[static_cast<std::size_t>(s - 2)] : nullptr;
  const Vertex* ptm = t > 1 ? &E[static_cast<std::size_t>(t - 2)] : nullptr;
  // --- the four reverse densities the join changes (the subpaths themselves stay untouched) ---
  // Every direction is at hand: the join's (w, from qs to pt, at squared distance d2) and each
  // vertex's unit direction to its predecessor (wo, at d2_wo); no normalisation is needed.
  // Area density at `next` from solid-angle density `pdf_w` along unit `w` over squared distance `dist2`.
  const auto area = [](float pdf_w, const Vertex& next, const vec3& w, float dist2) {
    return dist2 > 0.0f ? pdf_w * abs_cos(next, w) / dist2 : 0.0f;
  };
  float rev_qs = 0.0f, rev_pt = 0.0f, rev_qsm = 0.0f, rev_ptm = 0.0f;
  const bool need_pt = eye_lo <= t - 1, need_ptm = ptm && eye_lo <= t - 2;
  const bool need_qs = light_lo <= s - 1, need_qsm = qsm && light_lo <= s - 2;
  if (qs && pt) {
    Join own;
    if (join == nullptr) {
      const vec3 e = pt->p - qs->p;
      own.d2 = glm::dot(e, e);
      own.w = own.d2 > 0.0f ? e * (1.0f / std::sqrt(own.d2)) : vec3(0.0f);  // as connect() forms it
      join = &own;
    }
    const vec3 w = join->w, back = -w;
    const float d2 = join->d2;
    const bsdf::JoinPdfs& at_qs = join->at_qs;
    const bsdf::JoinPdfs& at_pt = join->at_pt;
    if (need_pt) rev_pt = area(at_qs.known ? at_qs.to_wi : pdf_dir(*qs, qsm ? &qs->wo : nullptr, w), *pt, w, d2);
    if (need_qs) rev_qs = area(at_pt.known ? at_pt.to_wi : pdf_dir(*pt, ptm ? &pt->wo : nullptr, back), *qs, w, d2);
    // A connector's endpoint sends a parallel beam: the density at the other end is per area.
    if (self == JoinKind::kDistant) rev_pt = parallel_jacobian(*pt, *qs, w);
    if (self == JoinKind::kOrtho) rev_qs = parallel_jacobian(*qs, *pt, w);
    if (need_ptm) rev_ptm = area(at_pt.known ? at_pt.to_wo : pdf_dir(*pt, &back, pt->wo), *ptm, pt->wo, pt->d2_wo);
    if (need_qsm) rev_qsm = area(at_qs.known ? at_qs.to_wo : pdf_dir(*qs, &w, qs->wo), *qsm, qs->wo, qs->d2_wo);
  } else if (pt) {  // s = 0: pt lies on an area light
    rev_pt = pdf_light_origin(*pt);
    if (need_ptm) {
      const RenderLight& l = rs_.lights[static_cast<std::size_t>(rs_.light_of_shape[static_cast<std::size_t>(pt->shape)])];
      rev_ptm = area(light_pdf_dir(l, *pt, pt->wo), *ptm, pt->wo, pt->d2_wo);
    }
  } else if (qs) {  // t = 0: qs is the lens point
    rev_qs = cam_.pdf_pos;
    if (need_qsm) rev_qsm = area(sensor_pdf_dir(*qs, qs->wo), *qsm, qs->wo, qs->d2_wo);
  }
  // --- hypothetical strategies: shorter eye subpaths, then shorter light subpaths ---
  // Ratios in double: long paths multiply many of them. Dirac densities are stored as 0 and
  // count as 1 here; their strategies are excluded by letter.
  double sum = 0.0;
  const auto runs = [&](int s2) { return static_cast<double>((others >> s2) & 1); };
  // The term of strategy s2 for density ratio ri (a connector's carries its factor; profiles
  // without connectors never take the branch).
  const auto term = [&](int s2, double ri) {
    double r2 = ri * ri;
    if (has_connectors_) [[unlikely]]
      r2 *= s2 == 1 && conn_w2_first != 0.0 ? conn_w2_first : s2 == n - 1 && conn_w2_last != 0.0 ? conn_w2_last : 1.0;
    return r2;
  };
  if (all_runs_) {
    // Each side: the join's two ratios, then the subpath's fixed part from prepare_joins().
    if (eye_lo <= t - 1) {
      const double a = remap(rev_pt) * (t == 1 && sampled ? inv_fwd(*pt) : th.eye_inv_fwd[static_cast<std::size_t>(t - 1)]);
      const double a2 = a * a;
      sum += a2 * runs(n - (t - 1));
      if (need_ptm) {
        const double b = remap(rev_ptm) * th.eye_inv_fwd[static_cast<std::size_t>(t - 2)];
        sum += a2 * b * b * (runs(n - (t - 2)) + (t >= 3 ? th.eye_acc[static_cast<std::size_t>(t - 3)] : 0.0));
      }
    }
    if (light_lo <= s - 1) {
      const double a = remap(rev_qs) * (qs != &L[static_cast<std::size_t>(s - 1)] ? inv_fwd(*qs) : th.light_inv_fwd[static_cast<std::size_t>(s - 1)]);
      const double a2 = a * a;
      sum += a2 * runs(s - 1);
      if (need_qsm) {
        const double b = remap(rev_qsm) * th.light_inv_fwd[static_cast<std::size_t>(s - 2)];
        sum += a2 * b * b * (runs(s - 2) + (s >= 3 ? th.light_acc[static_cast<std::size_t>(s - 3)] : 0.0));
      }
    }
    return static_cast<float>(1.0 / (1.0 + sum));
  }
  double ri = 1.0;
  for (int i = t - 1; i >= eye_lo; --i) {
    ri *= i == t - 1   ? remap(rev_pt) / remap(pt->pdf_fwd)
          : i == t - 2 ? remap(rev_ptm) / remap(E[static_cast<std::size_t>(i)].pdf_fwd)
                       : th.eye_ratio[static_cast<std::size_t>(i)];
    if ((others >> (n - i)) & 1) sum += term(n - i, ri);
  }
  ri = 1.0;
  for (int i = s - 1; i >= light_lo; --i) {
    ri *= i == s - 1   ? remap(rev_qs) / remap(qs->pdf_fwd)
          : i == s - 2 ? remap(rev_qsm) / remap(L[static_cast<std::size_t>(i)].pdf_fwd)
                       : th.light_ratio[static_cast<std::size_t>(i)];
    if ((others >> i) & 1) sum += term(i, ri);
  }
  return static_cast<float>(1.0 / (1.0 + sum * self_w2));
}

void Integrator::record(Thread& th, const Pending& r) const {
  if (o_.only != nullptr && !o_.only->records(r.key)) return;  // --only: not a requested path
  const Rgb rgb{r.c.x, r.c.y, r.c.z};
  ExactRgb e;
  if (!to_exact(rgb, &e)) {
    th.hist.add_nonfinite();
    if (!th.first_nonfinite)
      th.first_nonfinite = NonfiniteSample{strategies_.strategies[static_cast<std::size_t>(r.strategy)].name, unpack(r.key),
                                           th.pass, r.px, th.py};
    return;
  }
  if (is_zero(e)) return;
  const auto [id, row] = th.ids.get(th.hist, r.key, r.technique);
  th.hist.add_exact_at_row(id, row, r.batch, e);
  if (!o_.images) return;
  const std::uint32_t set = th.hist.class_set(id);
  if (r.splat) th.splats.add(*th.images, static_cast<int>(r.rx), static_cast<int>(r.ry), set, e);
  else th.row[static_cast<std::size_t>(r.px)].add(set, e);
}

template <Integrator::Connection C>
void Integrator::connect(Thread& th, Sampler& rng, int s, int t, int batch) const {
  constexpr bool by_light = C == Connection::kSplat || C == Connection::kOrtho || C == Connection::kLens;
  rng.set_dimension(kJoinDims + (static_cast<std::uint64_t>(C) * kMaxRuns + static_cast<std::uint64_t>(by_light ? s : t)) * kDimsPerJoin);
  constexpr JoinKind kind = C == Connection::kDistant ? JoinKind::kDistant : C == Connection::kOrtho ? JoinKind::kOrtho : JoinKind::kPlain;
  const int strategy_index = C == Connection::kDistant ? distant_of(t) : C == Connection::kOrtho ? ortho_of(s) : strategy(s, t);
  ConnectorStats* stats = kind != JoinKind::kPlain ? &th.connectors[static_cast<std::size_t>(strategy_index)] : nullptr;
  PathKey chain_s = 0;  // a connector's S letter
  vec3 contrib{0.0f};
  Vertex& sampled = th.sampled;
  bool splat = false;
  float rx = 0.0f, ry = 0.0f;
  const Vertex* qs = s > 0 ? &th.light[static_cast<std::size_t>(s - 1)] : nullptr;
  const Vertex* pt = t > 0 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
  Join join;
  bool joined = false;  // `join` describes this connection (every case but s = 0 and t = 0)
  std::array<const Vertex*, 2> ends{};  // the shadow ray's ends, in the order visible() takes them
  if constexpr (C == Connection::kEmitter) {
    // --- eye path hits an area light ---
    if (pt->kind != Kind::kSurface) return;
    const int li = rs_.light_of_shape[static_cast<std::size_t>(pt->shape)];
    if (li < 0) return;
    const LightParams& l = rs_.lights[static_cast<std::size_t>(li)].params;
    contrib = pt->beta * spatial_emission(l) * directional_emission(l, pt->n, pt->wo);
  } else if constexpr (C == Connection::kLens) {
    // --- light path hits the lens ---
    if (qs->kind != Kind::kLens) return;
    glm::vec2 raster;
    const vec3 we = importance(cam_.params, qs->p, qs->wo, &raster);
    if (is_black(we)) return;
    to_pixels(raster, &rx, &ry);
    contrib = qs->beta * we;
    splat = true;
  } else if constexpr (C == Connection::kSplat || C == Connection::kOrtho) {
    // --- a light vertex joined to a sensor point: a fresh one (the splat, t = 1) or, for
    //     ortho-projection, the film point on the line of sight through qs ---
    if (qs->kind == Kind::kLens || !qs->finite) return;
    std::optional<EndpointConnection> c;
    if constexpr (C == Connection::kSplat) {
      if (sensor_pair_[0] != 'D') return;  // a Dirac direction (orthographic, spot meter): no DD join
      c = connect_finite(cam_.params, rng.get2d(), qs->p);
      if (!c) return;
    } else {
      const auto* film = std::get_if<OrthographicParams>(&cam_.params);
      if (film == nullptr) return;
      ++stats->attempts;
      c = pathex::connect(*film, qs->p);
      if (!c) {
        ++stats->outside;
        return;
      }
      chain_s = bit(s + 1);  // c(k+1), the sensor's direction
    }
    sampled = Vertex{};
    sampled.kind = Kind::kCamera;
    sampled.p = c->position;
    sampled.n = cam_.pdf_pos == 0.0f ? vec3(0.0f) : c->normal;  // a pinhole is a point
    sampled.ns = sampled.n;
    sampled.letter = C == Connection::kSplat ? 'D' : sensor_pair_[0];
    sampled.pos_letter = sensor_pair_[1];
    sampled.pdf_fwd = cam_.pdf_pos;
    const vec3 w = c->wi;  // from qs to the sensor
    to_pixels(c->raster, &rx, &ry);
    vec3 fq;
    // A light vertex's beta already holds its spatial emission; only the directional part is left.
    if (qs->kind == Kind::kLight) fq = vec3(directional_emission(rs_.lights[static_cast<std::size_t>(qs->light)].params, qs->n, w));
    else fq = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(qs->shape)],
                        qs->wo, w, qs->ns, qs->n, &join.at_qs);
    join.w = w;
    join.d2 = c->distance * c->distance;
    joined = true;
    contrib = qs->beta * fq * (abs_cos(*qs, w) * c->weight);  // weight: We cos / d² (splat), We (film)
    ends = {qs, &sampled};
    splat = true;
  } else if constexpr (C == Connection::kNee || C == Connection::kDistant) {
    // --- an eye vertex joined to a light point: a fresh light sample (next-event estimation) or,
    //     for distant-projection, the aperture point on the line through pt against the light ---
    if (pt->kind != Kind::kSurface || !pt->finite || rs_.lights.empty()) return;
    const std::size_t li = pick_light(rng.get1d());
    const RenderLight& l = rs_.lights[li];
    std::optional<EndpointConnection> c;
    vec3 err{0.0f};  // the light point's rounding-error bound, which offsets the shadow ray
    if constexpr (C == Connection::kNee) {
      const glm::vec2 up = rng.get2d();
      if (light_pairs_[li][1] != 'D') return;  // Dirac directions (distant, laser): no DD join
      c = pathex::connect(l.params, sample_point(l, up, &err), pt->p);
      if (!c) return;
    } else {
      if (!std::holds_alternative<DistantLightParams>(l.params)) return;  // the light picked is not distant
      ++stats->attempts;
      c = pathex::connect(l.params, SurfacePoint{}, pt->p);
      if (!c) {
        ++stats->outside;
        return;
      }
      err = aperture_error(l);
      chain_s = bit(1);  // c1, the light's direction
    }
    sampled = Vertex{};
    sampled.kind = Kind::kLight;
    sampled.light = static_cast<int>(li);
    sampled.pos_letter = light_pairs_[li][0];
    sampled.letter = C == Connection::kNee ? 'D' : light_pairs_[li][1];
    sampled.p = c->position;
    sampled.n = c->normal;
    sampled.err = err;
    sampled.ns = sampled.n;
    sampled.pdf_fwd = light_pick_ * l.pdf_pos;
    const vec3 w = c->wi;  // from pt to the light
    const vec3 f = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(pt->shape)],
                             pt->wo, w, pt->ns, pt->n, &join.at_pt);
    join.w = -w;  // w runs from pt to the light, the join's from the light to pt
    join.d2 = c->distance * c->distance;
    joined = true;
    contrib = pt->beta * f * (abs_cos(*pt, w) / light_pick_) * c->weight;  // weight: Le cos / (p d²), I / d², E
    ends = {pt, &sampled};
  } else {
    // --- a shadow ray between y(s-1) and z(t-1) ---
    if (qs->kind == Kind::kLens || pt->kind != Kind::kSurface || qs->kind != Kind::kSurface) return;
    if (!qs->finite || !pt->finite) return;
    const vec3 d = pt->p - qs->p;
    const float d2 = glm::dot(d, d);
    if (d2 <= 0.0f) return;
    const vec3 w = d * (1.0f / std::sqrt(d2));  // one division, not three
    const vec3 fq = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(qs->shape)],
                              qs->wo, w, qs->ns, qs->n, &join.at_qs);
    const vec3 fp = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(pt->shape)],
                              pt->wo, -w, pt->ns, pt->n, &join.at_pt);
    join.w = w;
    join.d2 = d2;
    joined = true;
    const float g = abs_cos(*qs, w) * abs_cos(*pt, w) / d2;
    contrib = qs->beta * fq * fp * pt->beta * g;
    ends = {qs, pt};
  }
  if (is_black(contrib)) {
    if (stats) ++stats->no_transport;
    return;
  }
  const Vertex* fresh = C == Connection::kSplat || C == Connection::kNee || kind != JoinKind::kPlain ? &sampled : nullptr;
  if (!th.joins_ready) prepare_joins(th, th.ns, th.nt);
  const PathKey key = path_key(th, s, t, fresh) | chain_s;
  if (o_.only != nullptr && !o_.only->records(key)) return;  // --only: no MIS weight, no shadow ray for it
  float weight = 0.0f;
  if (has_mirror_ && mirror_can_sample(th, s, t, key)) {
    constexpr bool fresh_eye = C == Connection::kSplat || C == Connection::kOrtho;
    gather(th, s, t, fresh && !fresh_eye ? fresh : nullptr, nullptr, fresh_eye ? fresh : nullptr);
    weight = path_weight(th, key, kind == JoinKind::kDistant ? SelfKind::kDistant : kind == JoinKind::kOrtho ? SelfKind::kOrtho : SelfKind::kPlain, s);
  } else {
    weight = mis_weight(th, s, t, fresh, key, joined ? &join : nullptr, kind);
  }
  const int technique =
      Technique{strategy_index, C == Connection::kDistant ? 0 : s, C == Connection::kOrtho ? 0 : t, kind != JoinKind::kPlain}.code();
  const Pending r{key, contrib * weight, strategy_index, batch, technique, splat, stats != nullptr, rx, ry, th.px};
  if constexpr (C == Connection::kEmitter || C == Connection::kLens) {
    record(th, r);  // no shadow ray: the path's last edge was traced
  } else {
    // The weight is known before the shadow ray is: the ray joins the thread's batch, and the
    // contribution is recorded if the batch finds the segment unobstructed.
    ++th.rays;
    th.pending[static_cast<std::size_t>(th.shadow.add(*rs_.geometry, ends[0]->p, ends[0]->n, ends[0]->err, ends[1]->p, ends[1]->n, ends[1]->err))] = r;
    if (th.shadow.full()) trace_shadows(th);
  }
}

// --- the mirror connector ---

void Integrator::connect_mirror(Thread& th, Sampler& rng, int s, int t, int batch) const {
  const int strategy_index = mirror_of(s, t);
  ConnectorStats& stats = th.connectors[static_cast<std::size_t>(strategy_index)];
  // Random numbers: a fresh light sample's from one block per t, a fresh sensor sample's from one
  // block per s, after the seven blocks of connect()'s kinds.
  constexpr std::uint64_t kLightBlock = 7, kEyeBlock = 8;
  // --- the light end a: y(s-1), or a fresh light sample ---
  const Vertex* a = s >= 2 ? &th.light[static_cast<std::size_t>(s - 1)] : nullptr;
  const RenderLight* light = nullptr;
  if (a) {
    if (a->kind != Kind::kSurface || !a->finite) return;
  } else {
    if (rs_.lights.empty()) return;
    rng.set_dimension(kJoinDims + (kLightBlock * kMaxRuns + static_cast<std::uint64_t>(t)) * kDimsPerJoin);
    const std::size_t li = pick_light(rng.get1d());
    light = &rs_.lights[li];
    const glm::vec2 up = rng.get2d();
    if (light_pairs_[li][1] != 'D') return;  // a Dirac direction (distant, laser): no D end
    Vertex& y0 = th.sampled;
    y0 = Vertex{};
    y0.kind = Kind::kLight;
    y0.light = static_cast<int>(li);
    y0.pos_letter = light_pairs_[li][0];
    y0.letter = 'D';
    const SurfacePoint x = sample_point(*light, up, &y0.err);
    y0.p = light->is_area() ? x.position : light_position(light->params);
    y0.n = light->is_area() ? x.normal : vec3(0.0f);
    y0.ns = y0.n;
    y0.pdf_fwd = light_pick_ * light->pdf_pos;
    y0.beta = spatial_emission(light->params) / (light_pick_ * (light->pdf_pos > 0.0f ? light->pdf_pos : 1.0f));
    a = &y0;
  }
  // --- the eye end b: z(t-1), or (t = 1) a fresh sensor sample drawn per mirror ---
  const Vertex* b = t >= 2 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
  glm::vec2 u_lens{0.0f};
  if (b) {
    if (b->kind != Kind::kSurface || !b->finite) return;
  } else {
    if (sensor_pair_[0] != 'D') return;  // a Dirac direction (orthographic, spot meter): no D end
    rng.set_dimension(kJoinDims + (kEyeBlock * kMaxRuns + static_cast<std::uint64_t>(s)) * kDimsPerJoin);
    u_lens = rng.get2d();
  }
  if (!th.joins_ready) prepare_joins(th, th.ns, th.nt);
  // The letters: y(s-1)'s c(s) = D, the mirror's c(s+1) = S, z(t-1)'s c(s+2) = D.
  const PathKey light_part = s == 1 ? letter_bit(a->pos_letter, 0) : th.light_mask & (bit(s) - 1);
  const PathKey key = light_part | bit(s + 1) | ((th.eye_masks[static_cast<std::size_t>(t)] << (s + 2)) & ~bit(s + 2)) |
                      static_cast<PathKey>(s + t + 3) << kLengthShift;
  for (const PlanarMirror& mirror : rs_.mirrors) {
    ++stats.attempts;
    float rx = 0.0f, ry = 0.0f;
    std::optional<EndpointConnection> c;  // t = 1: the sensor's join to a's image
    if (t == 1) {
      c = connect_finite(cam_.params, u_lens, mirror_image(mirror, a->p));
      if (!c) {
        ++stats.outside;
        continue;
      }
      Vertex& z0 = th.sampled_eye;
      z0 = Vertex{};
      z0.kind = Kind::kCamera;
      z0.p = c->position;
      z0.n = cam_.pdf_pos == 0.0f ? vec3(0.0f) : c->normal;
      z0.ns = z0.n;
      z0.letter = 'D';
      z0.pos_letter = sensor_pair_[1];
      z0.pdf_fwd = cam_.pdf_pos;
      to_pixels(c->raster, &rx, &ry);
      b = &z0;
    }
    MirrorMiss miss = MirrorMiss::kNone;
    const std::optional<MirrorJoin> j = mirror_join(mirror, a->p, b->p, &miss);
    if (!j) {
      ++stats.outside;  // off the mirror, or the ends on different sides of its plane
      continue;
    }
    // f at a towards the mirror: the light's directional emission, or the BSDF.
    const vec3 fa = light ? vec3(directional_emission(light->params, a->n, j->w_a))
                          : bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(a->shape)], a->wo, j->w_a, a->ns, a->n);
    // Across the mirror the geometry term is the straight one to the image: |cos_a| |cos_b| / D².
    vec3 contrib = a->beta * fa * mirror.reflectance * abs_cos(*a, j->w_a);
    if (t == 1) {
      contrib *= c->weight;  // We cos / (p D²), D = |a' − sensor point|
    } else {
      const vec3 fb = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(b->shape)], b->wo, j->w_b, b->ns, b->n);
      contrib *= fb * b->beta * (abs_cos(*b, j->w_b) / (j->unfolded * j->unfolded));
    }
    if (is_black(contrib)) {
      ++stats.no_transport;
      continue;
    }
    Vertex& m = th.mirror_vertex;
    m = Vertex{};
    m.kind = Kind::kSurface;
    m.letter = 'S';
    m.p = j->point;
    m.n = mirror.normal;
    m.ns = mirror.normal;
    m.err = mirror.error;
    m.shape = mirror.shape;
    gather(th, s, t, s == 1 ? a : nullptr, &m, t == 1 ? b : nullptr);
    const Pending r{key,  contrib * path_weight(th, key, SelfKind::kMirror, s), strategy_index, batch, Technique{strategy_index, s, t, true}.code(),
                    t == 1, true, rx, ry, th.px, 2};
    // Both segments go into one batch; the contribution waits on the second.
    if (th.shadow.size() + 2 > OcclusionBatch::kCapacity) trace_shadows(th);
    th.rays += 2;
    Pending first = r;
    first.segments = 0;
    th.pending[static_cast<std::size_t>(th.shadow.add(*rs_.geometry, a->p, a->n, a->err, m.p, m.n, m.err))] = first;
    th.pending[static_cast<std::size_t>(th.shadow.add(*rs_.geometry, m.p, m.n, m.err, b->p, b->n, b->err))] = r;
    if (th.shadow.full()) trace_shadows(th);
  }
}

void Integrator::gather(Thread& th, int s, int t, const Vertex* fresh_light, const Vertex* middle, const Vertex* fresh_eye) const {
  th.path.clear();
  for (int i = 0; i < s; ++i) th.path.push_back(i == 0 && fresh_light ? *fresh_light : th.light[static_cast<std::size_t>(i)]);
  if (middle) th.path.push_back(*middle);
  for (int j = t - 1; j >= 0; --j) th.path.push_back(j == 0 && fresh_eye ? *fresh_eye : th.eye[static_cast<std::size_t>(j)]);
  Vertex& x0 = th.path.front();
  if (s == 0) {  // an eye vertex on an area light starts the path
    x0.kind = Kind::kLight;
    x0.light = rs_.light_of_shape[static_cast<std::size_t>(x0.shape)];
  }
  if (t == 0) th.path.back().kind = Kind::kCamera;  // a light vertex on the lens ends it
}

bool Integrator::mirror_can_sample(const Thread& th, int s, int t, PathKey key) const {
  const int k = packed_length(key) - 3;
  for (int m = 1; m <= k - 1; ++m) {
    if (((key >> m) & 7) != 2 || mirror_of(m, k - m) < 0) continue;  // c(m) c(m+1) c(m+2) = DSD
    const Vertex& x = m < s ? th.light[static_cast<std::size_t>(m)] : th.eye[static_cast<std::size_t>(s + t - 1 - m)];
    if (x.kind == Kind::kSurface && mirror_shape_[static_cast<std::size_t>(x.shape)]) return true;
  }
  return false;
}

float Integrator::path_weight(Thread& th, PathKey key, SelfKind self, int s) const {
  // Every vertex's area density as the light walk (lf) and as the eye walk (ef) would sample it,
  // Dirac ones stored as 0 and counted as 1 (remap()), as the subpaths store them. The density of
  // plain split i (light vertices x0 … x(i-1)) is Π_{v<i} lf(v) Π_{v>=i} ef(v); the mirror
  // connector's with its vertex at x_m lacks x_m's factor, Π_{v<m} lf(v) Π_{v>m} ef(v); the
  // projections' are split 1's and split k's with the projected endpoint's area density replaced
  // by 1 (as in mis_weight()). All are kept relative to split 0's: rel[i] = P_i / P_0.
  const std::vector<Vertex>& x = th.path;
  const int k = static_cast<int>(x.size()) - 1, n = k + 1;
  const auto letter_s = [&](int i) { return !packed_is_d(key, i); };  // c_i is S
  const auto lf = [&](int v) -> double {
    if (v == 0) return light_pick_ * rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
    if (v == 1 && letter_s(1) && rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos > 0.0f)
      return parallel_jacobian(x[1], x[0], glm::normalize(x[1].p - x[0].p));  // a distant light's parallel beam
    if (letter_s(v)) return 0.0;  // x(v-1) is a Dirac
    return pdf(v >= 2 ? &x[static_cast<std::size_t>(v - 2)] : nullptr, x[static_cast<std::size_t>(v - 1)], x[static_cast<std::size_t>(v)]);
  };
  const auto ef = [&](int v) -> double {
    if (v == k) return cam_.pdf_pos;
    if (v == k - 1 && letter_s(k + 1) && cam_.pdf_pos > 0.0f)
      return parallel_jacobian(x[static_cast<std::size_t>(k - 1)], x[static_cast<std::size_t>(k)],
                               glm::normalize(x[static_cast<std::size_t>(k - 1)].p - x[static_cast<std::size_t>(k)].p));
    if (letter_s(v + 2)) return 0.0;  // x(v+1) is a Dirac
    return pdf(v + 2 <= k ? &x[static_cast<std::size_t>(v + 2)] : nullptr, x[static_cast<std::size_t>(v + 1)], x[static_cast<std::size_t>(v)]);
  };
  std::vector<double>& rel = th.rel;
  std::vector<double>& e = th.eye_density;
  rel.assign(static_cast<std::size_t>(n) + 1, 1.0);
  e.assign(static_cast<std::size_t>(n), 1.0);
  for (int v = 0; v <= k; ++v) {
    e[static_cast<std::size_t>(v)] = remap(static_cast<float>(ef(v)));
    rel[static_cast<std::size_t>(v) + 1] = rel[static_cast<std::size_t>(v)] * remap(static_cast<float>(lf(v))) / e[static_cast<std::size_t>(v)];
  }
  const double light_pos = rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
  const auto dsd_at = [&](int i) { return ((key >> i) & 7) == 2; };
  const auto mirror_at = [&](int m) {
    return m >= 1 && m <= k - 1 && dsd_at(m) && mirror_of(m, k - m) >= 0 && x[static_cast<std::size_t>(m)].kind == Kind::kSurface &&
           mirror_shape_[static_cast<std::size_t>(x[static_cast<std::size_t>(m)].shape)];
  };
  double own = 0.0;
  switch (self) {
    case SelfKind::kPlain: own = rel[static_cast<std::size_t>(s)]; break;
    case SelfKind::kDistant: own = rel[1] / light_pos; break;
    case SelfKind::kOrtho: own = rel[static_cast<std::size_t>(n - 1)] / cam_.pdf_pos; break;
    case SelfKind::kMirror: own = rel[static_cast<std::size_t>(s)] / e[static_cast<std::size_t>(s)]; break;
  }
  double sum = 0.0;
  const auto add = [&](double p) {
    const double r = p / own;
    sum += r * r;
  };
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));
  const std::uint64_t plain = runs_mask_[static_cast<std::size_t>(n)] & d_pairs;
  for (int i = 0; i <= n; ++i)
    if ((plain >> i) & 1) add(rel[static_cast<std::size_t>(i)]);
  if (n - 1 >= 1 && distant_of(n - 1) >= 0 && dsd_at(0) && light_pos > 0.0) add(rel[1] / light_pos);
  if (n - 1 >= 1 && ortho_of(n - 1) >= 0 && dsd_at(n - 1) && cam_.pdf_pos > 0.0f) add(rel[static_cast<std::size_t>(n - 1)] / cam_.pdf_pos);
  for (int m = 1; m <= k - 1; ++m)
    if (mirror_at(m)) add(rel[static_cast<std::size_t>(m)] / e[static_cast<std::size_t>(m)]);
  return sum > 0.0 && std::isfinite(sum) ? static_cast<float>(1.0 / sum) : 0.0f;
}

void Integrator::trace_shadows(Thread& th) const {
  th.shadow.trace(*rs_.geometry);
  for (int lane = 0; lane < th.shadow.size(); ++lane) {
    const Pending& r = th.pending[static_cast<std::size_t>(lane)];
    if (r.segments == 0) continue;  // its contribution waits on a later lane
    bool visible = true;
    for (int i = lane - r.segments + 1; i <= lane; ++i) visible = visible && th.shadow.visible(i);
    if (r.connector) ++(visible ? th.connectors[static_cast<std::size_t>(r.strategy)].successes
                                : th.connectors[static_cast<std::size_t>(r.strategy)].occluded);
    if (visible) record(th, r);
  }
  th.shadow.clear();
}

float Integrator::weight_sum(Thread& th, int s, int t) const {
  // The full path in light-to-eye order, from the two subpaths as connected by (s, t).
  const int k = s + t - 1;
  std::vector<Vertex> x;
  for (int i = 0; i < s; ++i) x.push_back(th.light[static_cast<std::size_t>(i)]);
  for (int j = t - 1; j >= 0; --j) x.push_back(th.eye[static_cast<std::size_t>(j)]);
  if (s == 0) {  // the eye vertex on the emitter becomes the light vertex
    x[0].kind = Kind::kLight;
    x[0].light = rs_.light_of_shape[static_cast<std::size_t>(x[0].shape)];
  } else if (rs_.lights[static_cast<std::size_t>(x[0].light)].is_area()) {
    x[0].shape = rs_.lights[static_cast<std::size_t>(x[0].light)].shape;  // so an eye path may hit it
  }
  const std::string letters = label(th, s, t);
  const Thread saved_light_eye = th;
  float sum = 0.0f;
  for (int s2 = 0; s2 <= k + 1; ++s2) {
    const int t2 = k + 1 - s2;
    const auto letters_at = [&](int i, int count) { return letters.substr(static_cast<std::size_t>(i) + 1, static_cast<std::size_t>(count)); };
    bool plain = strategy(s2, t2) >= 0 && letters_at(s2, 2) == "DD";
    if (t2 == 0 && !lens_hits_) plain = false;
    if (s2 == 0 && x[0].kind == Kind::kLight && !rs_.lights[static_cast<std::size_t>(x[0].light)].is_area()) plain = false;
    const bool distant = s2 == 1 && distant_of(t2) >= 0 && letters_at(0, 3) == "DSD";
    const bool ortho = t2 == 1 && ortho_of(s2) >= 0 && letters_at(k, 3) == "DSD";
    if (!plain && !distant && !ortho) continue;
    const JoinKind kind = distant ? JoinKind::kDistant : ortho ? JoinKind::kOrtho : JoinKind::kPlain;
    // Re-split: light subpath x0 … x(s2-1), eye subpath xk … x(s2), with forward densities as
    // each side would have sampled them.
    for (int i = 0; i < s2; ++i) th.light[static_cast<std::size_t>(i)] = x[static_cast<std::size_t>(i)];
    for (int j = 0; j < t2; ++j) th.eye[static_cast<std::size_t>(j)] = x[static_cast<std::size_t>(k - j)];
    if (s2 > 0) {
      th.light[0].kind = Kind::kLight;
      th.light[0].pdf_fwd = light_pick_ * rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
    }
    if (s2 == 0) {
      th.eye[static_cast<std::size_t>(t2 - 1)].kind = Kind::kSurface;
    }
    // Each vertex's direction to its predecessor on its new subpath.
    for (int i = 0; i < s2; ++i) {
      Vertex& v = th.light[static_cast<std::size_t>(i)];
      if (i == 0) v.wo = vec3(0.0f), v.d2_wo = 0.0f;
      else link(v, th.light[static_cast<std::size_t>(i - 1)]);
    }
    for (int j = 0; j < t2; ++j) {
      Vertex& v = th.eye[static_cast<std::size_t>(j)];
      if (j == 0) v.wo = vec3(0.0f), v.d2_wo = 0.0f;
      else link(v, th.eye[static_cast<std::size_t>(j - 1)]);
    }
    // The letter of x_i in this path (c_{i+1}); a Dirac there keeps both densities through it symbolic.
    auto specular = [&](int i) { return i >= 1 && i <= k - 1 && letters[static_cast<std::size_t>(i) + 2] == 'S'; };
    for (int i = 1; i < s2; ++i)
      th.light[static_cast<std::size_t>(i)].pdf_fwd =
          specular(i - 1) ? 0.0f
                          : pdf(i > 1 ? &th.light[static_cast<std::size_t>(i - 2)] : nullptr,
                                th.light[static_cast<std::size_t>(i - 1)], th.light[static_cast<std::size_t>(i)]);
    for (int i = 0; i + 2 < s2; ++i)
      th.light[static_cast<std::size_t>(i)].pdf_rev =
          specular(i + 1) ? 0.0f
                          : pdf(&th.light[static_cast<std::size_t>(i + 2)], th.light[static_cast<std::size_t>(i + 1)],
                                th.light[static_cast<std::size_t>(i)]);
    if (t2 > 0) th.eye[0].pdf_fwd = cam_.pdf_pos;
    for (int j = 1; j < t2; ++j)
      th.eye[static_cast<std::size_t>(j)].pdf_fwd =
          specular(k - (j - 1)) ? 0.0f
                                : pdf(j > 1 ? &th.eye[static_cast<std::size_t>(j - 2)] : nullptr,
                                      th.eye[static_cast<std::size_t>(j - 1)], th.eye[static_cast<std::size_t>(j)]);
    for (int j = 0; j + 2 < t2; ++j)
      th.eye[static_cast<std::size_t>(j)].pdf_rev =
          specular(k - (j + 1)) ? 0.0f
                                : pdf(&th.eye[static_cast<std::size_t>(j + 2)], th.eye[static_cast<std::size_t>(j + 1)],
                                      th.eye[static_cast<std::size_t>(j)]);
    // Parallel beams (a distant light's, an orthographic sensor's) give their first vertex a
    // density per area, as light_subpath() and eye_subpath() set it.
    if (s2 >= 2 && th.light[0].pdf_fwd > 0.0f && light_pairs_[static_cast<std::size_t>(th.light[0].light)][1] == 'S')
      th.light[1].pdf_fwd = parallel_jacobian(th.light[1], th.light[0], glm::normalize(th.light[1].p - th.light[0].p));
    if (t2 >= 2 && cam_.pdf_pos > 0.0f && sensor_pair_[0] == 'S')
      th.eye[1].pdf_fwd = parallel_jacobian(th.eye[1], th.eye[0], glm::normalize(th.eye[1].p - th.eye[0].p));
    prepare_joins(th, s2, t2);  // the ratios of the re-split subpaths
    sum += mis_weight(th, s2, t2, nullptr, pack(letters), nullptr, kind);
  }
  th.light = saved_light_eye.light;
  th.eye = saved_light_eye.eye;
  prepare_joins(th, th.ns, th.nt);
  return sum;
}

void Integrator::sample(Thread& th, int px, int py, std::uint64_t pass) const {
  const std::uint64_t pixel = static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(cam_.width) + static_cast<std::uint64_t>(px);
  Sampler rng(o_.seed, pixel, pass, o_.sampler);
  rng.set_dimension(kEyeDims);
  const int batch = batch_of(pass, o_.batches);
  th.px = px;
  th.py = py;
  th.pass = pass;
  const int nt = eye_subpath(th, rng, px, py);
  rng.set_dimension(kLightDims);
  const int ns = light_subpath(th, rng);
  th.ns = ns;
  th.nt = nt;
  th.joins_ready = false;
  // The connections (s, t) in order of t, then s, over the ranges where they form a path of k =
  // s + t - 1 >= 1 edges and at most max_bounces_ + 1 (k - 1 <= max_bounces_): loops with exact
  // bounds rather than one loop whose tests the branch predictor keeps missing.
  // A light subpath that reached the lens ends there (random_walk stops), so only its last vertex
  // can be a lens vertex; it forms the t = 0 connection and no other.
  const bool lens_end = ns >= 2 && th.light[static_cast<std::size_t>(ns - 1)].kind == Kind::kLens;
  if (lens_end && lens_hits_ && ns - 2 <= max_bounces_ && strategy(ns, 0) >= 0)
    connect<Connection::kLens>(th, rng, ns, 0, batch);
  // s = 1 takes a fresh light sample, so it runs even when no light subpath was traced.
  const int s_max = (rs_.lights.empty() ? ns : std::max(ns, 1)) - (lens_end ? 1 : 0);
  if (nt >= 1)
    for (int s = 1; s <= std::min(s_max, max_bounces_ + 1); ++s)
      if (strategy(s, 1) >= 0) connect<Connection::kSplat>(th, rng, s, 1, batch);
  for (int t = 2; t <= nt; ++t) {
    const int s_hi = std::min(s_max, max_bounces_ + 2 - t);
    if (s_hi >= 0 && strategy(0, t) >= 0) connect<Connection::kEmitter>(th, rng, 0, t, batch);
    if (s_hi >= 1 && strategy(1, t) >= 0) connect<Connection::kNee>(th, rng, 1, t, batch);
    if (s_hi >= 1 && distant_of(t) >= 0) connect<Connection::kDistant>(th, rng, 1, t, batch);
    for (int s = 2; s <= s_hi; ++s)
      if (strategy(s, t) >= 0) connect<Connection::kJoin>(th, rng, s, t, batch);
  }
  if (has_connectors_ && nt >= 1)
    for (int s = 1; s <= std::min(ns - (lens_end ? 1 : 0), max_bounces_ + 1); ++s)
      if (ortho_of(s) >= 0) connect<Connection::kOrtho>(th, rng, s, 1, batch);
  // The mirror connector's path has s + t + 1 vertices: s + t - 1 interior ones.
  if (has_mirror_)
    for (int t = 1; t <= nt; ++t)
      for (int s = 1; s <= std::min(s_max, max_bounces_ + 1 - t); ++s)
        if (mirror_of(s, t) >= 0) connect_mirror(th, rng, s, t, batch);
}

}  // namespace

Result<std::vector<MisCheck>> check_mis_weights(const Scene& scene, const Profile& profile, std::uint64_t seed,
                                                int samples) {
  Result<StrategySet> strategies = runnable_strategies(profile);
  if (!strategies) return strategies.error();
  Result<RenderScene> rs = make_render_scene(scene);
  if (!rs) return rs.error();
  RenderOptions o;
  o.seed = seed;
  o.max_bounces = std::min(8, profile.max_bounces.value_or(8));
  HistogramLayout layout;
  ClassImages images(1, 1, nullptr, {});
  Integrator integrator(*rs, *strategies, o, nullptr);
  const Integrator general(*rs, *strategies, o, nullptr, /*general_mis=*/true);
  Integrator::Thread th{Histogram(layout, nullptr), {ClassImages::PixelSum(images)}, {}, {}, 0, {}, {}, {}};
  th.images = &images;
  th.connectors.resize(strategies->strategies.size());
  std::vector<MisCheck> out;
  for (int i = 0; i < samples; ++i) {
    const int px = i % rs->camera.width, py = (i / rs->camera.width) % rs->camera.height;
    Sampler rng(seed, static_cast<std::uint64_t>(i), 0);
    int ns = 0;
    const int nt = integrator.trace_subpaths(th, rng, px, py, &ns);
    for (int t = 0; t <= nt; ++t)
      for (int s = 0; s <= ns; ++s) {
        if (s == 1 || t == 1 || s + t < 2 || s + t - 2 > *o.max_bounces) continue;
        if (strategies->find(s, t) < 0) continue;
        const float sum = integrator.weight_sum_if_valid(th, s, t);
        if (sum < 0.0f) continue;  // not a path this connection forms
        const float weight = integrator.own_weight(th, s, t);
        const float weight_general = general.own_weight(th, s, t);
        out.push_back({integrator.label(th, s, t), s, t, sum, weight, weight_general, integrator.packed_label(th, s, t)});
      }
  }
  return out;
}

Result<RenderOutput> render(const Scene& scene, const Profile& profile, const Classifier* classifier,
                            const RenderOptions& options) {
  Result<StrategySet> strategies = runnable_strategies(profile);
  if (!strategies) return strategies.error();
  Result<RenderScene> rs = make_render_scene(scene);
  if (!rs) return rs.error();
  RenderOptions o = options;
  // The same rule as the checker's: an explicit bound overrides the profile's own.
  if (!o.max_bounces) o.max_bounces = profile.max_bounces.value_or(16);
  HistogramLayout layout;
  layout.num_batches = o.batches;
  for (const Strategy& st : strategies->strategies) layout.strategies.push_back(st.name);

  RenderOutput out{Histogram(layout, classifier),
                   o.images ? ClassImages(rs->camera.width, rs->camera.height, classifier, o.layer_classes)
                            : ClassImages(0, 0, nullptr, {}),
                   layout.strategies};
  Integrator integrator(*rs, *strategies, o, classifier);
  const int threads = o.threads > 0 ? o.threads : static_cast<int>(tbb::this_task_arena::max_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  tbb::enumerable_thread_specific<Integrator::Thread> locals(
      [&] {
        Integrator::Thread th{Histogram(layout, classifier),
                              std::vector<ClassImages::PixelSum>(static_cast<std::size_t>(out.images.width()), ClassImages::PixelSum(out.images)),
                              {}, {}, 0, {}, {}, {}};
        th.images = &out.images;
        th.splats = ClassImages::SplatBuffer(out.images.splat_entries(), out.images.splat_keys());
        th.connectors.resize(strategies->strategies.size());
        return th;
      });
  const int w = rs->camera.width, h = rs->camera.height;
  const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
  const auto start = std::chrono::steady_clock::now();
  // Passes run in chunks: a pixel takes a chunk's passes back to back, so that its camera
  // contributions reach the shared image once per chunk (and its part of the scene stays in
  // cache); cancelling stops on a whole chunk, so every finished pass covers the whole image.
  const PassSet todo = o.passes.value_or(PassSet::range(0, o.spp));
  for (const PassRange& chunk : todo.chunks(kPassesPerChunk)) {
    if (o.cancel && o.cancel->load()) break;
    const std::uint64_t first = chunk.first, end = chunk.last;
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 1), [&](const tbb::blocked_range<int>& rows) {
      Integrator::Thread& th = locals.local();
      for (int y = rows.begin(); y < rows.end(); ++y) {
        for (int x = 0; x < w; ++x)
          for (std::uint64_t p = first; p < end; ++p) integrator.sample(th, x, y, p);
        integrator.finish_row(th, out.images, y);
      }
    });
    for (std::uint64_t p = first; p < end; ++p) out.histogram.add_samples(batch_of(p, o.batches), pixels);
    out.passes_done.add(first, end);
    if (o.progress) o.progress(out.passes_done.count() * pixels, todo.count() * pixels);
  }
  out.spp_done = out.passes_done.count();
  out.complete = out.passes_done == todo;
  for (Integrator::Thread& th : locals) {
    th.splats.flush(out.images);
    th.ids.flush(th.hist);
    Result<bool> m = out.histogram.merge(th.hist);
    if (!m) return m.error();
    out.rays += th.rays;
    if (th.first_nonfinite && (!out.first_nonfinite || th.first_nonfinite->order() < out.first_nonfinite->order()))
      out.first_nonfinite = th.first_nonfinite;
  }
  // Connector statistics, in the profile's order (integer sums: the same for every thread count).
  for (std::size_t i = 0; i < strategies->strategies.size(); ++i) {
    const Strategy& st = strategies->strategies[i];
    if (st.connector == ConnectorKind::kNone) continue;
    ConnectorStats total{st.name, to_string(st.connector)};
    for (const Integrator::Thread& th : locals) {
      const ConnectorStats& c = th.connectors[i];
      total.attempts += c.attempts;
      total.successes += c.successes;
      total.outside += c.outside;
      total.occluded += c.occluded;
      total.no_transport += c.no_transport;
    }
    out.connectors.push_back(total);
  }
  out.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace pathex
