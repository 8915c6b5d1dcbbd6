// The installed API (include/pathex/pathex.h): value types over the library's own stages.
//
// Each public object holds a shared, immutable Impl built once by its constructor; a failed
// construction keeps the rendered Error (the same text the CLI prints) and nothing else. Nothing
// here adds behaviour: compile_class, resolve_profile, query, read_class_file, the Classifier,
// measure_missed, parse_check, decide_check, converge and run_trace are the functions the `pathex` command calls.
#include "pathex/pathex.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "automata/ops.h"
#include "bias/bias.h"
#include "check/check_file.h"
#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "io/class_file.h"
#include "io/input_file.h"
#include "io/profile_json.h"
#include "measure/converge.h"
#include "measure/trace_run.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "trace/accel/path_ids.h"
#include "trace/plan.h"

namespace pathex::api {

// --- the private halves of the public classes ---

struct PathClass::Impl {
  std::string expression;
  std::string error;
  std::optional<pathex::PathClass> compiled;
};

struct Renderer::Impl {
  std::string requested;
  std::string error;
  std::optional<Profile> profile;
};

struct ClassSet::Impl {
  std::string error;
  ClassTable table;  // owns the user's classes the classifier was built from
  std::vector<std::string> names;
  std::optional<Classifier> classifier;
};

struct Plan::Impl {
  std::string error;
  ClassTable table;  // owns the requested classes compiled for the scene
  std::optional<pathex::RenderPlan> plan;
  std::vector<std::string> strategies;
  std::vector<int> aimed_lights;
};

// The one friend of the public classes: the functions below reach their private halves through it.
struct Access {
  static const PathClass::Impl& of(const PathClass& c) { return *c.impl_; }
  static const Renderer::Impl& of(const Renderer& r) { return *r.impl_; }
  static ClassSet with(std::shared_ptr<const ClassSet::Impl> impl) {
    ClassSet s;
    s.impl_ = std::move(impl);
    return s;
  }
  // Builds the classifier over `classes`, or records why not.
  static void build_classifier(const std::vector<const pathex::PathClass*>& classes, ClassSet::Impl* impl) {
    for (const pathex::PathClass* c : classes) impl->names.push_back(c->name);
    Result<Classifier> cl = Classifier::build(classes, Limits{});
    if (!cl) {
      impl->error = cl.error().render();
      impl->names.clear();
      return;
    }
    impl->classifier = std::move(*cl);
  }
};

namespace {

Verdict from_internal(pathex::Verdict v) {
  switch (v) {
    case pathex::Verdict::kEmpty: return Verdict::kEmpty;
    case pathex::Verdict::kReachable: return Verdict::kReachable;
    case pathex::Verdict::kPartial: return Verdict::kPartial;
    case pathex::Verdict::kUnreachable: return Verdict::kUnreachable;
  }
  return Verdict::kEmpty;
}

Answer failed(std::string error) {
  Answer a;
  a.error = std::move(error);
  return a;
}

}  // namespace

std::string_view version() { return PATHEX_VERSION; }

// --- PathClass ---

PathClass::PathClass(std::string_view expression, Notation notation) {
  auto impl = std::make_shared<Impl>();
  impl->expression = std::string(expression);
  ClassOptions options;
  options.notation = notation == Notation::kHeckbert ? pathex::Notation::kHeckbert : pathex::Notation::kFull;
  Result<pathex::PathClass> c = compile_class(expression, options, &ClassTable::builtins());
  if (c) {
    impl->compiled = std::move(*c);
  } else {
    impl->error = c.error().render();
  }
  impl_ = std::move(impl);
}

bool PathClass::ok() const { return impl_->error.empty(); }
const std::string& PathClass::error() const { return impl_->error; }
const std::string& PathClass::expression() const { return impl_->expression; }

bool PathClass::matches(std::string_view full_path) const {
  return impl_->compiled && impl_->compiled->dfa.accepts(full_path);
}

bool PathClass::empty() const { return !impl_->compiled || is_empty(impl_->compiled->dfa); }

int PathClass::dfa_states() const { return impl_->compiled ? impl_->compiled->dfa.num_states : 0; }

std::vector<std::string> PathClass::shortest(int n, int max_letters) const {
  if (!impl_->compiled || n <= 0) return {};
  return enumerate_members(impl_->compiled->dfa, max_letters, static_cast<std::size_t>(n));
}

// --- Renderer ---

Renderer::Renderer(const std::string& name_or_file) {
  auto impl = std::make_shared<Impl>();
  impl->requested = name_or_file;
  Result<Profile> p = resolve_profile(name_or_file, Limits{});
  if (p) {
    impl->profile = std::move(*p);
  } else {
    impl->error = p.error().render();
  }
  impl_ = std::move(impl);
}

bool Renderer::ok() const { return impl_->error.empty(); }
const std::string& Renderer::error() const { return impl_->error; }
const std::string& Renderer::name() const { return impl_->profile ? impl_->profile->name : impl_->requested; }

std::vector<std::string> Renderer::builtin_names() {
  std::vector<std::string> names;
  for (const BuiltinProfileText& t : builtin_profile_texts()) names.emplace_back(t.name);
  return names;
}

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::kEmpty: return "empty";
    case Verdict::kReachable: return "reachable";
    case Verdict::kPartial: return "partial";
    case Verdict::kUnreachable: return "unreachable";
  }
  return "empty";
}

