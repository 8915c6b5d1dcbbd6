// Shard files: the exact state of a render, so that renders of disjoint sets of passes merge into
// exactly the bytes of one render of their union (`pathex trace --shard`, `pathex merge`,
// `pathex trace --resume`, MPI ranks that outlive a failed run).
//
// A render is fully described by what it was made from (the RenderIdentity: scene content,
// profile, classes, seed, options) and the set of passes it took; its outputs are functions of
// exact integer sums (stats/histogram.h, film/image.h), which add. A shard file holds those
// sums, not the floats of the outputs.
//
// File layout, version 6 (all integers little-endian; version 1 had the body uncompressed, version
// 2 per-strategy sums in place of the technique rows, version 3 every batch of every cell and row
// and every pixel of a stored tile as varints, version 4 one zstd frame for the whole body and no
// connector statistics, version 5 each pixel's words one after the other in its tile):
//
//   offset  size  what
//   0       8     magic "PXSHARD\n"
//   8       4     format version (6)
//   12      4     H: header length in bytes
//   16      H     header: a JSON object (UTF-8), keys below
//   16+H    8     N: body length in bytes
//   24+H    N     body: an index, then the exact sums encoded as below in zstd frames (any level;
//                 pathex writes its fast level -3)
//   24+H+N  4     CRC-32 (ISO-HDLC, zlib's crc32) of every byte before it
//
// A file whose length is not 28 + H + N is truncated (or has trailing bytes); a CRC mismatch
// means it was corrupted. Either is refused before anything else is read.
//
// Header keys: "pathex" (version of the writer), "scene" {name, file (absolute, "" for the
// embedded default), hash (scene_content_hash)}, "renderer" {name, source (built-in name or
// absolute file), hash}, "classes" {file (absolute, "" for the built-in classes), text (the class
// file's text), hash}, "ends" {lights: [...], sensor} (the scene's end types, which class files in
// Heckbert notation compile against), "seed", "spp" (the requested samples per pixel), "options"
// {max_bounces, sampler, light_sampling (absent in files written before issue 39's solid-angle
// sampling: then "area"), rr_depth, rr_threshold ("auto" or a number), rr_light_threshold (absent in files written before
// issue 39: then rr_threshold's), rr_join_threshold ("auto" or a number; absent in files written before issue 39's
// join roulette: then 0, none), splits (resolved, the profile's default too: 0 is --splits auto;
// absent in files written before issue 39's splitting: then 1), batches, replicates (absent in files
// written before issue 39's pixel groups: then batches, plain batch means), width, height, images, max_paths, manifold (null, or the
// manifold connector's limits {max_iterations, threshold, min_segment, singular, max_trials, seeds,
// biased_trials when > 0, rate when not 1: the resolved --manifold-rate; absent, 1})}, "strategies" [names],
// "connectors" [{strategy, connector}] (the strategies that run a connector, in the profile's order,
// with the connector's name: "mirror", "distant-projection", "ortho-projection", "manifold"), "share" and
// "passes" (each [[first, last), …]: the passes the run was asked for, and those whose sums this
// file holds), "run" {time_s, threads, rays}.
//
// Body. First its index, uncompressed: 4 bytes K, the number of image frames; (K + 2) × 8 bytes,
// the compressed size of each frame in order (the histogram frame, the K image frames, the
// connector frame), which fill the rest of the body; K × 8 bytes, each image frame's first tile
// key (plane × tiles per plane + tile), increasing: a frame's tiles have keys from its first key
// to below the next frame's (the last: below planes × tiles), so frames hold disjoint tiles and
// are decoded at once, on every core, with the histogram frame. Then the frames, each one zstd
// frame of the encoding below. `u` is an unsigned LEB128 varint; `x` is a 128-bit fixed-point sum
// zigzag-encoded ((v << 1) ^ (v >> 127), arithmetic shift) as an unsigned LEB128 varint, so zero
// is one byte and a typical sum (64 fraction bits) nine or ten. A frame is decoded as it is
// decompressed, a window of 1 MiB at a time, so a file cannot make pathex allocate more than its
// sums take; a path string is at most 512 KiB.
//   histogram: B × u batch samples, u non-finite count, x magnitude, u number of paths P, u number of
//              technique rows in all (room is made for them ahead); then per
//              path, by string: u length, the letters; u number of held cells C (batches with a
//              contribution or a nonzero sum), C × (u gap, u contributions, 3 × x sums); u number
//              of technique rows R, then R × (u Technique::code(), u contributions, u number of
//              nonzero batch sums K, K × (u gap, x per-batch luminance sum)), by code. A gap is
//              the batch's distance after the previous one listed minus one (the first: its
//              index), so that batches come in order and below B (B from the header); a shard
//              of one pass holds one batch per cell list.
//   images:    (each image frame; pathex writes 512 stored tiles a frame) u planes, u tiles per
//              plane, u number of stored tiles T in the frame; then per tile, by key: u plane, u
//              tile, 8 bytes: the mask of its 8 × 8 pixels (bit i: pixel i of the tile, row-major)
//              with a nonzero sum. Then the frame's V channel sums (per tile, per pixel of its mask,
//              R, G, B: V = 3 × the masks' pixels): their low 64-bit words in 8 byte planes (V
//              bytes each: byte 0 of every word, then byte 1, …, byte 7), then their high words,
//              each the zigzag varint of a signed 64-bit integer (one byte for sums below 64:
//              most). Tiles with nothing in them are not stored. A word's low bytes are mostly
//              zero (float contributions on a 2^-64 grid) and its high bytes noise: in planes zstd
//              compresses the frame to 0.50 of its size (0.65 with the words in turn) five times as fast.
//   connectors: (the last frame) u number of connector strategies C (the header's "connectors"), then per connector,
//              in the header's order, 14 × u: the counts of histogram.json's "connectors" (exact
//              integer sums over samples): attempts, successes, outside, occluded, no_transport,
//              no_solution, singular, wrong_type, too_short, iteration_limit, walks (chains handed
//              to the Newton solver), iterations (their Newton iterations in all), repeats, truncated
//              (ConnectorStats::counts_of's order, trace/render.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "stats/histogram.h"
#include "film/image.h"
#include "core/error.h"
#include "schedule/pass_set.h"
#include "trace/joins/manifold.h"
#include "trace/render.h"

