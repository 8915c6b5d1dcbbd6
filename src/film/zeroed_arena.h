// Zeroed memory for many small blocks that live as long as their owner (the image tiles of
// film/image.h), carved from 2 MiB chunks mapped straight from the kernel and advised as
// transparent huge pages (MADV_HUGEPAGE; this kernel's THP mode is "madvise"). A chunk then
// costs one page fault instead of 512, and no malloc bookkeeping: a 512 × 512 merge with twenty
// class layers allocated 145 MB of 3 KiB tiles one `new` at a time, and its heap growth and page
// faults took about a quarter of the merge (bench/README.md, "Scale-out"). Where the kernel
// gives no huge page the chunk is ordinary zeroed memory. Not thread-safe: callers lock.
#pragma once

#include <cstddef>
#include <vector>

namespace pathex {

class ZeroedArena {
 public:
  static constexpr std::size_t kChunk = std::size_t{2} << 20;

  ZeroedArena() = default;
  ~ZeroedArena();
  ZeroedArena(ZeroedArena&& other) noexcept;
  ZeroedArena& operator=(ZeroedArena&& other) noexcept;
  ZeroedArena(const ZeroedArena&) = delete;
  ZeroedArena& operator=(const ZeroedArena&) = delete;

  // `bytes` (at most kChunk) zeroed bytes, aligned to 64; throws std::bad_alloc when the kernel
  // maps no more memory. Freed with the arena.
  void* allocate(std::size_t bytes);

 private:
  void release();
  std::vector<void*> chunks_;
  char* next_ = nullptr;
  std::size_t left_ = 0;
};

}  // namespace pathex
