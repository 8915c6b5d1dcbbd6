// converge's run (measure/converge.h): the reference, the checker's verdicts per class, the ladder
// (each rung a render() call, dealt among MPI ranks), the statistics, converge.json, the plot and
// the output set. The command (cli/converge.cpp) parses options and prints the table.
#include "measure/converge.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include "automata/ops.h"
#include "bias/bias.h"
#include "io/atomic_file.h"
#include "io/class_file.h"
#include "io/convergence_plot.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/input_file.h"
#include "io/output_set.h"
#include "io/profile_json.h"
#include "measure/converge_json.h"
#include "measure/render_watch.h"
#include "output/render_job.h"
#include "scene/resolution.h"
#include "scene/universe.h"
#include "trace/plan.h"
#include "trace/render.h"

namespace pathex {
namespace {

// --- the reference (the ladder's budgets, class rows and measures: measure/ladder.h) ---

struct Reference {
  std::string kind;    // "closed-form", "file", "run"
  std::string source;  // the formula, the file, or the run that made it
  std::optional<ReferenceRun> run;  // for "run"
};

// --- one rung ---

struct RungSetup {
  RenderWatch* watch = nullptr;  // Ctrl-C keeps the finished rungs; a time budget stops a rung
  const Scene* scene = nullptr;
  const Classifier* classifier = nullptr;
  int threads = 0;
  std::optional<int> max_bounces;  // unset: each profile's own bound, else 16 (as trace)
  ManifoldOptions manifold;        // the manifold connector's limits
};

// Renders one rung: `plan` (trace/plan.h) at `budget` with `seed`. A time budget stops the render
// after the chunk in progress when the time is up; Ctrl-C (setup.watch) stops it and marks it interrupted.
// Under MPI every rank calls it for every rung (it is collective): the ranks deal the rung's
// passes among themselves (Cluster::deal: whoever is free takes the next chunk), and only rank 0's
// result holds the rung's measures (the others' `classes` are empty). A rung interrupted on any
// rank is interrupted on all.
Result<RungResult> run_rung(const RungSetup& setup, const RenderPlan& plan, const Budget& budget, std::uint64_t seed,
                            const std::vector<ClassRow>& rows) {
  Cluster* cluster = current_cluster();
  RenderOptions ro;
  ro.spp = budget.spp ? budget.spp : (std::uint64_t{1} << 24);
  std::unique_ptr<PassDealer> dealer;  // under MPI, the ranks' shared deal of the rung's passes
  if (cluster != nullptr) {
    dealer = cluster->deal(PassSet::range(0, ro.spp), kPassesPerChunk, ro.batches);
    ro.dealer = dealer.get();
  }
  ro.seed = seed;
  ro.threads = setup.threads;
  ro.max_bounces = setup.max_bounces;
  ro.manifold = setup.manifold;
  for (int i = 0; i < setup.classifier->num_classes(); ++i) ro.layer_classes.push_back(i);
  setup.watch->restart(budget.spp ? 0.0 : budget.seconds);
  ro.progress = setup.watch->progress();
  ro.cancel = setup.watch->cancel();
  const double cpu0 = process_cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  Result<RenderOutput> out = render(*setup.scene, plan, setup.classifier, ro);
  const double cpu1 = process_cpu_seconds();
  auto wall1 = std::chrono::steady_clock::now();
  dealer.reset();  // every rank has left the deal: the cluster is free for the reduction
  if (!out) return out.error();
  RungResult r;
  r.budget = budget;
  r.seed = seed;
  r.cpu_s = r.own_cpu_s = cpu1 - cpu0;
  if (cluster != nullptr) {
    RenderSums sums{std::move(out->histogram), std::move(out->images), std::move(out->connectors)};
    ShardRun run{out->time_s, ro.threads, out->rays, r.cpu_s};
    if (Result<bool> red = cluster->reduce(&sums, &out->passes_done, &run); !red) return red.error();
    out->histogram = std::move(sums.histogram);
    out->images = std::move(sums.images);
    out->connectors = std::move(sums.connectors);
    out->spp_done = out->passes_done.count();  // on rank 0, every rank's
    r.cpu_s = run.cpu_s;
    wall1 = std::chrono::steady_clock::now();
  }
  const bool root = cluster == nullptr || cluster->rank() == 0;
  r.spp = out->spp_done;
  r.wall_s = std::chrono::duration<double>(wall1 - wall0).count();
  r.interrupted = setup.watch->interrupted() || (root && out->spp_done == 0);
  if (cluster != nullptr) r.interrupted = cluster->count_failures(!r.interrupted) > 0;
  if (r.interrupted || !root) return r;
  if (Result<bool> m = measure_rung(*out, setup.classifier, rows, &r); !m) return m.error();
  r.output = std::move(*out);
  return r;
}

}  // namespace

Result<ConvergeResult> converge(const ConvergeOptions& a, const ConvergeHooks& hooks) {
  ConvergeResult res;
  const double cpu_start = process_cpu_seconds();
  const auto wall_start = std::chrono::steady_clock::now();
  double render_wall = 0.0, render_cpu = 0.0;  // inside render(): the ladder and the reference run
  double own_render_cpu = 0.0;                   // the part of render_cpu this process spent (MPI: rank 0's)
  // --- budgets ---
  if (!a.spp_list.empty() && !a.time_list.empty())
    return make_error(ErrorCode::kUsage, "--spp and --time are alternatives: give one ladder");
  const bool by_time = !a.time_list.empty();
  Result<std::vector<Budget>> ladder =
      parse_ladder(by_time ? a.time_list : (a.spp_list.empty() ? "4,16,64,256" : a.spp_list), by_time, by_time ? "--time" : "--spp");
  if (!ladder) return ladder.error();
  if (a.renderers.empty()) return make_error(ErrorCode::kUsage, "name at least one --renderer");

  // --- scene, output folder, profiles ---
  Result<Scene> scene = load_scene_file(a.scene, scene_load_options(a.limits));
  if (!scene) return scene.error();
  if (!a.resolution.empty())
    if (Result<bool> r = apply_resolution(a.resolution, &scene->camera); !r) return r.error();
  // Under MPI, rank 0 alone writes and shows progress (run_rung).
  const Cluster* cluster = current_cluster();
  const bool root = cluster == nullptr || cluster->rank() == 0;
  std::optional<OutputSet> out_set;
  if (root && !a.out.empty()) {
    Result<OutputSet> prepared = OutputSet::prepare(a.out);
    if (!prepared) return prepared.error();
    out_set.emplace(std::move(*prepared));
  }
  std::vector<Profile> profiles;
  for (const std::string& name : a.renderers) {
    Result<Profile> p = resolve_profile(name, a.limits);
    if (!p) return p.error();
    if (Result<StrategySet> ok = runnable_strategies(*p); !ok) return ok.error();
    profiles.push_back(std::move(*p));
  }
  // --- classes: the class file's, else the closed form's, else the built-ins; "total" first ---
  // The class file's classes, or the built-ins (as trace compiles them), unless the scene declares a
  // closed form and no class file is given: then its classes.
  const SceneTypes types = scene_types(*scene);
  // The reference run's profile: --reference-renderer, else one the checker says samples every path
  // of the scene within the deepest renderer's bound — pathex bias's default reference, bdpt plus
  // the connectors the tracer runs whose chains the scene has (issue 36: the first --renderer was
  // the default, and pt-nee cannot see a point light's caustic).
  int bound = a.max_bounces.value_or(16);
  if (!a.max_bounces)
    for (const Profile& p : profiles) bound = std::max(bound, p.max_bounces.value_or(16));
  Result<Profile> ref_profile = a.reference_renderer.empty() ? default_reference(scene_universe(types), bound, a.limits)
                                                             : resolve_profile(a.reference_renderer, a.limits);
  if (!ref_profile) return ref_profile.error();
  if (a.reference_renderer.empty()) ref_profile->max_bounces = bound;
  if (Result<StrategySet> ok = runnable_strategies(*ref_profile); !ok) return ok.error();
  RenderIdentity ends;
  for (LightType l : types.lights) ends.lights.push_back(to_string(l));
  ends.sensor = to_string(types.sensor);
  ends.only = a.only;
  ends.max_bounces = a.max_bounces.value_or(16);
  // With --only the scene's closed form (a total and its classes) is not the measure: the
  // reference is --reference FILE or a reference run of the requested classes.
  const bool closed_form = scene->reference.has_value() && a.only.empty();
  std::string class_text;
  if (!a.classes_file.empty()) {
    Result<std::string> text = read_input_file(a.classes_file, a.limits.max_file_bytes);
    if (!text) return text.error();
    class_text = std::move(*text);
  }
  Result<std::unique_ptr<RenderClasses>> listed = compile_render_classes(class_text, a.classes_file, ends, a.limits);
  if (!listed) return listed.error();
  std::vector<std::unique_ptr<PathClass>> owned;
  std::vector<const PathClass*> classes = (*listed)->classes;
  if (a.classes_file.empty() && closed_form) {
    ClassOptions copts;
    copts.limits = a.limits;
    copts.ends.lights.assign(types.lights.begin(), types.lights.end());
    copts.ends.sensors = {types.sensor};
    classes.clear();
    for (std::size_t i = 0; i < scene->reference->classes.size(); ++i) {
      const ReferenceClass& rc = scene->reference->classes[i];
      if (rc.name == "total") continue;
      Result<PathClass> pc = compile_class(rc.expr, copts);
      if (!pc) {
        Error e = pc.error();
        e.where = a.scene + ":/reference/classes/" + std::to_string(i) + "/class";
        return e;
      }
      owned.push_back(std::make_unique<PathClass>(std::move(*pc)));
      owned.back()->name = rc.name;
      owned.back()->text = rc.expr;
      classes.push_back(owned.back().get());
    }
  }
  // --- --only: the requested classes are measured, the others listed as not rendered ---
  std::vector<const PathClass*> not_rendered;
  std::string requested_text;
  if (!a.only.empty()) {
    std::vector<const PathClass*> estimated;
    for (std::size_t i = 0; i < classes.size(); ++i) ((*listed)->estimated[i] ? estimated : not_rendered).push_back(classes[i]);
    classes = std::move(estimated);
    for (const PathClass* c : (*listed)->requested) requested_text += (requested_text.empty() ? "" : " | ") + c->text;
  }
  const bool only = !a.only.empty();
  // --- the plans (trace/plan.h), as pathex trace makes them: each renderer runs the strategies
  // and joins that sample the (requested) paths of this scene, and records only those ---
  const std::vector<const PathClass*> requested = only ? (*listed)->requested : std::vector<const PathClass*>{};
  std::vector<RenderPlan> plans;  // per renderer of the ladder, then the reference's
  for (const Profile* p : [&] {
         std::vector<const Profile*> all;
         for (const Profile& q : profiles) all.push_back(&q);
         all.push_back(&*ref_profile);
         return all;
       }()) {
    const int bounces = a.max_bounces.value_or(p->max_bounces.value_or(16));
    Result<RenderPlan> plan = plan_render(*scene, *p, bounces, requested, a.limits);
    if (!plan) return plan.error();
    if (plan->samples_nothing()) {
      res.nothing_to_render = "nothing to render: no strategy of " + p->name +
                              " samples a path of the requested classes in this scene (" + describe(types) + ")";
      return res;
    }
    plans.push_back(std::move(*plan));
  }
  Result<Classifier> classifier = Classifier::build(classes, a.limits);
  if (!classifier) return classifier.error();
  // Row 0 is every path measured: the scene's total, or with --only the requested paths' total.
  std::vector<ClassRow> rows{{only ? "requested" : "total", only ? requested_text : "$all", std::nullopt, 0.0, std::nullopt, ""}};
  for (const PathClass* c : classes) rows.push_back({c->name, c->text, std::nullopt, 0.0, std::nullopt, ""});

  // Ctrl-C (or SIGTERM) stops the rung in progress and keeps the finished ones; the watch shows no
  // render progress (the rung's line below is converge's).
  std::optional<RenderWatch> watch;
  watch.emplace(/*show=*/false);
  RungSetup setup{&*watch, &*scene, &*classifier, a.threads, a.max_bounces, ManifoldOptions{}};  // the reference: the manifold's defaults
  const int width = scene->camera.width, height = scene->camera.height;
  const std::uint64_t base_seed = a.seed;
  const bool progress = root && hooks.progress;

  // --- the reference ---
  Reference ref;
  std::optional<RungResult> ref_run;
  std::string file_renderer;  // --reference FILE: the renderer that made it
  if (!a.reference.empty()) {
    if (Result<bool> r = load_reference_file(a.reference, width, height, &rows, &file_renderer); !r) return r.error();
    ref.kind = "file";
    ref.source = a.reference;
  } else if (closed_form) {
    for (ClassRow& row : rows)
      for (const ReferenceClass& rc : scene->reference->classes)
        if (rc.name == row.name) {
          row.reference = rc.luminance;
          if (scene->reference->uniform)
            row.pixels = std::vector<float>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                                            static_cast<float>(rc.luminance));
        }
    ref.kind = "closed-form";
    ref.source = scene->reference->source;
  } else {
    Budget rb = ladder->back();
    if (rb.spp) rb.spp *= a.reference_factor;
    else rb.seconds *= static_cast<double>(a.reference_factor);
    const std::uint64_t seed = base_seed ^ 0x5eed5eed5eedULL;
    if (progress) hooks.progress(ref_profile->name + " at " + rb.text(), true);
    Result<RungResult> r = run_rung(setup, plans.back(), rb, seed, rows);
    if (!r) return r.error();
    render_wall += r->wall_s;
    render_cpu += r->cpu_s;
    own_render_cpu += r->own_cpu_s;
    if (r->interrupted) {
      res.reference_interrupted = true;
      res.root = root;
      return res;
    }
    for (std::size_t i = 0; root && i < rows.size(); ++i) {
      rows[i].reference = r->classes[i].estimate;
      rows[i].reference_stderr = std::isfinite(r->classes[i].std_error) ? r->classes[i].std_error : 0.0;
    }
    if (root) {
      const std::vector<ImageLayer> layers = r->output->images.layers(1.0 / static_cast<double>(r->spp));
      for (std::size_t i = 0; i < rows.size(); ++i) rows[i].pixels = luminance_image(layers[i].image);
    }
    ref.kind = "run";
    ref.source = "a reference run of " + ref_profile->name + " at " + std::to_string(r->spp) + " spp, seed " +
                 std::to_string(seed) + ", written to " + a.out + "/reference.json and reference.exr";
    ref.run = ReferenceRun{ref_profile->name, r->spp, seed, r->cpu_s, r->wall_s, r->nonfinite};
    ref_run = std::move(*r);
  }

