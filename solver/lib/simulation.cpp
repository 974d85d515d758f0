#include "simulation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

#include <Eigen/CholmodSupport>

#include "far_field.hpp"
#include "kernels.hpp"
#include "strength.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace enamel {

namespace {

GeometryParams geometryOf(const CaseParams& p) {
  GeometryParams g;
  g.theta_deg = p.theta_D;
  g.w_s = p.w_s_over_d;
  g.h_s = p.h_s_over_d;
  g.a0 = p.a0();
  g.h_e = p.h_e_over_d;
  g.crisscross_phase = p.crisscross_phase;
  return g;
}

beam::Section sectionOf(const CaseParams& p) {
  return p.section == "circle" ? beam::circularSection(1.0, 1.0, p.nu_r, 1.0)
                               : beam::hexagonalSection(1.0, 1.0, p.nu_r, 1.0);
}

// Unbreakable interfaces (verification runs) keep the elastic branch however far they open.
cohesive::Law lawOf(const CaseParams& p) {
  if (!p.interfaces_breakable) return cohesive::Law{p.k(), 1e300, 1e300};
  return cohesive::makeLaw(p.k(), p.sigma0(), p.Gamma(), p.softening_over_delta0);
}

// Add (sign x) a 12x12 element matrix into a triplet list / an existing sparse pattern.
void addElementTriplets(std::vector<Eigen::Triplet<double>>& trip, const beam::Mat12& Ke, int a, int b) {
  const int dof[2] = {6 * a, 6 * b};
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      trip.emplace_back(dof[i / 6] + i % 6, dof[j / 6] + j % 6, Ke(i, j));
}

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

// --- static elastic solutions (verification, transverse modulus) ----------------------------------------
VecX solveStaticPrescribed(const SpMat& K, const std::vector<int>& dofs, const std::vector<double>& values,
                           bool* mechanism) {
  if (mechanism) *mechanism = false;
  const int n = static_cast<int>(K.rows());
  std::vector<double> uPres(n, 0.0);
  std::vector<int> freeIdx(n, 0);
  for (std::size_t i = 0; i < dofs.size(); ++i) { freeIdx[dofs[i]] = -1; uPres[dofs[i]] = values[i]; }
  int nf = 0;
  for (int i = 0; i < n; ++i)
    if (freeIdx[i] == 0) freeIdx[i] = nf++;
  std::vector<Eigen::Triplet<double>> tff;
  VecX rhs = VecX::Zero(nf);
  for (int c = 0; c < K.outerSize(); ++c)
    for (SpMat::InnerIterator it(K, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (freeIdx[r] < 0) continue;
      if (freeIdx[c] >= 0) tff.emplace_back(freeIdx[r], freeIdx[c], it.value());
      else rhs[freeIdx[r]] -= it.value() * uPres[c];
    }
  SpMat Kff(nf, nf);
  Kff.setFromTriplets(tff.begin(), tff.end());
  Eigen::CholmodSupernodalLLT<SpMat> chol;
  chol.cholmod().print = 0;  // a factorisation that fails is handled below, not printed
  chol.compute(Kff);
  VecX uf;
  if (chol.info() == Eigen::Success) {
    uf = chol.solve(rhs);
  } else {
    // K_ff only semi-definite: a part of the model is a mechanism (e.g. a rod end that the pre-crack's cut
    // leaves on a single interface, free to turn about it; the explicit schemes carry it on its mass). The
    // prescribed displacements do no work on a mechanism (the right-hand side is orthogonal to K's null
    // space), so any solution serves: factor K_ff + s I with s = 1e-10 of its largest diagonal entry (the
    // mechanism then stays where it is) and refine against K_ff itself, which removes the shift's error from
    // every mode with stiffness (each refinement multiplies it by s / (lambda + s)).
    const double shift = 1e-10 * Kff.diagonal().cwiseAbs().maxCoeff();
    chol.setShift(shift);
    chol.factorize(Kff);
    if (chol.info() != Eigen::Success) throw std::runtime_error("static solve: stiffness factorisation failed");
    uf = chol.solve(rhs);
    for (int it = 0; it < 4; ++it) uf += chol.solve(rhs - Kff * uf);
    if (mechanism) *mechanism = true;
  }
  VecX u(n);
  for (int i = 0; i < n; ++i) u[i] = freeIdx[i] >= 0 ? uf[freeIdx[i]] : uPres[i];
  return u;
}

SpMat assembleElasticStiffness(const Model& m, const std::vector<beam::Mat12>& beamKPerClass,
                               const std::vector<std::uint8_t>* beamBroken, const cohesive::Law& law) {
  std::vector<Eigen::Triplet<double>> trip;
  for (int e = 0; e < m.numBeams(); ++e)
    if (!beamBroken || !(*beamBroken)[e])
      addElementTriplets(trip, beamKPerClass[m.beamClass(e)], m.beamNodes[e][0], m.beamNodes[e][1]);
  for (int i = 0; i < m.numInterfaces(); ++i)
    addElementTriplets(trip, cohesive::elasticStiffness(law, m.ifaceGeom[i]), m.ifaceNodes[i][0], m.ifaceNodes[i][1]);
  SpMat K(m.numDofs(), m.numDofs());
  K.setFromTriplets(trip.begin(), trip.end());
  return K;
}

// --- transverse modulus ----------------------------------------------------------------------------------
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

// --- set-up ---------------------------------------------------------------------------------------------
Simulation::Simulation(const CaseParams& p)
    : params(p), model(coarsenFarField(buildCrossply(geometryOf(p)), static_cast<int>(p.far_field_slices),
                                       p.full_half_height_over_d)) {
  const Model& m = model;
  const int n = m.numDofs();
  Materials& mat = materials;
  mat.section = sectionOf(p);
  mat.law = lawOf(p);
  mat.rodsBreakable = p.rods_breakable;
  mat.deletionRule = p.deletion_rule;
  mat.rodStress = beam::parseRodStress(p.rod_stress);
  const beam::Section& section = mat.section;

  // Rod-element strengths: one per element, normal(mean, cv), seeded (docs/model.md).
  // Strengths drawn rod by rod, along each rod from its first slice (the realisation of a seed does not
  // depend on how the model numbers its rod elements). An element of the reduced far field spanning n
  // slices takes the n draws of the full model's elements it stands for, and the weakest of them.
  {
    std::size_t numDraws = 0;
    for (int e = 0; e < m.numBeams(); ++e) numDraws += m.beamSpan[e];
    const std::vector<double> draws = sampleRodStrengths(numDraws, p.sigma_ru(), p.cv, static_cast<std::uint64_t>(p.seed));
    std::vector<int> alongRods(m.numBeams());
    for (int e = 0; e < m.numBeams(); ++e) alongRods[e] = e;
    std::sort(alongRods.begin(), alongRods.end(), [&](int a, int b) {
      return std::make_pair(m.beamRod[a], m.beamNodes[a][0]) < std::make_pair(m.beamRod[b], m.beamNodes[b][0]);
    });
    mat.beamStrength.resize(m.numBeams());
    std::size_t next = 0;
    for (int r = 0; r < m.numBeams(); ++r) {
      const int e = alongRods[r];
      mat.beamStrength[e] = draws[next++];
      for (int part = 1; part < m.beamSpan[e]; ++part) mat.beamStrength[e] = std::min(mat.beamStrength[e], draws[next++]);
    }
  }
  if (!p.rods_breakable) std::fill(mat.beamStrength.begin(), mat.beamStrength.end(), INFINITY);

  // Element matrices: all rods of a ply share one orientation, so one matrix per ply (and per span in a
  // reduced far field: Model::beamClass).
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
  // Rod elements cut by the pre-crack carry no stiffness but keep their material's mass, lumped at their
  // nodes (as a deleted element does), so a rod end isolated by the cut is not massless. Assembled from
  // triplets with the rest (an insertion into a compressed matrix costs O(nnz) each: hours at 200 x 200 d).
  std::vector<Eigen::Triplet<double>> cutMass;
  {
    std::map<std::pair<int, int>, int> nodeOf;  // (rod, slice) -> node
    for (int i = 0; i < m.numNodes(); ++i) nodeOf[{m.nodeRod[i], m.nodeSlice[i]}] = i;
    for (std::size_t c = 0; c < m.precrackBeamRod.size(); ++c) {
      const int rod = m.precrackBeamRod[c], k = m.precrackBeamSlice[c];
      ops.cutBeamNodes.push_back({nodeOf.at({rod, k}), nodeOf.at({rod, k + 1})});
      addElementTriplets(cutMass, mat.beamMl[m.rodPly[rod]], ops.cutBeamNodes.back()[0], ops.cutBeamNodes.back()[1]);
    }
  }
  ops.K = assembleBeams(m, mat.beamK, n);
  ops.M = assembleBeams(m, mat.beamMc, n, cutMass);
  mat.omegaMaxElement = beam::maxFrequency(section, m.beamLength, beam::MassKind::Consistent);

  // Wave speed and Rayleigh damping (paper eq. 1-3, docs/solver.md): C = a M + b K,
  // a = zeta w_min, b = zeta / w_min, w_min = pi c_d / h_s.
  mat.E_transverse = p.E_transverse_over_Er > 0 ? p.E_transverse_over_Er : measureTransverseModulus(p);
  mat.c_d = std::sqrt(mat.E_transverse / 1.0);
  mat.omegaMin = M_PI * mat.c_d / m.h_s;
  mat.dampA = p.zeta * mat.omegaMin;
  mat.dampB = p.zeta / mat.omegaMin;
  mat.loading.vApp = p.rate_factor * p.v_app_over_cd * mat.c_d;
  mat.loading.rampTime = p.ramp_transits * m.h_s / mat.c_d;
  mat.loading.rateAdaptMax = p.rate_adapt_max;

  // Prescribed DOFs: u_y of the top (+) and bottom (-) rows, graded 1 - x/w_s.
  ops.dofToFree.assign(n, 0);
  auto prescribe = [&](const std::vector<int>& nodes, double sign) {
    for (int node : nodes) {
      ops.prescribedDofs.push_back(6 * node + 1);
      ops.prescribedShape.push_back(sign * (1.0 - m.X[node].x() / m.w_s));
      ops.dofToFree[6 * node + 1] = -1;
    }
  };
  prescribe(m.topNodes, +1.0);
  prescribe(m.bottomNodes, -1.0);
  for (int i = 0; i < n; ++i)
    if (ops.dofToFree[i] == 0) { ops.dofToFree[i] = static_cast<int>(ops.freeDofs.size()); ops.freeDofs.push_back(i); }

  // Node -> interface ends (CSR), for the deterministic gather.
  ops.nodeIfaceStart.assign(m.numNodes() + 1, 0);
  for (const auto& ab : m.ifaceNodes) { ++ops.nodeIfaceStart[ab[0] + 1]; ++ops.nodeIfaceStart[ab[1] + 1]; }
  for (int i = 0; i < m.numNodes(); ++i) ops.nodeIfaceStart[i + 1] += ops.nodeIfaceStart[i];
  ops.nodeIfaceList.resize(ops.nodeIfaceStart.back());
  std::vector<int> fill(ops.nodeIfaceStart.begin(), ops.nodeIfaceStart.end() - 1);
  for (int i = 0; i < m.numInterfaces(); ++i) {
    ops.nodeIfaceList[fill[m.ifaceNodes[i][0]]++] = 2 * i;
    ops.nodeIfaceList[fill[m.ifaceNodes[i][1]]++] = 2 * i + 1;
  }

  // Slices: contiguous nodes and interfaces, each interface within its slice (what the kernels rely on).
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
    ops.maxIfacesPerSlice = std::max(ops.maxIfacesPerSlice, ops.sliceIfaceStart[k + 1]);
    ops.sliceNodeStart[k + 1] += ops.sliceNodeStart[k];
    ops.sliceIfaceStart[k + 1] += ops.sliceIfaceStart[k];
  }

  state.q = VecX::Zero(n);
  state.v = VecX::Zero(n);
  state.a = VecX::Zero(n);
  state.lambdaMax.assign(m.numInterfaces(), 0.0);
  state.beamBroken.assign(m.numBeams(), 0);
  state.reaction = VecX::Zero(ops.prescribedDofs.size());

#ifdef _OPENMP
  // threads = 0: automatic, one thread per 30k DOF up to all cores (small models run faster on one).
  omp_set_num_threads(p.threads > 0 ? static_cast<int>(p.threads)
                                    : std::max(1, std::min(omp_get_num_procs(), n / 30000)));
#endif
  integrator = makeIntegrator(p, model, materials, ops);
  if (integrator->usesHalfStepVelocity()) state.vHalf = VecX::Zero(n);
}

Simulation::~Simulation() = default;

int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void Simulation::solveStaticElastic(double U, bool* mechanism) {
  stressSchedule_ = StressCheckSchedule{};  // q is replaced: the next deletion check computes every element
  const SpMat Kt = assembleElasticStiffness(model, materials.beamK, &state.beamBroken, materials.law);
  std::vector<int> dofs = ops.prescribedDofs;
  std::vector<double> values;
  for (double sh : ops.prescribedShape) values.push_back(sh * U);
  const int anchor = model.bottomNodes[0];  // against rigid translation in x and z
  dofs.insert(dofs.end(), {6 * anchor, 6 * anchor + 2});
  values.insert(values.end(), {0.0, 0.0});
  state.q = solveStaticPrescribed(Kt, dofs, values, mechanism);
  state.v.setZero();
  state.a.setZero();
  state.vHalf.setZero();
  state.appliedDisplacement = U;
  const VecX f = Kt * state.q;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) state.reaction[i] = f[ops.prescribedDofs[i]];
}