// --- query ---

Answer query(const PathClass& path_class, const Renderer& renderer, const QueryOptions& options) {
  if (!path_class.ok()) return failed(path_class.error());
  if (!renderer.ok()) return failed(renderer.error());
  const Limits limits;
  pathex::QueryOptions qo;
  qo.max_bounces = options.max_bounces;
  qo.limits = limits;
  if (!options.scene.empty()) {
    Result<Scene> s = load_scene_file(options.scene);
    if (!s) return failed(s.error().render());
    qo.universe = scene_universe(scene_types(*s));
  }
  Result<CompiledProfile> r = compile_profile(*Access::of(renderer).profile, options.max_bounces, limits);
  if (!r) return failed(r.error().render());
  Result<QueryResult> q = pathex::query(*Access::of(path_class).compiled, *r, qo);
  if (!q) return failed(q.error().render());
  Answer a;
  a.verdict = from_internal(q->verdict);
  for (const Witness& w : q->reachable) a.reachable_witnesses.push_back(w.path);
  for (const Witness& w : q->unreachable) a.unreachable_witnesses.push_back(w.path);
  return a;
}

// --- Plan ---

Plan::Plan(const Renderer& renderer, const std::string& scene, const std::vector<std::string>& only,
           std::optional<int> max_bounces) {
  auto impl = std::make_shared<Impl>();
  impl_ = impl;
  if (!renderer.ok()) {
    impl->error = renderer.error();
    return;
  }
  const Limits limits;
  Result<Scene> s = load_scene_file(scene);
  if (!s) {
    impl->error = s.error().render();
    return;
  }
  // The requested classes as pathex trace compiles them (output/render_job.cpp): a built-in class by
  // its $name, any other expression for the scene's ends.
  const SceneTypes types = scene_types(*s);
  ClassOptions copts;
  copts.limits = limits;
  copts.ends.lights.assign(types.lights.begin(), types.lights.end());
  copts.ends.sensors = {types.sensor};
  std::vector<const pathex::PathClass*> requested;
  for (std::size_t i = 0; i < only.size(); ++i) {
    const pathex::PathClass* same = nullptr;
    for (const auto& c : ClassTable::builtins().builtin_classes())
      if (c->name != "all" && !only[i].empty() && only[i][0] == '$' && c->name == only[i].substr(1)) same = c.get();
    if (same == nullptr) {
      Result<const pathex::PathClass*> added = impl->table.add("only-" + std::to_string(i + 1), only[i], copts);
      if (!added) {
        impl->error = added.error().render();
        return;
      }
      same = *added;
    }
    if (std::find(requested.begin(), requested.end(), same) == requested.end()) requested.push_back(same);
  }
  const Profile& profile = *Access::of(renderer).profile;
  Result<pathex::RenderPlan> p = plan_render(*s, profile, max_bounces.value_or(profile.max_bounces.value_or(16)), requested, limits);
  if (!p) {
    impl->error = p.error().render();
    return;
  }
  for (const Strategy& st : p->profile.strategies) impl->strategies.push_back(st.name + " " + st.describe());
  impl->aimed_lights = p->aimed_lights;
  impl->plan = std::move(*p);
}

bool Plan::ok() const { return impl_->error.empty(); }
const std::string& Plan::error() const { return impl_->error; }
const std::vector<std::string>& Plan::strategies() const { return impl_->strategies; }
const std::vector<int>& Plan::aimed_lights() const { return impl_->aimed_lights; }

bool Plan::records(std::string_view full_path) const {
  // L c0 … c(k+2) E with k >= 1, as many letters as a packed path holds.
  const std::size_t n = full_path.size();
  if (!impl_->plan || n < 6 || n - 2 > static_cast<std::size_t>(accel::kMaxPackedLetters) || full_path.front() != 'L' ||
      full_path.back() != 'E' || full_path.substr(1, n - 2).find_first_not_of("SD") != std::string_view::npos)
    return false;
  return impl_->plan->filter.records(accel::pack(std::string(full_path)));
}

// --- ClassSet ---

