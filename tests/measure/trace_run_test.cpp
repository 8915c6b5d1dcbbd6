// trace's run as a library call (measure/trace_run.h) and its job (output/trace_job.h): the
// options' exact messages, the identity of a fresh job, and one small render written with its hooks.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "measure/trace_run.h"
#include "output/trace_job.h"

namespace pathex {
namespace {

TEST(TraceJob, ShardOptionIsIOfNWithIBelowN) {
  Result<std::pair<std::uint64_t, std::uint64_t>> ok = parse_shard_option("1/4");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->first, 1u);
  EXPECT_EQ(ok->second, 4u);
  for (const char* bad : {"2/2", "x", "-1/2", "1/", "/2", "0/0", "1/-2", "1/2x"}) {
    Result<std::pair<std::uint64_t, std::uint64_t>> r = parse_shard_option(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_EQ(r.error().code, ErrorCode::kUsage);
    EXPECT_EQ(r.error().message, std::string("--shard ") + bad + ": expected i/n, shard i of n with 0 <= i < n (e.g. 0/4)");
  }
}

TEST(TraceJob, ResumeRefusesTheSettingsGiven) {
  TraceJobOptions o;
  o.resume = "somewhere";
  o.settings_given = {"--spp", "--seed"};
  Result<TraceJob> job = load_trace_job(o);
  ASSERT_FALSE(job);
  EXPECT_EQ(job.error().code, ErrorCode::kUsage);
  EXPECT_EQ(job.error().message, "--resume takes the render's settings from somewhere; --spp cannot be given with it");
}

TEST(TraceJob, AFreshJobOfTheDefaultSceneAndItsShard) {
  TraceJobOptions o;
  o.shard = "1/2";
  Result<TraceJob> job = load_trace_job(o);
  ASSERT_TRUE(job) << job.error().render();
  const RenderIdentity& id = job->header.identity;
  EXPECT_EQ(id.scene, "default (embedded cornell)");
  EXPECT_EQ(id.scene_file, "");
  EXPECT_EQ(id.renderer, "bdpt");
  EXPECT_EQ(id.renderer_source, "bdpt");
  EXPECT_EQ(id.max_bounces, 16);
  EXPECT_EQ(id.sampler, "sobol");
  EXPECT_EQ(id.batches, 32);
  EXPECT_EQ(id.replicates, 2);
  EXPECT_EQ(id.width, 64);
  EXPECT_EQ(id.height, 64);
  EXPECT_EQ(job->header.spp, 16u);
  EXPECT_TRUE(job->header.share == PassSet::range(0, 16).part(1, 2));
  EXPECT_EQ(job->header.passes.count(), 0u);
  EXPECT_FALSE(job->resumed);
  EXPECT_EQ(job->out, "pathex-out");
}

// Without --replicates the job resolves R from the resolution the render will have (issue 36), so
// every shard records the same design: 2 on the 64 × 64 box, 32 on a spot meter (one group, 31
// degrees of freedom instead of the one that 16 groups of two gave its single pixel), 16 at 3 × 1;
// an explicit R is kept, and one that does not divide B is refused.
TEST(TraceJob, TheReplicatesFollowTheSensorsPixelCount) {
  const auto replicates = [](const std::string& scene, const std::string& resolution, int r) -> Result<int> {
    TraceJobOptions o;
    o.scene = scene.empty() ? "" : std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/" + scene;
    o.resolution = resolution;
    o.replicates = r;
    Result<TraceJob> job = load_trace_job(o);
    if (!job) return job.error();
    return job->header.identity.replicates;
  };
  EXPECT_EQ(replicates("", "", 0).expect("the box"), 2);
  EXPECT_EQ(replicates("spotmeter-caustic.json", "", 0).expect("a spot meter"), 32);
  EXPECT_EQ(replicates("", "3x1", 0).expect("three pixels"), 16);
  EXPECT_EQ(replicates("", "4x4", 0).expect("sixteen pixels"), 2);
  EXPECT_EQ(replicates("spotmeter-caustic.json", "", 4).expect("explicit"), 4);
  const Result<int> bad = replicates("", "", 3);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "--replicates 3 must divide --batches 32 (the batches are pixel groups of that many replicates)");
}

TEST(TraceRun, MissedIsRefusedWithAShardAndTheImagesBeyondTheMemoryLimit) {
  TraceOptions o;
  o.job.shard = "0/2";
  o.missed = true;
  Result<TraceResult> r = run_trace(o);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "--missed measures a whole render in one process: it cannot be given with --shard, --resume or MPI");
  TraceOptions m;
  m.max_memory = 1024;
  r = run_trace(m);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
  EXPECT_EQ(r.error().where, "default (embedded cornell):/camera");
}

TEST(TraceRun, RendersThePassesAndWritesTheSetWithItsHooks) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("pathex-trace-run-" + std::to_string(::getpid()))).string();
  std::filesystem::remove_all(dir);
  TraceOptions o;
  o.job.spp = 2;
  o.job.out = dir;
  o.threads = 1;
  o.progress = false;
  int before = 0, extra = 0;
  TraceHooks hooks;
  hooks.before_render = [&](const TraceJob& job, const Dfa&) -> Result<bool> {
    ++before;
    EXPECT_EQ(job.header.identity.strategies, std::vector<std::string>{"bdpt"});
    return true;
  };
  hooks.extra_files = [&](const std::string& staged, const TraceResult& run) -> Result<bool> {
    ++extra;
    EXPECT_TRUE(std::filesystem::exists(staged + "/histogram.json"));
    EXPECT_TRUE(run.written.has_value());
    return true;
  };
  Result<TraceResult> r = run_trace(o, hooks);
  ASSERT_TRUE(r) << r.error().render();
  EXPECT_EQ(before, 1);
  EXPECT_EQ(extra, 1);
  EXPECT_TRUE(r->root);
  EXPECT_FALSE(r->nothing_to_render);
  EXPECT_EQ(r->header.passes.count(), 2u);
  ASSERT_TRUE(r->written);
  EXPECT_TRUE(r->written->report.run.complete);
  EXPECT_EQ(r->written->report.run.spp, 2u);
  for (const char* f : {"histogram.json", "classes.exr", "render.shard", "run.json"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pathex
