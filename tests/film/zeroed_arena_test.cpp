// The image tiles' arena (film/zeroed_arena.h): zeroed, aligned, disjoint blocks, across chunks.
#include "film/zeroed_arena.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <new>
#include <utility>

namespace pathex {
namespace {

TEST(ZeroedArena, BlocksAreZeroedAlignedAndDisjointAcrossChunks) {
  ZeroedArena arena;
  constexpr std::size_t kTile = 3072;  // an image tile's words
  const std::size_t n = 3 * ZeroedArena::kChunk / kTile;  // three chunks' worth
  std::vector<unsigned char*> blocks;
  for (std::size_t i = 0; i < n; ++i) {
    auto* p = static_cast<unsigned char*>(arena.allocate(kTile));
    ASSERT_EQ(reinterpret_cast<std::uintptr_t>(p) % 64, 0u);
    ASSERT_TRUE(std::all_of(p, p + kTile, [](unsigned char c) { return c == 0; })) << i;
    std::memset(p, static_cast<int>(i % 251) + 1, kTile);  // overlapping blocks would clobber each other
    blocks.push_back(p);
  }
  for (std::size_t i = 0; i < n; ++i)
    ASSERT_TRUE(std::all_of(blocks[i], blocks[i] + kTile, [&](unsigned char c) { return c == i % 251 + 1; })) << i;
  ZeroedArena moved(std::move(arena));  // the blocks now belong to `moved`
  EXPECT_EQ(blocks[0][0], 1);
  EXPECT_THROW(moved.allocate(ZeroedArena::kChunk + 1), std::bad_alloc);
}

}  // namespace
}  // namespace pathex
