#include "simulation/setup.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "base/errors.hpp"
#include "geometry/far_field.hpp"
#include "kernels/static_solve.hpp"
#include "laws/strength.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace enamel {

GeometryParams geometryOf(const CaseParams& p) {
  GeometryParams g;
  g.theta_deg = p.theta_D;
  g.w_s = p.w_s_over_d;
  g.h_s = p.h_s_over_d;
  g.a0 = p.a0();
  g.h_e = p.h_e_over_d;
  g.crisscross_phase = p.crisscross_phase;
  g.crisscrossCutAtTip = p.crisscross_at_tip == CrisscrossAtTip::cut;
  return g;
}

beam::Section sectionOf(const CaseParams& p) {
  return p.section == SectionShape::circle ? beam::circularSection(1.0, 1.0, p.nu_r, 1.0)
                               : beam::hexagonalSection(1.0, 1.0, p.nu_r, 1.0);
}

cohesive::Law lawOf(const CaseParams& p) {
  if (!p.interfaces_breakable) return cohesive::Law{p.k(), 1e300, 1e300};
  return cohesive::makeLaw(p.k(), p.sigma0(), p.Gamma(), p.softening_over_delta0, p.shear_strength_ratio);
}

Grips gripsOf(const CaseParams& p) {
  Grips g;
  if (p.grip_profile == GripProfile::about_centre) g.profile = Grips::Profile::aboutCentre;
  g.holdUx = p.grip_constraint == GripConstraint::uxuy;
  return g;
}

namespace {

SpMat assembleBeams(const Model& m, const std::vector<beam::Mat12>& perClass, int nDofs,
                    std::vector<Eigen::Triplet<double>> trip = {}) {
  trip.reserve(trip.size() + static_cast<std::size_t>(m.numBeams()) * 144);
  for (int e = 0; e < m.numBeams(); ++e)
    addElementTriplets(trip, perClass[m.beamClass(e)], m.beamNodes[e][0], m.beamNodes[e][1]);
  SpMat A(nDofs, nDofs);
  A.setFromTriplets(trip.begin(), trip.end());
  return A;
}

}  // namespace

Model buildModel(const CaseParams& p) {
  return coarsenFarField(buildCrossply(geometryOf(p)), static_cast<int>(p.far_field_slices), p.full_half_height_over_d);
}

void describeMaterials(const CaseParams& p, Materials& mat) {
  mat.section = sectionOf(p);
  mat.law = lawOf(p);
  mat.rodsBreakable = p.rods_breakable;
  mat.deletionRule = p.deletion_rule;
  mat.rodStress = p.rod_stress;
  mat.grips = gripsOf(p);
}

std::vector<double> drawRodStrengths(const Model& m, const CaseParams& p) {
  std::vector<double> strength(m.numBeams());
  if (!p.rods_breakable) {
    std::fill(strength.begin(), strength.end(), INFINITY);
    return strength;
  }
  std::size_t numDraws = 0;
  for (int e = 0; e < m.numBeams(); ++e) numDraws += m.beamSpan[e];
  const std::vector<double> draws = sampleRodStrengths(numDraws, p.sigma_ru(), p.cv, static_cast<std::uint64_t>(p.seed));
  std::vector<int> alongRods(m.numBeams());
  for (int e = 0; e < m.numBeams(); ++e) alongRods[e] = e;
  std::sort(alongRods.begin(), alongRods.end(), [&](int a, int b) {
    return std::make_pair(m.beamRod[a], m.beamNodes[a][0]) < std::make_pair(m.beamRod[b], m.beamNodes[b][0]);
  });
  std::size_t next = 0;
  for (int r = 0; r < m.numBeams(); ++r) {
    const int e = alongRods[r];
    strength[e] = draws[next++];
    for (int part = 1; part < m.beamSpan[e]; ++part) strength[e] = std::min(strength[e], draws[next++]);
  }
  return strength;
}

