#include "bias/bias.h"

#include <algorithm>
#include <memory>
#include <utility>

#include "automata/ops.h"
#include "classify/classifier.h"
#include "io/profile_json.h"
#include "scene/universe.h"

namespace pathex {

Result<Profile> default_reference(const Dfa& universe, int bound, const Limits& limits) {
  Result<std::vector<Profile>> builtins = builtin_profiles(limits);
  if (!builtins) return builtins.error();
  const auto bdpt = std::find_if(builtins->begin(), builtins->end(), [](const Profile& p) { return p.name == "bdpt"; });
  if (bdpt == builtins->end()) return make_error(ErrorCode::kUsage, "the built-in profile 'bdpt' is missing");
  Profile ref = *bdpt;
  ref.description = "The default reference of pathex bias: bdpt plus every connector the tracer runs whose chains the "
                    "scene's universe contains.";
  ref.source.clear();
  ref.max_bounces.reset();
  // Per connector (in the order the built-ins first name it), the widest strategy: the candidate
  // whose language holds the others'. The tracer runs one strategy per connector and (s, t).
  struct Candidate {
    Strategy strategy;
    Dfa language;
  };
  std::vector<Candidate> chosen;
  for (const Profile& p : *builtins)
    for (const Strategy& st : p.strategies) {
      if (st.connector == ConnectorKind::kNone) continue;
      Profile alone;
      alone.name = p.name;
      alone.strategies = {st};
      if (!runnable_strategies(alone)) continue;  // not run by the tracer (yet)
      Result<Dfa> language = strategy_language(st, bound, limits);
      if (!language) return language.error();
      if (is_empty(dfa_intersect(*language, universe))) continue;  // no chain of it in this scene
      auto same = std::find_if(chosen.begin(), chosen.end(),
                               [&](const Candidate& c) { return c.strategy.connector == st.connector; });
      if (same == chosen.end()) chosen.push_back({st, std::move(*language)});
      else if (is_subset(same->language, *language)) *same = {st, std::move(*language)};
    }
  for (Candidate& c : chosen) {
    c.strategy.name = to_string(c.strategy.connector);
    ref.name += "+" + c.strategy.name;
    ref.strategies.push_back(std::move(c.strategy));
  }
  return ref;
}

Result<int> reference_bound(const std::string& renderer, std::optional<int> renderer_bound,
                            std::optional<int> requested) {
  if (requested) {
    if (renderer_bound && *requested <= *renderer_bound)
      return make_error(ErrorCode::kUsage,
                        "--reference-bounces " + std::to_string(*requested) + " must exceed " + renderer +
                            "'s bound of " + std::to_string(*renderer_bound) +
                            " interior vertices, or the light beyond that bound could not be counted");
    return *requested;
  }
  return std::min(kMaxReferenceBounces,
                  std::max(kDefaultReferenceBounces, renderer_bound ? *renderer_bound + kReferenceExtraBounces : 0));
}

Dfa reference_scope(const Scene& scene, int bound) {
  return dfa_intersect(scene_universe(scene_types(scene)), dfa_universe_bounded(bound));
}

std::optional<std::string> first_unsampled(const Dfa& reachable, const Dfa& scope, const Dfa& language) {
  return shortest_member(dfa_difference(dfa_intersect(language, scope), reachable));
}

Result<Profile> choose_reference(const std::string& name_or_path, const Scene& scene, const Profile& renderer,
                                 const BiasOptions& o) {
  Result<Profile> ref = [&]() -> Result<Profile> {
    if (!name_or_path.empty()) return resolve_profile(name_or_path, o.limits);
    const std::optional<int> r_bound = o.renderer_bounces ? o.renderer_bounces : renderer.max_bounces;
    Result<int> bound = reference_bound(renderer.name, r_bound, o.reference_bounces);
    if (!bound) return bound.error();
    return default_reference(scene_universe(scene_types(scene)), *bound, o.limits);
  }();
  if (!ref) return ref.error();
  if (Result<StrategySet> runs = runnable_strategies(*ref); !runs) return runs.error();
  return ref;
}

namespace {

// An internal class of the reference render's classifier: a language with a name.
std::unique_ptr<PathClass> language_class(std::string name, std::string text, Dfa dfa) {
  auto c = std::make_unique<PathClass>();
  c->name = std::move(name);
  c->text = std::move(text);
  c->dfa = std::move(dfa);
  return c;
}

Witness explained(const std::string& path, const CompiledProfile& why_not) {
  return Witness{path, chain_evidence(path), {}, unreachable_reason(path, why_not)};
}

}  // namespace

Result<BiasRun> run_bias(const Scene& scene, const std::string& scene_name, const Profile& renderer,
                         const Profile& reference, const std::vector<const PathClass*>& classes,
                         const BiasOptions& o) {
  for (const PathClass* c : classes)
    if (c->name == kMissedClass)
      return make_error(ErrorCode::kUsage, std::string("the class name '") + kMissedClass +
                                               "' is reserved for what the renderer misses, expected another name");
  // --- the languages: what R samples, what the reference samples, what R misses ---
  const std::optional<int> r_bound = o.renderer_bounces ? o.renderer_bounces : renderer.max_bounces;
  Result<int> bound = reference_bound(renderer.name, r_bound, o.reference_bounces);
  if (!bound) return bound.error();
  Result<CompiledProfile> r = compile_profile(renderer, r_bound, o.limits);
  if (!r) return r.error();
  Result<CompiledProfile> ref = compile_profile(reference, *bound, o.limits);
  if (!ref) return ref.error();
  const Dfa scope = reference_scope(scene, *bound);
  const Dfa missed = dfa_difference(scope, r->reachable);
  const Dfa neither = dfa_difference(missed, ref->reachable);

  // --- the classifier: the user's classes, "missed", and "missed" within each user class ---
  std::vector<std::unique_ptr<PathClass>> internal;
  internal.push_back(language_class(kMissedClass, "paths " + renderer.name + " cannot sample", missed));
  for (const PathClass* c : classes)
    internal.push_back(language_class(kMissedClass + (":" + c->name), c->text, dfa_intersect(c->dfa, missed)));
  std::vector<const PathClass*> all = classes;
  std::vector<ClassInfo> infos;
  for (const PathClass* c : classes) infos.push_back({c->name, c->text});
  for (const auto& c : internal) {
    all.push_back(c.get());
    infos.push_back({c->name, c->text});
  }
  Result<Classifier> classifier = Classifier::build(all, o.limits);
  if (!classifier) return classifier.error();
  const int n = static_cast<int>(classes.size());  // "missed" is class n, missed in class i is n + 1 + i

  // --- the reference render ---
  RenderOptions ro;
  ro.spp = o.spp;
  ro.seed = o.seed;
  ro.threads = o.threads;
  ro.max_bounces = *bound;
  ro.images = o.images;
  if (ro.images)
    for (int i = 0; i <= n; ++i) ro.layer_classes.push_back(i);
  ro.progress = o.progress;
  ro.cancel = o.cancel;
  Result<RenderOutput> out = render(scene, reference, &*classifier, ro);
  if (!out) return out.error();
  RunInfo info;
  info.scene = scene_name;
  info.renderer = reference.name;
  info.spp = out->spp_done;
  info.spp_requested = o.spp;
  info.seed = o.seed;
  info.complete = out->complete;
  // histogram.json's report, like trace's: max_paths rows and one "other" row summing the rest.
  Result<HistogramReport> hist = make_report(out->histogram, info, &*classifier, infos, o.max_paths);
  if (!hist) return hist.error();

  // --- the report ---
  BiasReport rep;
  rep.scene = scene_name;
  rep.renderer = renderer.name;
  rep.renderer_bounces = r_bound;
  rep.reference = reference.name;
  for (const Strategy& st : reference.strategies) rep.reference_strategies.push_back(st.describe());
  rep.reference_bounces = *bound;
  rep.spp = out->spp_done;
  rep.seed = o.seed;
  rep.complete = out->complete;
  rep.time_s = out->time_s;
  rep.nonfinite_samples = hist->nonfinite_samples;
  rep.total = hist->total;
  rep.covered = is_empty(missed);
  rep.missed = hist->classes[static_cast<std::size_t>(n)].estimate;
  if (rep.total.luminance > 0) {
    rep.share = rep.missed.luminance / rep.total.luminance;
    rep.share_std_error = std::isfinite(rep.missed.std_error) ? rep.missed.std_error / rep.total.luminance : 0.0;
  }
  QueryOptions qo;
  qo.universe = scope;
  qo.witnesses = 1;
  qo.max_len = 0;
  qo.limits = o.limits;
  for (int i = 0; i < n; ++i) {
    const PathClass& c = *classes[static_cast<std::size_t>(i)];
    MissedClass mc;
    mc.name = c.name;
    mc.expr = c.text;
    mc.light = hist->classes[static_cast<std::size_t>(i)].estimate;
    mc.missed = hist->classes[static_cast<std::size_t>(n + 1 + i)].estimate;
    Result<QueryResult> q = query(c, *r, qo);
    if (!q) return q.error();
    mc.verdict = q->verdict;
    if (!q->unreachable.empty()) mc.witness = q->unreachable.front();
    if (std::optional<std::string> w = shortest_member(dfa_intersect(c.dfa, neither))) mc.neither = explained(*w, *ref);
    rep.classes.push_back(std::move(mc));
  }
  // Missed paths: R's verdict once per row of the report (a distinct path), never per sample; the
  // missed paths past the rows are counted by their class set, decided when the path was interned.
  std::uint64_t missed_paths = 0;
  for (Histogram::PathId id = 0; id < out->histogram.num_paths(); ++id) {
    const std::vector<int>& members = classifier->members(out->histogram.class_set(id));
    missed_paths += std::binary_search(members.begin(), members.end(), n) ? 1 : 0;
  }
  for (const PathEstimate& p : hist->paths) {
    if (r->reachable.accepts(p.path)) continue;
    MissedPath mp;
    mp.estimate = p;
    mp.share = rep.total.luminance > 0 ? p.estimate.luminance / rep.total.luminance : 0.0;
    mp.chains = chain_evidence(p.path);
    mp.reason = unreachable_reason(p.path, *r);
    rep.paths.push_back(std::move(mp));
  }
  rep.other_missed_paths = missed_paths - rep.paths.size();
  if (std::optional<std::string> w = shortest_member(missed)) rep.shortest = explained(*w, *r);
  if (std::optional<std::string> first = shortest_member(neither)) {
    for (const std::string& w : enumerate_members(neither, static_cast<int>(first->size()) + 8,
                                                  static_cast<std::size_t>(std::max(o.witnesses, 1))))
      rep.neither.push_back(explained(w, *ref));
    rep.neither_finite = is_finite(neither);
  }

  // histogram.json keeps the user's classes and "missed" (the per-class parts are in the report).
  hist->classes.resize(static_cast<std::size_t>(n + 1));
  return BiasRun{std::move(rep), std::move(*out), std::move(*hist)};
}

}  // namespace pathex