namespace pathex {

// A strategy of the render that runs a connector (histogram.json "connectors": strategy, connector).
struct ConnectorStrategy {
  std::string strategy;   // the profile's name for it (one of RenderIdentity::strategies)
  std::string connector;  // to_string(ConnectorKind): "mirror", "distant-projection", …
  bool operator==(const ConnectorStrategy&) const = default;
};

inline constexpr std::uint32_t kShardFormatVersion = 6;
inline constexpr const char* kShardExtension = ".shard";

// What must agree for two renders to merge: all but the names and files (the same scene, profile
// and class file may sit at other paths on other machines: they are compared by content hash),
// and the requested spp (see merge).
struct RenderIdentity {
  std::string pathex;        // pathex_version() of the writer
  std::string scene;         // as the user named it (histogram.json "scene")
  std::string scene_file;    // absolute; "" for the embedded default
  std::string scene_hash;    // scene_content_hash
  std::string renderer;      // the profile's name (histogram.json "renderer")
  std::string renderer_source;  // as resolved: a built-in name or an absolute file
  std::string renderer_hash;
  std::string classes_file;  // absolute; "" for the built-in classes
  std::string classes_text;  // the class file's text; "" for the built-in classes
  std::string classes_hash;
  std::vector<std::string> only;    // pathex trace --only: the requested classes' expressions, in order
  std::vector<std::string> lights;  // the scene's light types ("area", …)
  std::string sensor;               // and sensor type
  std::uint64_t seed = 1;
  int max_bounces = 16;
  std::string sampler = "sobol";  // RenderOptions::sampler, by name
  std::string light_sampling = to_string(RenderOptions{}.light_sampling);  // RenderOptions::light_sampling, by name
  int rr_depth = 3;
  double rr_threshold = RenderOptions{}.rr_threshold;  // RenderOptions::rr_threshold (a float, exact as a double)
  double rr_light_threshold = RenderOptions{}.rr_light_threshold;  // RenderOptions::rr_light_threshold
  double rr_join_threshold = RenderOptions{}.rr_join_threshold;  // RenderOptions::rr_join_threshold
  int splits = 1;  // RenderOptions::splits, resolved (resolved_splits()); 1 in files written before issue 39's
  int batches = kDefaultBatches;
  int replicates = kDefaultReplicates;  // per pixel; dividing batches (stats/histogram.h, "Batches")
  int width = 0, height = 0;  // the camera's resolution (the scene's, or --resolution's)
  bool images = true;
  std::uint64_t max_paths = 1000;  // rows of histogram.json's path table (--max-paths)
  // The manifold connector's limits (pathex trace --manifold-*), when the profile runs it; unset
  // otherwise (they change nothing then).
  std::optional<ManifoldOptions> manifold;
  std::vector<std::string> strategies;  // the histogram's strategy names
  std::vector<ConnectorStrategy> connectors;  // those of them that run a connector, in order
  bool operator==(const RenderIdentity&) const = default;
};

// The first difference between two identities, as a phrase naming it and both values
// ("another scene (content hash 0a… against 1b…)"), or nullopt when they agree.
std::optional<std::string> identity_difference(const RenderIdentity& a, const RenderIdentity& b);

// How a shard's render went (informative; never compared).
struct ShardRun {
  double time_s = 0;
  int threads = 0;
  std::uint64_t rays = 0;
  double cpu_s = 0;  // CPU seconds of rendering, all threads (summed over shards, resumes and ranks)
};

struct ShardHeader {
  RenderIdentity identity;
  std::uint64_t spp = 0;  // requested: the whole render is the passes [0, spp)
  PassSet share;          // the passes the run that wrote the file was asked for (a shard's share)
  PassSet passes;         // the passes whose sums the file holds (within share; all of it when complete)
  ShardRun run;
};

// A render's exact state, what a shard file holds: every field a sum over the passes it took.
struct RenderSums {
  Histogram histogram;
  ClassImages images;
  std::vector<ConnectorStats> connectors;  // one per RenderIdentity::connectors, in its order
};

// The file's bytes. `sums` hold the sums of exactly `header.passes`; their connector statistics
// are those of header.identity.connectors.
std::string encode_shard(const ShardHeader& header, const RenderSums& sums);
// The same bytes written to `path` as they are encoded (whole or not at all: io/atomic_file.h),
// without holding the file in memory.
Result<bool> write_shard(const std::string& path, const ShardHeader& header, const RenderSums& sums);

// A shard file checked (length, CRC) and its header parsed; the body is decoded by add_shard_sums.
struct ShardFile {
  std::string path;
  ShardHeader header;
  std::string bytes;  // the whole file
  std::size_t body_offset = 0, body_size = 0;
};
// Errors (kBadFile) name the file: not a shard file, another format version, truncated,
// corrupted (checksum), or a header value of the wrong type (with its JSON pointer). The header is
// read by the one JSON reader (io/json_reader.h); unknown keys are refused like missing ones.
Result<ShardFile> parse_shard(std::string bytes, const std::string& path);
// `buffer`: memory to read the file into (a finished ShardFile's `bytes`, whose pages are already
// mapped: a merge of 16 files of 11 MB spent 0.45 s of CPU faulting in fresh ones).
Result<ShardFile> read_shard(const std::string& path, std::string buffer = {});

// Adds the file's sums to `sums`, which must have the file's layout: the histogram's batches and
// strategies, the images' size and planes (built from the same classes), the connectors' names.
// `files`: how many files of the same render the caller will add in all (this one included): the
// histogram makes room ahead for that many times this file's paths and rows (address space
// only, capped; pages are touched by the paths that come), so that adding the others does not
// move its batch rows again and again.
Result<bool> add_shard_sums(const ShardFile& file, RenderSums* sums, std::size_t files = 1);

}  // namespace pathex
