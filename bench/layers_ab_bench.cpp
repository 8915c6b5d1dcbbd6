// Where the class layers' time goes: renders the embedded Cornell box (bdpt, 16 spp, one thread)
// alternately with the 20-class file's layers and without any (the pairs of BM_RenderClasses/20),
// and prints the median ratio of CPU times. With --phases it also prints each render's start and
// end on CLOCK_MONOTONIC, so that bench/phase_perf.py can split a perf profile of the whole run
// into the two sides and list, per function, how many samples each side spent there: the
// difference per function is the layers' cost, measured in one interleaved process, where a
// comparison of two profiles taken minutes apart on this shared machine is mostly noise.
//
//   build/bench/layers_ab_bench 40                       # 40 pairs, median ratio
//   perf record -k CLOCK_MONOTONIC -F 2000 -o /tmp/ab.data build/bench/layers_ab_bench 40 --phases 2> /tmp/ab.txt
//   python3 bench/phase_perf.py /tmp/ab.data /tmp/ab.txt
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "io/class_file.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace {

double clock_s(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pathex;
  const int pairs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 30;
  const bool phases = argc > 2 && std::string(argv[2]) == "--phases";
  const Scene scene = load_scene_json(default_scene_json(), ".", "default").expect("a benchmark input");
  const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("a benchmark input");
  ClassTable table;
  std::vector<const PathClass*> classes;
  (void)read_class_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/twenty.json", ClassOptions{}, &table);
  for (const auto& c : table.user_classes()) classes.push_back(c.get());
  const Classifier none = Classifier::build({}, Limits{}).expect("a benchmark input");
  const Classifier twenty = Classifier::build(classes, Limits{}).expect("a benchmark input");
  RenderOptions plain;
  plain.threads = 1;
  plain.spp = 16;
  plain.max_bounces = 8;
  RenderOptions layered = plain;
  for (int i = 0; i < twenty.num_classes(); ++i) layered.layer_classes.push_back(i);
  std::vector<double> ratios;
  bool layers_first = false;  // alternated, so that neither side always runs on a warm cache
  for (int i = 0; i < pairs; ++i) {
    double with_s = 0, without_s = 0;
    for (int side = 0; side < 2; ++side) {
      const bool with = (side == 0) == layers_first;
      const double t0 = clock_s(CLOCK_PROCESS_CPUTIME_ID), m0 = clock_s(CLOCK_MONOTONIC);
      const Result<RenderOutput> out = render(scene, bdpt, with ? &twenty : &none, with ? layered : plain);
      (with ? with_s : without_s) += clock_s(CLOCK_PROCESS_CPUTIME_ID) - t0;
      if (phases) std::fprintf(stderr, "PHASE %d %.9f %.9f\n", with ? 1 : 0, m0, clock_s(CLOCK_MONOTONIC));
      if (!out) return 1;
    }
    ratios.push_back(with_s / without_s);
    layers_first = !layers_first;
  }
  std::sort(ratios.begin(), ratios.end());
  const auto pct = [&](std::size_t k) { return 100.0 * (ratios[k] - 1.0); };
  std::printf("20 class layers against none, %d pairs: median %+.2f %%, quartiles %+.2f %% %+.2f %%\n", pairs,
              pct(ratios.size() / 2), pct(ratios.size() / 4), pct(3 * ratios.size() / 4));
  return 0;
}