  // --- what the reference and each renderer can sample of every class (the checker's verdict) ---
  // A class holding a path that a renderer of the ladder samples and the reference cannot is not
  // measurable with that reference: its value lacks that path's light, so every error against it
  // would be wrong (a renderer that is right would be "many σ off"). A renderer is never ranked on a
  // class holding a path it cannot sample that the reference (or, when what the reference samples
  // is not known, another renderer of the ladder) samples. Paths none of them samples are in no
  // estimate (pathex bias lists them).
  const Dfa scope = reference_scope(*scene, bound);
  std::vector<const Dfa*> languages{only && (*listed)->requested_language ? &*(*listed)->requested_language : &scope};
  for (const PathClass* c : classes) languages.push_back(&c->dfa);
  const auto unsampled = [&](const Dfa& reachable, const Dfa& within) {
    std::vector<std::optional<std::string>> out;
    for (const Dfa* l : languages) out.push_back(first_unsampled(reachable, within, *l));
    return out;
  };
  std::vector<Dfa> reach;  // per renderer of the ladder
  Dfa ladder_reach = dfa_empty();
  for (const Profile& p : profiles) {
    Result<CompiledProfile> cp = compile_profile(p, a.max_bounces.value_or(p.max_bounces.value_or(16)), a.limits);
    if (!cp) return cp.error();
    ladder_reach = dfa_union(ladder_reach, cp->reachable);
    reach.push_back(std::move(cp->reachable));
  }
  std::string ref_reach_note;  // why what the reference reaches is not known, when it is not
  std::optional<Dfa> ref_reach;
  if (ref.kind != "closed-form") {
    std::optional<Profile> judged;
    if (ref.kind == "run") {
      judged = *ref_profile;
    } else if (file_renderer.empty()) {
      ref_reach_note = "the reference is an image alone: what its renderer samples is not known, so no class is checked";
    } else if (file_renderer == ref_profile->name) {  // e.g. an earlier converge's reference.json
      judged = *ref_profile;
    } else if (Result<Profile> p = resolve_profile(file_renderer, a.limits); p) {
      judged = std::move(*p);
    } else {
      ref_reach_note = "the reference's renderer '" + file_renderer + "' is not a built-in profile or a file here: what it samples is not checked";
    }
    if (judged) {
      Result<CompiledProfile> cp = compile_profile(*judged, a.max_bounces.value_or(judged->max_bounces.value_or(16)), a.limits);
      if (!cp) return cp.error();
      ref_reach = std::move(cp->reachable);
      const std::vector<std::optional<std::string>> miss = unsampled(*ref_reach, dfa_intersect(scope, ladder_reach));
      for (std::size_t i = 0; i < rows.size(); ++i)
        if (miss[i] && rows[i].reference) {
          rows[i].unmeasurable = judged->name + " cannot sample " + *miss[i];
          rows[i].reference.reset();
          rows[i].pixels.reset();
        }
    }
  }
  std::vector<std::vector<std::optional<std::string>>> cannot;  // [renderer][row]: a path it cannot sample
  const Dfa seen = dfa_intersect(scope, ref_reach ? *ref_reach : ladder_reach);
  for (const Dfa& r : reach) cannot.push_back(unsampled(r, seen));

