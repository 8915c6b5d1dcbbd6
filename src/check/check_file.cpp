// Check files (the CI gate of `pathex check`): reading a file into cases and requirements, and
// deciding each requirement exactly (the checker's verdicts, and for missed, undersampled and
// finite requirements a render). The command (cli/check.cpp) prints the outcomes and writes the
// JSON and JUnit reports.
#include "check/check_file.h"

#include <chrono>
#include <filesystem>
#include <limits>

#include <nlohmann/json.hpp>

#include "automata/ops.h"
#include "check/reach_cache.h"
#include "io/class_file.h"
#include "io/estimate_text.h"
#include "io/json_reader.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex {
namespace {

// The check file and the limits a run reads and decides it under.
struct CheckFileRun {
  std::string file;
  Limits limits;
};

Error bad(const std::string& file, const std::string& pointer, std::string message) {
  return JsonReader(file).fail(pointer, std::move(message));
}

// Relative paths in a check file are tried against the check file's folder, then the current one.
std::string resolve(const std::string& check_file, const std::string& p) {
  namespace fs = std::filesystem;
  if (p.empty() || fs::path(p).is_absolute()) return p;
  const fs::path beside = fs::path(check_file).parent_path() / p;
  std::error_code ec;
  if (fs::exists(beside, ec)) return beside.string();
  return p;
}

// The value of a requirement's "missed" key, through the one JSON reader.
Result<MissedRequirement> parse_missed(const nlohmann::json& jm, const std::string& file, const std::string& ptr) {
  const JsonReader reader(file);
  if (!jm.is_object()) return reader.fail(ptr, "expected {\"max_share\": a share from 0 to 1, \"spp\": samples per pixel}");
  if (Result<bool> k = reader.keys(jm, ptr, {"max_share", "spp", "reference"}); !k) return k.error();
  MissedRequirement m;
  Result<double> share = reader.number(jm, "max_share", ptr, 0.0, 1.0);
  if (!share) return share.error();
  m.max_share = *share;
  Result<long long> spp = reader.integer(jm, "spp", ptr, 1, 1 << 24, 64);
  if (!spp) return spp.error();
  m.spp = static_cast<std::uint64_t>(*spp);
  if (jm.contains("reference")) {
    Result<std::string> ref = reader.string(jm, "reference", ptr);
    if (!ref) return ref.error();
    m.reference = *ref;
  }
  return m;
}

// The value of a requirement's "undersampled" key.
Result<MissedRequirement> parse_undersampled(const nlohmann::json& ju, const std::string& file, const std::string& ptr) {
  const JsonReader reader(file);
  if (!ju.is_object())
    return reader.fail(ptr, "expected {\"spp\": the renderer's samples per pixel, \"reference_spp\": the reference's, \"max_flagged\": a count}");
  if (Result<bool> k = reader.keys(ju, ptr, {"spp", "reference_spp", "max_flagged", "min_share", "reference"}); !k) return k.error();
  MissedRequirement m;
  m.undersampled = true;
  Result<long long> spp = reader.integer(ju, "spp", ptr, 1, 1 << 24, 16);
  if (!spp) return spp.error();
  m.renderer_spp = static_cast<std::uint64_t>(*spp);
  Result<long long> ref_spp = reader.integer(ju, "reference_spp", ptr, 1, 1 << 24, 64);
  if (!ref_spp) return ref_spp.error();
  m.spp = static_cast<std::uint64_t>(*ref_spp);
  Result<long long> flagged = reader.integer(ju, "max_flagged", ptr, 0, std::numeric_limits<long long>::max(), 0);
  if (!flagged) return flagged.error();
  m.max_flagged = static_cast<std::uint64_t>(*flagged);
  Result<double> share = reader.number(ju, "min_share", ptr, 0.0, 1.0, 0.01);
  if (!share) return share.error();
  m.min_share = *share;
  if (ju.contains("reference")) {
    Result<std::string> ref = reader.string(ju, "reference", ptr);
    if (!ref) return ref.error();
    m.reference = *ref;
  }
  return m;
}

}  // namespace

