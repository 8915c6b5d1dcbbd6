#include "oracle/naive_matcher.h"

#include <functional>
#include <vector>

namespace pathex::oracle {

bool naive_match(const Regex& r, std::string_view s) {
  const std::size_t n = s.size() + 1;
  // memo[node][i][j]: -1 unknown, 0 no, 1 yes.
  std::vector<signed char> memo(r.nodes.size() * n * n, -1);
  std::function<bool(int, std::size_t, std::size_t)> m = [&](int node, std::size_t i, std::size_t j) -> bool {
    signed char& slot = memo[(static_cast<std::size_t>(node) * n + i) * n + j];
    if (slot >= 0) return slot != 0;
    const Node& nd = r.at(node);
    bool res = false;
    switch (nd.kind) {
      case NodeKind::kSet: {
        if (j == i + 1) {
          const auto l = letter_from_char(s[i]);
          res = l && (nd.mask & (1u << *l));
        }
        break;
      }
      case NodeKind::kAlt:
        for (int k : nd.kids) res = res || m(k, i, j);
        break;
      case NodeKind::kAnd:
        res = true;
        for (int k : nd.kids) res = res && m(k, i, j);
        break;
      case NodeKind::kNot: res = !m(nd.kids[0], i, j); break;
      case NodeKind::kConcat: {
        // Split s[i, j) among the children, left to right.
        std::function<bool(std::size_t, std::size_t)> rest = [&](std::size_t kid, std::size_t from) -> bool {
          if (kid + 1 == nd.kids.size()) return m(nd.kids[kid], from, j);
          for (std::size_t mid = from; mid <= j; ++mid)
            if (m(nd.kids[kid], from, mid) && rest(kid + 1, mid)) return true;
          return false;
        };
        res = rest(0, i);
        break;
      }
      case NodeKind::kRepeat: {
        // reach[c][p]: s[i, p) is c copies. Copies may be empty, so counts above the length
        // only matter up to min; cap the count at max(min, length) + 1.
        const int len = static_cast<int>(j - i);
        const int cap = nd.max == kUnbounded ? std::max(nd.min, len) + 1 : nd.max;
        std::vector<std::vector<char>> reach(static_cast<std::size_t>(cap) + 1, std::vector<char>(n, 0));
        reach[0][i] = 1;
        for (int c = 0; c < cap && !res; ++c) {
          for (std::size_t p = i; p <= j; ++p) {
            if (!reach[static_cast<std::size_t>(c)][p]) continue;
            for (std::size_t q = p; q <= j; ++q)
              if (m(nd.kids[0], p, q)) reach[static_cast<std::size_t>(c) + 1][q] = 1;
          }
        }
        for (int c = nd.min; c <= cap && !res; ++c) res = reach[static_cast<std::size_t>(c)][j] != 0;
        break;
      }
    }
    slot = res ? 1 : 0;
    return res;
  };
  return m(r.root, 0, s.size());
}

}  // namespace pathex::oracle
