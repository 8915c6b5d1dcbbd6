// What `pathex trace`, `pathex merge` and the MPI ranks share: the classes a render is labelled
// with, rebuilt from a RenderIdentity (so a merge needs neither the scene nor the class file), and
// the one routine that turns a render's exact sums into its output folder. Every render's outputs
// go through write_render_outputs, which is why a merge, a resumed render and an MPI run write
// exactly the bytes of one uninterrupted process.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "stats/histogram.h"
#include "film/image.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "bias/bias.h"
#include "scene/scene.h"
#include "output/shard.h"
#include "schedule/pass_deal.h"
#include "schedule/pass_set.h"
#include "trace/prune.h"
#include "trace/render.h"

namespace pathex {

// The classes of a render, compiled: the class file's entries (or the built-ins but $all), then
// each --only expression that is not one of them by name ($name), as class "only-N".
struct RenderClasses {
  ClassTable table;
  std::vector<const PathClass*> classes;
  std::unique_ptr<Classifier> classifier;
  std::vector<ClassInfo> infos;
  // The requested classes (identity.only and the class file's "render": true entries); empty: all.
  std::vector<const PathClass*> requested;
  std::optional<Dfa> requested_language;  // their union; unset: every path
  // Per class: whether it is estimated, i.e. all its paths (with the render's ends and bound) are
  // requested. The others are reported "not rendered".
  std::vector<std::uint8_t> estimated;
};
// Compiles `text` (a class file's contents, read from `filename`; both "" for the built-in
// classes) and identity.only against the end types of `identity` (lights, sensor).
Result<std::unique_ptr<RenderClasses>> compile_render_classes(const std::string& text, const std::string& filename,
                                                              const RenderIdentity& identity, const Limits& limits);

// The classes of a render of `scene`, as trace compiles them (compile_render_classes): the class file's
// or, without one, the built-ins but $all; Heckbert and LPE entries get the scene's light and
// sensor types. A class file entry named "missed" (bias's layer) is refused at its JSON pointer.
Result<std::unique_ptr<RenderClasses>> bias_classes(const std::string& classes_file, const Scene& scene,
                                                    const Limits& limits);

// Empty sums (RenderSums, output/shard.h) laid out for `identity` and `classes`: every class gets an
// image layer, every connector strategy of the identity its statistics.
RenderSums empty_sums(const RenderIdentity& identity, const RenderClasses& classes);

// The render folder's outputs: histogram.json, classes.exr and the PNGs (unless the identity has
// no images), the shard file render.shard, and run.json (how the run went: never compared).
// `header.passes` are the passes the sums hold; histogram.json's spp is their number and it is
// complete when they are all of header.share. Each file is written whole or not at all.
struct WrittenReport {
  HistogramReport report;
  std::string json_text;
};
// What histogram.json holds for these sums, made but not written (write_render_outputs writes it;
// the C++ API's trace without a folder reads it).
Result<WrittenReport> render_report(const ShardHeader& header, const RenderSums& sums, const RenderClasses& classes);
// histogram.json also lists what each connector did (sums.connectors; "connectors": [{strategy, connector,
// attempts, successes, failures {outside, occluded, no_transport; the manifold's no_solution, singular, wrong_type, too_short, iteration_limit instead of outside}, and for the manifold repeats, truncated, walks and mean_iterations}] in the profile's order;
// absent when the profile has none).
// With requested classes, histogram.json lists them ("only": [{name, expr}]) and marks every class
// not contained in them "rendered": false; the EXR and PNGs have no layer for a class that was not
// rendered. run.json's "pruned" lists the strategies the checker did not run or narrowed
// ([{strategy, profile, runs (null: not run), reason}]; trace/prune.h).
Result<WrittenReport> write_render_outputs(const std::string& dir, const ShardHeader& header, const RenderSums& sums,
                                           const RenderClasses& classes, const std::vector<PrunedStrategy>& not_run = {});

// Where the MPI ranks of a render into `dir` keep their own shard files until rank 0 has written
// the outputs: the folder "<dir>.ranks" beside it (the output folder holds only its set).
std::string ranks_folder(const std::string& dir);

// The shard files of a render folder: every *.shard in it and in its ranks folder, by name; an
// error if there is none.
Result<std::vector<std::string>> render_folder_shards(const std::string& dir);

inline constexpr const char* kRenderShardName = "render.shard";

// Shard files combined into one render's state: the identity they share, the largest requested
// spp, the union of their shares and of their passes, and the sum of their sums.
struct CombinedRender {
  ShardHeader header;
  std::unique_ptr<RenderClasses> classes;
  RenderSums sums;
};
// Reads the files in order, the next while one is added (two files' bytes in memory at once). Refuses damaged files
// (kBadFile), files of another pathex build than this one, and (kUsage, naming both files) files
// of different renders (identity_difference) or holding the same pass twice (naming the passes).
Result<CombinedRender> combine_shards(const std::vector<std::string>& paths, const Limits& limits);

}  // namespace pathex

namespace pathex {

// The processes one render is split across: one by default; pathex-mpi installs its MPI ranks
// (cli/mpi/) before running the command line. Each rank renders the chunks of the run's passes
// that their shared deal hands it.
class Cluster {
 public:
  virtual ~Cluster() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // This rank's side of the deal of `todo` in chunks of `chunk` passes among the ranks
  // (schedule/pass_deal.h) for a render of `batches` batches: every rank makes one and renders the
  // chunks it is handed until none is left (or it stops). Not collective; while it lives, this
  // rank makes no other call on the cluster, and destroying it waits until every rank has left
  // the deal.
  virtual std::unique_ptr<PassDealer> deal(const PassSet& todo, std::uint64_t chunk, int batches) = 0;
  // Collective: adds every rank's sums, passes and run figures into rank 0's, exactly. The other
  // ranks' arguments are left unspecified (their sums are only read). Rank 0 calls `before_changing`
  // (when set) before it first changes `*sums`: until then others may read them (write them to a
  // file from another thread). Fails naming a rank that did not take part.
  virtual Result<bool> reduce(RenderSums* sums, PassSet* passes, ShardRun* run,
                              const std::function<void()>& before_changing = {}) = 0;
  // Collective: the number of ranks whose `ok` is false, on every rank (0 when all succeeded).
  virtual int count_failures(bool ok) = 0;
};
Cluster* current_cluster();  // null: one process
void set_cluster(Cluster* cluster);

}  // namespace pathex