// --- static elastic start -------------------------------------------------------------------------------
double computeFirstDamageDisplacement(const Model& m, const Materials& mat, const VecX& q1,
                                      const std::vector<std::uint8_t>& beamBroken, bool interfacesBreakable,
                                      bool& limitedByRod) {
  double uc = INFINITY;
  limitedByRod = false;
  if (interfacesBreakable && m.numInterfaces() > 0) {
    // the largest effective separation lambda_i(q1) (no interface is assembled or changed)
    double worst = 0;
    for (int i = 0; i < m.numInterfaces(); ++i)
      worst = std::max(worst, cohesive::effectiveSeparation(computeLocalOpening(m, q1, i)));
    if (worst > 0) uc = mat.law.delta0() / worst;
  }
  if (mat.rodsBreakable && m.numBeams() > 0) {
    std::vector<double> ratio;
    computeStressRatiosForBeams(m, mat, q1, beamBroken, ratio);
    const double worst = *std::max_element(ratio.begin(), ratio.end());
    if (worst > 0 && 1.0 / worst < uc) {
      uc = 1.0 / worst;
      limitedByRod = true;
    }
  }
  return uc;
}

namespace {

// The quasi-static state of the loading at time t, U(t) = U: every DOF moves with the grips in proportion to
// the static field q1 at unit displacement (q = U q1, v = U'(t) q1, a = U''(t) q1), the reactions are the
// static ones U R1, and the grips' power is R . v of the grips.
void setQuasiStaticState(const Operators& ops, const Loading& loading, const VecX& q1, const VecX& reaction1,
                         double U, double t, State& s) {
  const double V = loading.velocity(t);
  s.time = t;
  s.loadingTime = t;  // the loading clock (adaptive rate) starts where the loading is, at phi = 1
  s.appliedDisplacement = U;
  s.q = U * q1;
  s.v = V * q1;
  s.a = loading.acceleration(t) * q1;
  s.reaction = U * reaction1;
  double power = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) power += s.reaction[i] * ops.prescribedShape[i] * V;
  s.lastExternalPower = power;
}

}  // namespace