ClassSet ClassSet::builtins() {
  auto impl = std::make_shared<Impl>();
  std::vector<const pathex::PathClass*> classes;
  for (const auto& c : pathex::ClassTable::builtins().builtin_classes())
    if (c->name != "all") classes.push_back(c.get());
  Access::build_classifier(classes, impl.get());
  return Access::with(std::move(impl));
}

ClassSet ClassSet::from_file(const std::string& filename) {
  auto impl = std::make_shared<Impl>();
  Result<bool> r = read_class_file(filename, ClassOptions{}, &impl->table);
  if (!r) {
    impl->error = r.error().render();
    return Access::with(std::move(impl));
  }
  std::vector<const pathex::PathClass*> classes;
  for (const auto& c : impl->table.user_classes()) classes.push_back(c.get());
  Access::build_classifier(classes, impl.get());
  return Access::with(std::move(impl));
}

ClassSet ClassSet::from_expressions(const std::vector<std::pair<std::string, std::string>>& named_expressions) {
  auto impl = std::make_shared<Impl>();
  std::vector<const pathex::PathClass*> classes;
  for (const auto& [name, expression] : named_expressions) {
    Result<const pathex::PathClass*> c = impl->table.add(name, expression, ClassOptions{});
    if (!c) {
      impl->error = c.error().render();
      return Access::with(std::move(impl));
    }
    classes.push_back(*c);
  }
  Access::build_classifier(classes, impl.get());
  return Access::with(std::move(impl));
}

bool ClassSet::ok() const { return impl_->error.empty(); }
const std::string& ClassSet::error() const { return impl_->error; }
const std::vector<std::string>& ClassSet::names() const { return impl_->names; }

std::vector<std::string> ClassSet::classify(std::string_view full_path) const {
  std::vector<std::string> out;
  if (!impl_->classifier) return out;
  for (int m : impl_->classifier->members(impl_->classifier->classify(full_path)))
    out.push_back(impl_->classifier->name(m));
  return out;
}

}  // namespace pathex::api

namespace pathex::api {

// --- bias ---

BiasAnswer bias(const std::string& scene_file, const Renderer& renderer, const BiasOptions& options) {
  BiasAnswer a;
  if (!renderer.ok()) {
    a.error = renderer.error();
    return a;
  }
  pathex::BiasOptions bo;
  bo.spp = options.spp;
  bo.seed = options.seed;
  bo.threads = options.threads;
  bo.images = false;
  Result<Scene> scene = load_scene_file(scene_file, scene_load_options(bo.limits));
  if (!scene) {
    a.error = scene.error().render();
    return a;
  }
  Result<BiasRun> run = measure_missed(*scene, scene_file, *Access::of(renderer).profile, options.reference, {}, bo);
  if (!run) {
    a.error = run.error().render();
    return a;
  }
  const BiasReport& r = run->report;
  a.reference = r.reference;
  a.total = r.total.luminance;
  a.missed = r.missed.luminance;
  a.share = r.share;
  a.share_stderr = r.share_std_error;
  a.exact = r.covered;
  if (r.shortest) a.shortest_missed = r.shortest->path;
  return a;
}

}  // namespace pathex::api

namespace pathex::api {

// --- check ---

bool CheckAnswer::passed() const {
  if (!ok()) return false;
  for (const CheckOutcome& o : outcomes)
    if (!o.passed) return false;
  return true;
}

CheckAnswer check(const std::string& check_file) {
  CheckAnswer a;
  const Limits limits;
  Result<std::string> text = read_input_file(check_file, limits.max_file_bytes);
  if (!text) {
    a.error = text.error().render();
    return a;
  }
  Result<std::vector<Case>> cases = parse_check(*text, check_file);
  if (!cases) {
    a.error = cases.error().render();
    return a;
  }
  Result<std::vector<Outcome>> decided = decide_check(check_file, *cases, limits);
  if (!decided) {
    a.error = decided.error().render();
    return a;
  }
  for (const Outcome& o : *decided)
    a.outcomes.push_back({o.c->name, o.r->describe(), o.passed, o.verdict, o.counterexample ? o.counterexample->path : ""});
  return a;
}

}  // namespace pathex::api