  // --- the ladder: every renderer at every budget, each rung its own render and seed ---
  setup.manifold = a.manifold;  // (the reference run, above, keeps the defaults)
  std::vector<std::vector<RungResult>> results(profiles.size());
  bool complete = true;
  for (std::size_t k = 0; k < profiles.size() && complete; ++k)
    for (std::size_t i = 0; i < ladder->size(); ++i) {
      const std::uint64_t seed = base_seed + 1000 * k + i;
      if (progress) hooks.progress(profiles[k].name + " at " + (*ladder)[i].text(), false);
      Result<RungResult> r = run_rung(setup, plans[k], (*ladder)[i], seed, rows);
      if (!r) return r.error();
      render_wall += r->wall_s;
      render_cpu += r->cpu_s;
      own_render_cpu += r->own_cpu_s;
      if (r->interrupted) {
        complete = false;
        break;
      }
      r->output.reset();  // the ladder keeps its numbers only
      results[k].push_back(std::move(*r));
    }
  if (progress) hooks.progress("", false);
  watch.reset();
  if (!root) {  // the other ranks have done their part
    res.root = false;
    res.complete = complete;
    return res;
  }

  // --- statistics ---
  std::vector<std::vector<Series>> series(profiles.size());
  std::vector<std::string> warnings;
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    std::uint64_t nonfinite = 0;
    for (const RungResult& r : results[k]) nonfinite += r.nonfinite;
    if (nonfinite > 0)
      warnings.push_back(profiles[k].name + ": " + std::to_string(nonfinite) + " non-finite samples (a bug: numbers must stay finite)");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      series[k].push_back(analyse(results[k], i, rows[i], cannot[k][i].has_value()));
      if (!series[k].back().warning.empty()) warnings.push_back(profiles[k].name + " on " + rows[i].name + ": " + series[k].back().warning);
    }
  }
  // The most efficient renderer per class (pooled efficiency 1 / mean(error² × CPU time)).
  std::vector<std::string> renderer_names;
  for (const Profile& p : profiles) renderer_names.push_back(p.name);
  const Rankings rankings = rank_renderers(rows, renderer_names, series, cannot);

  // --- the plot: one panel per class with a reference ---
  std::vector<PlotPanel> panels;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].reference) continue;
    PlotPanel p{rows[i].name == "total" ? "total (the whole image)" : rows[i].name + "  " + rows[i].expr, {}};
    for (std::size_t k = 0; k < profiles.size(); ++k) {
      PlotSeries ps{profiles[k].name, {}, series[k][i].error, {}};
      for (const RungResult& r : results[k]) {
        ps.time.push_back(r.cpu_s);
        ps.std_error.push_back(r.classes[i].std_error);
      }
      p.series.push_back(std::move(ps));
    }
    panels.push_back(std::move(p));
  }
  std::optional<PlotFiles> plot;  // drawn only to be written
  if (out_set) {
    Result<PlotFiles> drawn = draw_convergence_plot(panels);
    if (!drawn) return drawn.error();
    plot = std::move(*drawn);
  }

  // Overhead: everything but render() — references, statistics, the plot (the writing below is
  // measured by bench/converge_overhead.py from the outside).
  ConvergeRun doc;
  doc.scene = a.scene;
  doc.complete = complete;
  doc.by_time = by_time;
  doc.ladder = *ladder;
  doc.seed = a.seed;
  doc.threads = a.threads > 0 ? a.threads : static_cast<int>(std::thread::hardware_concurrency());
  doc.ranks = cluster != nullptr ? cluster->size() : 1;  // MPI ranks, each with `threads`
  doc.max_bounces = a.max_bounces;
  doc.width = width;
  doc.height = height;
  doc.only = only;
  for (const PathClass* c : not_rendered) doc.not_rendered.emplace_back(c->name, c->text);
  doc.reference_kind = ref.kind;
  doc.reference_source = ref.source;
  doc.reference_run = ref.run;
  doc.reach_note = ref_reach_note;
  doc.rows = &rows;
  doc.renderers = renderer_names;
  doc.results = &results;
  doc.series = &series;
  doc.cannot = &cannot;
  doc.rankings = &rankings;
  doc.warnings = &warnings;
  doc.render_wall_s = render_wall;
  doc.render_cpu_s = render_cpu;
  doc.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  doc.overhead_cpu_s = process_cpu_seconds() - cpu_start - own_render_cpu;
  const std::string json_text = converge_json_text(doc);

  // --- outputs: one set, whole or not at all ---
  if (out_set) {
    const SignalShield shield;
    Result<bool> written = out_set->write([&](const std::string& dir) -> Result<bool> {
      if (Result<bool> w = write_file_atomic(dir + "/converge.json", json_text); !w) return w;
      if (Result<bool> w = write_file_atomic(dir + "/converge.svg", plot->svg); !w) return w;
      if (Result<bool> w = write_file_atomic(dir + "/converge.png", plot->png); !w) return w;
      const auto with_report = [&]() -> Result<bool> {  // e.g. --report: a file of the set, from the files staged
        return hooks.extra_files ? hooks.extra_files(dir) : Result<bool>(true);
      };
      if (!ref_run) return with_report();
      RunInfo info;
      info.scene = a.scene;
      info.renderer = ref_profile->name;
      info.spp = ref_run->spp;
      info.spp_requested = ref_run->spp;
      info.seed = ref_run->seed;
      std::vector<ClassInfo> infos;
      for (std::size_t i = 1; i < rows.size(); ++i) infos.push_back({rows[i].name, rows[i].expr});
      Result<HistogramReport> rep = make_report(ref_run->output->histogram, info, &*classifier, infos, std::uint64_t{1000});
      if (!rep) return rep.error();
      if (Result<bool> w = write_file_atomic(dir + "/reference.json", histogram_json_text(*rep)); !w) return w;
      if (Result<bool> w = write_exr(dir + "/reference.exr", ref_run->output->images.layers(1.0 / static_cast<double>(ref_run->spp))); !w) return w;
      return with_report();
    });
    if (!written) return written.error();
  }

  res.complete = complete;
  res.reference_kind = ref.kind;
  res.reference_source = ref.source;
  res.reference_written = ref_run.has_value() && out_set.has_value();
  res.reach_note = ref_reach_note;
  res.only = only;
  res.not_rendered = doc.not_rendered;
  res.renderers = std::move(renderer_names);
  res.json_text = json_text;
  res.rows = std::move(rows);
  res.results = std::move(results);
  res.series = std::move(series);
  res.cannot = std::move(cannot);
  res.rankings = rankings;
  res.warnings = std::move(warnings);
  return res;
}

}  // namespace pathex