StaticStart Simulation::startFromStaticElastic(double fraction) {
  StaticStart st;
  st.fraction = fraction;
  solveStaticElastic(1.0, &st.mechanism);
  const VecX q1 = state.q, reaction1 = state.reaction;
  st.firstDamageDisplacement = computeFirstDamageDisplacement(model, materials, q1, state.beamBroken,
                                                              params.interfaces_breakable, st.limitedByRod);
  if (!(std::isfinite(st.firstDamageDisplacement) && st.firstDamageDisplacement > 0))
    throw IntegratorError("static_start = " + std::to_string(fraction) +
                          ": no interface opens and no rod element is stressed under the applied displacement "
                          "(first-damage displacement U_c = " + std::to_string(st.firstDamageDisplacement) +
                          "): there is no elastic stage to skip; use static_start = 0");
  st.displacement = fraction * st.firstDamageDisplacement;
  st.time = materials.loading.timeOfDisplacement(st.displacement);
  setQuasiStaticState(ops, materials.loading, q1, reaction1, st.displacement, st.time, state);
  // each interface's history at its current (elastic) separation (recorded only near delta0: cohesive.hpp)
  VecX f;
  state.failedInterfaces = computeForcesForInterfaces(model, materials.law, ops, state.q, state.lambdaMax, true, f);
  integrator->initialise(model, materials, ops, state);
  // the grips did the work the specimen holds (quasi-statically: no damping work is booked for the skipped stage)
  state.externalWork = strainEnergyOfBeams() + strainEnergyOfInterfaces() + integrator->kineticEnergy(ops, state);
  return st;
}