namespace pathex::api {

// --- converge ---

ConvergeAnswer converge(const std::string& scene_file, const std::vector<Renderer>& renderers, const ConvergeOptions& options) {
  ConvergeAnswer a;
  pathex::ConvergeOptions co;
  co.scene = scene_file;
  for (const Renderer& r : renderers) {
    if (!r.ok()) {
      a.error = r.error();
      return a;
    }
    co.renderers.push_back(Access::of(r).requested);
  }
  for (std::uint64_t spp : options.spp) co.spp_list += (co.spp_list.empty() ? "" : ",") + std::to_string(spp);
  if (options.spp.empty()) co.spp_list = ",";  // refused by the ladder's parser, as an empty --spp
  co.seed = options.seed;
  co.threads = options.threads;
  co.max_bounces = options.max_bounces;
  co.classes_file = options.classes_file;
  co.only = options.only;
  co.reference = options.reference;
  co.reference_renderer = options.reference_renderer;
  co.reference_factor = options.reference_factor;
  co.out = options.out;
  Result<pathex::ConvergeResult> run = pathex::converge(co);
  if (!run) {
    a.error = run.error().render();
    return a;
  }
  const pathex::ConvergeResult& r = *run;
  if (!r.nothing_to_render.empty()) {
    a.error = r.nothing_to_render;
    return a;
  }
  if (r.reference_interrupted) {
    a.error = "interrupted during the reference run";
    return a;
  }
  a.reference_kind = r.reference_kind;
  a.reference_source = r.reference_source;
  a.warnings = r.warnings;
  a.complete = r.complete;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    ConvergeClass c;
    c.name = r.rows[i].name;
    c.expression = r.rows[i].expr;
    c.reference = r.rows[i].reference;
    for (const Ranking& b : r.rankings.best)
      if (b.cls == c.name) c.best = b.renderer;
    for (std::size_t k = 0; k < r.renderers.size(); ++k) {
      const Series& s = r.series[k][i];
      ConvergeSeries cs;
      cs.renderer = r.renderers[k];
      for (std::size_t j = 0; j < r.results[k].size(); ++j) {
        const RungResult& rung = r.results[k][j];
        ConvergeRung cr;
        cr.spp = rung.spp;
        cr.cpu_s = rung.cpu_s;
        cr.estimate = rung.classes[i].estimate;
        cr.std_error = rung.classes[i].std_error;
        if (j < s.error.size() && std::isfinite(s.error[j])) cr.error = s.error[j];
        if (j < s.z.size() && std::isfinite(s.z[j])) cr.z = s.z[j];
        cs.rungs.push_back(cr);
      }
      cs.slope = s.slope;
      cs.efficiency = s.pooled_efficiency;
      if (r.cannot[k][i]) cs.cannot_sample = *r.cannot[k][i];
      cs.warning = s.warning;
      c.renderers.push_back(std::move(cs));
    }
    a.classes.push_back(std::move(c));
  }
  return a;
}

}  // namespace pathex::api

namespace pathex::api {

// --- trace ---

namespace {

TraceEstimate trace_estimate(std::string name, std::string expression, const Estimate& e, double total) {
  TraceEstimate t;
  t.name = std::move(name);
  t.expression = std::move(expression);
  t.luminance = e.luminance;
  t.std_error = e.std_error;
  t.share = total != 0.0 ? e.luminance / total : 0.0;
  return t;
}

}  // namespace

TraceAnswer trace(const std::string& scene_file, const Renderer& renderer, const TraceOptions& options) {
  TraceAnswer a;
  if (!renderer.ok()) {
    a.error = renderer.error();
    return a;
  }
  pathex::TraceOptions to;
  to.job.scene = scene_file;
  to.job.renderer = Access::of(renderer).requested;
  to.job.classes_file = options.classes_file;
  to.job.only = options.only;
  to.job.spp = options.spp;
  to.job.seed = options.seed;
  to.job.max_bounces = options.max_bounces;
  to.job.max_paths = options.max_paths;
  to.threads = options.threads;
  to.progress = false;
  to.write = !options.out.empty();
  if (to.write) to.job.out = options.out;
  to.job.no_images = !to.write;  // without a folder the images would go nowhere
  Result<pathex::TraceResult> run = run_trace(to);
  if (!run) {
    a.error = run.error().render();
    return a;
  }
  if (run->nothing_to_render) {
    a.error = "no strategy of " + run->job.profile->name + " samples a path of the requested classes in this scene";
    return a;
  }
  const HistogramReport& r = run->written->report;
  const double total = r.total.luminance;
  a.renderer = r.run.renderer;
  a.spp = r.run.spp;
  a.total = trace_estimate("total", "", r.total, total);
  for (const ClassEstimate& c : r.classes) {
    a.classes.push_back(trace_estimate(c.name, c.expr, c.estimate, total));
    a.classes.back().share = c.share;
    a.classes.back().rendered = c.rendered;
  }
  for (const PathEstimate& p : r.paths) a.paths.push_back(trace_estimate(p.path, "", p.estimate, total));
  if (r.other) a.paths.push_back(trace_estimate("other", "", r.other->estimate, total));
  a.distinct_paths = r.distinct_paths;
  a.nonfinite_samples = r.nonfinite_samples;
  a.cpu_s = run->header.run.cpu_s;
  a.complete = r.run.complete;
  return a;
}

}  // namespace pathex::api
