#include "film/zeroed_arena.h"

#include <sys/mman.h>

#include <cstdint>
#include <new>
#include <utility>

namespace pathex {
namespace {

// A kChunk-aligned chunk (a huge page needs an aligned 2 MiB range): twice the size is mapped and
// the unaligned ends are unmapped again.
void* map_chunk() {
  constexpr std::size_t kChunk = ZeroedArena::kChunk;
  void* p = ::mmap(nullptr, 2 * kChunk, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t aligned = (at + kChunk - 1) & ~(std::uintptr_t{kChunk} - 1);
  if (aligned > at) ::munmap(p, aligned - at);
  if (aligned + kChunk < at + 2 * kChunk) ::munmap(reinterpret_cast<void*>(aligned + kChunk), at + 2 * kChunk - aligned - kChunk);
  void* chunk = reinterpret_cast<void*>(aligned);
  ::madvise(chunk, kChunk, MADV_HUGEPAGE);  // advice only: without THP the chunk is ordinary pages
  return chunk;
}

}  // namespace

ZeroedArena::~ZeroedArena() { release(); }

ZeroedArena::ZeroedArena(ZeroedArena&& other) noexcept
    : chunks_(std::move(other.chunks_)), next_(std::exchange(other.next_, nullptr)), left_(std::exchange(other.left_, 0)) {
  other.chunks_.clear();
}

ZeroedArena& ZeroedArena::operator=(ZeroedArena&& other) noexcept {
  if (this != &other) {
    release();
    chunks_ = std::move(other.chunks_);
    other.chunks_.clear();
    next_ = std::exchange(other.next_, nullptr);
    left_ = std::exchange(other.left_, 0);
  }
  return *this;
}

void ZeroedArena::release() {
  for (void* c : chunks_) ::munmap(c, kChunk);
  chunks_.clear();
  next_ = nullptr;
  left_ = 0;
}

void* ZeroedArena::allocate(std::size_t bytes) {
  bytes = (bytes + 63) & ~std::size_t{63};
  if (bytes > kChunk) throw std::bad_alloc();
  if (bytes > left_) {
    chunks_.reserve(chunks_.size() + 1);  // before mapping: a failure here leaks nothing
    void* c = map_chunk();
    chunks_.push_back(c);
    next_ = static_cast<char*>(c);
    left_ = kChunk;
  }
  void* p = next_;
  next_ += bytes;
  left_ -= bytes;
  return p;
}

}  // namespace pathex