Result<std::vector<Case>> parse_check(const std::string& text, const std::string& file) {
  Result<nlohmann::json> parsed = parse_json(text, file);
  if (!parsed) return parsed.error();
  const nlohmann::json& doc = *parsed;
  if (!doc.is_object()) return bad(file, "/", "expected an object with a \"cases\" array");
  for (const auto& [k, v] : doc.items())
    if (k != "cases" && k != "$schema" && k != "description")
      return bad(file, "/" + pointer_token(k), "unknown key '" + k + "', expected cases");
  if (!doc.contains("cases") || !doc.at("cases").is_array()) return bad(file, "/cases", "expected an array of cases");
  std::vector<Case> cases;
  const auto& arr = doc.at("cases");
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const std::string ptr = "/cases/" + std::to_string(i);
    const auto& jc = arr[i];
    if (!jc.is_object()) return bad(file, ptr, "expected an object with name, renderer and require");
    for (const auto& [k, v] : jc.items())
      if (k != "name" && k != "renderer" && k != "scene" && k != "max_bounces" && k != "require" && k != "notation" &&
          k != "classes" && k != "description")
        return bad(file, ptr + "/" + pointer_token(k),
                   "unknown key '" + k + "', expected one of name, renderer, scene, max_bounces, require, notation, classes, description");
    Case c;
    c.pointer = ptr;
    if (!jc.contains("name") || !jc.at("name").is_string()) return bad(file, ptr + "/name", "expected a string case name");
    c.name = jc.at("name").get<std::string>();
    if (!jc.contains("renderer") || !jc.at("renderer").is_string())
      return bad(file, ptr + "/renderer", "expected a renderer: a built-in profile name or a profile file");
    c.renderer = jc.at("renderer").get<std::string>();
    if (c.renderer.find('/') != std::string::npos || c.renderer.ends_with(".json")) c.renderer = resolve(file, c.renderer);
    if (jc.contains("scene")) {
      if (!jc.at("scene").is_string()) return bad(file, ptr + "/scene", "expected a scene file path");
      c.scene = resolve(file, jc.at("scene").get<std::string>());
    }
    if (jc.contains("classes")) {
      if (!jc.at("classes").is_string()) return bad(file, ptr + "/classes", "expected a class file path");
      c.classes = resolve(file, jc.at("classes").get<std::string>());
    }
    if (jc.contains("max_bounces") && !jc.at("max_bounces").is_null()) {
      Result<long long> m = JsonReader(file).integer(jc, "max_bounces", ptr, 0, kMaxBouncesCeiling);
      if (!m) return m.error();
      c.max_bounces = static_cast<int>(*m);
    }
    if (jc.contains("notation")) {
      const auto n = jc.at("notation").is_string() ? notation_from_string(jc.at("notation").get<std::string>()) : std::nullopt;
      if (!n) return bad(file, ptr + "/notation", "expected \"full\", \"heckbert\" or \"lpe\"");
      c.notation = *n;
    }
    if (!jc.contains("require") || !jc.at("require").is_array() || jc.at("require").empty())
      return bad(file, ptr + "/require", "expected a non-empty array of requirements");
    const auto& reqs = jc.at("require");
    for (std::size_t j = 0; j < reqs.size(); ++j) {
      const std::string rp = ptr + "/require/" + std::to_string(j);
      const auto& jr = reqs[j];
      if (!jr.is_object())
        return bad(file, rp,
                   "expected {\"class\": …, \"verdict\": …}, {\"covers-scene\": true}, {\"missed\": {…}}, {\"undersampled\": {…}} or {\"finite\": true}");
      Requirement r;
      r.pointer = rp;
      if (jr.contains("finite")) {
        for (const auto& [k, v] : jr.items())
          if (k != "finite" && k != "spp" && k != "seed")
            return bad(file, rp + "/" + pointer_token(k), "unknown key '" + k + "', expected finite with optional spp and seed");
        if (jr.at("finite") != true) return bad(file, rp + "/finite", "expected true");
        if (c.scene.empty()) return bad(file, ptr + "/scene", "a finite requirement renders the case's scene: expected a scene file path");
        Result<long long> spp = JsonReader(file).integer(jr, "spp", rp, 1, 1 << 20, 16);
        if (!spp) return spp.error();
        Result<long long> seed = JsonReader(file).integer(jr, "seed", rp, 0, std::numeric_limits<long long>::max(), 1);
        if (!seed) return seed.error();
        r.finite = FiniteRequirement{static_cast<std::uint64_t>(*spp), static_cast<std::uint64_t>(*seed)};
        c.require.push_back(std::move(r));
        continue;
      }
      for (const auto& [k, v] : jr.items())
        if (k != "class" && k != "verdict" && k != "covers-scene" && k != "missed" && k != "undersampled")
          return bad(file, rp + "/" + pointer_token(k),
                     "unknown key '" + k + "', expected class and verdict, or covers-scene, or missed, or undersampled, or finite");
      if (jr.contains("undersampled")) {
        if (jr.size() != 1) return bad(file, rp, "undersampled stands alone: no other key beside it");
        if (c.scene.empty()) return bad(file, rp + "/undersampled", "an undersampled requirement needs the case's scene");
        Result<MissedRequirement> m = parse_undersampled(jr.at("undersampled"), file, rp + "/undersampled");
        if (!m) return m.error();
        r.missed = *m;
      } else if (jr.contains("missed")) {
        if (jr.size() != 1) return bad(file, rp, "missed stands alone: no other key beside it");
        if (c.scene.empty()) return bad(file, rp + "/missed", "a missed requirement needs the case's scene");
        Result<MissedRequirement> m = parse_missed(jr.at("missed"), file, rp + "/missed");
        if (!m) return m.error();
        r.missed = *m;
      } else if (jr.contains("covers-scene")) {
        if (jr.at("covers-scene") != true) return bad(file, rp + "/covers-scene", "expected true");
        if (jr.contains("class") || jr.contains("verdict"))
          return bad(file, rp, "covers-scene stands alone: no class or verdict beside it");
        r.covers_scene = true;
      } else {
        if (!jr.contains("class") || !jr.at("class").is_string())
          return bad(file, rp + "/class", "expected a class: an expression or a $name");
        if (!jr.contains("verdict") || !jr.at("verdict").is_string())
          return bad(file, rp + "/verdict", "expected a verdict: reachable, not-unreachable, unreachable, partial or empty");
        r.cls = jr.at("class").get<std::string>();
        r.verdict = jr.at("verdict").get<std::string>();
        if (r.verdict != "reachable" && r.verdict != "not-unreachable" && r.verdict != "unreachable" &&
            r.verdict != "partial" && r.verdict != "empty")
          return bad(file, rp + "/verdict",
                     "unknown verdict '" + r.verdict + "', expected reachable, not-unreachable, unreachable, partial or empty");
      }
      c.require.push_back(std::move(r));
    }
    cases.push_back(std::move(c));
  }
  return cases;
}