// --- the level above a scheme's step -------------------------------------------------------------------

/// One time step: the scheme's step; delete overloaded rods; measure the crack when something broke.
void Simulation::step() {
  const int failedBefore = state.failedInterfaces;
  integrator->advance(model, materials, ops, state);
  const int deleted = deleteOverloadedBeams();
  if (deleted > 0 || state.failedInterfaces != failedBefore) state.crackAdvance = measureCrackAdvance();
}

namespace {

// Deletion rule (docs/model.md), independent of element order and thread count:
//  "most_overloaded": the element(s) with the largest stress ratio >= 1, ties within 1e-9 relative
//                     (mirror-symmetric rods) together; the rest are re-evaluated next step.
//  "all":             every element with ratio >= 1.
std::vector<int> findOverloadedBeams(const std::vector<double>& ratio, const std::vector<std::uint8_t>& beamBroken,
                                     const std::string& rule) {
  double worst = 0;
  for (double r : ratio) worst = std::max(worst, r);
  if (worst < 1.0) return {};
  const double threshold = rule == "all" ? 1.0 : worst * (1.0 - 1e-9);
  std::vector<int> overloaded;
  for (std::size_t e = 0; e < ratio.size(); ++e)
    if (!beamBroken[e] && ratio[e] >= threshold) overloaded.push_back(static_cast<int>(e));
  return overloaded;
}

// Book the energy a deleted rod element releases as rod fracture energy: its strain energy 1/2 u^T K_e u,
// and with a consistent mass the kinetic energy of the mass lumping 1/2 v^T (M_e,consistent - M_e,lumped) v.
void bookEnergyOfDeletedBeam(const Model& m, const Materials& mat, int e, bool consistentMass, State& s) {
  const int a = m.beamNodes[e][0], b = m.beamNodes[e][1];
  const int c = m.beamClass(e);
  const beam::Vec12 u = gatherElement(s.q, a, b), v = gatherElement(s.v, a, b);
  s.rodFractureEnergy += 0.5 * u.dot(mat.beamK[c] * u);
  if (consistentMass) s.rodFractureEnergy += 0.5 * v.dot((mat.beamMc[c] - mat.beamMl[c]) * v);
}

}  // namespace

