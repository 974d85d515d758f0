#pragma once
// Crossply geometry generator (docs/model.md).
//
// Axes: x = crack growth, y = loading (opening), z = ply stacking, periodic with period B = sqrt(3) d.
// Two plies per period, each one row of rods: ply 1 at z = 0 with rods at +theta, ply 2 at z = t =
// sqrt(3)/2 d with rods at -theta. Discrete yz-slices at x_k = k h_e carry one node per rod; beams join
// consecutive nodes of a rod; interfaces join the nodes of two rods that are Voronoi neighbours in a slice
// (periodic in z), with area h_e * l_i (l_i the shared Voronoi edge length).
//
// The model is plain arrays, one set per kind of thing (nodes, beams, interfaces), ready for explicit
// loops and for deleting elements (the solver keeps alive flags; the geometry never changes afterwards).
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "geometry/cohesive.hpp"

namespace enamel {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

/// What the generator needs; all lengths in units of d.
struct GeometryParams {
  double theta_deg = 30;         // decussation angle theta_D
  double w_s = 32;               // specimen width (x)
  double h_s = 16;               // specimen height (y)
  double a0 = 16;                // pre-crack length, on the mid-plane y = h_s/2, from x = 0
  double h_e = 0.3;              // requested slice spacing (adjusted so that w_s is a whole number of slices)
  double crisscross_phase = 0;   // the crisscross lattice's shift from its origin, in d/sin(theta) (docs/model.md)
  bool crisscrossCutAtTip = false;  // origin: false a0_eff (its rods intact), true a0_eff - h_e/2 (cut: paper Fig. 4)
  bool precrack = true;          // false: an uncracked block (used to measure the transverse modulus)
};

/// Interface tags (the layers drawn in Figs. 4-6, 8).
enum InterfaceTag : std::int8_t {
  kTagPly1 = 0,            // both rods in ply 1
  kTagPly2 = 1,            // both rods in ply 2
  kTagInterlayer12 = 2,    // ply 1 (z = 0) to ply 2 (z = t)
  kTagInterlayer21 = 3,    // ply 2 (z = t) to ply 1 of the next period (z = B): the periodic wrap
};
const char* interfaceTagName(int tag);

struct Model {
  // --- geometry constants ---
  double d = 1;
  double theta = 0;        // radians
  double s = 1;            // in-slice rod spacing d / cos(theta)
  double t = 0;            // ply thickness sqrt(3)/2 d
  double B = 0;            // z-period sqrt(3) d
  double w_s = 0, h_s = 0, a0 = 0, h_e = 0;  // h_e is the slice spacing actually used; a0 as requested
  int precrackLastSlice = -1;  // K: the pre-crack removes what crosses the mid-plane in slices 0..K (precrackTip)
  double a0Eff = 0;        // the pre-crack tip the model has: (K + 1/4) h_e (Delta_a is measured from it)
  double yCrack = 0;       // mid-plane y = h_s / 2
  double xCrisscross = 0;  // a crisscross point on the mid-plane (theta > 0)
  int numSlices = 0;

  // --- rods ---
  std::vector<std::int8_t> rodPly;   // 0 = ply 1, 1 = ply 2
  std::vector<int> rodIndex;         // j in y = yCrack + j s +/- (x - xCrisscross) tan(theta) (+/- d/4 at theta = 0)
  Vec3 rodDirection(int ply) const;  // unit axis of the rods of a ply

  // --- nodes (6 DOF each: ux uy uz rx ry rz), numbered slice by slice ---
  std::vector<Vec3> X;               // reference positions, z in {0, t}
  std::vector<int> nodeRod, nodeSlice;
  std::vector<std::int8_t> nodePly;

  // --- beam elements (rod segments between consecutive slices), in the order of their first node ---
  std::vector<std::array<int, 2>> beamNodes;
  std::vector<int> beamRod;
  std::vector<std::int8_t> beamSpan; // slices an element spans: 1, or up to farFieldSlices in a reduced far field
  double beamLength = 0;             // h_e / cos(theta): the length of a one-slice element
  /// Element class (one set of element matrices each): 2 (span - 1) + ply.
  int beamClass(int e) const { return 2 * (beamSpan[e] - 1) + rodPly[beamRod[e]]; }
  int numBeamClasses() const { return 2 * farFieldSlices; }
  double beamLengthOfClass(int c) const { return (c / 2 + 1) * beamLength; }

  // --- interface elements ---
  std::vector<std::array<int, 2>> ifaceNodes;            // A, B (B possibly through the periodic wrap)
  std::vector<cohesive::InterfaceGeometry> ifaceGeom;    // frame, arms, area
  std::vector<std::int8_t> ifaceTag;
  std::vector<int> ifaceSlice;
  std::vector<double> ifaceEdgeLength;                   // l_i (lumped: area / the length along x it stands for)
  std::vector<std::int8_t> ifaceZShift;                  // image of B used: z_B + shift * B

