#pragma once
// The reduced far field (docs/solver.md, "Reduced far field").
//
// Away from the crack plane the material stays elastic (docs/solver.md: the inelastic reach measured at the default G), so it need not be resolved
// slice by slice. coarsenFarField keeps the full model inside the band |y - y_crack| <= fullHalfHeight and,
// outside it, keeps a rod's node only in every m-th slice (m = farFieldSlices), at the rod's two ends and on
// the loaded rows (the grips stay exactly as in the full model):
//   - rod elements join consecutive kept nodes of a rod: an element spans 1..m slices (Model::beamSpan), an
//     exact Euler-Bernoulli element of that length;
//   - every interface of the full model whose two nodes are not both kept moves to the nearest slice where
//     both of its rods have a kept node, rigidly attached to those nodes, and the interfaces that land on the
//     same pair of nodes are lumped into one: area = the sum, normal = the area-weighted mean normal, point =
//     the area-weighted mean of their Voronoi-edge midpoints in y and z, in the nodes' slice in x (the force
//     kernels take in-slice arms). Rigid-arm kinematics with one point for both arms: a rigid motion still
//     opens nothing. Below delta0 the law is linear and isotropic (k delta, contact included), so a lumped
//     interface's force is the sum of its parts' forces for any motion of its two nodes up to the parts' x
//     offsets from the nodes' slice (at most farFieldSlices / 2 slices), which are dropped.
// Inside the band (and wherever both nodes are kept) nothing changes: with a band wider than the specimen
// the result is the full model itself, element for element (test FarField.WideBandIsTheFullModel).
// What it assumes, and what the runner checks (runner.cpp): no interface outside the band passes delta0 and
// no rod element there breaks; the run stops with a message when the inelastic zone comes near the band's edge.
#include <vector>

#include "geometry/geometry.hpp"

namespace enamel {

/// The model with the reduced far field (see above). slices >= 1; slices = 1 returns the model unchanged.
/// Throws std::invalid_argument when the band does not hold the pre-crack's cut (fullHalfHeight < 1 d).
Model coarsenFarField(const Model& full, int slices, double fullHalfHeight);

}  // namespace enamel