// A deleted element's stiffness (and its stiffness damping) is removed; its consistent mass is replaced by
// the lumped mass of the same element, so no material mass vanishes and no node is left massless (the paper
// subtracts M_e, eq. 17; see docs/model.md, departures). The energy it held is booked as rod fracture energy.
int Simulation::deleteOverloadedBeams() {
  lastDeleted.clear();
  if (!materials.rodsBreakable) return 0;
  checkStressRatiosForBeams(model, materials, state.q, state.beamBroken, state.step, integrator->lastStepMoveBound(),
                            stressSchedule_, beamStressRatio_);
  lastDeleted = findOverloadedBeams(beamStressRatio_, state.beamBroken, materials.deletionRule);
  if (lastDeleted.empty()) return 0;
  for (int e : lastDeleted) {
    bookEnergyOfDeletedBeam(model, materials, e, integrator->usesConsistentMass(), state);
    removeBeamFromMatrices(model, materials, e, ops);
    state.beamBroken[e] = 1;
    state.deletionOrder.push_back(e);
  }
  integrator->updateOperators(ops);
  return static_cast<int>(lastDeleted.size());
}

void Simulation::replayDeletions() {
  for (int e : state.deletionOrder) removeBeamFromMatrices(model, materials, e, ops);
  if (!state.deletionOrder.empty()) integrator->updateOperators(ops);
}

