#include "bias/bias.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>
#include <utility>

#include "automata/ops.h"
#include "classify/classifier.h"
#include "stats/significance.h"
#include "io/profile_json.h"
#include "scene/universe.h"
#include "trace/plan.h"

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
  // Per connector (in the order the built-ins first name it), the widest strategies: every
  // candidate whose language no other candidate's holds. bdpt+manifold's two manifold strategies,
  // t >= 2 and the pinhole-ending t = 1, hold neither the other (and pt-nee+manifold's lies within
  // the first), so both join: the t = 1 one samples a caustic seen through glass by the light's
  // density, and without it the reference of lamp-glass.json's LDDSSDSSDSE read +-8 % at 16,384
  // spp where bdpt+manifold reads +-2 % at 256. Where two overlap in (s, t) the tracer runs the
  // first (StrategyTable), and every chain of a connector is the same expression.
  struct Candidate {
    Strategy strategy;
    Dfa language;
  };
  std::vector<Candidate> chosen;
  std::vector<ConnectorKind> order;  // the connectors in the order the built-ins first name them
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
      const auto same = [&](const Candidate& c) { return c.strategy.connector == st.connector; };
      if (std::any_of(chosen.begin(), chosen.end(), [&](const Candidate& c) { return same(c) && is_subset(*language, c.language); }))
        continue;
      chosen.erase(std::remove_if(chosen.begin(), chosen.end(),
                                  [&](const Candidate& c) { return same(c) && is_subset(c.language, *language); }),
                   chosen.end());
      if (std::find(order.begin(), order.end(), st.connector) == order.end()) order.push_back(st.connector);
      chosen.push_back({st, std::move(*language)});
    }
  // In that order of connectors, then of strategies; named after the connector (the first of
  // each) or as the built-in names it (the others, e.g. manifold-splat).
  const auto rank = [&](ConnectorKind k) { return std::find(order.begin(), order.end(), k) - order.begin(); };
  std::stable_sort(chosen.begin(), chosen.end(),
                   [&](const Candidate& a, const Candidate& b) { return rank(a.strategy.connector) < rank(b.strategy.connector); });
  ConnectorKind last = ConnectorKind::kNone;
  for (Candidate& c : chosen) {
    const bool first = c.strategy.connector != last;
    last = c.strategy.connector;
    if (first) {
      c.strategy.name = to_string(c.strategy.connector);
      ref.name += "+" + c.strategy.name;
    }
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

// R's estimates against the reference's, pair by pair (UnderSampled in bias.h). Each difference
// is a t statistic with the Welch–Satterthwaite degrees of freedom of its two stderrs (each
// estimate's own, Estimate::dof: a rare path's few hits give fewer than the render's `r_dof`,
// `ref_dof`): a path R never sampled (0 ± 0) is judged on the reference's stderr alone, with its
// dof, however few passes R's budget took. A reference estimate that is not 0 but has a stderr
// of 0 (its few hits agreed exactly across the replicates) has an unknown error: no claim.
UnderSampling compare_estimates(std::vector<UnderSampled> pairs, double rate, double min_difference, int r_dof, int ref_dof) {
  UnderSampling u;
  u.rate = rate;
  u.min_difference = min_difference;
  u.dof = std::max(std::min(r_dof, ref_dof), 1);
  std::vector<UnderSampled> compared;
  for (UnderSampled& p : pairs) {
    if (!std::isfinite(p.renderer.std_error) || !std::isfinite(p.reference.std_error)) continue;  // no stderr: no claim
    if (p.reference.std_error == 0 && p.reference.luminance != 0) continue;                        // nor an unknown one
    compared.push_back(std::move(p));
  }
  u.comparisons = static_cast<int>(compared.size());
  u.each = 1 - std::pow(1 - rate, 1.0 / std::max(u.comparisons, 1));
  u.sigmas = sidak_sigmas(u.comparisons, rate, u.dof);
  for (UnderSampled& p : compared) {
    const double vr = p.renderer.std_error * p.renderer.std_error;
    const double vref = p.reference.std_error * p.reference.std_error;
    const double rounding = 1e-6 * std::max(std::fabs(p.renderer.luminance), std::fabs(p.reference.luminance));
    const double sigma = std::sqrt(vr + vref + rounding * rounding);
    const double diff = p.renderer.luminance - p.reference.luminance;
    if (sigma == 0 || std::fabs(diff) < min_difference) continue;  // equal, or too little light to matter
    p.z = diff / sigma;
    const int dr = std::max(std::min(p.renderer.dof, r_dof), 1), dref = std::max(std::min(p.reference.dof, ref_dof), 1);
    p.dof = vr + vref > 0 ? welch_dof(vr, dr, vref, dref) : dref;
    if (student_two_sided_tail(std::fabs(p.z), static_cast<int>(std::lround(p.dof))) < u.each) u.flagged.push_back(std::move(p));
  }
  std::stable_sort(u.flagged.begin(), u.flagged.end(),
                   [](const UnderSampled& a, const UnderSampled& b) { return std::fabs(a.z) > std::fabs(b.z); });
  return u;
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
  // With a comparison of R's own estimates (UnderSampling): "sampled", the paths R can sample
  // within the reference's scope, and "sampled" within each user class.
  const bool compare = o.renderer_spp > 0 || o.renderer_histogram != nullptr;
  if (compare) {
    const Dfa sampled = dfa_difference(scope, missed);
    internal.push_back(language_class("sampled", "paths " + renderer.name + " can sample", sampled));
    for (const PathClass* c : classes)
      internal.push_back(language_class("sampled:" + c->name, c->text, dfa_intersect(c->dfa, sampled)));
  }
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
  const std::size_t sampled_class = static_cast<std::size_t>(2 * n + 1);  // then sampled in class i: 2n + 2 + i

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
  // The reference runs as pathex trace would run it (trace/plan.h): its strategies that can sample
  // a path of this scene.
  Result<RenderPlan> ref_plan = plan_render(scene, reference, *bound, {}, o.limits);
  if (!ref_plan) return ref_plan.error();
  Result<RenderOutput> out = render(scene, *ref_plan, &*classifier, ro);
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

  // --- R's own estimates against the reference's: light R can sample but did not find ---
  if (compare) {
    std::optional<HistogramReport> r_report;
    std::uint64_t r_spp = 0;
    std::uint64_t r_seed = o.seed;
    int r_dof = 0;
    if (o.renderer_spp > 0) {
      Result<Classifier> r_classifier = Classifier::build(classes, o.limits);
      if (!r_classifier) return r_classifier.error();
      RenderOptions rro;
      rro.spp = o.renderer_spp;
      rro.seed = r_seed = o.seed + 1;  // independent of the reference's samples
      rro.threads = o.threads;
      rro.max_bounces = r_bound ? std::min(*r_bound, *bound) : *bound;  // the light the reference measures
      rro.images = false;
      rro.splits = o.renderer_splits;
      rro.cancel = o.cancel;
      Result<RenderPlan> r_plan = plan_render(scene, renderer, *rro.max_bounces, {}, o.limits);
      if (!r_plan) return r_plan.error();
      Result<RenderOutput> r_out = render(scene, *r_plan, &*r_classifier, rro);
      if (!r_out) return r_out.error();
      RunInfo r_info = info;
      r_info.renderer = renderer.name;
      r_info.spp = r_spp = r_out->spp_done;
      r_info.spp_requested = o.renderer_spp;
      r_info.seed = r_seed;
      std::vector<ClassInfo> user(infos.begin(), infos.begin() + n);
      Result<HistogramReport> rr = make_report(r_out->histogram, r_info, &*r_classifier, user);
      if (!rr) return rr.error();
      r_report = std::move(*rr);
      r_dof = r_out->histogram.stderr_dof();
      rep.complete = rep.complete && r_out->complete;
    } else {
      RunInfo r_info = info;
      r_info.renderer = renderer.name;
      Result<HistogramReport> rr = make_report(*o.renderer_histogram, r_info, nullptr, {});
      if (!rr) return rr.error();
      r_report = std::move(*rr);
      r_spp = o.spp;
      r_dof = o.renderer_histogram->stderr_dof();
    }
    std::vector<UnderSampled> pairs;
    pairs.push_back({"total", false, r_report->total, hist->classes[sampled_class].estimate});
    if (r_report->classes.size() == static_cast<std::size_t>(n))
      for (int i = 0; i < n; ++i)
        pairs.push_back({classes[static_cast<std::size_t>(i)]->name, false, r_report->classes[static_cast<std::size_t>(i)].estimate,
                         hist->classes[sampled_class + 1 + static_cast<std::size_t>(i)].estimate});
    std::unordered_map<std::string, const Estimate*> r_paths;
    for (const PathEstimate& p : r_report->paths) r_paths.emplace(p.path, &p.estimate);
    for (const PathEstimate& p : hist->paths) {
      if (!r->reachable.accepts(p.path)) continue;
      const auto found = r_paths.find(p.path);
      Estimate never;  // R did not sample it: 0 ± 0
      never.std_error = 0;
      pairs.push_back({p.path, true, found != r_paths.end() ? *found->second : never, p.estimate});
    }
    rep.undersampled = compare_estimates(std::move(pairs), o.undersampled_rate,
                                         o.undersampled_share * hist->classes[sampled_class].estimate.luminance,
                                         r_dof, out->histogram.stderr_dof());
    rep.undersampled->min_share = o.undersampled_share;
    rep.undersampled->spp = r_spp;
    rep.undersampled->seed = r_seed;
  }

  // histogram.json keeps the user's classes and "missed" (the per-class parts are in the report).
  hist->classes.resize(static_cast<std::size_t>(n + 1));
  return BiasRun{std::move(rep), std::move(*out), std::move(*hist)};
}

Result<BiasRun> measure_missed(const Scene& scene, const std::string& scene_name, const Profile& renderer,
                               const std::string& reference, const std::vector<const PathClass*>& classes,
                               const BiasOptions& options) {
  Result<Profile> ref = choose_reference(reference, scene, renderer, options);
  if (!ref) return ref.error();
  return run_bias(scene, scene_name, renderer, *ref, classes, options);
}

}  // namespace pathex
