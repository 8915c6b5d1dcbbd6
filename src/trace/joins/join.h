// One join's result (DESIGN §4, §7): what every strategy hands the estimator, whether it is a
// plain join (s, DD, t) or a connector (s, DSD, t).
//
// A join takes the two subpaths (or fresh endpoint samples) and builds the rest of a full path:
// the vertices it needs (a fresh light or sensor sample, a projected aperture or film point, a
// mirror vertex), the path's letters, its contribution before weighting, the straight segments that
// must all be unoccluded for it to count (none when the last edge was traced, one for a shadow ray,
// two across a mirror), and what MIS needs of its own density. The estimator
// (Integrator::estimate()) weighs it and queues its segments in one place, whichever join made it.
#pragma once

#include <array>

#include "reach/profile.h"
#include "trace/accel/path_ids.h"
#include "trace/bsdf.h"
#include "trace/vertex.h"

namespace pathex::tracer {

// The most interior vertices a connector builds between its two ends (the manifold connector's
// specular chain): its kMaxChain + 1 segments fill at most one shadow-ray packet.
inline constexpr int kMaxChain = 15;

// What MIS needs of a join's own density, as the join computed it: the unit direction w from the
// light end to the eye end and their squared distance, and the BSDF densities at each end that the
// join's BSDF evaluation gave for free. The MIS routine recomputes only the densities at the two
// ends (Veach's ratios); the subpaths keep the rest as the walks stored them.
struct JoinDensity {
  vec3 w{0.0f};
  float d2 = 0.0f;
  bsdf::JoinPdfs at_qs;  // at the light end, wo = its wo, wi = w
  bsdf::JoinPdfs at_pt;  // at the eye end, wo = its wo, wi = -w
};

// A straight segment from `from` to `to` that must be unoccluded (rays leave each end offset by its
// rounding-error bound).
struct Segment {
  const Vertex* from = nullptr;
  const Vertex* to = nullptr;
};

struct JoinResult {
  // The strategy: its chain (kNone for the plain join), the light and eye subpath vertices it
  // joins (a connector's on either side of its chain), and the strategy table's index of it.
  ConnectorKind chain = ConnectorKind::kNone;
  int s = 0, t = 0;
  int strategy = -1;
  accel::PathKey letters = 0;       // the full path's letters, packed
  vec3 contribution{0.0f};          // before the MIS weight
  // The vertices it built: one standing for y0 (a fresh light sample, an aperture point), one for
  // z0 (a fresh sensor sample, a film point), and the chain between the subpaths in light-to-eye
  // order (a mirror vertex; the manifold connector's specular vertices): the first chain_length of
  // chain_vertices.
  Vertex light0{}, eye0{};
  std::array<Vertex, kMaxChain> chain_vertices{};
  bool has_light0 = false, has_eye0 = false;
  int chain_length = 0;
  // The segments to test, all of which must be clear (the first num_segments).
  std::array<Segment, kMaxChain + 1> segments{};
  int num_segments = 0;
  // Its density for MIS: the join's direction and end densities (has_density: the join has two
  // ends; an eye vertex on a light, s = 0, and a light vertex on the lens, t = 0, have one).
  JoinDensity density{};
  bool has_density = false;
  // Where it lands: a splat to raster point (rx, ry), else the sample's own pixel.
  bool splat = false;
  float rx = 0.0f, ry = 0.0f;

  // A join's start: strategy (s, chain, t), nothing built yet. (The end densities' values are read
  // only where `known`.)
  void begin(ConnectorKind kind, int light_s, int eye_t, int strategy_index) {
    chain = kind;
    s = light_s;
    t = eye_t;
    strategy = strategy_index;
    density.at_qs.known = density.at_pt.known = false;
    has_density = false;
    has_light0 = has_eye0 = false;
    chain_length = 0;
    splat = false;
    rx = ry = 0.0f;
    num_segments = 0;
  }
  // What a connector that builds chain_vertices (mirror, manifold) records once it has a
  // contribution: its strategy (s, chain, t), the path's letters, and the length + 1 segments from
  // a across the chain to b, all of which must be clear. At s = 1 (t = 1) the connector stands on a
  // fresh light (sensor) sample, light0 (eye0). MIS recomputes every density of such a path.
  void set_connector(ConnectorKind kind, int light_s, int eye_t, int strategy_index, accel::PathKey key, vec3 c, int length,
                     const Vertex* a, const Vertex* b) {
    begin(kind, light_s, eye_t, strategy_index);
    letters = key;
    contribution = c;
    has_light0 = light_s == 1;
    has_eye0 = eye_t == 1;
    chain_length = length;
    for (int i = 0; i <= length; ++i)
      segments[static_cast<std::size_t>(i)] = {i == 0 ? a : &chain_vertices[static_cast<std::size_t>(i - 1)],
                                                i == length ? b : &chain_vertices[static_cast<std::size_t>(i)]};
    num_segments = length + 1;
  }

  // The fresh endpoint standing in for y0 or z0 (z0 first), as the plain-join MIS routine takes it.
  const Vertex* fresh() const { return has_eye0 ? &eye0 : has_light0 ? &light0 : nullptr; }
};

}  // namespace pathex::tracer