// --- measurements ---------------------------------------------------------------------------------------
double Simulation::strainEnergyOfBeams() const { return 0.5 * state.q.dot(ops.K * state.q); }

double Simulation::strainEnergyOfInterfaces() const {
  // Energies per interface in parallel, then one sum in a fixed order: the result (and so the energy
  // balance and its checks) does not depend on the thread count.
  const Model& m = model;
  std::vector<double> energy(m.numInterfaces());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < m.numInterfaces(); ++i) {
    energy[i] = m.ifaceGeom[i].area *
                cohesive::storedEnergyDensity(materials.law, computeLocalOpening(m, state.q, i), state.lambdaMax[i]);
  }
  return std::accumulate(energy.begin(), energy.end(), 0.0);
}

double Simulation::fractureEnergyOfInterfaces() const {
  double sum = 0;
  for (int i = 0; i < model.numInterfaces(); ++i)
    sum += model.ifaceGeom[i].area * cohesive::dissipatedEnergyDensity(materials.law, state.lambdaMax[i]);
  return sum;
}

int Simulation::countFailedInterfaces() const {
  int n = 0;
  for (double lm : state.lambdaMax) n += cohesive::isFailed(materials.law, lm);
  return n;
}

// How far the inelastic zone reaches from the crack plane: the largest |y - y_crack| over the interfaces past
// delta0 and the deleted rod elements, each at the midpoint of its two nodes' reference positions (0 while
// everything is elastic). The runner warns when it comes near the loaded edges (the R-curve then depends on
// the specimen's height: studies/scene/README.md).
double Simulation::inelasticReach() const { return std::max(inelasticInterfaceReach(), brokenRodReach()); }

namespace {
double distanceFromCrackPlane(const Model& m, const std::array<int, 2>& n) {
  return std::abs(0.5 * (m.X[n[0]].y() + m.X[n[1]].y()) - m.yCrack);
}
}  // namespace

double Simulation::inelasticInterfaceReach() const {
  double reach = 0;
  for (int i = 0; i < model.numInterfaces(); ++i)
    if (cohesive::isInelastic(materials.law, state.lambdaMax[i]))
      reach = std::max(reach, distanceFromCrackPlane(model, model.ifaceNodes[i]));
  return reach;
}

double Simulation::brokenRodReach() const {
  double reach = 0;
  for (int e = 0; e < model.numBeams(); ++e)
    if (state.beamBroken[e]) reach = std::max(reach, distanceFromCrackPlane(model, model.beamNodes[e]));
  return reach;
}