namespace {

bool satisfies(const std::string& wanted, Verdict v) {
  if (wanted == "reachable") return v == Verdict::kReachable;
  if (wanted == "not-unreachable") return v == Verdict::kReachable || v == Verdict::kPartial;
  if (wanted == "unreachable") return v == Verdict::kUnreachable || v == Verdict::kEmpty;
  return to_string(v) == wanted;
}

// An error about a file a case refers to (an unknown renderer, a scene or class file that cannot
// be read) is placed at the case's key in the check file, naming the referenced file; an error
// inside a file that was read (a bad scene or profile) keeps its own location.
Error at_case_key(Error e, const std::string& check_file, const std::string& pointer, const std::string& referenced) {
  if (!e.where.empty() && e.where != referenced) return e;
  if (e.where == referenced && !referenced.empty()) e.message = referenced + ": " + e.message;
  e.where = check_file + ":" + pointer;
  return e;
}

// A finite requirement: renders the case's scene with its renderer (no images) and returns "" when
// no contribution was non-finite, else how many and where the first arose.
Result<std::string> render_finite(const Case& c, const Requirement& r, ReachCache& cache, const Limits& limits) {
  Result<Scene> scene = load_scene_file(c.scene, scene_load_options(limits));
  if (!scene) return scene.error();
  Result<const Profile*> profile = cache.profile(c.renderer);
  if (!profile) return profile.error();
  RenderOptions ro;
  ro.spp = r.finite->spp;
  ro.seed = r.finite->seed;
  ro.max_bounces = c.max_bounces;
  ro.images = false;
  Result<RenderOutput> out = render(*scene, **profile, nullptr, ro);
  if (!out) return out.error();
  const std::uint64_t n = out->histogram.nonfinite();
  if (n == 0) return std::string();
  std::string s = std::to_string(n) + " non-finite samples";
  if (out->first_nonfinite)
    s += "; the first from strategy " + out->first_nonfinite->strategy + " on path " + out->first_nonfinite->path;
  return s;
}

// A missed requirement: one reference render of the case's scene (pathex bias) without images. It
// fails when the renderer misses more than max_share of the light; the counterexample is the
// shortest path it cannot sample, and the details name the largest missed path.
Result<bool> decide_missed(const CheckFileRun& a, ReachCache& cache, const Case& c, const Requirement& r, Outcome* o) {
  Result<Scene> scene = load_scene_file(c.scene, scene_load_options(a.limits));
  if (!scene) return at_case_key(scene.error(), a.file, c.pointer + "/scene", c.scene);
  Result<const Profile*> renderer = cache.profile(c.renderer);
  if (!renderer) return at_case_key(renderer.error(), a.file, c.pointer + "/renderer", c.renderer);
  BiasOptions bo;
  bo.spp = r.missed->spp;
  if (r.missed->undersampled) {
    bo.renderer_spp = r.missed->renderer_spp;
    bo.undersampled_share = r.missed->min_share;
  }
  bo.renderer_bounces = c.max_bounces;
  bo.images = false;
  bo.limits = a.limits;
  const std::string reference = r.missed->reference.empty() || r.missed->reference.find('/') == std::string::npos
                                    ? r.missed->reference
                                    : resolve(a.file, r.missed->reference);
  const std::string key = r.missed->undersampled ? "/undersampled" : "/missed";
  Result<BiasRun> run = measure_missed(*scene, c.scene, **renderer, reference, {}, bo);
  if (!run) return at_case_key(run.error(), a.file, r.pointer + key, reference);
  const BiasReport& b = run->report;
  if (b.undersampled) {
    const UnderSampling& u = *b.undersampled;
    o->passed = u.flagged.size() <= r.missed->max_flagged;
    o->verdict = std::to_string(u.flagged.size()) + " under-sampled of " + std::to_string(u.comparisons) +
                 " compared with " + b.reference;
    o->missed = b;
    return true;
  }
  o->passed = b.share <= r.missed->max_share;
  o->verdict = percent(b.share, 2) + " ± " + percent(b.share_std_error, 2) + " of what " + b.reference + " finds";
  if (!o->passed && b.shortest) o->counterexample = b.shortest;
  o->missed = b;
  return true;
}

// Decides every requirement of every case, in order.

}  // namespace

