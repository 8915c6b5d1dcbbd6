#include "schedule/pass_set.h"

#include <algorithm>

namespace pathex {

PassSet PassSet::range(std::uint64_t first, std::uint64_t last) {
  PassSet s;
  s.add(first, last);
  return s;
}

PassSet PassSet::part(std::uint64_t index, std::uint64_t count) const {
  // 128-bit products: m · index cannot overflow.
  __extension__ using U128 = unsigned __int128;
  const std::uint64_t m = this->count();
  const auto bound = [&](std::uint64_t i) { return static_cast<std::uint64_t>(static_cast<U128>(m) * i / count); };
  std::uint64_t from = bound(index), to = bound(index + 1);  // ordinal numbers [from, to)
  PassSet out;
  std::uint64_t seen = 0;  // ordinal of the current range's first pass
  for (const PassRange& r : ranges_) {
    const std::uint64_t n = r.last - r.first;
    const std::uint64_t lo = std::max(from, seen), hi = std::min(to, seen + n);
    if (lo < hi) out.add(r.first + (lo - seen), r.first + (hi - seen));
    seen += n;
  }
  return out;
}

void PassSet::add(std::uint64_t first, std::uint64_t last) {
  if (first >= last) return;
  // After every range (a render's chunks come in order): appended or joined in constant time.
  if (ranges_.empty() || ranges_.back().last < first) {
    ranges_.push_back({first, last});
    return;
  }
  if (ranges_.back().last == first) {
    ranges_.back().last = last;
    return;
  }
  std::vector<PassRange> out;
  out.reserve(ranges_.size() + 1);
  PassRange fresh{first, last};
  bool placed = false;
  for (const PassRange& r : ranges_) {
    if (r.last < fresh.first) {
      out.push_back(r);
    } else if (fresh.last < r.first) {
      if (!placed) out.push_back(fresh), placed = true;
      out.push_back(r);
    } else {  // overlapping or adjacent: join
      fresh.first = std::min(fresh.first, r.first);
      fresh.last = std::max(fresh.last, r.last);
    }
  }
  if (!placed) out.push_back(fresh);
  ranges_ = std::move(out);
}

void PassSet::add(const PassSet& other) {
  for (const PassRange& r : other.ranges_) add(r.first, r.last);
}

std::uint64_t PassSet::count() const {
  std::uint64_t n = 0;
  for (const PassRange& r : ranges_) n += r.last - r.first;
  return n;
}

std::vector<PassRange> PassSet::chunks(std::uint64_t n) const {
  std::vector<PassRange> out;
  for (const PassRange& r : ranges_)
    for (std::uint64_t p = r.first; p < r.last; p += std::min(n, r.last - p)) out.push_back({p, p + std::min(n, r.last - p)});
  return out;
}

PassSet PassSet::intersect(const PassSet& other) const {
  PassSet out;
  for (const PassRange& a : ranges_)
    for (const PassRange& b : other.ranges_) out.add(std::max(a.first, b.first), std::min(a.last, b.last));
  return out;
}

PassSet PassSet::minus(const PassSet& other) const {
  PassSet out;
  for (const PassRange& a : ranges_) {
    std::uint64_t from = a.first;
    for (const PassRange& b : other.ranges_) {
      if (b.last <= from || b.first >= a.last) continue;
      out.add(from, b.first);
      from = std::max(from, b.last);
    }
    out.add(from, a.last);
  }
  return out;
}

std::string PassSet::to_string() const {
  if (ranges_.empty()) return "none";
  std::string s;
  for (const PassRange& r : ranges_) {
    if (!s.empty()) s += ", ";
    s += std::to_string(r.first);
    if (r.last - r.first > 1) s += "-" + std::to_string(r.last - 1);
  }
  return s;
}

}  // namespace pathex