int Simulation::countInelasticInterfaces() const {
  int n = 0;
  for (double lm : state.lambdaMax) n += cohesive::isInelastic(materials.law, lm);
  return n;
}

// J at the outer boundary (docs/model.md), per unit thickness B:
//   J = (1/B) [ - sum_{loaded nodes} F_y (du_y/dx)  +  W_right - W_left ]
// with F_y the force the grips apply, du_y/dx = -/+ U / w_s on the top/bottom rows, and W the strain energy
// per unit length in x at the free left and right faces (first slice: beams of the first segment over h_e,
// interfaces of the end slice over their tributary h_e / 2; in a reduced far field an element spanning n
// slices over n h_e, and an interface over the length along x it stands for, area / edge length).
double Simulation::computeJ() const {
  const Model& m = model;
  const double U = state.appliedDisplacement;
  double sumFdudx = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
    const double dudx = ops.prescribedShape[i] >= 0 ? -U / m.w_s : U / m.w_s;
    sumFdudx += state.reaction[i] * dudx;
  }
  // side 0: the left face (slice 0, the elements starting there); 1: the right face (the last slice)
  auto faceEnergyDensity = [&](int slice, int side) {
    double eb = 0, ebLong = 0, ei = 0;
    for (int e = 0; e < m.numBeams(); ++e) {
      if (state.beamBroken[e] || m.nodeSlice[m.beamNodes[e][side]] != slice) continue;
      const beam::Vec12 u = gatherElement(state.q, m.beamNodes[e][0], m.beamNodes[e][1]);
      const double energy = 0.5 * u.dot(materials.beamK[m.beamClass(e)] * u);
      if (m.beamSpan[e] == 1) eb += energy;
      else ebLong += energy / (m.beamSpan[e] * m.h_e);
    }
    for (int i = 0; i < m.numInterfaces(); ++i) {
      if (m.ifaceSlice[i] != slice) continue;
      const double w = cohesive::storedEnergyDensity(materials.law, computeLocalOpening(m, state.q, i), state.lambdaMax[i]);
      ei += m.hasFarField() ? m.ifaceEdgeLength[i] * w * (0.5 * m.h_e) : m.ifaceGeom[i].area * w;
    }
    return eb / m.h_e + ebLong + ei / (0.5 * m.h_e);
  };
  const double Wleft = faceEnergyDensity(0, 0);
  const double Wright = faceEnergyDensity(m.numSlices - 1, 1);
  return (-sumFdudx + Wright - Wleft) / m.B;
}