  // --- boundary node sets (loaded in u_y): topmost / bottommost node of each ply in each slice ---
  std::vector<int> topNodes, bottomNodes;

  // --- removed by the pre-crack (not part of the model's elements; kept as crack-tracking seeds) ---
  int precrackBeams = 0, precrackInterfaces = 0;
  std::vector<std::array<int, 2>> precrackIfaceRods;  // rods of each removed interface
  std::vector<int> precrackIfaceSlice;
  std::vector<int> precrackBeamRod, precrackBeamSlice;  // rod and first slice of each removed beam

  // --- reduced far field (far_field.hpp): 1 and infinity in the full model ---
  int farFieldSlices = 1;            // outside the full band, a rod keeps a node in every this many slices
  double fullHalfHeight = INFINITY;  // the full band: |y - yCrack| <= fullHalfHeight
  bool hasFarField() const { return farFieldSlices > 1 && fullHalfHeight < 0.5 * h_s; }

  int numNodes() const { return static_cast<int>(X.size()); }
  int numBeams() const { return static_cast<int>(beamNodes.size()); }
  int numInterfaces() const { return static_cast<int>(ifaceNodes.size()); }
  int numRods() const { return static_cast<int>(rodPly.size()); }
  int numDofs() const { return 6 * numNodes(); }
};

/// The pre-crack tip (docs/model.md, Geometry): snapped to a quarter point of the slice lattice, so that no
/// round-off in a0 or h_e decides what the pre-crack removes. K = floor(a0/h_e + 1e-6); the pre-crack removes
/// the interfaces of slices k <= K and the rod elements [k-1, k] with k <= K that cross the mid-plane, and the
/// tip is a0_eff = (K + 1/4) h_e: between the last cut slice and the first intact element's midpoint.
struct PrecrackTip {
  int lastSlice = -1;  // K
  double a0Eff = 0;    // (K + 1/4) h_e
};
PrecrackTip precrackTip(double a0, double h_e);
constexpr double kTipSnapTolerance = 1e-6;   // in slices: a0/h_e this close below an integer counts as it
constexpr double kCrackPlaneTolerance = 1e-6;  // d: a node this close to the mid-plane counts as above it

/// Whether a point at height y lies below the mid-plane for the pre-crack's cuts: y < yCrack - 1e-6 d, so a
/// node on the plane (a crisscross point on a slice) is on one fixed side whatever the round-off.
bool belowCrackPlane(const Model& m, double y);

/// y of the centre of rod j of a ply at position x (the analytic rod centre line).
double rodCentreY(const Model& m, int ply, int j, double x);

/// One Voronoi cell of a slice: polygon (in (y, z)) and the edges it shares with neighbours.
struct VoronoiEdge {
  int neighbour;       // index of the neighbouring point, or -1 for the specimen boundary (y = 0 or h_s)
  int zShift;          // neighbour's image: z_neighbour + zShift * period
  double length;
  Vec2 midpoint;       // (y, z)
};
struct VoronoiCell {
  std::vector<Vec2> polygon;     // counter-clockwise vertices (y, z)
  std::vector<VoronoiEdge> edges;
  double area = 0;
  double perimeter = 0;
};

/// Edges shorter than this (d) are no interface: where a slice's plies are aligned (ply-1 and ply-2 rods at the
/// same y, every d/(2 sin theta) along x) the section is a rectangular lattice whose Voronoi vertices join four
/// cells, and round-off makes each diagonal an edge of length ~1e-9 or none; 1e-6 d drops them whatever the
/// round-off (at 1e-9 a hair of h_e changed the ci theta30 specimen's interfaces).
constexpr double kMinVoronoiEdge = 1e-6;

/// Voronoi tessellation of points (y, z) in the strip yLo <= y <= yHi, periodic in z with period `period`.
/// Cells are clipped by the strip; edges shorter than minEdge are dropped (degenerate vertices).
std::vector<VoronoiCell> computeSliceVoronoi(const std::vector<Vec2>& points, double period, double yLo,
                                             double yHi, double minEdge = kMinVoronoiEdge);

/// Build the whole crossply specimen. Throws std::invalid_argument on impossible parameters.
Model buildCrossply(const GeometryParams& p);

/// Number the nodes slice by slice and the rod elements in the order of their first node (what the force
/// kernels rely on); interfaces keep their order. buildCrossply and coarsenFarField end with it.
void numberNodesBySlice(Model& m);

}  // namespace enamel
