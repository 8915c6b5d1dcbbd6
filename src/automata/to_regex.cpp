#include "automata/to_regex.h"

#include <optional>
#include <string>
#include <utility>

#include "core/limits.h"

namespace pathex {
namespace {

using Kind = Expr::Kind;

Expr leaf(Kind k, LetterMask m = 0) {
  Expr e;
  e.kind = k;
  e.mask = m;
  return e;
}

Expr node(Kind k, std::vector<Expr> kids) {
  Expr e;
  e.kind = k;
  e.size = 1;
  for (const Expr& c : kids) e.size += c.size;
  e.kids = std::move(kids);
  return e;
}

Expr e_set(LetterMask m) { return m ? leaf(Kind::kSet, m) : leaf(Kind::kEmpty); }
Expr e_eps() { return leaf(Kind::kEps); }

Expr e_star(const Expr& a);

// x? for a non-nullable x; a nullable x already holds ε.
Expr e_opt(const Expr& a) {
  if (a.kind == Kind::kEmpty) return e_eps();
  if (nullable(a)) return a;
  if (a.kind == Kind::kPlus) return e_star(a.kids[0]);  // (x+)? = x*
  return node(Kind::kOpt, {a});
}

// The items of a concatenation, as a list.
std::vector<Expr> items(const Expr& e) {
  if (e.kind == Kind::kCat) return e.kids;
  return {e};
}

Expr from_items(std::vector<Expr> v) {
  if (v.empty()) return e_eps();
  if (v.size() == 1) return v[0];
  return node(Kind::kCat, std::move(v));
}

// Does v[at, at + n) equal `want`?
bool run_equals(const std::vector<Expr>& v, std::size_t at, const std::vector<Expr>& want) {
  if (at + want.size() > v.size()) return false;
  for (std::size_t i = 0; i < want.size(); ++i)
    if (!(v[at + i] == want[i])) return false;
  return true;
}

Expr e_alt(const Expr& a, const Expr& b);

// The union of a list of expressions.
Expr from_list(const std::vector<Expr>& v) {
  Expr u = leaf(Kind::kEmpty);
  for (const Expr& x : v) u = e_alt(u, x);
  return u;
}

Expr e_alt(const Expr& a, const Expr& b) {
  if (a.kind == Kind::kEmpty) return b;
  if (b.kind == Kind::kEmpty) return a;
  std::vector<Expr> parts;
  bool eps = false;
  LetterMask letters = 0;
  auto take = [&](const Expr& x, auto&& self) -> void {
    switch (x.kind) {
      case Kind::kAlt: for (const Expr& k : x.kids) self(k, self); break;
      case Kind::kOpt: eps = true; self(x.kids[0], self); break;
      case Kind::kEps: eps = true; break;
      case Kind::kSet: letters |= x.mask; break;
      default:
        for (const Expr& p : parts)
          if (p == x) return;
        parts.push_back(x);
    }
  };
  take(a, take);
  take(b, take);
  if (letters) parts.insert(parts.begin(), e_set(letters));
  // y | x+ y -> x* y, and y | y x+ -> y x*.
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (std::size_t j = 0; j < parts.size(); ++j) {
      if (i == j || parts[j].kind != Kind::kCat) continue;
      const std::vector<Expr> y = items(parts[i]);
      const std::vector<Expr>& v = parts[j].kids;
      if (v.size() != y.size() + 1) continue;
      if (v.front().kind == Kind::kPlus && run_equals(v, 1, y)) {
        std::vector<Expr> w = v;
        w.front() = node(Kind::kStar, {v.front().kids[0]});
        parts[i] = from_items(std::move(w));
        parts.erase(parts.begin() + static_cast<long>(j));
        return e_alt(from_list(parts), leaf(eps ? Kind::kEps : Kind::kEmpty));
      }
      if (v.back().kind == Kind::kPlus && run_equals(v, 0, y)) {
        std::vector<Expr> w = v;
        w.back() = node(Kind::kStar, {v.back().kids[0]});
        parts[i] = from_items(std::move(w));
        parts.erase(parts.begin() + static_cast<long>(j));
        return e_alt(from_list(parts), leaf(eps ? Kind::kEps : Kind::kEmpty));
      }
    }
  // x* absorbs x, x+ and x? beside it; x+ absorbs x.
  std::vector<Expr> kept;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    bool absorbed = false;
    for (std::size_t j = 0; j < parts.size() && !absorbed; ++j) {
      if (i == j) continue;
      const Expr& o = parts[j];
      if ((o.kind == Kind::kStar || o.kind == Kind::kPlus) && o.kids[0] == parts[i]) absorbed = true;
      if (o.kind == Kind::kStar && parts[i].kind == Kind::kPlus && parts[i].kids[0] == o.kids[0]) absorbed = true;
    }
    if (!absorbed) kept.push_back(parts[i]);
  }
  Expr u = kept.size() == 1 ? kept[0] : node(Kind::kAlt, std::move(kept));
  return eps ? e_opt(u) : u;
}

// y+, with (a*b)+ = (a|b)*b and (ba*)+ = b(a|b)* for letter sets a and b: every string over a∪b
// that ends (starts) with a letter of b. State elimination produces the left side for "[SD]*D".
Expr e_plus(const Expr& y) {
  if (y.kind == Kind::kCat && y.kids.size() == 2) {
    const Expr& first = y.kids[0];
    const Expr& second = y.kids[1];
    auto star_of_set = [](const Expr& e) { return e.kind == Kind::kStar && e.kids[0].kind == Kind::kSet; };
    if (star_of_set(first) && second.kind == Kind::kSet)
      return node(Kind::kCat, {node(Kind::kStar, {e_set(first.kids[0].mask | second.mask)}), second});
    if (first.kind == Kind::kSet && star_of_set(second))
      return node(Kind::kCat, {first, node(Kind::kStar, {e_set(first.mask | second.kids[0].mask)})});
  }
  return node(Kind::kPlus, {y});
}

Expr e_cat(const Expr& a, const Expr& b) {
  if (a.kind == Kind::kEmpty || b.kind == Kind::kEmpty) return leaf(Kind::kEmpty);
  if (a.kind == Kind::kEps) return b;
  if (b.kind == Kind::kEps) return a;
  std::vector<Expr> v = items(a);
  for (const Expr& x : items(b)) v.push_back(x);
  // Peephole: y y* -> y+, y* y -> y+, y* y* -> y*, y+ y* / y* y+ -> y+, y? y* / y* y? -> y*,
  // where y may be a run of several items (ab(ab)* -> (ab)+).
  bool changed = true;
  while (changed) {
    changed = false;
    for (std::size_t i = 0; i < v.size() && !changed; ++i) {
      if (v[i].kind != Kind::kStar) continue;
      const Expr y = v[i].kids[0];
      const std::vector<Expr> body = items(y);
      if (i >= body.size() && run_equals(v, i - body.size(), body)) {
        v.erase(v.begin() + static_cast<long>(i - body.size()), v.begin() + static_cast<long>(i + 1));
        const std::vector<Expr> plus = items(e_plus(y));
        v.insert(v.begin() + static_cast<long>(i - body.size()), plus.begin(), plus.end());
        changed = true;
      } else if (run_equals(v, i + 1, body)) {
        v.erase(v.begin() + static_cast<long>(i), v.begin() + static_cast<long>(i + 1 + body.size()));
        const std::vector<Expr> plus = items(e_plus(y));
        v.insert(v.begin() + static_cast<long>(i), plus.begin(), plus.end());
        changed = true;
      } else if (i + 1 < v.size() && v[i + 1].kids.size() == 1 && v[i + 1].kids[0] == y &&
                 (v[i + 1].kind == Kind::kStar || v[i + 1].kind == Kind::kOpt || v[i + 1].kind == Kind::kPlus)) {
        const Kind k = v[i + 1].kind == Kind::kPlus ? Kind::kPlus : Kind::kStar;
        v.erase(v.begin() + static_cast<long>(i), v.begin() + static_cast<long>(i + 2));
        v.insert(v.begin() + static_cast<long>(i), node(k, {y}));
        changed = true;
      } else if (i > 0 && v[i - 1].kids.size() == 1 && v[i - 1].kids[0] == y &&
                 (v[i - 1].kind == Kind::kOpt || v[i - 1].kind == Kind::kPlus)) {
        const Kind k = v[i - 1].kind == Kind::kPlus ? Kind::kPlus : Kind::kStar;
        v.erase(v.begin() + static_cast<long>(i - 1), v.begin() + static_cast<long>(i + 1));
        v.insert(v.begin() + static_cast<long>(i - 1), node(k, {y}));
        changed = true;
      }
    }
  }
  return from_items(std::move(v));
}

Expr e_star(const Expr& a) {
  switch (a.kind) {
    case Kind::kEmpty:
    case Kind::kEps: return e_eps();
    case Kind::kStar: return a;
    case Kind::kPlus:
    case Kind::kOpt: return e_star(a.kids[0]);
    case Kind::kAlt: {
      // (x*|y)* = (x|y)*
      Expr u = leaf(Kind::kEmpty);
      for (const Expr& k : a.kids)
        u = e_alt(u, (k.kind == Kind::kStar || k.kind == Kind::kPlus || k.kind == Kind::kOpt) ? k.kids[0] : k);
      return u.kind == Kind::kAlt || u.kind == Kind::kSet || u.kind == Kind::kCat ? node(Kind::kStar, {u}) : e_star(u);
    }
    default: return node(Kind::kStar, {a});
  }
}

// --- printing ---

enum Level { kLevelAlt = 0, kLevelCat = 1, kLevelPostfix = 2, kLevelAtom = 3 };

struct Printed {
  std::string text;
  Level level;
};

Printed print(const Expr& e, const ExprStyle& st);

// `e` as an operand that needs at least `min` binding strength.
std::string operand(const Expr& e, const ExprStyle& st, Level min) {
  Printed p = print(e, st);
  return p.level < min ? "(" + p.text + ")" : p.text;
}

std::string count_suffix(int n, bool open) {
  return "{" + std::to_string(n) + (open ? ",}" : "}");
}

Printed print(const Expr& e, const ExprStyle& st) {
  switch (e.kind) {
    case Kind::kEmpty:
    case Kind::kEps: return {"", kLevelAtom};
    case Kind::kSet: return {st.atom(e.mask), kLevelAtom};
    case Kind::kStar: return {operand(e.kids[0], st, kLevelAtom) + "*", kLevelPostfix};
    case Kind::kPlus: return {operand(e.kids[0], st, kLevelAtom) + "+", kLevelPostfix};
    case Kind::kOpt: return {operand(e.kids[0], st, kLevelAtom) + st.optional, kLevelPostfix};
    case Kind::kAlt: {
      std::string s;
      for (std::size_t i = 0; i < e.kids.size(); ++i) {
        if (i) s += '|';
        s += operand(e.kids[i], st, st.alternation_binds_items ? kLevelPostfix : kLevelCat);
      }
      if (st.alternation_binds_items) return {"(" + s + ")", kLevelAtom};
      return {s, kLevelAlt};
    }
    case Kind::kCat: {
      // Runs of equal items, a following y+ or y* joining the run of y.
      std::string s;
      const std::vector<Expr>& v = e.kids;
      for (std::size_t i = 0; i < v.size();) {
        std::size_t j = i;
        while (j < v.size() && v[j] == v[i]) ++j;
        const int n = static_cast<int>(j - i);
        if (j < v.size() && (v[j].kind == Kind::kPlus || v[j].kind == Kind::kStar) && v[j].kids[0] == v[i]) {
          const int m = n + (v[j].kind == Kind::kPlus ? 1 : 0);
          if (m >= st.min_run) {
            s += operand(v[i], st, kLevelAtom) + count_suffix(m, /*open=*/true);
            i = j + 1;
            continue;
          }
        }
        if (n >= st.min_run) {
          s += operand(v[i], st, kLevelAtom) + count_suffix(n, /*open=*/false);
        } else {
          for (std::size_t k = i; k < j; ++k) s += operand(v[k], st, kLevelPostfix);
        }
        i = j;
      }
      return {s, kLevelCat};
    }
  }
  return {"", kLevelAtom};
}

std::string full_atom(LetterMask m) {
  for (int l = 0; l < kNumLetters; ++l)
    if (m == (1u << l)) return std::string(1, letter_char(l));
  if (m == kScatterMask) return ".";
  std::string s = "[";
  for (int l = 0; l < kNumLetters; ++l)
    if (m & (1u << l)) s += letter_char(l);
  return s + "]";
}

}  // namespace