// Crack tip (docs/model.md): the connected cluster of failed interfaces and deleted rod elements that
// touches the pre-crack. Each element touches (rod, slice) points (an interface: its two rods in its slice;
// a rod element: its rod at its two slices); two elements are connected when they touch the same rod in the
// same or adjacent slices. Delta_a = max x over the cluster - a0 (projected on x); daughter cracks do not count.
double Simulation::measureCrackAdvance() const {
  const Model& m = model;
  const int ns = m.numSlices;
  struct Touch { long key; int elem; };
  std::vector<Touch> touches;
  std::vector<double> elemX;
  std::vector<char> seed;
  auto addElem = [&](double x, bool isSeed, std::initializer_list<std::pair<int, int>> pts) {
    const int id = static_cast<int>(elemX.size());
    elemX.push_back(x);
    seed.push_back(isSeed);
    for (auto [rod, slice] : pts) touches.push_back({static_cast<long>(rod) * ns + slice, id});
  };
  for (std::size_t i = 0; i < m.precrackIfaceRods.size(); ++i)
    addElem(m.precrackIfaceSlice[i] * m.h_e, true,
            {{m.precrackIfaceRods[i][0], m.precrackIfaceSlice[i]}, {m.precrackIfaceRods[i][1], m.precrackIfaceSlice[i]}});
  for (std::size_t i = 0; i < m.precrackBeamRod.size(); ++i)
    addElem((m.precrackBeamSlice[i] + 0.5) * m.h_e, true,
            {{m.precrackBeamRod[i], m.precrackBeamSlice[i]}, {m.precrackBeamRod[i], m.precrackBeamSlice[i] + 1}});
  for (int i = 0; i < m.numInterfaces(); ++i) {
    if (!cohesive::isFailed(materials.law, state.lambdaMax[i])) continue;
    const int k = m.ifaceSlice[i];
    addElem(k * m.h_e, false, {{m.nodeRod[m.ifaceNodes[i][0]], k}, {m.nodeRod[m.ifaceNodes[i][1]], k}});
  }
  for (int e = 0; e < m.numBeams(); ++e) {
    if (!state.beamBroken[e]) continue;
    const int k = m.nodeSlice[m.beamNodes[e][0]];
    addElem((k + 0.5) * m.h_e, false, {{m.beamRod[e], k}, {m.beamRod[e], k + 1}});
  }
  std::sort(touches.begin(), touches.end(), [](const Touch& x, const Touch& y) {
    return x.key < y.key || (x.key == y.key && x.elem < y.elem);
  });
  std::vector<std::vector<int>> elemTouches(elemX.size());
  for (const Touch& t : touches) elemTouches[t.elem].push_back(static_cast<int>(t.key));
  auto range = [&](long key) {
    auto lo = std::lower_bound(touches.begin(), touches.end(), key, [](const Touch& t, long k) { return t.key < k; });
    auto hi = lo;
    while (hi != touches.end() && hi->key == key) ++hi;
    return std::make_pair(lo, hi);
  };
  std::vector<char> visited(elemX.size(), 0);
  std::vector<int> stack;
  for (std::size_t i = 0; i < elemX.size(); ++i)
    if (seed[i]) { visited[i] = 1; stack.push_back(static_cast<int>(i)); }
  double maxX = 0;
  while (!stack.empty()) {
    const int e = stack.back();
    stack.pop_back();
    maxX = std::max(maxX, elemX[e]);
    for (int key : elemTouches[e]) {
      const int slice = key % ns;
      for (int dk = -1; dk <= 1; ++dk) {
        if (slice + dk < 0 || slice + dk >= ns) continue;
        auto [lo, hi] = range(key + dk);
        for (auto it = lo; it != hi; ++it)
          if (!visited[it->elem]) { visited[it->elem] = 1; stack.push_back(it->elem); }
      }
    }
  }
  return std::max(0.0, maxX - m.a0);
}

Measurement Simulation::measure() const {
  Measurement r;
  r.step = state.step;
  r.time = state.time;
  r.appliedDisplacement = state.appliedDisplacement;
  r.rateMultiplier = state.rateMultiplier;
  r.J = computeJ();
  r.crackAdvance = state.crackAdvance;
  r.kinetic = integrator->kineticEnergy(ops, state);
  // beyond the quasi-static motion q' = (U'/U) q; U' the grips' velocity now
  const double U = state.appliedDisplacement;
  const double rate = U > 0 ? computeGripVelocity(materials.loading, state, 0.0, integrator->timeStep()) / U : 0.0;
  r.kineticBeyond = integrator->kineticEnergyBeyond(ops, state, rate);
  r.strainBeams = strainEnergyOfBeams();
  r.strainInterfaces = strainEnergyOfInterfaces();
  r.damping = state.dampingWork;
  r.fracture = fractureEnergyOfInterfaces();
  r.rodFracture = state.rodFractureEnergy;
  r.external = state.externalWork;
  const double stored = r.kinetic + r.strainBeams + r.strainInterfaces + r.damping + r.fracture + r.rodFracture;
  r.balanceError = r.external > 0 ? (r.external - stored) / r.external : 0.0;
  r.brokenBeams = state.brokenBeams();
  r.failedInterfaces = countFailedInterfaces();
  r.inelasticInterfaces = countInelasticInterfaces();
  r.inelasticReach = inelasticReach();
  double P = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) P += state.reaction[i] * ops.prescribedShape[i];
  r.load = P;
  return r;
}

}  // namespace enamel
