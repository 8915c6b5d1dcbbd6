// Compiles a path class, asks whether two renderers can sample it, and classifies a few paths,
// through the installed API only (<pathex/pathex.h>); given a scene file, also measures how much
// of its light pt-nee cannot sample (`pathex bias`). Exit code 2 on bad input, like `pathex`.
#include <cstdio>
#include <iostream>

#include <pathex/pathex.h>

int main(int argc, char** argv) {
  namespace px = pathex::api;
  std::cout << "pathex " << px::version() << "\n";

  // 1. A path class: light reaches a diffuse vertex through specular ones (classic LS+D.*E).
  px::PathClass caustic("L..S+D.*..E");
  if (!caustic.ok()) {
    std::cerr << caustic.error() << "\n";
    return 2;
  }
  std::cout << caustic.expression() << ": " << caustic.dfa_states() << " DFA states, shortest";
  for (const std::string& p : caustic.shortest(2)) std::cout << " " << p;
  std::cout << "\n";

  // 2. Can these renderers sample it? The verdict and the shortest path each one misses.
  for (const char* name : {"pt-nee", "bdpt"}) {
    const px::Answer a = px::query(caustic, px::Renderer(name));
    if (!a.ok()) {
      std::cerr << a.error << "\n";
      return 2;
    }
    std::cout << name << ": " << px::to_string(a.verdict);
    if (!a.unreachable_witnesses.empty()) std::cout << ", misses " << a.unreachable_witnesses.front();
    std::cout << "\n";
  }

  // 3. Classify full paths by the built-in classes, in one pass each.
  const px::ClassSet classes = px::ClassSet::builtins();
  for (const char* path : {"LDDDDE", "LDDDDSE", "LDDSDDSE"}) {
    std::cout << path << ":";
    for (const std::string& c : classes.classify(path)) std::cout << " " << c;
    std::cout << "\n";
  }

  // Errors are values: a bad expression says where and what was expected.
  const px::PathClass bad("L(DD");
  std::cout << "bad expression: " << (bad.ok() ? "accepted" : "refused") << "\n";

  // 4. How much of a scene's light does pt-nee miss? One reference render (bdpt plus the
  // connectors the scene needs) measures it, with the shortest path it cannot sample.
  if (argc > 1) {
    px::BiasOptions o;
    o.spp = 4;
    const px::BiasAnswer b = px::bias(argv[1], px::Renderer("pt-nee"), o);
    if (!b.ok()) {
      std::cerr << b.error << "\n";
      return 2;
    }
    char share[64];
    std::snprintf(share, sizeof share, "%.2f %% +- %.2f %%", 100.0 * b.share, 100.0 * b.share_stderr);
    std::cout << "pt-nee misses " << share << " of what " << b.reference << " finds, e.g. " << b.shortest_missed << "\n";
  }
  return 0;
}