bool nullable(const Expr& e) {
  switch (e.kind) {
    case Kind::kEps:
    case Kind::kStar:
    case Kind::kOpt: return true;
    case Kind::kEmpty:
    case Kind::kSet: return false;
    case Kind::kPlus: return nullable(e.kids[0]);
    case Kind::kAlt:
      for (const Expr& k : e.kids)
        if (nullable(k)) return true;
      return false;
    case Kind::kCat:
      for (const Expr& k : e.kids)
        if (!nullable(k)) return false;
      return true;
  }
  return false;
}

Result<Expr> dfa_to_expr(const Dfa& d, int max_states, int max_nodes) {
  const std::vector<std::uint8_t> live = d.live();
  if (d.num_states == 0 || !live[static_cast<std::size_t>(d.start)]) return leaf(Kind::kEmpty);
  std::vector<int> index(static_cast<std::size_t>(d.num_states), -1);
  int n = 0;
  for (int s = 0; s < d.num_states; ++s)
    if (live[static_cast<std::size_t>(s)]) index[static_cast<std::size_t>(s)] = n++;
  if (n > max_states)
    return make_error(ErrorCode::kLimit, "the automaton has " + std::to_string(n) + " live states, more than the " +
                                             std::to_string(max_states) + " an expression is written for");
  // The generalised NFA: states 0..n-1, start n, final n+1; R[p][q] the expression on p -> q.
  const int total = n + 2, start = n, final = n + 1;
  std::vector<std::optional<Expr>> R(static_cast<std::size_t>(total * total));
  auto at = [&](int p, int q) -> std::optional<Expr>& { return R[static_cast<std::size_t>(p * total + q)]; };
  auto add = [&](int p, int q, const Expr& e) {
    std::optional<Expr>& slot = at(p, q);
    slot = slot ? e_alt(*slot, e) : e;
  };
  for (int s = 0; s < d.num_states; ++s) {
    const int p = index[static_cast<std::size_t>(s)];
    if (p < 0) continue;
    for (int l = 0; l < kNumLetters; ++l) {
      const int q = index[static_cast<std::size_t>(d.step(s, l))];
      if (q >= 0) add(p, q, e_set(static_cast<LetterMask>(1u << l)));
    }
    if (d.accept[static_cast<std::size_t>(s)]) add(p, final, e_eps());
  }
  add(start, index[static_cast<std::size_t>(d.start)], e_eps());

  std::vector<bool> gone(static_cast<std::size_t>(n), false);
  for (int round = 0; round < n; ++round) {
    // The cheapest state to remove: what its removal writes, Σ in-size·outs + Σ out-size·ins.
    int best = -1;
    long long best_cost = 0;
    for (int q = 0; q < n; ++q) {
      if (gone[static_cast<std::size_t>(q)]) continue;
      long long ins = 0, outs = 0, in_size = 0, out_size = 0;
      for (int p = 0; p < total; ++p) {
        if (p == q || (p < n && gone[static_cast<std::size_t>(p)])) continue;
        if (at(p, q)) ++ins, in_size += at(p, q)->size;
        if (at(q, p)) ++outs, out_size += at(q, p)->size;
      }
      const long long loop = at(q, q) ? at(q, q)->size : 0;
      const long long cost = in_size * outs + out_size * ins + loop * ins * outs;
      if (best < 0 || cost < best_cost) best = q, best_cost = cost;
    }
    const int q = best;
    const Expr loop = at(q, q) ? e_star(*at(q, q)) : e_eps();
    for (int p = 0; p < total; ++p) {
      if (p == q || (p < n && gone[static_cast<std::size_t>(p)]) || !at(p, q)) continue;
      const Expr head = e_cat(*at(p, q), loop);
      for (int r = 0; r < total; ++r) {
        if (r == q || (r < n && gone[static_cast<std::size_t>(r)]) || !at(q, r)) continue;
        add(p, r, e_cat(head, *at(q, r)));
        if (at(p, r)->size > max_nodes)
          return make_error(ErrorCode::kLimit, "the expression of this automaton grows past " +
                                                   std::to_string(max_nodes) + " nodes");
      }
    }
    for (int p = 0; p < total; ++p) at(p, q).reset(), at(q, p).reset();
    gone[static_cast<std::size_t>(q)] = true;
  }
  return at(start, final) ? *at(start, final) : leaf(Kind::kEmpty);
}

std::string print_expr(const Expr& e, const ExprStyle& style) { return print(e, style).text; }

std::string to_full_notation(const Expr& e) {
  ExprStyle st;
  st.atom = full_atom;
  return print_expr(e, st);
}

}  // namespace pathex
