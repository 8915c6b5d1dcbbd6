// pathex merge: combine the render folders of one render's disjoint passes (shards, interrupted
// runs, the kept files of a failed MPI run) into the outputs of one render of their union:
// histogram.json, classes.exr and the PNGs byte for byte those of a single run with the same
// passes, because they are computed from the same exact integer sums by the same code.
#include <iostream>

#include "cli/common.h"
#include "output/render_job.h"
#include "io/output_set.h"

namespace pathex::cli {
namespace {

struct MergeArgs {
  std::vector<std::string> dirs;
  std::string out;
  bool partial = false;
  bool quiet = false;
  Limits limits;
};

int run(const MergeArgs& a) {
  std::vector<std::string> files;
  for (const std::string& dir : a.dirs) {
    Result<std::vector<std::string>> f = render_folder_shards(dir);
    if (!f) return report(f.error());
    files.insert(files.end(), f->begin(), f->end());
  }
  Result<CombinedRender> combined = combine_shards(files, a.limits);
  if (!combined) return report(combined.error());
  ShardHeader& header = combined->header;
  const PassSet whole = PassSet::range(0, header.spp);
  const PassSet missing = whole.minus(header.passes);
  if (!missing.empty() && !a.partial)
    return report(make_error(ErrorCode::kUsage, "passes " + missing.to_string() + " of 0-" + std::to_string(header.spp - 1) +
                                                    " are in no shard; give --partial to merge what there is (marked \"complete\": false)"));
  header.share = whole;  // the merge is of the whole render: complete when no pass is missing
  Result<OutputSet> out_set = OutputSet::prepare(a.out);
  if (!out_set) return report(out_set.error());
  {
    const SignalShield shield;
    Result<bool> w = out_set->write([&](const std::string& dir) -> Result<bool> {
      Result<WrittenReport> r = write_render_outputs(dir, header, combined->sums, *combined->classes);
      if (!r) return r.error();
      return true;
    });
    if (!w) return report(w.error());
  }
  if (!a.quiet) {
    std::cout << "merged " << files.size() << " shard file" << (files.size() == 1 ? "" : "s") << ": " << header.passes.count()
              << " of " << header.spp << " spp";
    if (!missing.empty()) std::cout << " (missing passes " << missing.to_string() << ")";
    std::cout << "\nwrote " << a.out << "/histogram.json" << (header.identity.images ? ", classes.exr and PNG previews" : "")
              << ", " << kRenderShardName << "\n";
  }
  return missing.empty() ? kExitOk : kExitNo;
}

}  // namespace

Command add_merge(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* sub = app.add_subcommand("merge", "Merge render folders of disjoint passes (pathex trace --shard) into one render");
  sub->footer("Example:\n"
              "  pathex trace --spp 64 --shard 0/2 --out s0 && pathex trace --spp 64 --shard 1/2 --out s1\n"
              "  pathex merge s0 s1 --out merged     # byte-identical to: pathex trace --spp 64 --out single\n"
              "Refuses (exit 2) renders of another scene, profile, seed, class file, options or pathex build,\n"
              "overlapping passes, missing passes (unless --partial: exit 1, \"complete\": false) and damaged shard files.");
  sub->add_option("DIR", args->dirs, "Render folders (each holds one or more *.shard files)")->required();
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_flag("--partial", args->partial, "Merge even if passes are missing; the result is marked \"complete\": false");
  sub->add_flag("--quiet", args->quiet, "Print nothing on success");
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