Result<std::vector<Outcome>> decide_check(const std::string& file, const std::vector<Case>& cases, const Limits& limits) {
  const CheckFileRun a{file, limits};
  ReachCache cache(a.limits);
  std::vector<Outcome> outcomes;
  for (const Case& c : cases) {
    Result<const CompiledProfile*> compiled = cache.compiled(c.renderer, c.max_bounces);
    if (!compiled) return at_case_key(compiled.error(), a.file, c.pointer + "/renderer", c.renderer);
    const CompiledProfile& cp = **compiled;
    ClassOptions copts;
    copts.limits = a.limits;
    copts.notation = c.notation;
    std::optional<Dfa> universe;
    if (!c.scene.empty()) {
      Result<const SceneUniverse*> scene = cache.scene(c.scene);
      if (!scene) return at_case_key(scene.error(), a.file, c.pointer + "/scene", c.scene);
      universe = (*scene)->universe;
      copts.ends = (*scene)->ends;
    }
    ClassTable table;
    if (!c.classes.empty()) {
      Result<bool> r = read_class_file(c.classes, copts, &table);
      if (!r) return at_case_key(r.error(), a.file, c.pointer + "/classes", c.classes);
    }
    for (const Requirement& r : c.require) {
      const auto t0 = std::chrono::steady_clock::now();
      Outcome o;
      o.c = &c;
      o.r = &r;
      if (r.missed || r.finite) {
        if (r.missed) {
          Result<bool> m = decide_missed(a, cache, c, r, &o);
          if (!m) return m.error();
        } else {
          Result<std::string> found = render_finite(c, r, cache, a.limits);
          if (!found) return at_case_key(found.error(), a.file, c.pointer + "/scene", c.scene);
          o.passed = found->empty();
          o.verdict = o.passed ? "no non-finite sample" : *found;
        }
        o.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        outcomes.push_back(std::move(o));
        continue;
      }
      QueryOptions qo;
      qo.max_bounces = c.max_bounces;
      qo.universe = universe;
      qo.witnesses = 1;
      qo.max_len = 0;
      qo.limits = a.limits;
      Result<PathClass> pc = r.covers_scene ? compile_class("$all", copts, &table) : compile_class(r.cls, copts, &table);
      if (!pc) {
        Error e = pc.error();
        e.where = a.file + ":" + r.pointer + (r.covers_scene ? "" : "/class");
        return e;
      }
      Result<QueryResult> q = query(*pc, cp, qo);
      if (!q) {
        Error e = q.error();
        e.where = a.file + ":" + r.pointer;
        return e;
      }
      o.verdict = to_string(q->verdict);
      o.passed = r.covers_scene ? (q->verdict == Verdict::kReachable || q->verdict == Verdict::kEmpty)
                                : satisfies(r.verdict, q->verdict);
      if (!o.passed) {
        // The counterexample: for "reachable"-like requirements an unreachable path, else a reachable one.
        const bool want_reach = r.covers_scene || r.verdict == "reachable" || r.verdict == "not-unreachable";
        const std::vector<Witness>& side = want_reach ? q->unreachable : q->reachable;
        if (!side.empty()) o.counterexample = side.front();
      }
      o.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      outcomes.push_back(std::move(o));
    }
  }
  return outcomes;
}

}  // namespace pathex