void buildElementClasses(const Model& m, Materials& mat) {
  const beam::Section& section = mat.section;
  for (int c = 0; c < m.numBeamClasses(); ++c) {
    const int ply = c % 2;
    const double L = m.beamLengthOfClass(c);
    const Vec3 xb = L * m.rodDirection(ply);
    const beam::Mat3 R = beam::localFrame(Vec3::Zero(), xb);
    mat.beamK.push_back(beam::globalStiffness(section, Vec3::Zero(), xb));
    mat.beamMc.push_back(beam::globalConsistentMass(section, Vec3::Zero(), xb));
    mat.beamMl.push_back(beam::rotateToGlobal(beam::lumpedMassDiagonal(section, L).asDiagonal().toDenseMatrix(), R));
    beam::Mat12 T = beam::Mat12::Zero();
    for (int blk = 0; blk < 4; ++blk) T.block<3, 3>(3 * blk, 3 * blk) = R;
    mat.beamLocalForceOperator.push_back(beam::localStiffness(section, L) * T);
    mat.beamStressOperator.emplace_back();
    for (int r = 0; r < 5; ++r) mat.beamStressOperator.back().row(r) = mat.beamLocalForceOperator.back().row(beam::kStressRows[r]);
    mat.beamTorsionOperator.push_back(mat.beamLocalForceOperator.back().row(beam::kTorsionRow));
    mat.beamStressChangeBound.push_back(beam::stressChangeBound(section, mat.beamStressOperator.back()));
  }
  mat.omegaMaxElement = beam::maxFrequency(section, m.beamLength, beam::MassKind::Consistent);
}

// Assembled from triplets with the rest (an insertion into a compressed matrix costs O(nnz) each: hours at
// 200 x 200 d).
void assembleOperators(const Model& m, const Materials& mat, Operators& ops) {
  std::vector<Eigen::Triplet<double>> cutMass;
  std::map<std::pair<int, int>, int> nodeOf;  // (rod, slice) -> node
  for (int i = 0; i < m.numNodes(); ++i) nodeOf[{m.nodeRod[i], m.nodeSlice[i]}] = i;
  for (std::size_t c = 0; c < m.precrackBeamRod.size(); ++c) {
    const int rod = m.precrackBeamRod[c], k = m.precrackBeamSlice[c];
    ops.cutBeamNodes.push_back({nodeOf.at({rod, k}), nodeOf.at({rod, k + 1})});
    addElementTriplets(cutMass, mat.beamMl[m.rodPly[rod]], ops.cutBeamNodes.back()[0], ops.cutBeamNodes.back()[1]);
  }
  ops.K = assembleBeams(m, mat.beamK, m.numDofs());
  ops.M = assembleBeams(m, mat.beamMc, m.numDofs(), cutMass);
}

void setWaveSpeedDampingAndLoading(const CaseParams& p, const Model& m, Materials& mat) {
  mat.E_transverse = p.E_transverse_over_Er > 0 ? p.E_transverse_over_Er : measureTransverseModulus(p);
  mat.c_d = std::sqrt(mat.E_transverse / 1.0);
  mat.omegaMin = M_PI * mat.c_d / m.h_s;
  mat.dampA = p.zeta * mat.omegaMin;
  mat.dampB = p.zeta / mat.omegaMin;
  mat.loading.vApp = p.rate_factor * p.v_app_over_cd * mat.c_d;
  mat.loading.rampTime = p.ramp_transits * m.h_s / mat.c_d;
  mat.loading.rateAdaptMax = p.rate_adapt_max;
}

void prescribeGrips(const Model& m, const Grips& grips, Operators& ops) {
  const int n = m.numDofs();
  ops.dofToFree.assign(n, 0);
  auto prescribe = [&](int dof, double shape, double slope) {
    ops.prescribedDofs.push_back(dof);
    ops.prescribedShape.push_back(shape);
    ops.prescribedSlope.push_back(slope);
    ops.dofToFree[dof] = -1;
  };
  for (const auto& [nodes, sign] : {std::make_pair(&m.topNodes, +1.0), std::make_pair(&m.bottomNodes, -1.0)})
    for (int node : *nodes) prescribe(6 * node + 1, grips.shape(sign, m.X[node].x() / m.w_s), grips.slope(sign));
  if (grips.holdUx)
    for (const std::vector<int>* nodes : {&m.topNodes, &m.bottomNodes})
      for (int node : *nodes) prescribe(6 * node, 0.0, 0.0);
  for (int i = 0; i < n; ++i)
    if (ops.dofToFree[i] == 0) { ops.dofToFree[i] = static_cast<int>(ops.freeDofs.size()); ops.freeDofs.push_back(i); }
}

void indexInterfacesByNode(const Model& m, Operators& ops) {
  ops.nodeIfaceStart.assign(m.numNodes() + 1, 0);
  for (const auto& ab : m.ifaceNodes) { ++ops.nodeIfaceStart[ab[0] + 1]; ++ops.nodeIfaceStart[ab[1] + 1]; }
  for (int i = 0; i < m.numNodes(); ++i) ops.nodeIfaceStart[i + 1] += ops.nodeIfaceStart[i];
  ops.nodeIfaceList.resize(ops.nodeIfaceStart.back());
  std::vector<int> fill(ops.nodeIfaceStart.begin(), ops.nodeIfaceStart.end() - 1);
  for (int i = 0; i < m.numInterfaces(); ++i) {
    ops.nodeIfaceList[fill[m.ifaceNodes[i][0]]++] = 2 * i;
    ops.nodeIfaceList[fill[m.ifaceNodes[i][1]]++] = 2 * i + 1;
  }
}

