#include "kernels/kernels.hpp"
#include "kernels/node_blocks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "base/errors.hpp"
#include "kernels/loading_rate.hpp"

namespace enamel {

// --- loading -------------------------------------------------------------------------------------------
double Loading::velocity(double t) const {
  if (t >= rampTime) return vApp;
  return vApp * 0.5 * (1.0 - std::cos(M_PI * t / rampTime));
}
double Loading::displacement(double t) const {
  if (rampTime <= 0) return vApp * t;
  if (t >= rampTime) return vApp * (0.5 * rampTime + (t - rampTime));
  return vApp * (0.5 * t - rampTime / (2 * M_PI) * std::sin(M_PI * t / rampTime));
}
double Loading::acceleration(double t) const {
  if (t >= rampTime) return 0.0;
  return vApp * 0.5 * M_PI / rampTime * std::sin(M_PI * t / rampTime);
}

double Loading::timeOfDisplacement(double U) const {
  if (U <= 0) return 0.0;
  if (rampTime <= 0) return U / vApp;
  if (U >= displacement(rampTime)) return U / vApp + 0.5 * rampTime;  // U = v_app (t - T_r / 2)
  double lo = 0, hi = rampTime;
  for (int it = 0; it < 200 && hi - lo > 4 * std::numeric_limits<double>::epsilon() * rampTime; ++it) {
    const double mid = 0.5 * (lo + hi);
    (displacement(mid) < U ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

beam::Vec12 gatherElement(const VecX& q, int a, int b) {
  beam::Vec12 u;
  u.head<6>() = q.segment<6>(6 * a);
  u.tail<6>() = q.segment<6>(6 * b);
  return u;
}

// --- prescribed DOFs: u_p = shape_p U(tau), tau = t unless the rate is adaptive ---------------------------
void prescribeDisplacements(const Operators& ops, const Loading& loading, State& s) {
  const double U = loading.displacement(s.loadingTime);
  s.appliedDisplacement = U;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) s.q[ops.prescribedDofs[i]] = ops.prescribedShape[i] * U;
}

void prescribeVelocities(const Operators& ops, double V, VecX& v) {
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) v[ops.prescribedDofs[i]] = ops.prescribedShape[i] * V;
}

double computeGripVelocity(const Loading& loading, const State& s, double h, double dt) {
  if (!loading.adaptive()) return loading.velocity(s.time + h);
  const LoadingClock c = loadingClockAt(s, h, dt);
  return c.phi * loading.velocity(c.tau);
}

void applyBoundaryConditions(const Operators& ops, const Loading& loading, double dt, State& s) {
  prescribeDisplacements(ops, loading, s);
  if (!loading.adaptive()) {
    prescribeVelocities(ops, loading.velocity(s.time), s.v);
    prescribeVelocities(ops, loading.acceleration(s.time), s.a);
    return;
  }
  const LoadingClock c = loadingClockAt(s, 0.0, dt);
  prescribeVelocities(ops, c.phi * loading.velocity(c.tau), s.v);
  prescribeVelocities(ops, c.phi * c.phi * loading.acceleration(c.tau) + c.phiRate * loading.velocity(c.tau), s.a);
}

// --- interfaces ----------------------------------------------------------------------------------------
namespace {
// w += the wrench of one interface end (six doubles: force, moment)
[[gnu::always_inline]] inline void addWrench(double* w, const cohesive::Wrench& e) {
  for (int c = 0; c < 3; ++c) w[c] += e.force[c], w[3 + c] += e.moment[c];
}

// addWrench of both ends, A then B, from the force on B, written out: wA -= (F_B, rA x F_B), wB += (F_B, rB x F_B),
// which is adding cohesive::wrenchOnSide's (F_A, rA x F_A) with F_A = -F_B (a + (-b) = a - b, and
// (-x) - (-y) = -(x - y), exactly), in six scalar sums per end.
[[gnu::always_inline]] inline void addWrenchesOfForce(const cohesive::SliceInterface& g, const cohesive::Vec3& F,
                                                      double* wA, double* wB) {
  const double fx = F.x(), fy = F.y(), fz = F.z();
  wA[0] -= fx, wA[1] -= fy, wA[2] -= fz;
  wA[3] -= g.armAy * fz - g.armAz * fy, wA[4] -= g.armAz * fx, wA[5] += g.armAy * fx;
  wB[0] += fx, wB[1] += fy, wB[2] += fz;
  wB[3] += g.armBy * fz - g.armBz * fy, wB[4] += g.armBz * fx, wB[5] += -(g.armBy * fx);
}
}  // namespace

// Per interface: its force on B (the compact form's opening, law and force), then the wrench on A and on B
// added to their nodes' six sums. A node's sum receives its interface ends in ascending interface order, the
// order of the CSR Operators::nodeIfaceList, from +0: the sums a per-node gather in that order would make.
[[gnu::flatten]] int addInterfaceWrenchesOfSlice(const Model& m, const cohesive::Law& lawGiven, const Operators& ops,
                                                 int k, const double* q, double* lambdaMax, bool update,
                                                 double* wrench) {
  const cohesive::Law law = lawGiven;  // a local copy: the stores below cannot alias it, so it stays in registers
  int failed = 0;
  const int first = ops.sliceIfaceStart[k], last = ops.sliceIfaceStart[k + 1], firstNode = ops.sliceNodeStart[k];
  std::fill(wrench, wrench + 6 * (ops.sliceNodeStart[k + 1] - firstNode), 0.0);
  const auto* nodes = m.ifaceNodes.data();
  const cohesive::SliceInterface* packed = ops.ifacePacked.data();
  using Map3 = Eigen::Map<const cohesive::Vec3>;
  for (int i = first; i < last; ++i) {
    const int A = nodes[i][0], B = nodes[i][1];
    const double before = lambdaMax[i];
    double lm = before;
    const cohesive::Vec3 F = cohesive::computeInterfaceForceOnB(law, packed[i], Map3(q + 6 * A), Map3(q + 6 * A + 3),
                                                                Map3(q + 6 * B), Map3(q + 6 * B + 3), lm);
    if (update && lm != before) lambdaMax[i] = lm;  // most interfaces keep theirs: no store
    failed += cohesive::isFailed(law, lm);
    addWrench(wrench + 6 * (A - firstNode), cohesive::wrenchOnSide(packed[i], F, false));
    addWrench(wrench + 6 * (B - firstNode), cohesive::wrenchOnSide(packed[i], F, true));
  }
  return failed;
}

namespace {
// c of InterfaceSchedule: a bound on |lambda change| / |q change|_inf. The opening's 2-norm moves by at most
// sqrt(3) (2 + |arms|) |q change|_inf, and lambda of the mixed-mode law (weight 1/beta^2 on the shear part of
// lambda^2) by at most max(1, 1/beta) times that; the factor is 1 exactly at beta = 1.
double separationRate(const cohesive::Law& law, const cohesive::SliceInterface& g) {
  const double shearFactor = std::max(1.0, std::sqrt(law.shearWeight));
  return shearFactor * std::sqrt(3.0) *
         (2.0 + std::abs(g.armAy) + std::abs(g.armAz) + std::abs(g.armBy) + std::abs(g.armBz));
}

double lambdaTrack(const cohesive::Law& law) { return std::sqrt(cohesive::kElasticTrack) * law.delta0(); }

// A due interface: the law at its opening (history updated) and the drift from which it is due again. Off the
// elastic branch it is due at every step, and `correction` is its force beyond the elastic one (the law's minus
// elasticForceOnB): returns true; on the elastic branch its force is the elastic one: returns false.
// Not inlined: at most steps few interfaces are due, and addInterfaceCorrectionsOfSliceScheduled is flattened,
// which would otherwise inline the law into its scan of the schedule.
[[gnu::noinline]] bool evaluateDueInterface(const cohesive::Law& law, const cohesive::SliceInterface& g,
                                            const double* qA, const double* qB, double drift, double& lambdaMax,
                                            double& due, int& failed, cohesive::Vec3& correction) {
  using Map3 = Eigen::Map<const cohesive::Vec3>;
  const Map3 uA(qA), thA(qA + 3), uB(qB), thB(qB + 3);
  const cohesive::Vec3 opening = cohesive::localOpening(g, cohesive::computeOpening(g, uA, thA, uB, thB));
  const cohesive::Vec3 t = cohesive::computeTraction(law, opening, lambdaMax);
  failed += cohesive::isFailed(law, lambdaMax);
  if (cohesive::secantStiffness(law, lambdaMax) != law.k) {
    due = drift;  // off the elastic branch: the law at every step
    correction = cohesive::forceOnBOfTraction(g, t) - cohesive::elasticForceOnB(law, g, uA, thA, uB, thB);
    return true;
  }
  const double room = (1.0 - kInterfaceScheduleMargin) * lambdaTrack(law) - cohesive::effectiveSeparation(law, opening);
  due = room > 0 ? drift + room / separationRate(law, g) : drift;  // (a NaN opening: due again)
  return false;
}
}  // namespace

void advanceInterfaceSchedule(const Model& m, const cohesive::Law& law, const Operators& ops, double moved,
                              const std::vector<double>& sliceMoved, double largestValue, InterfaceSchedule& schedule) {
  if (!std::isfinite(moved) || static_cast<int>(schedule.due.size()) != m.numInterfaces()) {
    schedule.drift.assign(m.numSlices, 0.0);
    schedule.due.assign(m.numInterfaces(), 0.0);
    schedule.sliceChunkStart.assign(m.numSlices + 1, 0);
    for (int k = 0; k < m.numSlices; ++k) {
      const int interfaces = ops.sliceIfaceStart[k + 1] - ops.sliceIfaceStart[k];
      schedule.sliceChunkStart[k + 1] = schedule.sliceChunkStart[k] + (interfaces + kInterfaceChunk - 1) / kInterfaceChunk;
    }
    schedule.chunkDue.assign(schedule.sliceChunkStart[m.numSlices], 0.0);
    schedule.largestRate = 0;
    for (const auto& g : ops.ifacePacked) schedule.largestRate = std::max(schedule.largestRate, separationRate(law, g));
  } else {
    const bool perSlice = static_cast<int>(sliceMoved.size()) == m.numSlices;
    for (int k = 0; k < m.numSlices; ++k)  // the 1e-6 covers the round-off of these running sums
      schedule.drift[k] += (perSlice ? sliceMoved[k] : moved) * (1.0 + 1e-6);
  }
  const double roundOff = 32.0 * std::numeric_limits<double>::epsilon() * schedule.largestRate * largestValue;
  schedule.allDue = !(roundOff <= 0.25 * kInterfaceScheduleMargin * lambdaTrack(law));  // true for a NaN
}

NodeBlockMatrix elasticInterfaceBlocks(const Model& m, const cohesive::Law& law, const Operators& ops) {
  using Block = std::array<double, 36>;
  auto blockOf = [](const Eigen::Matrix<double, 12, 12>& K, int sideRow, int sideColumn) {
    Block b;
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i) b[6 * j + i] = K(6 * sideRow + i, 6 * sideColumn + j);
    return b;
  };
  auto addTo = [](Block& sum, const Block& b) {
    for (int e = 0; e < 36; ++e) sum[e] += b[e];
  };
  auto row = [&](int R, BlockRow& blocks) {
    Block diagonal{};
    for (int e = ops.nodeIfaceStart[R]; e < ops.nodeIfaceStart[R + 1]; ++e) {  // ascending interface order
      const int i = ops.nodeIfaceList[e] / 2, side = ops.nodeIfaceList[e] % 2;
      const Eigen::Matrix<double, 12, 12> K = cohesive::elasticStiffness(law, m.ifaceGeom[i]);
      addTo(diagonal, blockOf(K, side, side));
      const int other = m.ifaceNodes[i][1 - side];
      auto at = std::find_if(blocks.begin(), blocks.end(), [&](const auto& b) { return b.first == other; });
      if (at == blocks.end()) blocks.push_back({other, Block{}}), at = blocks.end() - 1;
      addTo(at->second, blockOf(K, side, 1 - side));
    }
    if (ops.nodeIfaceStart[R] == ops.nodeIfaceStart[R + 1]) return;  // no interface: an empty row
    blocks.push_back({R, diagonal});
    std::stable_sort(blocks.begin(), blocks.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  };
  NodeBlockMatrix K = toNodeBlocks(m.numNodes(), row, kInterfaceGroups, kInterfaceBlockTolerance);
  if (K.split.empty() && !K.values.empty())
    throw SolverError("interface stiffness: couples (ux, ry, rz) with (uy, uz, rx): an interface not in its slice");
  return K;
}

[[gnu::flatten]] SliceCorrections addInterfaceCorrectionsOfSliceScheduled(
    const Model& m, const cohesive::Law& lawGiven, const Operators& ops, int k, const double* q, double* lambdaMax,
    InterfaceSchedule& schedule, double* wrench, long& evaluated) {
  const double drift = schedule.drift[k], dueBelow = schedule.allDue ? INFINITY : drift;
  SliceCorrections pass;
  const cohesive::Law law = lawGiven;  // a local copy, as in addInterfaceWrenchesOfSlice
  const int first = ops.sliceIfaceStart[k], last = ops.sliceIfaceStart[k + 1], firstNode = ops.sliceNodeStart[k];
  const auto* nodes = m.ifaceNodes.data();
  const cohesive::SliceInterface* packed = ops.ifacePacked.data();
  double* due = schedule.due.data();
  double* chunkDue = schedule.chunkDue.data();
  for (int c = schedule.sliceChunkStart[k], i = first; c < schedule.sliceChunkStart[k + 1]; ++c) {
    const int end = std::min(last, i + kInterfaceChunk);
    if (chunkDue[c] > dueBelow) {  // none due: all elastic, their forces in K_I q
      i = end;
      continue;
    }
    if (!pass.wrench) std::fill(wrench, wrench + 6 * (ops.sliceNodeStart[k + 1] - firstNode), 0.0);
    pass.wrench = true;
    ++pass.chunks;
    double smallest = INFINITY;
    for (; i < end; ++i) {
      if (due[i] <= dueBelow) {  // otherwise elastic, and its force is in K_I q
        const int A = nodes[i][0], B = nodes[i][1];
        cohesive::Vec3 correction;
        ++evaluated;
        if (evaluateDueInterface(law, packed[i], q + 6 * A, q + 6 * B, drift, lambdaMax[i], due[i], pass.failed, correction))
          addWrenchesOfForce(packed[i], correction, wrench + 6 * (A - firstNode), wrench + 6 * (B - firstNode));
      }
      smallest = std::min(smallest, due[i]);
    }
    chunkDue[c] = smallest;
  }
  return pass;
}

cohesive::Vec3 computeLocalOpening(const Model& m, const VecX& q, int i) {
  const int A = m.ifaceNodes[i][0], B = m.ifaceNodes[i][1];
  const auto& g = m.ifaceGeom[i];
  return g.frame * cohesive::computeOpening(g, q.segment<3>(6 * A), q.segment<3>(6 * A + 3), q.segment<3>(6 * B),
                                            q.segment<3>(6 * B + 3));
}

// f_iface = -(the wrench the interfaces exert on each node), slice by slice into a buffer of the thread.
int computeForcesForInterfaces(const Model& m, const cohesive::Law& law, const Operators& ops, const VecX& q,
                               std::vector<double>& lambdaMax, bool update, VecX& f) {
  f.resize(m.numDofs());
  // Private to each thread, so that they stay in registers (Eigen's vector stores may alias anything: shared
  // pointers are reloaded after every interface): the law, and where the histories go.
  const cohesive::Law lawHere = law;
  double* lambda = lambdaMax.data();
  int failed = 0;
#pragma omp parallel reduction(+ : failed) firstprivate(lawHere, lambda)
  {
    std::vector<double> wrench(6 * static_cast<std::size_t>(ops.maxNodesPerSlice));
#pragma omp for schedule(static)
    for (int k = 0; k < m.numSlices; ++k) {
      failed += addInterfaceWrenchesOfSlice(m, lawHere, ops, k, q.data(), lambda, update, wrench.data());
      const int firstNode = ops.sliceNodeStart[k];
      for (int dof = 6 * firstNode; dof < 6 * ops.sliceNodeStart[k + 1]; ++dof) f[dof] = -wrench[dof - 6 * firstNode];
    }
  }
  return failed;
}

// --- rod elements --------------------------------------------------------------------------------------
namespace {
// sigma = max tensile stress of the local end forces f_l = (K_local T) u_e, of which only the rows
// beam::kStressRows enter. Always inlined: the deletion check below runs it for every rod element at every
// step (a call costs ~20% of that loop).
[[gnu::always_inline]] inline double stressOfBeam(const Model& m, const Materials& mat, const VecX& q, int e) {
  const beam::Vec5 fl = mat.beamStressOperator[m.beamClass(e)].lazyProduct(
      gatherElement(q, m.beamNodes[e][0], m.beamNodes[e][1]));
  return beam::maxTensileStressOfRows(mat.section, fl);
}

// The alternative definitions of case key rod_stress (choices.hpp RodStress); axial_bending is stressOfBeam above.
// principal reads one more row of K_local T, the torque.
double stressOfBeamAlternative(const Model& m, const Materials& mat, const VecX& q, int e) {
  const int c = m.beamClass(e);
  const beam::Vec12 ue = gatherElement(q, m.beamNodes[e][0], m.beamNodes[e][1]);
  const beam::Vec5 fl = mat.beamStressOperator[c].lazyProduct(ue);
  const double torque = mat.rodStress == RodStress::principal ? mat.beamTorsionOperator[c].dot(ue) : 0.0;
  return beam::rodStressOfRows(mat.rodStress, mat.section, fl, torque);
}
}  // namespace

double computeStressOfBeam(const Model& m, const Materials& mat, const VecX& q, int e) {
  if (mat.rodStress != RodStress::axial_bending) return stressOfBeamAlternative(m, mat, q, e);
  return stressOfBeam(m, mat, q, e);
}

void computeStressRatiosForBeams(const Model& m, const Materials& mat, const VecX& q,
                                 const std::vector<std::uint8_t>& beamBroken, std::vector<double>& ratio) {
  ratio.resize(m.numBeams());
  if (mat.rodStress != RodStress::axial_bending) {  // rod_stress alternatives: off the default's loop
#pragma omp parallel for schedule(static)
    for (int e = 0; e < m.numBeams(); ++e)
      ratio[e] = beamBroken[e] ? 0.0 : stressOfBeamAlternative(m, mat, q, e) / mat.beamStrength[e];
    return;
  }
#pragma omp parallel for schedule(static)
  for (int e = 0; e < m.numBeams(); ++e) ratio[e] = beamBroken[e] ? 0.0 : stressOfBeam(m, mat, q, e) / mat.beamStrength[e];
}

namespace {
// A fresh schedule: drifts 0, every element due, and which pair of slices each element's drift follows.
void startStressCheckSchedule(const Model& m, StressCheckSchedule& schedule) {
  const int ne = m.numBeams();
  schedule.drift = 0;
  schedule.pairDrift.assign(std::max(0, m.numSlices - 1), 0.0);
  schedule.pairOf.assign(ne, -1);
  for (int e = 0; e < ne; ++e) {
    const int a = m.nodeSlice[m.beamNodes[e][0]], b = m.nodeSlice[m.beamNodes[e][1]];
    if (std::abs(a - b) == 1) schedule.pairOf[e] = std::min(a, b);
  }
  schedule.due.assign(ne, 0.0);
  const int chunks = (ne + kStressCheckChunk - 1) / kStressCheckChunk;
  schedule.chunkDue.assign(chunks, 0.0);
  schedule.chunkPairs.assign(2 * static_cast<std::size_t>(chunks), 0);
  schedule.chunkFollowsDrift.assign(chunks, 0);
  for (int c = 0; c < chunks; ++c) {
    int first = std::numeric_limits<int>::max(), last = -1;
    for (int e = c * kStressCheckChunk; e < std::min(ne, (c + 1) * kStressCheckChunk); ++e) {
      const int pair = schedule.pairOf[e];
      if (pair < 0) schedule.chunkFollowsDrift[c] = 1;
      else first = std::min(first, pair), last = std::max(last, pair);
    }
    schedule.chunkPairs[2 * c] = first, schedule.chunkPairs[2 * c + 1] = last;
  }
}

// The largest drift any element of chunk c follows.
double driftOfChunk(const StressCheckSchedule& schedule, int c) {
  double drift = schedule.chunkFollowsDrift[c] ? schedule.drift : 0.0;
  for (int pair = schedule.chunkPairs[2 * c]; pair <= schedule.chunkPairs[2 * c + 1]; ++pair)
    drift = std::max(drift, schedule.pairDrift[pair]);
  return drift;
}

// After a step that moved by at most `moved` (and sliceMoved[k] in slice k, where given): every drift grows by
// its bound; the 1e-6 covers the round-off of these running sums.
void advanceStressCheckDrifts(double moved, const std::vector<double>& sliceMoved, StressCheckSchedule& schedule) {
  schedule.drift += moved * (1.0 + 1e-6);
  const bool perSlice = sliceMoved.size() == schedule.pairDrift.size() + 1;
  for (std::size_t k = 0; k < schedule.pairDrift.size(); ++k)
    schedule.pairDrift[k] += (perSlice ? std::max(sliceMoved[k], sliceMoved[k + 1]) : moved) * (1.0 + 1e-6);
}
}  // namespace

// Every element afresh (drifts 0, all due), or after a step that moved by `moved` (`sliceMoved` per slice): only
// those whose due drift has come; each computed one gets its next due drift from its margin to
// 1 - kStressScheduleMargin.
void checkStressRatiosForBeams(const Model& m, const Materials& mat, const VecX& q,
                               const std::vector<std::uint8_t>& beamBroken, long step, double moved,
                               const std::vector<double>& sliceMoved, StressCheckSchedule& schedule,
                               std::vector<double>& ratio) {
  const int ne = m.numBeams();
  if (mat.rodStress != RodStress::axial_bending || !std::isfinite(moved)) {  // no bound: compute them all
    computeStressRatiosForBeams(m, mat, q, beamBroken, ratio);
    schedule.step = -1;
    schedule.computed = ne;
    schedule.visitedChunks = (ne + kStressCheckChunk - 1) / kStressCheckChunk;  // every element read
    schedule.largestRatio = 0;
    for (double r : ratio) schedule.largestRatio = std::max(schedule.largestRatio, r);
    return;
  }
  if (schedule.step < 0 || step != schedule.step + 1 || static_cast<int>(schedule.due.size()) != ne) {
    startStressCheckSchedule(m, schedule);
    ratio.assign(ne, 0.0);
  } else {
    advanceStressCheckDrifts(moved, sliceMoved, schedule);
  }
  schedule.step = step;
  const double globalDrift = schedule.drift;
  const double* pairDrift = schedule.pairDrift.data();
  const int* pairOf = schedule.pairOf.data();
  double* due = schedule.due.data();
  long computed = 0, visited = 0;
  double largest = 0;
  const int chunks = static_cast<int>(schedule.chunkDue.size());
#pragma omp parallel for schedule(static) reduction(+ : computed, visited) reduction(max : largest)
  for (int c = 0; c < chunks; ++c) {
    if (schedule.chunkDue[c] > driftOfChunk(schedule, c)) continue;  // none of its elements is due
    ++visited;
    double chunkDue = INFINITY;
    for (int e = c * kStressCheckChunk; e < std::min(ne, (c + 1) * kStressCheckChunk); ++e) {
      if (beamBroken[e]) {  // it broke after the check that made its chunk due, so its chunk is read
        ratio[e] = 0.0;
        continue;
      }
      const double drift = pairOf[e] < 0 ? globalDrift : pairDrift[pairOf[e]];
      if (due[e] <= drift) {  // otherwise it cannot have reached 1 - margin since its last computation
        const double strength = mat.beamStrength[e];
        const double r = stressOfBeam(m, mat, q, e) / strength;
        ratio[e] = r;
        largest = std::max(largest, r);
        due[e] = drift + std::max(0.0, 1.0 - kStressScheduleMargin - r) * strength /
                             mat.beamStressChangeBound[m.beamClass(e)];
        ++computed;
      }
      if (!(due[e] >= chunkDue)) chunkDue = due[e];  // (a NaN due keeps the chunk due)
    }
    schedule.chunkDue[c] = chunkDue;
  }
  schedule.computed = computed;
  schedule.visitedChunks = visited;
  schedule.largestRatio = largest;
}

namespace {
void addElementInPlace(SpMat& A, const beam::Mat12& Ke, int a, int b, double sign) {
  const int dof[2] = {6 * a, 6 * b};
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) A.coeffRef(dof[i / 6] + i % 6, dof[j / 6] + j % 6) += sign * Ke(i, j);
}
}  // namespace

// K -= K_e;  M -= (M_e,consistent - M_e,lumped)
void removeBeamFromMatrices(const Model& m, const Materials& mat, int e, Operators& ops) {
  const int a = m.beamNodes[e][0], b = m.beamNodes[e][1];
  const int c = m.beamClass(e);
  addElementInPlace(ops.K, mat.beamK[c], a, b, -1.0);
  addElementInPlace(ops.M, mat.beamMc[c] - mat.beamMl[c], a, b, -1.0);
}

}  // namespace enamel