void indexSlices(const Model& m, Operators& ops) {
  ops.sliceNodeStart.assign(m.numSlices + 1, 0);
  ops.sliceIfaceStart.assign(m.numSlices + 1, 0);
  for (int i = 0; i < m.numNodes(); ++i) {
    if (i > 0 && m.nodeSlice[i] < m.nodeSlice[i - 1]) throw SolverError("model: nodes not numbered slice by slice");
    ++ops.sliceNodeStart[m.nodeSlice[i] + 1];
  }
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const int k = m.ifaceSlice[i];
    if ((i > 0 && k < m.ifaceSlice[i - 1]) || m.nodeSlice[m.ifaceNodes[i][0]] != k || m.nodeSlice[m.ifaceNodes[i][1]] != k)
      throw SolverError("model: interfaces not built slice by slice, or joining nodes of another slice");
    ++ops.sliceIfaceStart[k + 1];
    ops.ifacePacked.push_back(cohesive::packInSlice(m.ifaceGeom[i]));
  }
  for (int k = 0; k < m.numSlices; ++k) {
    ops.maxNodesPerSlice = std::max(ops.maxNodesPerSlice, ops.sliceNodeStart[k + 1]);
    ops.sliceNodeStart[k + 1] += ops.sliceNodeStart[k];
    ops.sliceIfaceStart[k + 1] += ops.sliceIfaceStart[k];
  }
}

State stateAtRest(const Model& m, const Operators& ops) {
  State s;
  const int n = m.numDofs();
  s.q = VecX::Zero(n);
  s.v = VecX::Zero(n);
  s.a = VecX::Zero(n);
  s.lambdaMax.assign(m.numInterfaces(), 0.0);
  s.beamBroken.assign(m.numBeams(), 0);
  s.reaction = VecX::Zero(ops.prescribedDofs.size());
  return s;
}

void setThreadCount(const CaseParams& p, int numDofs) {
#ifdef _OPENMP
  const int n = p.threads > 0 ? static_cast<int>(p.threads)
                              : std::max(1, std::min(omp_get_num_procs(), numDofs / 30000));
  omp_set_num_threads(n);
#else
  (void)numDofs;
  const int n = p.threads > 0 ? static_cast<int>(p.threads) : 1;
#endif
  setBlasThreadCount(n);
}

double measureTransverseModulus(const CaseParams& p, double* blockStrain) {
  GeometryParams g = geometryOf(p);
  g.h_s = std::min(p.h_s_over_d, 12.0);
  g.w_s = std::min(p.w_s_over_d, 24.0);
  g.a0 = 0.5 * g.w_s;
  g.precrack = false;
  const Model m = buildCrossply(g);
  const beam::Section sec = sectionOf(p);
  const cohesive::Law law = lawOf(p);
  std::vector<beam::Mat12> Kply(2);
  for (int ply = 0; ply < 2; ++ply)
    Kply[ply] = beam::globalStiffness(sec, Vec3::Zero(), m.beamLength * m.rodDirection(ply));
  const SpMat K = assembleElasticStiffness(m, Kply, nullptr, law);

  // Prescribed: u_y = +delta/2 on the top rows, -delta/2 on the bottom rows; u_x = u_z = 0 at one node.
  const double delta = 1e-3;
  std::vector<int> dofs;
  std::vector<double> values;
  for (int node : m.topNodes) { dofs.push_back(6 * node + 1); values.push_back(0.5 * delta); }
  for (int node : m.bottomNodes) { dofs.push_back(6 * node + 1); values.push_back(-0.5 * delta); }
  dofs.insert(dofs.end(), {6 * m.bottomNodes[0], 6 * m.bottomNodes[0] + 2});
  values.insert(values.end(), {0.0, 0.0});
  const VecX u = solveStaticPrescribed(K, dofs, values);
  const VecX f = K * u;
  double P = 0;
  for (int node : m.topNodes) P += f[6 * node + 1];
  // Height between the mean top and bottom rows; area = w_s (the slices' total tributary length) x B.
  double yTop = 0, yBot = 0;
  for (int node : m.topNodes) yTop += m.X[node].y();
  for (int node : m.bottomNodes) yBot += m.X[node].y();
  yTop /= m.topNodes.size();
  yBot /= m.bottomNodes.size();
  const double strain = delta / (yTop - yBot);
  if (blockStrain) *blockStrain = strain;
  return P / (m.w_s * m.B) / strain;
}

}  // namespace enamel
